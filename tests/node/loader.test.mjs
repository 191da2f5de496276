// The chunk loader (web/loader.js) on a network and a clock the test drives: what it decides
// (which request goes when, and why) read from its log, never timed. The browser tests
// (tests/browser/network.test.mjs) run the same loader against real servers.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { ChunkLoader, LOG_LIMIT, MAX_AHEAD, MAX_IN_FLIGHT, MAX_IN_FLIGHT_MULTIPLEXED } from '../../web/loader.js';
import { FetchError } from '../../web/net.js';

globalThis.navigator ??= { onLine: true }; // notice() reads it

// Timers that fire only when the test moves the time on.
class FakeTimers {
  constructor() {
    this.time = 1000; // a page's clock is never at 0
    this.timers = new Map();
    this.ids = 0;
  }
  now() { return this.time; }
  setTimeout(fn, ms) {
    this.timers.set(++this.ids, { end: this.time + ms, fn });
    return this.ids;
  }
  clearTimeout(id) { this.timers.delete(id); }
  advance(ms) {
    this.time += ms;
    for (const [id, t] of [...this.timers].sort((a, b) => a[1].end - b[1].end)) {
      if (t.end > this.time) continue;
      this.timers.delete(id);
      t.fn();
    }
  }
}

// Requests stay open until the test answers them: send(r, n) passes n more bytes, finish(r)
// completes the body, fail(r, error) breaks it.
class FakeNetwork {
  constructor() {
    this.requests = [];
    this.fetch = (url, opts) => new Promise((resolve, reject) => {
      const r = { url, index: Number(/(\d+)$/.exec(url)[1]), opts, received: 0, open: true, resolve, reject };
      this.requests.push(r);
      opts.signal.addEventListener('abort', () => {
        r.open = false;
        reject(new FetchError('cancelled', { kind: 'aborted' }));
      });
    });
  }
  open() { return this.requests.filter((r) => r.open); }
  send(r, n) {
    r.received += n;
    r.opts.onProgress(n);
  }
  finish(r) {
    r.open = false;
    r.resolve(new Uint8Array(r.received));
  }
  fail(r, error) {
    r.open = false;
    r.reject(error);
  }
}

const settle = () => new Promise((resolve) => setImmediate(resolve));

function makeLoader({ chunks = 8, size = 64 << 10, timing, ...rest } = {}) {
  const clock = new FakeTimers();
  const net = new FakeNetwork();
  const delivered = [];
  const result = { failed: null, done: false };
  const loader = new ChunkLoader({
    urls: Array.from({ length: chunks }, (_, i) => `chunk-${i}`),
    sizes: new Array(chunks).fill(size),
    check: () => null,
    deliver: (i) => delivered.push(i) > 0,
    fail: (message) => { result.failed = message; },
    done: () => { result.done = true; },
    fetch: net.fetch,
    clock,
    timing: timing ?? (() => null),
    ...rest,
  });
  return { loader, net, clock, delivered, result, size };
}

// A link that sends one response at a time, in request order, `piece` bytes a step: what a
// slow link does with responses that do not overlap.
async function runLink({ loader, net, size, result }, piece = 4096) {
  loader.pump();
  for (let steps = 0; !result.done && steps < 10000; steps++) {
    await settle();
    const r = net.open()[0];
    if (!r) continue;
    net.send(r, Math.min(piece, size - r.received));
    if (r.received === size) net.finish(r);
  }
  assert.ok(result.done, 'the stream ended');
}

const requests = (loader) => loader.log.filter((e) => e.event === 'request');

test('over a slow link the chunks are requested one after another, not as a batch', async () => {
  // 150 KB/s, 30 ms to the first byte (as Resource Timing would report them).
  const link = { firstByteMs: 30, transferMs: (64 << 10) / 150 };
  const run = makeLoader({ timing: () => link });
  await runLink(run);
  assert.deepEqual(run.delivered, [0, 1, 2, 3, 4, 5, 6, 7]);
  assert.equal(run.result.failed, null);
  // Once a response has been measured, the lead is what the link delivers while a request waits
  // for its first byte, with the margin: 150 KB/s × 30 ms × 1.25.
  const firstResponse = run.loader.log.find((e) => e.event === 'response').seq;
  const later = requests(run.loader).filter((e) => e.seq > firstResponse);
  assert.ok(later.length >= 3, `requests after the first response: ${later.length}`);
  for (const e of later) {
    assert.ok(Math.abs(e.lead - 150e3 * 0.030 * 1.25) < 1e-6, `lead of ${JSON.stringify(e)}`);
    assert.ok(e.others.length <= 1, `at most the one before it under way: ${JSON.stringify(e)}`);
    assert.ok(e.outstanding < e.lead, `issued near the end of the one before: ${JSON.stringify(e)}`);
    assert.equal(e.reason, 'first');
  }
});

test('over a fast link several requests are under way together (the lead covers the round trip)', async () => {
  // 10 MB/s, 30 ms to the first byte: 375 KB arrive while a request waits.
  const link = { firstByteMs: 30, transferMs: (64 << 10) / 10000 };
  const run = makeLoader({ chunks: 16, timing: () => link });
  await runLink(run);
  const firstResponse = run.loader.log.find((e) => e.event === 'response').seq;
  const later = requests(run.loader).filter((e) => e.seq > firstResponse);
  assert.ok(later.some((e) => e.others.length >= 2), `batched: ${JSON.stringify(later.map((e) => e.others.length))}`);
  for (const e of later) assert.ok(e.others.length === 0 || e.outstanding < e.lead, JSON.stringify(e));
});

test('over HTTP/2 more small requests are under way together than the six of HTTP/1.1', async () => {
  // Chunks of 4 KB on a 10 MB/s link 100 ms from its first byte: a request waits a round trip
  // for each, so only many under way together fill the link.
  const most = async (protocol) => {
    const link = { firstByteMs: 100, transferMs: 4096 / 10000, protocol };
    const run = makeLoader({ chunks: 64, size: 4096, timing: () => link });
    // All requests answer together once the loader has issued what it will.
    run.loader.pump();
    let peak = 0;
    for (let steps = 0; !run.result.done && steps < 1000; steps++) {
      await settle();
      const open = run.net.open();
      peak = Math.max(peak, open.length);
      for (const r of open) {
        run.net.send(r, 4096);
        run.net.finish(r);
      }
    }
    assert.ok(run.result.done, 'the stream ended');
    assert.deepEqual(run.delivered, Array.from({ length: 64 }, (_, i) => i));
    return peak;
  };
  assert.equal(await most('http/1.1'), MAX_IN_FLIGHT);
  assert.equal(await most(''), MAX_IN_FLIGHT, 'unknown protocol: as HTTP/1.1');
  assert.equal(await most('h2'), MAX_IN_FLIGHT_MULTIPLEXED);
  assert.equal(await most('h3'), MAX_IN_FLIGHT_MULTIPLEXED);
});

test('a 503 is fetched again when its backoff has run out, not before', async () => {
  const run = makeLoader({ chunks: 2 });
  run.loader.pump();
  await settle();
  const first = run.net.open().find((r) => r.index === 0);
  run.net.fail(first, new FetchError('HTTP 503 (Service Unavailable)', { kind: 'http', status: 503, transient: true }));
  await settle();
  const backoff = run.loader.log.findLast((e) => e.event === 'backoff' && e.index === 0);
  assert.ok(backoff.delayMs >= 500 && backoff.delayMs <= 1000, `first backoff: ${backoff.delayMs} ms`);
  assert.match(run.loader.notice(), /^The server answered HTTP 503 \(Service Unavailable\): retrying part 1 of 2 in (1 s|a moment)\.$/);
  run.clock.advance(backoff.delayMs - 1);
  assert.equal(run.net.open().filter((r) => r.index === 0).length, 0, 'still waiting 1 ms before its end');
  run.clock.advance(1);
  const again = requests(run.loader).at(-1);
  assert.deepEqual([again.index, again.reason, again.cause, again.attempt], [0, 'retry', 'http 503', 2]);
  assert.equal(run.loader.retries, 1);
  // The second failure waits longer: 1 to 2 s.
  run.net.fail(run.net.open().find((r) => r.index === 0), new FetchError('HTTP 503', { kind: 'http', status: 503, transient: true }));
  await settle();
  const second = run.loader.log.findLast((e) => e.event === 'backoff' && e.index === 0);
  assert.ok(second.seq > backoff.seq && second.delayMs >= 1000 && second.delayMs <= 2000, `second backoff: ${second.delayMs} ms`);
  run.loader.stop();
});

test('a stalled or dropped request is fetched again, with its cause in the log', async () => {
  const run = makeLoader({ chunks: 1 });
  run.loader.pump();
  await settle();
  run.net.fail(run.net.open()[0], new FetchError('no data for 10 s', { kind: 'stall', transient: true }));
  await settle();
  run.clock.advance(1000);
  run.net.fail(run.net.open()[0], new FetchError('connection lost', { kind: 'network', transient: true }));
  await settle();
  run.clock.advance(2000);
  const r = run.net.open()[0];
  run.net.send(r, run.size);
  run.net.finish(r);
  await settle();
  assert.ok(run.result.done);
  assert.deepEqual(requests(run.loader).map((e) => [e.reason, e.cause]),
    [['first', undefined], ['retry', 'stall'], ['retry', 'network']]);
  assert.deepEqual(run.loader.log.filter((e) => e.event === 'failure').map((e) => e.cause), ['stall', 'network']);
});

test('the online event sends every waiting chunk at once, ending its backoff', async () => {
  const run = makeLoader({ chunks: 3 });
  run.loader.pump();
  await settle();
  for (const r of run.net.open()) run.net.fail(r, new FetchError('connection lost', { kind: 'network', transient: true }));
  await settle();
  assert.equal(run.net.open().length, 0, 'all waiting on their backoff');
  const waiting = [...run.loader.waiting.keys()];
  assert.ok(waiting.length >= 1);
  run.loader.retryNow(); // the clock has not moved
  const online = run.loader.log.find((e) => e.event === 'online');
  assert.deepEqual(online.waiting, waiting);
  const after = requests(run.loader).filter((e) => e.seq > online.seq);
  assert.deepEqual(after.map((e) => e.index), waiting);
  for (const e of after) assert.deepEqual([e.reason, e.cause], ['online', 'network']);
  assert.equal(run.loader.waiting.size, 0);
  run.clock.advance(60000); // the cancelled backoffs send nothing more
  assert.equal(requests(run.loader).length, waiting.length * 2);
  run.loader.stop();
});

test('a pause drops the requests under way and sends none until resumed', async () => {
  const run = makeLoader({ chunks: 4 });
  run.loader.pump();
  await settle();
  const underWay = run.net.open().map((r) => r.index);
  assert.ok(underWay.length >= 1);
  run.loader.setPaused(true);
  await settle();
  assert.equal(run.net.open().length, 0, 'dropped');
  run.clock.advance(60000);
  await settle();
  const pause = run.loader.log.find((e) => e.event === 'pause');
  assert.deepEqual(run.loader.log.filter((e) => e.seq > pause.seq).map((e) => e.event), [], 'nothing while paused');
  run.loader.setPaused(false);
  const resumed = requests(run.loader).filter((e) => e.seq > pause.seq);
  assert.deepEqual(resumed.map((e) => [e.index, e.reason]), underWay.map((i) => [i, 'resume']));
  run.loader.stop();
});

test('the log keeps the newest entries only', () => {
  const run = makeLoader({ chunks: 1 });
  for (let k = 0; k < LOG_LIMIT + 10; k++) run.loader.note({ event: 'pause' });
  assert.equal(run.loader.log.length, LOG_LIMIT);
  assert.equal(run.loader.log[0].seq, 10);
});

// Plans: an order of chunk indices the page may change while streaming.

const notFound = () => new FetchError('HTTP 404 (Not Found)', { kind: 'http', status: 404, transient: false });

// Answers every open request but the ones `hold` names, in full, until none is left.
async function answerAll(net, size, hold = () => false) {
  for (let steps = 0; steps < 100; steps++) {
    await settle();
    const open = net.open().filter((r) => !hold(r.index));
    if (!open.length) return;
    for (const r of open) {
      net.send(r, size);
      net.finish(r);
    }
  }
}

test('chunks are requested and handed over in the order of the plan', async () => {
  const order = [0, 5, 2, 7, 1, 3, 6, 4];
  const run = makeLoader({ order });
  await runLink(run);
  assert.deepEqual(run.delivered, order);
  assert.deepEqual(requests(run.loader).map((e) => e.index), order);
  assert.equal(run.result.failed, null);
});

test('the loader fetches at most MAX_AHEAD plan places past the next chunk to hand over', async () => {
  const order = [0, ...Array.from({ length: 19 }, (_, k) => 19 - k)]; // 0, 19, 18, ..., 1
  const run = makeLoader({ chunks: 20, order });
  run.loader.pump();
  await answerAll(run.net, run.size, (i) => i === 0); // the base does not come yet
  assert.deepEqual(requests(run.loader).map((e) => e.index), order.slice(0, MAX_AHEAD));
  assert.deepEqual(run.delivered, []);
  await answerAll(run.net, run.size);
  assert.deepEqual(run.delivered, order);
  assert.deepEqual(requests(run.loader).map((e) => e.index), order);
  assert.ok(run.result.done);
});

test('a replan drops the requests for chunks it left, keeps the others, and wakes an idle loader', async () => {
  let idle = 0;
  const run = makeLoader({ order: [0, 1, 2, 3, 4, 5, 6, 7], onIdle: () => { idle++; } });
  run.loader.pump();
  await settle();
  const open = () => run.net.open().map((r) => r.index);
  assert.deepEqual(open(), [0, 1, 2, 3], 'the first lead worth of requests');
  const [r0, , r2] = run.net.open();
  run.net.send(r0, run.size);
  run.net.finish(r0);
  run.net.send(r2, run.size);
  run.net.finish(r2);
  await settle();
  assert.deepEqual(run.delivered, [0]);
  assert.deepEqual(open(), [1, 3, 4, 5], 'two more went out as the first two ended');
  const sent = requests(run.loader).length;
  run.loader.replan([3, 5, 6, 0]); // 0 was handed over already: ignored
  const replan = run.loader.log.find((e) => e.event === 'replan');
  assert.equal(replan.count, 3);
  const after = run.loader.log.filter((e) => e.seq > replan.seq);
  assert.deepEqual(after.filter((e) => e.event === 'drop').map((e) => [e.index, e.reason]), [[1, 'replan'], [4, 'replan']]);
  assert.deepEqual(after.filter((e) => e.event === 'discard').map((e) => e.index), [2]);
  assert.deepEqual(requests(run.loader).slice(sent).map((e) => e.index), [6], '3 and 5 are still under way');
  assert.deepEqual(open(), [3, 5, 6]);
  await answerAll(run.net, run.size);
  assert.deepEqual(run.delivered, [0, 3, 5, 6]);
  assert.equal(idle, 1, 'the end of the plan');
  assert.equal(run.result.done, false, 'waiting for more');
  assert.equal(run.loader.stopped, false);
  run.loader.replan([]); // nothing new: still idle, not called again
  assert.equal(idle, 1);
  run.loader.replan([7, 1]);
  assert.deepEqual(open(), [7, 1]);
  await answerAll(run.net, run.size);
  assert.deepEqual(run.delivered, [0, 3, 5, 6, 7, 1]);
  assert.equal(idle, 2);
  assert.deepEqual(requests(run.loader).map((e) => e.index), [0, 1, 2, 3, 4, 5, 6, 7, 1]);
  run.loader.stop();
});

test('a replan from deliver() keeps the chunk being handed over', async () => {
  const run = makeLoader({ chunks: 4, order: [0, 1, 2, 3], onIdle: () => {} });
  run.loader.deliver = (i) => {
    run.delivered.push(i);
    if (i === 0) run.loader.replan([2, 1]);
    return true;
  };
  run.loader.pump();
  await answerAll(run.net, run.size);
  assert.deepEqual(run.delivered, [0, 2, 1]);
  assert.deepEqual(run.loader.plan, [0, 2, 1]);
  run.loader.stop();
});

test('a replan cancels the backoff of a chunk it left', async () => {
  const run = makeLoader({ chunks: 4, order: [0, 1, 2, 3], onIdle: () => {} });
  run.loader.pump();
  await settle();
  const r1 = run.net.open().find((r) => r.index === 1);
  run.net.fail(r1, new FetchError('HTTP 503', { kind: 'http', status: 503, transient: true }));
  await settle();
  assert.ok(run.loader.waiting.has(1));
  run.loader.replan([0, 2, 3]); // 0 is not in yet: still in the plan
  assert.equal(run.loader.waiting.size, 0);
  run.clock.advance(60000);
  assert.equal(requests(run.loader).filter((e) => e.index === 1).length, 1, 'not fetched again');
  await answerAll(run.net, run.size);
  assert.deepEqual(run.delivered, [0, 2, 3]);
  assert.equal(run.loader.notice(), '', 'a chunk out of the plan is no news');
  run.loader.stop();
});

test('with onChunkFailed a 404 skips its chunk once the chunks before it are in, and the rest goes on', async () => {
  const skipped = [];
  const delivered = [];
  const run = makeLoader({
    chunks: 5, order: [0, 3, 1, 4, 2], deliver: (i) => delivered.push(i) > 0,
    onChunkFailed: (i, message) => skipped.push({ i, message, delivered: [...delivered] }),
  });
  run.loader.pump();
  await settle();
  run.net.fail(run.net.open().find((r) => r.index === 1), notFound());
  await settle();
  assert.deepEqual(skipped, [], 'chunks before it in the plan are still coming');
  await answerAll(run.net, run.size);
  assert.deepEqual(delivered, [0, 3, 4, 2]);
  assert.deepEqual(skipped.map((s) => [s.i, s.delivered]), [[1, [0, 3]]]);
  assert.match(skipped[0].message, /^Could not download part 2 of 5 of the dataset \(chunk-1\): HTTP 404 \(Not Found\)\.$/);
  assert.deepEqual(run.loader.log.filter((e) => e.event === 'skip').map((e) => e.index), [1]);
  assert.equal(run.result.failed, null);
  assert.ok(run.result.done, 'the end of the plan');
  assert.equal(requests(run.loader).filter((e) => e.index === 1).length, 1, 'never asked again');
});

test('with onChunkFailed the page can replan from the callback before anything after is handed over', async () => {
  // Chunk 2 needs chunk 1 (a node's second chunk, or a child).
  const run = makeLoader({ chunks: 5, order: [0, 1, 2, 3, 4], onChunkFailed: (i) => run.loader.replan(i === 1 ? [3, 4] : []) });
  run.loader.pump();
  await settle();
  run.net.fail(run.net.open().find((r) => r.index === 1), notFound());
  await answerAll(run.net, run.size);
  assert.deepEqual(run.delivered, [0, 3, 4]);
  assert.equal(run.result.failed, null);
});

test('a chunk damaged every time is skipped in plan mode with onChunkFailed', async () => {
  const skipped = [];
  const run = makeLoader({
    chunks: 3, order: [0, 2, 1], check: (i) => (i === 2 ? 'not a part of this dataset' : null),
    onChunkFailed: (i, message) => skipped.push([i, message]),
  });
  run.loader.pump();
  for (let k = 0; k < 10 && !run.result.done; k++) {
    await answerAll(run.net, run.size);
    run.clock.advance(60000);
  }
  assert.deepEqual(run.delivered, [0, 1]);
  assert.equal(skipped.length, 1);
  assert.match(skipped[0][1], /^Part 3 of 3 of the dataset arrived damaged 4 times in a row/);
  assert.equal(run.result.failed, null);
});

test('chunks that arrived before attach() are checked and handed over in plan order', async () => {
  const checked = [];
  const run = makeLoader({ chunks: 4, order: [0, 3, 1, 2], check: null, deliver: null });
  run.loader.warm();
  await answerAll(run.net, run.size);
  assert.deepEqual(run.delivered, [], 'nothing before attach()');
  run.loader.attach({
    check: (i) => { checked.push(i); return null; },
    deliver: (i) => run.delivered.push(i) > 0,
  });
  assert.deepEqual(checked, [0, 3, 1, 2]);
  assert.deepEqual(run.delivered, [0, 3, 1, 2]);
  assert.ok(run.result.done);
});

test('a provisional limit keeps what was fetched before the first plan, for the plan to judge', async () => {
  const checked = [];
  const run = makeLoader({ chunks: 5, check: null, deliver: null, onIdle: () => {} });
  run.loader.warm();
  await answerAll(run.net, run.size); // the manifest's order, as far as the loader looks ahead
  const early = requests(run.loader).map((e) => e.index);
  assert.ok(early.length > 2, `fetched ahead: ${early}`);
  run.loader.attach({
    check: (i) => { checked.push(i); return null; },
    deliver: (i) => run.delivered.push(i) > 0,
    allowed: 1,
    provisional: true,
  });
  assert.deepEqual(checked, [0], 'only the base is checked before the plan');
  run.loader.replan([2, 1]); // the plan wants 2 and 1 (not 3 or 4)
  assert.deepEqual(checked, [0, 2, 1]);
  assert.deepEqual(run.delivered, [0, 2, 1]);
  assert.deepEqual(requests(run.loader).map((e) => e.index), early, 'nothing fetched twice');
  assert.ok(run.loader.log.some((e) => e.event === 'discard' && e.index === 3), 'what the plan left is discarded');
  run.loader.stop();
});

test('without onChunkFailed a 404 stops the stream after the chunks before it in the plan', async () => {
  const run = makeLoader({ chunks: 5, order: [0, 3, 1, 4, 2] });
  run.loader.pump();
  await settle();
  run.net.fail(run.net.open().find((r) => r.index === 1), notFound());
  await settle();
  assert.deepEqual(run.net.open().map((r) => r.index), [0, 3], 'the requests after it are dropped');
  await answerAll(run.net, run.size);
  assert.deepEqual(run.delivered, [0, 3]);
  assert.match(run.result.failed, /^Could not download part 2 of 5 .*\. Showing the last complete level\.$/);
  assert.ok(run.result.done);
  assert.deepEqual(requests(run.loader).map((e) => e.index), [0, 3, 1, 4]);
});

test('a chunk that fails for a while before one that cannot be had is still fetched again', async () => {
  const run = makeLoader({ chunks: 4 });
  run.loader.pump();
  await settle();
  const [r0, r1, r2] = run.net.open();
  run.net.fail(r2, notFound());
  await settle();
  run.net.fail(r1, new FetchError('connection lost', { kind: 'network', transient: true }));
  await settle();
  run.net.send(r0, run.size);
  run.net.finish(r0);
  await settle();
  run.clock.advance(60000);
  assert.deepEqual(requests(run.loader).map((e) => [e.index, e.reason]),
    [[0, 'first'], [1, 'first'], [2, 'first'], [3, 'first'], [1, 'retry']]);
  await answerAll(run.net, run.size);
  assert.deepEqual(run.delivered, [0, 1]);
  assert.match(run.result.failed, /^Could not download part 3 of 4 .* Showing the last complete level\.$/);
});

test('chunks the viewer gave back leave what was handed over, and a later plan fetches them again', async () => {
  const run = makeLoader({ order: [0, 1, 2], onIdle: () => {} });
  run.loader.pump();
  await answerAll(run.net, run.size);
  assert.deepEqual(run.delivered, [0, 1, 2]);
  const have = run.loader.haveBytes();
  run.loader.replan([1]); // handed over: ignored
  assert.equal(run.net.open().length, 0);
  run.loader.forget([1, 5]); // 5 was never handed over: nothing to forget
  assert.equal(run.loader.log.filter((e) => e.event === 'forget')[0].count, 1);
  assert.equal(run.loader.haveBytes(), have - run.size);
  run.loader.replan([1, 3]);
  assert.deepEqual(run.net.open().map((r) => r.index), [1, 3]);
  await answerAll(run.net, run.size);
  assert.deepEqual(run.delivered, [0, 1, 2, 1, 3]);
  run.loader.stop();
});

test('a chunk the viewer gave back before its turn is fetched again in its turn', async () => {
  const run = makeLoader({ order: [0, 1, 2], onIdle: () => {} });
  run.loader.pump();
  await settle();
  const [r0, r1, r2] = run.net.open();
  for (const r of [r1, r2]) {
    run.net.send(r, run.size);
    run.net.finish(r);
  }
  await settle();
  assert.deepEqual(run.delivered, [], 'chunks 1 and 2 wait for 0');
  run.loader.forget([2]); // checked, then given back by the viewer
  assert.equal(run.loader.log.filter((e) => e.event === 'forget')[0].count, 1);
  run.net.send(r0, run.size);
  run.net.finish(r0);
  await settle();
  assert.deepEqual(run.delivered, [0, 1]);
  assert.deepEqual(run.net.open().map((r) => r.index), [2], 'fetched again');
  await answerAll(run.net, run.size);
  assert.deepEqual(run.delivered, [0, 1, 2]);
  run.loader.stop();
});
