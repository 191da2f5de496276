// Streams a packed dataset's chunks along a plan: an order of chunk indices, by default every
// chunk in manifest order. A dataset of nodes (FORMAT.md §1.1) is read a part at a time: the
// page plans the nodes its view needs, most important first, each after its parent, and
// replans when the view changes (replan(): what was handed over stays, the rest of the plan is
// replaced, and requests for chunks it no longer holds are dropped). Chunks are fetched a few
// plan places ahead, each checked against the manifest (size, content hash) before it is handed
// over, handed over strictly in plan order. A chunk that fails in a way that may pass (connection
// lost, no data for the stall time, HTTP 5xx, 408, 429, damaged bytes) is fetched again after a
// backoff, bypassing caches. One that cannot pass (404 and other 4xx, damaged every time) waits
// until every chunk before it in the plan has been handed over, then either stops the stream,
// so the viewer keeps the level it reached, or, when the page takes such failures
// (onChunkFailed), is left out of the plan while the rest goes on (the page replans without
// what needs it). At the end of the plan the stream ends, or, when the page plans more
// (onIdle), waits for the next plan. Nothing here blocks: every step runs in a network callback
// and takes well under a millisecond (the check hashes in wasm).
//
// The loader may start before the viewer program is ready, from the manifest's chunk names
// alone (the shell checks each against FORMAT.md's file rule first): the base chunk at once,
// more once the program's bytes are in (warm()), so the link is busy while the browser compiles
// the program. attach() then brings the checks and the hand-over; nothing is handed over, or
// kept past the check, before it.
import { fetchBytes, retryDelayMs, seconds, STALL_SECONDS } from './net.js';

// Chunks should arrive one after another, each at the link's full rate: chunks sharing a link
// finish together, so the viewer waits for the whole batch and then gets all of its work at
// once, which it is still applying long after the last byte. So a request starts when the bytes
// still to come of those under way drop below the lead: what the link delivers while a request
// waits for its first byte (measured: rate of finished responses, time to their first byte),
// with a margin, so that the next response starts as the last one ends and the link never idles.
// At most MAX_IN_FLIGHT requests (many small chunks on a long link): browsers open six
// connections to a host over HTTP/1.1, and a seventh request would only queue. Over HTTP/2 or 3
// (Resource Timing's nextHopProtocol) requests share one connection and more of them may be
// under way: small chunks, each a round trip to its first byte, then fill the link.
export const MAX_IN_FLIGHT = 6;
export const MAX_IN_FLIGHT_MULTIPLEXED = 16;
export const MIN_LEAD_BYTES = 4 << 10;
export const MAX_LEAD_BYTES = 1 << 20;
export const FIRST_LEAD_BYTES = 256 << 10;  // before anything is measured
export const LEAD_MARGIN = 1.25;
export const STARTUP_SECONDS = 1;
// ... until the base is in: it alone decides when the first surface appears, so it shares the
// link with one more request only (which keeps the link busy while the base's last bytes come).
export const MAX_IN_FLIGHT_BEFORE_BASE = 2;
export const MAX_AHEAD = 12;                // plan places fetched past the next one the viewer needs
export const MAX_AHEAD_MULTIPLEXED = 32;    // ... over HTTP/2 or 3
export const MAX_AHEAD_BYTES = 64 << 20;    // ... and at most this much held in the page
export const MAX_DAMAGED = 4;               // a chunk damaged this often in a row is broken at the source
export const LOG_LIMIT = 2000;              // entries kept in ChunkLoader.log (the newest)

const grouped = (n) => n.toLocaleString('en-US');

// The network's timing of a finished request (Resource Timing; the project's server and the
// documented nginx config send Timing-Allow-Origin for other origins): time to the first byte
// and transfer time, which a busy main thread does not stretch as it does callback times.
export function networkTiming(url) {
  if (typeof performance === 'undefined' || !performance.getEntriesByName || typeof location === 'undefined') return null;
  const entries = performance.getEntriesByName(new URL(url, location.href).href, 'resource');
  const e = entries[entries.length - 1];
  if (!e || !(e.responseStart > e.startTime) || !(e.responseEnd > e.responseStart)) return null;
  return { firstByteMs: e.responseStart - e.startTime, transferMs: e.responseEnd - e.responseStart,
    protocol: e.nextHopProtocol || '' };
}

// What the loader waits on: the page's clock and timers (tests give a fake one).
const pageClock = {
  now: () => performance.now(),
  setTimeout: (fn, ms) => setTimeout(fn, ms),
  clearTimeout: (id) => clearTimeout(id),
};

export class ChunkLoader {
  // urls, names (as the manifest gives them, for messages), sizes: per chunk.
  // order: the plan, chunk indices (default: every chunk in manifest order), each after the
  // chunks it needs (a node's after its parent's, FORMAT.md §1.1); the loader keeps its order.
  // fail(message): the stream cannot go on (called once, after the chunks before the bad one
  // have been delivered). done(): every allowed chunk of the plan delivered, or stopped.
  // onIdle(): given, the end of the plan does not end the stream: it is called once there, and
  // the loader waits for replan() to give it more.
  // onChunkFailed(index, message): given, a chunk that cannot be had does not end the stream:
  // once every chunk before it in the plan has been delivered, it is left out of the plan and
  // this is called before anything after it is handed over, so the page can replan without the
  // chunks that need it.
  // check, deliver, allowed: see attach(); given here, the loader is attached from the start.
  // fetch, clock, timing: the network, the clock and timers, and the network's timing of a
  // finished request (net.js fetchBytes, the page's clock, Resource Timing unless given).
  constructor({ urls, names = urls, sizes, order = null, allowed = urls.length, stallMs = STALL_SECONDS * 1000,
    check = null, deliver = null, fail, done, onIdle = null, onChunkFailed = null, fetch = fetchBytes,
    clock = pageClock, timing = networkTiming }) {
    Object.assign(this, { urls, names, sizes, allowed, stallMs, check, deliver, failed: fail, done });
    Object.assign(this, { onIdle, onChunkFailed, fetch, clock, timing });
    this.attached = !!check;
    this.warmed = this.attached;   // before: the program is still downloading, only the base
    this.programNearlyIn = false;  // its last bytes are coming: the first split chunk too
    this.unchecked = new Set();    // arrived before attach(), or past a provisional limit: parked unchecked
    this.provisional = false;      // the limit holds until the first plan (attach())
    this.checking = new Set();     // offered to the check, its answer not in yet
    this.total = urls.length;
    this.plan = [];                // chunk indices in the order they are handed over
    this.position = new Map();     // chunk index -> its place in the plan
    this.nextPos = 0;              // place in the plan of the next chunk to hand over
    this.setTail(order ?? urls.map((_, i) => i));
    this.idle = false;             // onIdle() called at the end of the plan, waiting for more
    this.handingOver = false;      // in deliverReady() (a callback may replan meanwhile)
    // By chunk index. The first four hold chunks the plan has yet to hand over; trouble also
    // keeps those a replan left (their failure counts hold if they come back).
    this.inFlight = new Map();     // index -> { controller, received }
    this.arrived = new Map();      // index -> bytes, checked, waiting for an earlier chunk
    this.waiting = new Map();      // index -> { at, timer }: to be fetched again at time `at`
    this.unavailable = new Map();  // index -> message: cannot be had, skipped in its turn
    this.trouble = new Map();      // index -> { failures, damaged, last }: chunks that failed
    this.deliveredBytes = 0;
    this.networkBytes = 0;         // off the wire, failed and aborted requests included
    this.retries = 0;              // requests made again after a failure
    this.refused = 0;              // responses the check refused (never handed over)
    this.rate = 0;                 // bytes/s of the last finished response, first byte to last
    this.firstByteMs = 0;          // time to the first byte of the last response that had one
    this.multiplexed = false;      // the responses came over HTTP/2 or 3 (measure())
    this.paused = false;
    this.stopped = false;
    this.failure = null;           // { index, message }: the first chunk that cannot be had
    // What the loader decided, in order (the newest LOG_LIMIT entries), for the panel's
    // diagnostics and for tests, which check decisions instead of timing them:
    //   { event: 'request', index, reason, cause?, attempt, others, outstanding, lead, attached }
    //     reason: 'first'; 'retry' (its backoff ran out; cause: what failed); 'online' (the
    //     browser's online event ended its backoff); 'resume' (dropped by a pause). others: the
    //     chunks under way then, outstanding: their bytes still to come, lead: see lead().
    //   { event: 'response', index, bytes }   { event: 'failure', index, cause, transient }
    //   { event: 'refused', index, cause }    { event: 'backoff', index, delayMs }
    //   { event: 'online', waiting }          { event: 'pause' }   { event: 'resume' }
    //   { event: 'replan', count }: the plan past what was handed over is now `count` chunks.
    //   { event: 'drop', index, reason: 'replan' }: a request under way for a chunk it left.
    //   { event: 'forget', count }: chunks handed over that the viewer gave back (forget()).
    //   { event: 'discard', index, bytes }: a chunk it left that had arrived.
    //   { event: 'skip', index }: a chunk that cannot be had, left out (onChunkFailed).
    //   { event: 'idle' }: the end of the plan, waiting for more (onIdle).
    // Each has `seq`, its place in the whole log.
    this.log = [];
    this.logged = 0;
    this.wokenOnline = new Set();  // waiting chunks the online event sent off
    this.dropped = new Set();      // chunks a pause dropped while under way
  }

  note(entry) {
    this.log.push({ seq: this.logged++, ...entry });
    if (this.log.length > LOG_LIMIT) this.log.splice(0, this.log.length - LOG_LIMIT);
  }

  part(i) {
    return `part ${i + 1} of ${this.total}`;
  }

  // The plan past what was handed over becomes `tail`, less what was handed over and repeats.
  setTail(tail) {
    const plan = this.plan.slice(0, this.nextPos);
    const position = new Map(plan.map((i, p) => [i, p]));
    for (const i of tail) {
      if (!Number.isInteger(i) || i < 0 || i >= this.total) throw new RangeError(`No chunk ${i} of ${this.total}.`);
      if (position.has(i)) continue;
      position.set(i, plan.length);
      plan.push(i);
    }
    Object.assign(this, { plan, position });
  }

  inPlanOrder(indices) {
    return [...indices].sort((a, b) => this.position.get(a) - this.position.get(b));
  }

  // The viewer is ready. check(i, bytes): null when the bytes are chunk i, else what is wrong in
  // words. deliver(i, bytes): hands chunk i over; false = the viewer stopped (it says why
  // itself). allowed: plan places to fetch (fewer than the plan's when memory is short).
  // provisional: the limit holds until a plan comes (replan), so what is under way or in is
  // kept for it to judge instead of thrown away.
  attach({ check, deliver, allowed = this.urls.length, provisional = false }) {
    Object.assign(this, { check, deliver, attached: true, warmed: true, provisional });
    if (provisional) this.allowed = allowed;
    else this.limitTo(allowed);
    this.acceptParked();
    this.deliverReady();
    this.pump();
  }

  // Chunks that arrived before they could be checked (before attach(), or past a provisional
  // limit) go to the check in plan order, once their place allows.
  acceptParked() {
    if (!this.attached) return;
    for (const i of this.inPlanOrder([...this.unchecked].filter((j) => this.position.has(j)))) {
      if (this.stopped) return;
      if (this.provisional && this.position.get(i) >= this.allowed) continue;
      this.unchecked.delete(i);
      if (this.failure && this.position.get(i) > this.position.get(this.failure.index)) this.arrived.delete(i);
      else if (this.arrived.has(i)) this.accept(i, this.arrived.get(i));
    }
  }

  // Plan places to fetch from now on (more, or fewer: the requests and chunks past them are
  // dropped).
  setAllowed(allowed) {
    if (this.stopped) return;
    this.provisional = false;
    this.limitTo(allowed);
    this.acceptParked();
    if (this.nextPos < Math.min(this.allowed, this.plan.length)) this.idle = false;
    this.deliverReady();
    this.pump();
  }

  limitTo(allowed) {
    this.allowed = allowed;
    for (const [j, e] of [...this.inFlight]) {
      if (this.position.get(j) >= allowed) {
        e.controller.abort();
        this.inFlight.delete(j);
      }
    }
    for (const j of [...this.arrived.keys()]) if (this.position.get(j) >= allowed) this.arrived.delete(j);
  }

  // The view changed: what was handed over stays, the rest of the plan becomes `tail` (chunk
  // indices; those handed over and repeats are ignored). Chunks it keeps are kept wherever they
  // are (under way, arrived, waiting on a backoff); requests for the others are dropped, their
  // bytes discarded and their backoffs cancelled. Once the stream has ended (stopped, or a chunk
  // it cannot do without failed) the plan stays as it is.
  replan(tail) {
    if (this.stopped || this.failure) return;
    this.setTail(tail);
    this.note({ event: 'replan', count: this.plan.length - this.nextPos });
    const left = (j) => !this.position.has(j);
    for (const [j, e] of [...this.inFlight]) {
      if (!left(j)) continue;
      e.controller.abort();
      this.inFlight.delete(j);
      this.note({ event: 'drop', index: j, reason: 'replan' });
    }
    for (const [j, bytes] of [...this.arrived]) {
      if (!left(j)) continue;
      this.arrived.delete(j);
      this.unchecked.delete(j);
      this.note({ event: 'discard', index: j, bytes: bytes.length });
    }
    for (const [j, w] of [...this.waiting]) {
      if (!left(j)) continue;
      this.clock.clearTimeout(w.timer);
      this.waiting.delete(j);
    }
    for (const j of [...this.unavailable.keys()]) if (left(j)) this.unavailable.delete(j);
    for (const set of [this.dropped, this.wokenOnline]) for (const j of [...set]) if (left(j)) set.delete(j);
    if (this.nextPos < Math.min(this.allowed, this.plan.length)) this.idle = false;
    this.provisional = false; // (the plan has spoken for what was fetched before it)
    this.acceptParked();
    this.deliverReady();
    this.pump();
  }

  // The viewer gave these chunks back (short of memory, it forgot regions the view no longer
  // needs, or could not keep one that came late): those handed over leave what was handed over,
  // so that a later plan may fetch them again; those checked and waiting for their turn are
  // dropped, to be fetched again in their turn.
  forget(indices) {
    const gone = new Set(indices.filter((i) => this.position.has(i) && this.position.get(i) < this.nextPos));
    let waiting = 0;
    for (const i of indices) {
      if (gone.has(i) || !this.arrived.delete(i)) continue;
      this.unchecked.delete(i);
      waiting++;
    }
    if (!gone.size && !waiting) return;
    const handed = this.plan.slice(0, this.nextPos).filter((i) => !gone.has(i));
    for (const i of gone) this.deliveredBytes -= this.sizes[i];
    this.plan = [...handed, ...this.plan.slice(this.nextPos)];
    this.nextPos = handed.length;
    this.position = new Map(this.plan.map((i, p) => [i, p]));
    this.note({ event: 'forget', count: gone.size + waiting });
    this.pump();
  }

  // The program's bytes are in: the link is free for more than the base.
  warm() {
    this.warmed = true;
    this.pump();
  }

  // The program's last bytes are coming: one more request (the first split chunk, the smallest)
  // now keeps the link busy over the round trip after them, and takes little from the program
  // the first surface waits for.
  nearlyWarm() {
    if (this.warmed || this.programNearlyIn) return;
    this.programNearlyIn = true;
    this.pump();
  }

  // Link rate and time to first byte from a finished response: the network's own timing when
  // the browser gives it, else callback times (the least time to a first byte seen, as a busy
  // main thread only adds to it).
  measure(i, entry, bytes) {
    const t = this.timing(this.urls[i]);
    const firstByteMs = t ? t.firstByteMs : entry.firstByte - entry.start;
    const transferMs = t ? t.transferMs : this.clock.now() - entry.firstByte;
    if (entry.firstByte && firstByteMs > 0) this.firstByteMs = t || !this.firstByteMs ? firstByteMs : Math.min(this.firstByteMs, firstByteMs);
    if (transferMs > 0 && bytes >= MIN_LEAD_BYTES) this.rate = bytes / (transferMs / 1000);
    if (t && t.protocol) this.multiplexed = /^h[23]/.test(t.protocol);
  }

  // Bytes still to come of the requests under way below which the next one starts (see above).
  lead() {
    if (!this.rate || !this.firstByteMs) return FIRST_LEAD_BYTES;
    // Until the viewer is attached its program is starting, and the main thread may run no
    // callbacks for a while (compiling, the base, the first surface: 0.3 s to over 1 s here):
    // requests not opened before would wait with the link idle.
    const seconds = this.attached ? this.firstByteMs / 1000 * LEAD_MARGIN : STARTUP_SECONDS;
    return Math.min(MAX_LEAD_BYTES, Math.max(MIN_LEAD_BYTES, this.rate * seconds));
  }

  // Requests under way at most, once the base is in.
  inFlightLimit() {
    return this.multiplexed ? MAX_IN_FLIGHT_MULTIPLEXED : MAX_IN_FLIGHT;
  }

  pump() {
    if (this.paused || this.stopped) return;
    // After a failure only the chunks before it, which are handed over before it is reported.
    const end = Math.min(this.allowed, this.failure ? this.position.get(this.failure.index) : this.plan.length,
      this.warmed ? this.nextPos + (this.multiplexed ? MAX_AHEAD_MULTIPLEXED : MAX_AHEAD) : this.programNearlyIn ? 2 : 1);
    let ahead = 0, outstanding = 0;
    for (const b of this.arrived.values()) ahead += b.length;
    for (const [j, e] of this.inFlight) {
      ahead += this.sizes[j];
      outstanding += Math.max(0, this.sizes[j] - e.received);
    }
    // Once the program is in, the base has at most a few round trips left: open the other
    // requests now, as the main thread may be busy starting the program for a while (no
    // callbacks run then, so requests not opened before it would wait).
    const baseComing = this.nextPos === 0 && !this.arrived.has(this.plan[0]) && !this.warmed;
    const limit = baseComing ? MAX_IN_FLIGHT_BEFORE_BASE : this.inFlightLimit();
    for (let p = this.nextPos; p < end && this.inFlight.size < limit; p++) {
      const i = this.plan[p];
      if (this.arrived.has(i) || this.checking.has(i) || this.inFlight.has(i) || this.waiting.has(i) || this.unavailable.has(i)) continue;
      if (p > this.nextPos && ahead + this.sizes[i] > MAX_AHEAD_BYTES) break;
      if (this.inFlight.size > 0 && outstanding >= this.lead()) break;
      this.fetchChunk(i, outstanding);
      ahead += this.sizes[i];
      outstanding += this.sizes[i];
    }
  }

  // outstanding: bytes still to come of the requests under way (for the log).
  fetchChunk(i, outstanding = 0) {
    const trouble = this.trouble.get(i);
    let reason = 'first';
    if (this.dropped.delete(i)) reason = 'resume';
    else if (this.wokenOnline.delete(i)) reason = 'online';
    else if (trouble) reason = 'retry';
    this.note({
      event: 'request', index: i, reason, ...(trouble ? { cause: causeOf(trouble.last) } : {}),
      attempt: trouble ? trouble.failures + 1 : 1, others: [...this.inFlight.keys()], outstanding,
      lead: this.lead(), attached: this.attached,
    });
    const entry = { controller: new AbortController(), received: 0, start: this.clock.now(), firstByte: 0 };
    this.inFlight.set(i, entry);
    if (trouble) this.retries++;
    this.fetch(this.urls[i], {
      signal: entry.controller.signal,
      stallMs: this.stallMs,
      limit: this.sizes[i],
      // After a failure, past any cache: a proxy or the browser may hold the damaged copy.
      cache: trouble ? 'reload' : 'default',
      onProgress: (n) => {
        if (!entry.firstByte) entry.firstByte = this.clock.now();
        entry.received += n;
        this.networkBytes += n;
        if (this.inFlight.size < this.inFlightLimit()) this.pump(); // outstanding bytes dropped
      },
    }).then((bytes) => {
      if (this.inFlight.get(i) !== entry) return; // dropped meanwhile (pause, replan, stop)
      this.inFlight.delete(i);
      this.note({ event: 'response', index: i, bytes: bytes.length });
      this.measure(i, entry, bytes.length);
      if (this.attached && !(this.provisional && this.position.get(i) >= this.allowed)) {
        this.accept(i, bytes);
      } else {
        this.arrived.set(i, bytes);
        this.unchecked.add(i);
      }
      this.pump();
    }, (e) => {
      if (this.inFlight.get(i) !== entry) return; // dropped meanwhile: its failure is no news
      this.inFlight.delete(i);
      if (e.kind === 'aborted' || this.stopped) return;
      this.note({ event: 'failure', index: i, cause: causeOf(e), transient: !!e.transient });
      if (e.transient) this.retryLater(i, e);
      else this.cannotHave(i, `Could not download ${this.part(i)} of the dataset (${this.names[i]}): ${e.message}.`);
      this.pump();
    });
  }

  // Checks chunk i; keeps it for the hand-over, or fetches it again when damaged. The check may
  // answer later (a promise: the viewer checks in its worker); the chunk waits meanwhile.
  accept(i, bytes) {
    this.arrived.delete(i);
    const size = bytes.length;
    let damage;
    try {
      damage = this.check(i, bytes);
    } catch (e) { // the viewer could not even look at it (no memory): stop here
      this.failAt(i, e.message);
      return;
    }
    if (damage && typeof damage.then === 'function') {
      this.checking.add(i);
      damage.then((d) => {
        this.checked(i, bytes, size, d);
        if (!this.stopped) this.pump(); // room ahead for more
      }, (e) => {
        this.checking.delete(i);
        if (!this.stopped) this.failAt(i, e.message);
      });
      return;
    }
    this.checked(i, bytes, size, damage);
  }

  // The check's answer for chunk i (`size` bytes: a check that took them over leaves `bytes`
  // empty, and only the count is kept).
  checked(i, bytes, size, damage) {
    this.checking.delete(i);
    if (this.stopped) return;
    if (!this.position.has(i)) return; // the page replanned without it meanwhile
    if (bytes.length !== size) bytes = { length: size };
    if (damage) {
      this.refused++;
      this.note({ event: 'refused', index: i, cause: 'damaged' });
      this.retryLater(i, { kind: 'damaged', message: damage, transient: true });
    } else {
      this.trouble.delete(i);
      this.arrived.set(i, bytes);
      this.deliverReady();
    }
  }

  retryLater(i, error) {
    const t = this.trouble.get(i) || { failures: 0, damaged: 0, last: null };
    t.failures++;
    t.damaged = error.kind === 'damaged' ? t.damaged + 1 : 0;
    t.last = error;
    this.trouble.set(i, t);
    if (t.damaged >= MAX_DAMAGED) {
      this.cannotHave(i, `${this.part(i)[0].toUpperCase()}${this.part(i).slice(1)} of the dataset arrived damaged ` +
        `${t.damaged} times in a row (${error.message}): the copy on the server does not match its manifest.`);
      return;
    }
    const delay = retryDelayMs(t.failures, error.retryAfterMs);
    this.note({ event: 'backoff', index: i, delayMs: delay });
    const timer = this.clock.setTimeout(() => {
      this.waiting.delete(i);
      this.pump();
    }, delay);
    this.waiting.set(i, { at: this.clock.now() + delay, timer });
  }

  // The link is back (the browser's `online` event): every waiting chunk goes now.
  retryNow() {
    this.note({ event: 'online', waiting: [...this.waiting.keys()] });
    for (const [i, w] of this.waiting) {
      this.clock.clearTimeout(w.timer);
      this.waiting.delete(i);
      this.wokenOnline.add(i);
    }
    this.pump();
  }

  // Chunk i cannot be had (a 4xx, damaged every time): skipped in its turn when the page takes
  // that (onChunkFailed), else the end of the stream.
  cannotHave(i, message) {
    if (!this.onChunkFailed) {
      this.failAt(i, message);
      return;
    }
    this.unavailable.set(i, message);
    this.deliverReady();
  }

  // Chunk i cannot be had and the stream cannot go on without it: the chunks before it in the
  // plan that are still coming are delivered first, then the failure is reported. Nothing after
  // it is fetched any more.
  failAt(i, message) {
    const place = this.position.get(i);
    if (place === undefined) return; // left the plan meanwhile
    if (this.failure && this.position.get(this.failure.index) <= place) return;
    this.failure = { index: i, message };
    for (const [j, e] of [...this.inFlight]) {
      if (this.position.get(j) > place) {
        e.controller.abort();
        this.inFlight.delete(j);
      }
    }
    for (const [j, w] of [...this.waiting]) {
      if (this.position.get(j) >= place) {
        this.clock.clearTimeout(w.timer);
        this.waiting.delete(j);
      }
    }
    for (const j of [...this.arrived.keys()]) {
      if (this.position.get(j) > place) {
        this.arrived.delete(j);
        this.unchecked.delete(j);
      }
    }
    this.reportFailure();
  }

  reportFailure() {
    if (!this.failure || this.stopped) return;
    const place = this.position.get(this.failure.index);
    if (this.nextPos < place) return;
    if (!this.attached && place > 0) return; // the chunks before it first
    const { message } = this.failure;
    this.stop();
    this.failed(place > 0 ? `${message} Showing the last complete level.` : message);
  }

  deliverReady() {
    if (!this.attached || this.handingOver) return; // a hand-over under way goes on from the new state
    this.handingOver = true;
    try {
      this.handOver();
    } finally {
      this.handingOver = false;
    }
    if (this.stopped) return;
    if (this.nextPos >= Math.min(this.allowed, this.plan.length)) this.endOfPlan();
    this.reportFailure();
  }

  // Hands over the chunks that are next in the plan and here, and skips those that cannot be had.
  handOver() {
    while (!this.stopped && this.nextPos < this.plan.length) {
      const i = this.plan[this.nextPos];
      if (this.unavailable.has(i)) {
        this.skip(i);
        continue;
      }
      if (!this.arrived.has(i) || this.unchecked.has(i)) return;
      const bytes = this.arrived.get(i);
      this.arrived.delete(i);
      this.nextPos++; // before deliver(): a replan from there keeps chunk i in the plan
      let accepted;
      try {
        accepted = this.deliver(i, bytes);
      } catch (e) {
        this.stop();
        this.failed(e.message);
        return;
      }
      if (!accepted) {
        this.stop();
        return;
      }
      this.deliveredBytes += bytes.length;
    }
  }

  // Chunk i, next in the plan, cannot be had: out of the plan, and the page told (it may replan).
  skip(i) {
    const message = this.unavailable.get(i);
    this.unavailable.delete(i);
    this.plan.splice(this.nextPos, 1);
    this.position.delete(i);
    for (let p = this.nextPos; p < this.plan.length; p++) this.position.set(this.plan[p], p);
    this.note({ event: 'skip', index: i });
    this.onChunkFailed(i, message);
  }

  // Every allowed chunk of the plan is delivered: the end, or a wait for the next plan.
  endOfPlan() {
    if (!this.onIdle) {
      this.stop();
      return;
    }
    if (this.idle) return;
    this.idle = true;
    this.note({ event: 'idle' });
    this.onIdle();
  }

  // Bytes of the dataset in hand: delivered, arrived and partly downloaded.
  haveBytes() {
    let have = this.deliveredBytes;
    for (const b of this.arrived.values()) have += b.length;
    for (const e of this.inFlight.values()) have += e.received;
    return have;
  }

  // What the network side is doing, in plain words, or '' when all is well: the chunk earliest
  // in the plan that failed and is waiting or being fetched again.
  notice(now = this.clock.now()) {
    if (this.stopped || this.failure || this.paused) return '';
    const troubled = [...this.trouble.keys()].filter((j) => this.position.has(j) && !this.unavailable.has(j));
    if (!troubled.length) return '';
    const i = this.inPlanOrder(troubled)[0];
    const { last, failures } = this.trouble.get(i);
    const what = this.part(i);
    let cause;
    if (!navigator.onLine) cause = 'You are offline';
    else if (last.kind === 'network') cause = 'Connection lost';
    else if (last.kind === 'stall') cause = `No data for ${Math.round(this.stallMs / 1000)} s`;
    else if (last.kind === 'damaged') cause = `${what[0].toUpperCase()}${what.slice(1)} arrived damaged (${last.message})`;
    else cause = `The server answered ${last.message}`;
    const w = this.waiting.get(i);
    if (w) return `${cause}: retrying ${what} in ${seconds(w.at - now)}.`;
    return `${cause}: retrying ${what} now (attempt ${failures + 1}).`;
  }

  // Pausing stops the network at once: requests under way are dropped (and fetched again on
  // resume, with their failure counts kept); what arrived completely is kept.
  setPaused(paused) {
    this.paused = paused;
    this.note({ event: paused ? 'pause' : 'resume' });
    if (paused) {
      for (const [i, e] of this.inFlight) {
        e.controller.abort();
        this.dropped.add(i);
      }
      this.inFlight.clear();
      for (const w of this.waiting.values()) this.clock.clearTimeout(w.timer);
      this.waiting.clear();
    } else {
      this.pump();
    }
  }

  stop() {
    if (this.stopped) return;
    this.stopped = true;
    for (const e of this.inFlight.values()) e.controller.abort();
    this.inFlight.clear();
    for (const w of this.waiting.values()) this.clock.clearTimeout(w.timer);
    this.waiting.clear();
    this.done();
  }
}

// What failed, for the log: 'http 503', 'network', 'stall', 'damaged'.
function causeOf(e) {
  return e.kind === 'http' ? `http ${e.status}` : e.kind;
}

// "2,345 of 16,384 bytes" / "its content does not match the manifest's hash", for check().
export function damageText(code, got, expected) {
  if (code === 2) return `${grouped(got)} bytes instead of ${grouped(expected)}`;
  if (code === 3) return "its content does not match the manifest's hash";
  return 'not a part of this dataset';
}
