// The viewer over real servers and failing networks, in headless Chromium:
//   - real nginx with the documented config (server/nginx.conf), skipped with a message when
//     nginx is not installed; the project's own server; python3 -m http.server (no Range, no CORS)
//   - viewer and data on different origins (CORS)
//   - faults injected into the project's server (tests/support/faults.mjs): a chunk failing twice with
//     503, truncated, corrupted, missing (404), slow, stalled past the stall timer, its
//     connection dropped; the browser going offline and back; a hostile manifest; a memory limit
// For each: no page error, no bad data applied (the final surface equals `tetstream iso` on the
// same level), retries where they make sense (the server's request log), a plain message, and
// `complete` when the fault passes.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { createServer } from '../support/server.mjs';
import { precompressDir } from '../../server/precompress.mjs';
import { startNginx, startPythonHttpServer } from '../support/nginx.mjs';
import {
  webDir, outDir, checkBuilds, launchBrowser, makePack, cliIso, readManifest, assertSurfaceMatches, openViewer,
  waitForState, waitForChunksReceived, waitForLevel, frames, frameReport,
} from './support.mjs';

let tmp, pack, manifest, browser, own, ownUrl, dataServer, dataUrl;
const references = new Map(); // "chunks isovalue" -> tetstream iso result

// Harmonic 24³ in 16 KB chunks: 10 chunks, enough to put faults in the middle of the stream.
const NAME = 'Harmonic 24³';
// Failed requests are logged to the console by the browser; these are expected here.
const NETWORK_ERRORS = [/Failed to load resource/, /net::ERR_/];

function reference(isovalue, chunks) {
  const key = `${chunks} ${isovalue}`;
  if (!references.has(key)) references.set(key, cliIso(isovalue, { dir: pack, chunks }));
  return references.get(key);
}

function listen(server) {
  return new Promise((resolve) => server.listen(0, '127.0.0.1', () => resolve(`http://127.0.0.1:${server.address().port}`)));
}

function chunkFile(i) {
  return manifest.chunks[i].file;
}

// Parts of the test stream, as the viewer's messages count them.
const parts = () => manifest.chunks.length;

// GET requests the own server saw for chunk i since `since` (a length of its requestLog).
function requestsFor(i, since, server = own) {
  return server.requestLog.slice(since).filter((r) => r.method === 'GET' && r.url.endsWith(chunkFile(i)));
}

// The chunk loader's log in the page (web/loader.js): its requests and why they were made.
async function loaderLog(page) {
  return (await page.evaluate(() => window.tetstream.stats())).requestLog;
}
const requestEvents = (log, i) => log.filter((e) => e.event === 'request' && (i === undefined || e.index === i));

before(async () => {
  checkBuilds();
  await precompressDir(webDir); // nginx's gzip_static must not send an older build's .gz
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'tetstream-network-'));
  // One node (--leaf-vertices 0): the chunks stream in manifest order, as these tests of the
  // network expect (selective.test.mjs has a dataset of nodes).
  ({ dir: pack } = makePack(tmp, 'h24', { n: 24, packArgs: ['--chunk-kb', '12', '--leaf-vertices', '0', '--name', NAME] }));
  manifest = readManifest(pack);
  assert.ok(manifest.chunks.length >= 8, `a stream of several chunks (${manifest.chunks.length})`);

  // A manifest that passes JSON parsing but names a file outside its folder.
  const hostile = path.join(tmp, 'hostile');
  fs.mkdirSync(hostile);
  const evil = structuredClone(manifest);
  evil.chunks[1].file = '../../../etc/passwd';
  fs.writeFileSync(path.join(hostile, 'manifest.json'), JSON.stringify(evil));

  own = createServer({ mounts: [{ prefix: '/data', dir: pack }, { prefix: '/hostile', dir: hostile }, { prefix: '/', dir: webDir }] });
  ownUrl = await listen(own);
  dataServer = createServer({ mounts: [{ prefix: '/data', dir: pack }] }); // another origin: another port
  dataUrl = await listen(dataServer);
  browser = await launchBrowser();
});

after(async () => {
  if (browser) await browser.close();
  for (const s of [own, dataServer]) if (s) await new Promise((resolve) => s.close(resolve));
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

// Opens the viewer, waits for the end, checks the common things; returns { page, s, problems }.
async function streamTo(url, { allow = NETWORK_ERRORS, recordNotices = true, states = ['complete', 'error'] } = {}) {
  const { page, problems } = await openViewer(browser, url, { allow, recordNotices });
  const s = await waitForState(page, states);
  return { page, s, problems };
}

function assertCompleteAndRight(s, what) {
  assert.equal(s.state, 'complete', `${what}: ended in ${s.state}: ${s.error}`);
  assert.equal(s.chunksReceived, manifest.chunks.length);
  assert.equal(s.vertices, manifest.vertices);
  assert.equal(s.tets, manifest.tets);
  assertSurfaceMatches(s, reference(s.isovalue, manifest.chunks.length), what);
}

// openViewer with set-up before the page loads: setUp(page) (routes, init scripts).
async function openViewerWith(url, setUp) {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  const problems = [];
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  page.on('crash', () => problems.push('page crashed'));
  page.on('console', (m) => {
    if (m.type() === 'error' && !NETWORK_ERRORS.some((re) => re.test(m.text()))) problems.push(`console error: ${m.text()}`);
  });
  await setUp(page);
  await page.goto(url);
  return { page, problems };
}

// openViewer with chunk requests failing while linkDown() says so (page.route).
function openViewerWithRoute(url, linkDown) {
  return openViewerWith(url, (page) => page.route(/\/data\/chunks\/\d+-/, (route) => {
    const index = Number(/chunks\/(\d+)-/.exec(route.request().url())[1]);
    return linkDown() && index >= 2 ? route.abort('internetdisconnected') : route.continue();
  }));
}

async function notices(page) {
  return page.evaluate(() => window.__notices);
}

// ------------------------------------------------------------------ real servers, origins

test('real nginx with the documented config: the dataset completes and equals tetstream iso', async (t) => {
  const nginx = await startNginx({ mounts: [{ prefix: '/', dir: webDir }, { prefix: '/data', dir: pack }] });
  if (!nginx) return t.skip('nginx is not installed (apt-get install nginx): skipped');
  try {
    const { page, s, problems } = await streamTo(`${nginx.url}index.html?data=/data/manifest.json`);
    assertCompleteAndRight(s, 'nginx');
    assert.equal(s.retries, 0);
    assert.equal(s.programBytesReceived, s.programBytesTotal, 'the progress bar counted the whole program');
    t.diagnostic(`nginx: first surface ${s.firstSurfaceMs.toFixed(0)} ms, complete ${s.completeMs.toFixed(0)} ms`);
    assert.deepEqual(problems, []);
    await page.close();
  } finally {
    await nginx.stop();
  }
});

test('viewer and data on different origins (CORS): nginx and the own server as the data host', async (t) => {
  const nginx = await startNginx({ mounts: [{ prefix: '/data', dir: pack }] });
  const hosts = [[`${dataUrl}/data/manifest.json`, 'own server']];
  if (nginx) hosts.push([`${nginx.url}data/manifest.json`, 'nginx']);
  else t.diagnostic('nginx is not installed: cross-origin data from the own server only');
  try {
    for (const [manifestUrl, what] of hosts) {
      const { page, s, problems } = await streamTo(`${ownUrl}/index.html?data=${encodeURIComponent(manifestUrl)}`);
      assertCompleteAndRight(s, `cross-origin from ${what}`);
      assert.deepEqual(problems, []);
      await page.close();
    }
  } finally {
    if (nginx) await nginx.stop();
  }
});

test('python3 -m http.server (no Range, no CORS, same origin) serves viewer and data', async (t) => {
  const site = path.join(tmp, 'site');
  fs.cpSync(webDir, site, { recursive: true });
  fs.cpSync(pack, path.join(site, 'data'), { recursive: true });
  const py = await startPythonHttpServer({ dir: site });
  if (!py) return t.skip('python3 is not installed: skipped');
  try {
    const { page, s, problems } = await streamTo(`${py.url}index.html?data=data/manifest.json`);
    assertCompleteAndRight(s, 'python http.server');
    assert.deepEqual(problems, []);
    await page.close();
  } finally {
    await py.stop();
  }
});

test('progress from the first byte: the bar counts the viewer program before it runs', async () => {
  // The program's first quarter comes, then the rest waits until the test releases it: the bar
  // is seen part way, whatever the speed of the machine. (A quarter of the smallest encoding the
  // server may send is at most a quarter of the one it sends.)
  const sent = ['tetstream.wasm', 'tetstream.wasm.br', 'tetstream.wasm.gz']
    .filter((f) => fs.existsSync(path.join(webDir, f))).map((f) => fs.statSync(path.join(webDir, f)).size);
  const slow = createServer({
    mounts: [{ prefix: '/data', dir: pack }, { prefix: '/', dir: webDir }],
    faults: [{ match: /^\/tetstream\.wasm$/, kind: 'hold', afterBytes: Math.floor(Math.min(...sent) / 4), times: 1 }],
  });
  const hold = slow.faults[0];
  const slowUrl = await listen(slow);
  try {
    const { page, problems } = await openViewer(browser, `${slowUrl}/index.html?data=/data/manifest.json&stallSeconds=600`);
    const status = () => page.evaluate(() => ({
      text: document.getElementById('status-text').textContent,
      width: (parseFloat(document.getElementById('status-program').style.width) || 0) +
        (parseFloat(document.getElementById('status-fill').style.width) || 0),
      viewer: window.tetstream.stats().programBytesReceived,
    }));
    await hold.whenHeld(1);
    await page.waitForFunction(() => /^Loading the viewer: [1-9]\d* of \d+ KB…$/.test(document.getElementById('status-text').textContent),
      null, { timeout: 60000 });
    const early = await status();
    await page.screenshot({ path: path.join(outDir, 'network-progress.png') });
    assert.ok(early.width > 0 && early.width < 60, `the bar has started: ${JSON.stringify(early)}`);
    hold.release();
    await page.waitForFunction((w) => parseFloat(document.getElementById('status-program').style.width) +
      (parseFloat(document.getElementById('status-fill').style.width) || 0) > w, early.width, { timeout: 60000 });
    const s = await waitForState(page, ['complete', 'error']);
    assertCompleteAndRight(s, 'slow link');
    const meta = Number(await page.getAttribute('meta[name="tetstream-wasm-bytes"]', 'content'));
    assert.equal(s.programBytesTotal, meta);
    assert.equal(s.programBytesReceived, meta, 'every byte of the program was counted');
    assert.deepEqual(problems, []);
    await page.close();
  } finally {
    await new Promise((resolve) => slow.close(resolve));
  }
});

test('over a slow link the chunks come one after another at the full rate, not as a batch sharing it', async () => {
  // Chunks sharing a link end together, and the viewer then gets all their splits at once: it is
  // still applying them long after the last byte. So on a slow link the loader asks for the next
  // chunk only when what is left of the one under way comes in about one round trip. The page
  // is told the link is 150 KB/s with 30 ms to the first byte (its Resource Timing entries for
  // chunks say so), so its lead is 150 KB/s × 30 ms × 1.25 = 5.6 KB whatever the speed of the
  // machine. The server holds the split chunks until the viewer runs (this server is fast: they
  // would all be in before it), and the last 16 KB of one chunk until the test releases them.
  // (One node, the root: a sequence of chunks of 16 to 64 KB, as a stream of every node in order.)
  const { dir } = makePack(tmp, 'h40', { n: 40, packArgs: ['--chunk-kb', '64', '--leaf-vertices', '0'] });
  const list = readManifest(dir).chunks;
  assert.ok(list.length >= 7, `a stream of several chunks (${list.length})`);
  const k = list.length - 2;
  const slow = createServer({
    mounts: [{ prefix: '/data', dir }, { prefix: '/', dir: webDir }],
    faults: [
      { match: list[k].file, kind: 'hold', afterBytes: list[k].bytes - 16384, times: 1 },
      { match: /\/chunks\/(?!00000-)\d+-/, kind: 'hold' },
    ],
  });
  const [hold, startUp] = slow.faults;
  const slowUrl = await listen(slow);
  const sizes = Object.fromEntries(list.map((c) => [c.file.replace(/.*\//, ''), c.bytes]));
  try {
    // ?stallSeconds=600: held requests are not given up on here, however slow the start.
    const { page, problems } = await openViewerWith(`${slowUrl}/index.html?data=/data/manifest.json&stallSeconds=600`, (p) => p.addInitScript((bytes) => {
      const real = performance.getEntriesByName.bind(performance);
      performance.getEntriesByName = (name, type) => {
        const file = /\/chunks\/([^/?#]+)/.exec(name)?.[1];
        if (!(file in bytes)) return real(name, type);
        return [{ name, entryType: 'resource', startTime: 1000, responseStart: 1030, responseEnd: 1030 + bytes[file] / 150 }];
      };
    }, sizes));
    await waitForState(page, ['streaming', 'complete', 'error']);
    startUp.release();
    // While chunk k has 16 KB to come (more than the lead), the next one is not asked for. The
    // page has seen the bytes before the hold (the viewer counts them) when this is checked.
    await hold.whenHeld(1);
    const before = list.slice(0, k).reduce((n, c) => n + c.bytes, 0) + list[k].bytes - 16384;
    await page.waitForFunction((n) => window.tetstream.stats().bytesDownloaded >= n, before, { timeout: 120000 });
    const held = await loaderLog(page);
    assert.equal(requestEvents(held, k + 1).length, 0, `chunk ${k + 1} waits while chunk ${k} is held: ${JSON.stringify(requestEvents(held))}`);
    hold.release();
    const s = await waitForState(page, ['complete', 'error']);
    assert.equal(s.state, 'complete', s.error);
    assertSurfaceMatches(s, cliIso(s.isovalue, { dir, chunks: list.length }), 'slow link, one chunk after another');
    // Every request once the viewer runs and the link is measured: less than the lead still to
    // come of those under way. (Before, a few go out together while the program starts, as no
    // callback runs then.)
    const log = s.requestLog;
    const measured = log.find((e) => e.event === 'response' && e.index === 0).seq;
    const later = requestEvents(log).filter((e) => e.attached && e.seq > measured);
    assert.ok(later.length >= 4, `chunks requested once the viewer runs: ${later.length}`);
    assert.ok(later.some((e) => e.index === k) && later.some((e) => e.index === k + 1), 'the held chunk and the next among them');
    for (const e of later) {
      assert.ok(Math.abs(e.lead - 5625) < 1, `the lead from the page's link timing: ${JSON.stringify(e)}`);
      assert.ok(e.outstanding < e.lead, `each response mostly alone on the link: ${JSON.stringify(e)}`);
      assert.equal(e.reason, 'first');
    }
    assert.deepEqual(problems, []);
    await page.close();
  } finally {
    hold.release();
    startUp.release();
    await new Promise((resolve) => slow.close(resolve));
  }
});

// ------------------------------------------------------------------ injected faults

test('a chunk that fails twice with 503 is retried with backoff and the stream completes', async (t) => {
  const since = own.requestLog.length;
  own.setFaults([{ match: `/data/${chunkFile(3)}`, kind: 'status', status: 503, times: 2 }]);
  const { page, problems } = await openViewer(browser, `${ownUrl}/index.html?data=/data/manifest.json`,
    { allow: NETWORK_ERRORS, recordNotices: true });
  // The retry message while it waits, as the status line shows it at that moment (read in the
  // page: on a slow machine the backoff can run out before a round trip from here), then a
  // screenshot to look at.
  const shown = await (await page.waitForFunction(() => {
    const text = document.querySelector('#status-text')?.textContent ?? '';
    return /retrying part 4 of \d+ in/.test(window.tetstream.stats().notice) && /retrying part 4/.test(text) && text;
  }, null, { timeout: 20000 })).jsonValue();
  await frames(page, 3);
  await page.screenshot({ path: path.join(outDir, 'network-retry.png') });
  assert.match(shown,
    new RegExp(`^The server answered HTTP 503 \\(Service Unavailable\\): retrying part 4 of ${parts()} (in (\\d+ s|a moment)|now \\(attempt 2\\))\\.$`));
  const s = await waitForState(page, ['complete', 'error']);
  assertCompleteAndRight(s, '503 twice');
  assert.deepEqual(requestsFor(3, since).map((r) => r.status), [503, 503, 200], 'two failures, then the chunk');
  assert.deepEqual(requestEvents(s.requestLog, 3).map((e) => [e.reason, e.cause]),
    [['first', undefined], ['retry', 'http 503'], ['retry', 'http 503']], 'each retry after its backoff');
  assert.equal(s.retries, 2);
  assert.equal(s.chunksRefused, 0);
  assert.equal(s.notice, '', 'the message goes once the chunk is in');
  t.diagnostic(`notices seen: ${JSON.stringify(await notices(page))}`);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a truncated chunk (short but "successful" response) is refused and fetched again', async () => {
  const since = own.requestLog.length;
  own.setFaults([{ match: `/data/${chunkFile(4)}`, kind: 'truncate', times: 1 }]);
  const { page, s, problems } = await streamTo(`${ownUrl}/index.html?data=/data/manifest.json`);
  assertCompleteAndRight(s, 'truncated');
  assert.equal(requestsFor(4, since).length, 2);
  assert.equal(s.chunksRefused, 1, 'the short copy was refused, never applied');
  assert.equal(s.retries, 1);
  const seen = await notices(page);
  assert.ok(seen.some((n) => new RegExp(`^Part 5 of ${parts()} arrived damaged \\([\\d,]+ bytes instead of [\\d,]+\\): retrying part 5 of ${parts()} `).test(n)),
    `a plain message: ${JSON.stringify(seen)}`);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a corrupted chunk (bit flips) fails the hash check, is never applied and is fetched again', async () => {
  const since = own.requestLog.length;
  own.setFaults([{ match: `/data/${chunkFile(5)}`, kind: 'corrupt', times: 1 }]);
  const { page, s, problems } = await streamTo(`${ownUrl}/index.html?data=/data/manifest.json`);
  assertCompleteAndRight(s, 'corrupted');
  assert.equal(requestsFor(5, since).length, 2);
  assert.equal(s.chunksRefused, 1);
  const seen = await notices(page);
  assert.ok(seen.some((n) => n.startsWith(`Part 6 of ${parts()} arrived damaged (its content does not match the manifest's hash)`)),
    `a plain message: ${JSON.stringify(seen)}`);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a dropped connection mid-chunk is retried and the stream completes', async () => {
  const since = own.requestLog.length;
  own.setFaults([{ match: `/data/${chunkFile(2)}`, kind: 'drop', times: 2 }]);
  const { page, s, problems } = await streamTo(`${ownUrl}/index.html?data=/data/manifest.json`);
  assertCompleteAndRight(s, 'dropped connection');
  assert.equal(requestsFor(2, since).length, 3);
  assert.equal(s.retries, 2);
  const seen = await notices(page);
  assert.ok(seen.some((n) => new RegExp(`^Connection lost: retrying part 3 of ${parts()} `).test(n)), `a plain message: ${JSON.stringify(seen)}`);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a slow chunk is waited for (no retry), and frames keep coming meanwhile', async (t) => {
  const since = own.requestLog.length;
  // Part 4's headers come, its body is held until the test has seen the frames below. Slow is
  // not stalled: the stall timer (?stallSeconds=600 here, so that a busy machine's slow start
  // cannot run it out) is what abandons a request, not slowness (the next test).
  own.setFaults([{ match: `/data/${chunkFile(3)}`, kind: 'hold', times: 1 }]);
  const hold = own.faults[0];
  try {
    const { page, problems } = await openViewer(browser, `${ownUrl}/index.html?data=/data/manifest.json&stallSeconds=600`,
      { allow: NETWORK_ERRORS, recordNotices: true });
    // While part 4 is held back: the page keeps drawing (ten animation frames).
    await hold.whenHeld(1);
    await page.waitForFunction(() => window.tetstream.stats().chunksReceived === 3, null, { timeout: 120000 });
    const waiting = await page.evaluate(() => new Promise((resolve) => {
      let n = 0;
      const tick = () => {
        if (++n < 10) requestAnimationFrame(tick);
        else resolve({ frames: n, received: window.tetstream.stats().chunksReceived });
      };
      requestAnimationFrame(tick);
    }));
    assert.equal(waiting.received, 3, 'part 4 was still on its way');
    assert.equal(waiting.frames, 10, 'frames kept coming while waiting');
    hold.release();
    const s = await waitForState(page, ['complete', 'error']);
    assertCompleteAndRight(s, 'slow chunk');
    assert.equal(requestsFor(3, since).length, 1, 'slow is not stalled: no second request');
    assert.deepEqual(requestEvents(s.requestLog, 3).map((e) => e.reason), ['first']);
    assert.equal(s.retries, 0);
    assert.deepEqual(await notices(page), []);
    t.diagnostic(`slow chunk: ${frameReport(s)}`);
    assert.deepEqual(problems, []);
    await page.close();
  } finally {
    hold.release();
  }
});

test('a chunk stalled past the stall timer (?stallSeconds=1) is abandoned and fetched again', async () => {
  const since = own.requestLog.length;
  // Held until the viewer has given up on it and asked again (the second request is not held).
  own.setFaults([{ match: `/data/${chunkFile(3)}`, kind: 'hold', times: 1 }]);
  const hold = own.faults[0];
  try {
    const { page, problems } = await openViewer(browser, `${ownUrl}/index.html?data=/data/manifest.json&stallSeconds=1`,
      { allow: NETWORK_ERRORS, recordNotices: true });
    await page.waitForFunction(() => window.tetstream.stats().requestLog
      .some((e) => e.event === 'request' && e.index === 3 && e.reason === 'retry'), null, { timeout: 120000 });
    hold.release();
    const s = await waitForState(page, ['complete', 'error']);
    assertCompleteAndRight(s, 'stalled chunk');
    assert.equal(requestsFor(3, since).length, 2);
    assert.deepEqual(requestEvents(s.requestLog, 3).map((e) => [e.reason, e.cause]), [['first', undefined], ['retry', 'stall']]);
    assert.equal(s.retries, 1);
    const seen = await notices(page);
    assert.ok(seen.some((n) => new RegExp(`^No data for 1 s: retrying part 4 of ${parts()} `).test(n)), `a plain message: ${JSON.stringify(seen)}`);
    assert.deepEqual(problems, []);
    await page.close();
  } finally {
    hold.release();
  }
});

test('a 404 chunk stops the stream with a message naming the part; the loaded level stays usable', async () => {
  const since = own.requestLog.length;
  own.setFaults([{ match: `/data/${chunkFile(6)}`, kind: 'status', status: 404 }]);
  const { page, s, problems } = await streamTo(`${ownUrl}/index.html?data=/data/manifest.json`);
  assert.equal(s.state, 'error');
  assert.equal(s.error, `Could not download part 7 of ${parts()} of the dataset (${chunkFile(6)}): HTTP 404 (not found). ` +
    'Showing the last complete level.');
  assert.equal(await page.textContent('#status-text'), s.error);
  assert.equal(requestsFor(6, since).length, 1, 'a 404 is not retried');
  assert.equal((await waitForChunksReceived(page, 6)).chunksReceived, 6, 'every chunk before it was kept');
  const level = await waitForLevel(page);
  assert.equal(level.vertices, manifest.chunks[5].vertices);
  assertSurfaceMatches(level, reference(level.isovalue, 6), 'the level reached');
  // Still usable: the level slider down to the base and back, and the isovalue.
  await page.evaluate(() => window.tetstream.setLevel(0));
  const base = await waitForLevel(page);
  assert.equal(base.vertices, manifest.chunks[0].vertices);
  assertSurfaceMatches(base, reference(base.isovalue, 1), 'the base');
  await page.evaluate(() => window.tetstream.setLevel(1));
  await page.evaluate(() => window.tetstream.setIsovalue(0.3));
  const back = await waitForLevel(page);
  assert.equal(back.vertices, manifest.chunks[5].vertices);
  assertSurfaceMatches(back, reference(back.isovalue, 6), 'back at the level reached, another isovalue');
  assert.equal(back.state, 'error', 'the message stays');
  await frames(page);
  await page.screenshot({ path: path.join(outDir, 'network-404.png') });
  assert.deepEqual(problems, []);
  await page.close();
});

test('a refinement worker that cannot be loaded stops the viewer with a message, never a hang', async () => {
  own.setFaults([{ match: '/worker.js', kind: 'status', status: 404 }]);
  const { page, s, problems } = await streamTo(`${ownUrl}/index.html?data=/data/manifest.json`, { states: ['error'] });
  own.setFaults([]);
  assert.equal(s.state, 'error');
  assert.match(s.error, /refinement worker/, s.error);
  assert.equal(await page.textContent('#status-text'), s.error);
  assert.deepEqual(problems, []);
  await page.close();
});

test('offline and back: retries wait for the network and streaming resumes when it returns', async () => {
  own.setFaults([]);
  // The link is down for every chunk after the first two (requests fail as on a dead network)
  // until the test brings it back; the browser is told it is offline meanwhile.
  let linkDown = true;
  const { page: viewer, problems } = await openViewerWithRoute(`${ownUrl}/index.html?data=/data/manifest.json`, () => linkDown);
  await viewer.waitForFunction(() => window.tetstream.stats().chunksReceived >= 2, null, { timeout: 20000 });
  await viewer.context().setOffline(true);
  await viewer.waitForFunction((n) => new RegExp(`^You are offline: retrying part 3 of ${n} (in|now)`).test(window.tetstream.stats().notice),
    parts(), { timeout: 60000 });
  // Part 3 retried meanwhile, each time after a longer backoff; now waiting on its third (2 to 4 s).
  await viewer.waitForFunction(() => {
    const mine = window.tetstream.stats().requestLog.filter((e) => e.index === 2);
    return mine.filter((e) => e.event === 'backoff').length >= 3 && mine.at(-1).event === 'backoff';
  }, null, { timeout: 60000 });
  const during = await viewer.evaluate(() => window.tetstream.stats());
  assert.equal(during.state, 'streaming');
  assert.equal(during.chunksReceived, 2, 'nothing arrives while the link is down');
  assert.ok(during.retries >= 2, `retried meanwhile: ${during.retries}`);
  const backoffs = during.requestLog.filter((e) => e.event === 'backoff' && e.index === 2).map((e) => e.delayMs);
  assert.ok(backoffs.length >= 3 && backoffs.every((ms, n) => n === 0 || ms >= backoffs[n - 1]), `the backoff grows: ${backoffs}`);
  await frames(viewer, 2);
  await viewer.screenshot({ path: path.join(outDir, 'network-offline.png') });
  linkDown = false;
  await viewer.context().setOffline(false);
  const s = await waitForState(viewer, ['complete', 'error']);
  assertCompleteAndRight(s, 'offline and back');
  // Resumed on the online event, not after a backoff: part 3, waiting then, went at once.
  const online = s.requestLog.find((e) => e.event === 'online');
  assert.ok(online, 'the online event reached the loader');
  assert.ok(online.waiting.includes(2), `part 3 was waiting: ${JSON.stringify(online)}`);
  const next = requestEvents(s.requestLog, 2).find((e) => e.seq > online.seq);
  assert.equal(next.reason, 'online', `part 3 went on the online event: ${JSON.stringify(next)}`);
  assert.deepEqual(problems, []);
  await viewer.close();
});

// ------------------------------------------------------------------ bad manifest, memory

test('a hostile manifest is refused before any chunk is fetched, in plain words', async () => {
  const since = own.requestLog.length;
  own.setFaults([]);
  const { page, s, problems } = await streamTo(`${ownUrl}/index.html?data=/hostile/manifest.json`);
  assert.equal(s.state, 'error');
  assert.match(s.error, /^The dataset description \(manifest\.json\) is not usable: .*chunks\[1\]\.file/);
  assert.equal(own.requestLog.slice(since).filter((r) => r.url.includes('/hostile/chunks')).length, 0);
  await frames(page);
  assert.equal((await page.evaluate(() => window.tetstream.stats())).state, 'error');
  assert.deepEqual(problems, []);
  await page.close();
});

test('?maxMemoryMB= below the full dataset stops at the last level that fits, with a message', async (t) => {
  own.setFaults([]);
  // The full dataset's estimate, from an unlimited run's stats, then 80% of it as the limit.
  const probe = await openViewer(browser, `${ownUrl}/index.html?data=/data/manifest.json`);
  await waitForState(probe.page, ['streaming', 'complete', 'error']);
  const needed = (await probe.page.evaluate(() => window.tetstream.stats())).memory.neededBytes;
  await probe.page.close();
  const limitMB = Math.floor((0.8 * needed) / 1048576 * 10) / 10;

  const { page, s, problems } = await streamTo(`${ownUrl}/index.html?data=/data/manifest.json&maxMemoryMB=${limitMB}`);
  t.diagnostic(`needs ${(needed / 1048576).toFixed(1)} MB; limit ${limitMB} MB: ${s.chunksAllowed} of ${s.chunksTotal} chunks`);
  assert.equal(s.state, 'error');
  assert.equal(s.memoryLimited, true);
  assert.ok(s.chunksAllowed >= 1 && s.chunksAllowed < s.chunksTotal, `stopped part way: ${s.chunksAllowed}`);
  assert.equal(s.chunksReceived, s.chunksAllowed);
  assert.match(s.error, new RegExp(`^This dataset needs about [\\d.]+ MB of memory at full detail, more than the [\\d.]+ MB ` +
    `this page may use\\. Streaming stopped after part ${s.chunksAllowed} of ${parts()} \\([\\d.]+% of the vertices\\); ` +
    'that level stays fully usable\\.$'));
  assert.ok(s.memory.limitBytes <= limitMB * 1048576 + 1);
  assert.ok(s.memory.allowedBytes <= s.memory.limitBytes);
  const level = await waitForLevel(page);
  assertSurfaceMatches(level, reference(level.isovalue, s.chunksAllowed), 'the level that fits');
  await frames(page);
  await page.screenshot({ path: path.join(outDir, 'network-memory.png') });
  assert.deepEqual(problems, []);
  await page.close();

  // Not even the base fits: refused at once.
  const tiny = await streamTo(`${ownUrl}/index.html?data=/data/manifest.json&maxMemoryMB=1`);
  assert.equal(tiny.s.state, 'error');
  assert.match(tiny.s.error, /even at its coarsest level, more than the 1\.0 MB this page may use\.$/);
  assert.equal(tiny.s.chunksReceived, 0);
  assert.deepEqual(tiny.problems, []);
  await tiny.page.close();
});
