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
  waitForState, waitForLevel, frames, frameReport, MAX_FRAME_MS,
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

// GET requests the own server saw for chunk i since `since` (ms, Date.now()).
function requestsFor(i, since, server = own) {
  return server.requestLog.filter((r) => r.method === 'GET' && r.url.endsWith(chunkFile(i)) && r.time >= since);
}

before(async () => {
  checkBuilds();
  await precompressDir(webDir); // nginx's gzip_static must not send an older build's .gz
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'tetstream-network-'));
  ({ dir: pack } = makePack(tmp, 'h24', { n: 24, packArgs: ['--chunk-kb', '12', '--name', NAME] }));
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

// openViewer with chunk requests failing while linkDown() says so (page.route), set up before
// the page loads.
async function openViewerWithRoute(url, linkDown) {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  const problems = [];
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  page.on('crash', () => problems.push('page crashed'));
  page.on('console', (m) => {
    if (m.type() === 'error' && !NETWORK_ERRORS.some((re) => re.test(m.text()))) problems.push(`console error: ${m.text()}`);
  });
  await page.route(/\/data\/chunks\/\d+-/, (route) => {
    const index = Number(/chunks\/(\d+)-/.exec(route.request().url())[1]);
    return linkDown() && index >= 2 ? route.abort('internetdisconnected') : route.continue();
  });
  await page.goto(url);
  return { page, problems };
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
  // A slow link (150 KB/s) so that the program takes a second or two to arrive.
  const slow = createServer({ mounts: [{ prefix: '/data', dir: pack }, { prefix: '/', dir: webDir }], throttleBytesPerSec: 150e3 });
  const slowUrl = await listen(slow);
  try {
    const { page, problems } = await openViewer(browser, `${slowUrl}/index.html?data=/data/manifest.json`);
    const status = () => page.evaluate(() => ({
      text: document.getElementById('status-text').textContent,
      width: (parseFloat(document.getElementById('status-program').style.width) || 0) +
        (parseFloat(document.getElementById('status-fill').style.width) || 0),
      viewer: window.tetstream.stats().programBytesReceived,
    }));
    await page.waitForFunction(() => /^Loading the viewer: [1-9]\d* of \d+ KB…$/.test(document.getElementById('status-text').textContent),
      null, { timeout: 20000 });
    const early = await status();
    await page.screenshot({ path: path.join(outDir, 'network-progress.png') });
    assert.ok(early.width > 0 && early.width < 60, `the bar has started: ${JSON.stringify(early)}`);
    await page.waitForFunction((w) => parseFloat(document.getElementById('status-program').style.width) +
      (parseFloat(document.getElementById('status-fill').style.width) || 0) > w, early.width, { timeout: 20000 });
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

test('over a slow link the chunks come one after another at the full rate, not as a batch sharing it', async (t) => {
  // Chunks sharing a link end together, and the viewer then gets all their splits at once: it is
  // still applying them long after the last byte. 64 KB chunks over 150 KB/s, 30 ms before each
  // response: a chunk alone takes ~0.4 s, and the next request should start only near its end.
  const { dir } = makePack(tmp, 'h40', { n: 40, packArgs: ['--chunk-kb', '64'] });
  const chunks = readManifest(dir).chunks.length;
  const slow = createServer({ mounts: [{ prefix: '/data', dir }, { prefix: '/', dir: webDir }], throttleBytesPerSec: 150e3, latencyMs: 30 });
  const slowUrl = await listen(slow);
  try {
    const { page, problems } = await openViewer(browser, `${slowUrl}/index.html?data=/data/manifest.json`);
    const s = await waitForState(page, ['complete', 'error']);
    assert.equal(s.state, 'complete', s.error);
    assertSurfaceMatches(s, cliIso(s.isovalue, { dir, chunks }), 'slow link, one chunk after another');
    // The chunks requested once the viewer runs (a few go out together while the program
    // starts, as no callback runs then), in request order: how long each response overlaps the
    // one before, against that one's transfer time.
    const timing = await page.evaluate((after) => performance.getEntriesByType('resource')
      .filter((e) => /\/chunks\/\d+-/.test(e.name) && e.startTime > after)
      .sort((a, b) => a.startTime - b.startTime)
      .map((e) => ({ file: e.name.replace(/.*\//, ''), firstByte: e.responseStart, end: e.responseEnd })), s.firstSurfaceMs);
    assert.ok(timing.length >= 4, `chunks requested after the first surface: ${timing.length}`);
    const overlaps = timing.slice(1).map((e, k) => Math.max(0, timing[k].end - e.firstByte) / (timing[k].end - timing[k].firstByte));
    t.diagnostic(`overlap with the response before, as a share of its transfer time: ${overlaps.map((x) => x.toFixed(2)).join(' ')}`);
    // Batched requests would overlap nearly all the way, every one. Late responses on a busy
    // machine right after the first surface, while the program still settles (session 21's
    // fresh-clone runs: 0.00 0.67 0.57 0.00 0.00 0.00 and 0.00 0.95 0.56 0.57 0.00 0.14), are not
    // batching: at most half of them may overlap the one before by half.
    const shared = overlaps.filter((x) => x >= 0.5).length;
    assert.ok(shared <= Math.max(1, Math.floor(overlaps.length / 2)),
      `each response mostly alone on the link: ${overlaps.map((x) => x.toFixed(2)).join(' ')}`);
    assert.deepEqual(problems, []);
    await page.close();
  } finally {
    await new Promise((resolve) => slow.close(resolve));
  }
});

// ------------------------------------------------------------------ injected faults

test('a chunk that fails twice with 503 is retried with backoff and the stream completes', async (t) => {
  const since = Date.now();
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
  assert.equal(s.retries, 2);
  assert.equal(s.chunksRefused, 0);
  assert.equal(s.notice, '', 'the message goes once the chunk is in');
  t.diagnostic(`notices seen: ${JSON.stringify(await notices(page))}`);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a truncated chunk (short but "successful" response) is refused and fetched again', async () => {
  const since = Date.now();
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
  const since = Date.now();
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
  const since = Date.now();
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
  const since = Date.now();
  // Held for 7 s (the stall timer is 10 s): the viewer asks for part 4 early, and a slow machine
  // can take 3 s or more to receive the three parts before it, which left a 3 s hold run out
  // before the second of frames below began.
  own.setFaults([{ match: `/data/${chunkFile(3)}`, kind: 'slow', delayMs: 7000, times: 1 }]);
  const { page, problems } = await openViewer(browser, `${ownUrl}/index.html?data=/data/manifest.json`,
    { allow: NETWORK_ERRORS, recordNotices: true });
  // While part 4 is held back: the page keeps drawing (animation frames for one second).
  await page.waitForFunction(() => window.tetstream.stats().chunksReceived === 3, null, { timeout: 20000 });
  const waiting = await page.evaluate(() => new Promise((resolve) => {
    let n = 0;
    const end = performance.now() + 1000;
    const tick = (time) => {
      n++;
      if (time < end) requestAnimationFrame(tick);
      else resolve({ frames: n, received: window.tetstream.stats().chunksReceived });
    };
    requestAnimationFrame(tick);
  }));
  assert.equal(waiting.received, 3, 'part 4 was still on its way');
  assert.ok(waiting.frames >= 10, `frames kept coming while waiting: ${waiting.frames} in 1 s`);
  const s = await waitForState(page, ['complete', 'error']);
  assertCompleteAndRight(s, 'slow chunk');
  assert.equal(requestsFor(3, since).length, 1, 'slow is not stalled: no second request');
  assert.equal(s.retries, 0);
  assert.deepEqual(await notices(page), []);
  t.diagnostic(`slow chunk: ${waiting.frames} frames in the second waiting for it; ${frameReport(s)}`);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a chunk stalled past the stall timer (?stallSeconds=1) is abandoned and fetched again', async () => {
  const since = Date.now();
  own.setFaults([{ match: `/data/${chunkFile(3)}`, kind: 'slow', delayMs: 4000, times: 1 }]);
  const { page, s, problems } = await streamTo(`${ownUrl}/index.html?data=/data/manifest.json&stallSeconds=1`);
  assertCompleteAndRight(s, 'stalled chunk');
  assert.equal(requestsFor(3, since).length, 2);
  assert.equal(s.retries, 1);
  const seen = await notices(page);
  assert.ok(seen.some((n) => new RegExp(`^No data for 1 s: retrying part 4 of ${parts()} `).test(n)), `a plain message: ${JSON.stringify(seen)}`);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a 404 chunk stops the stream with a message naming the part; the loaded level stays usable', async () => {
  const since = Date.now();
  own.setFaults([{ match: `/data/${chunkFile(6)}`, kind: 'status', status: 404 }]);
  const { page, s, problems } = await streamTo(`${ownUrl}/index.html?data=/data/manifest.json`);
  assert.equal(s.state, 'error');
  assert.equal(s.error, `Could not download part 7 of ${parts()} of the dataset (${chunkFile(6)}): HTTP 404 (not found). ` +
    'Showing the last complete level.');
  assert.equal(await page.textContent('#status-text'), s.error);
  assert.equal(requestsFor(6, since).length, 1, 'a 404 is not retried');
  assert.equal(s.chunksReceived, 6, 'every chunk before it was kept');
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

test('offline and back: retries wait for the network and streaming resumes when it returns', async () => {
  own.setFaults([]);
  // The link is down for every chunk after the first two (requests fail as on a dead network)
  // until the test brings it back; the browser is told it is offline meanwhile.
  let linkDown = true;
  const { page: viewer, problems } = await openViewerWithRoute(`${ownUrl}/index.html?data=/data/manifest.json`, () => linkDown);
  await viewer.waitForFunction(() => window.tetstream.stats().chunksReceived >= 2, null, { timeout: 20000 });
  await viewer.context().setOffline(true);
  await viewer.waitForFunction((n) => new RegExp(`^You are offline: retrying part 3 of ${n} (in|now)`).test(window.tetstream.stats().notice),
    parts(), { timeout: 20000 });
  await new Promise((resolve) => setTimeout(resolve, 2500)); // the backoff grows meanwhile
  const during = await viewer.evaluate(() => window.tetstream.stats());
  assert.equal(during.state, 'streaming');
  assert.equal(during.chunksReceived, 2, 'nothing arrives while the link is down');
  assert.ok(during.retries >= 2, `retried meanwhile: ${during.retries}`);
  await frames(viewer, 2);
  await viewer.screenshot({ path: path.join(outDir, 'network-offline.png') });
  const back = Date.now();
  linkDown = false;
  await viewer.context().setOffline(false);
  const s = await waitForState(viewer, ['complete', 'error']);
  assertCompleteAndRight(s, 'offline and back');
  assert.ok(Date.now() - back < 10000, 'resumed on the online event, not after a long backoff');
  assert.deepEqual(problems, []);
  await viewer.close();
});

// ------------------------------------------------------------------ bad manifest, memory

test('a hostile manifest is refused before any chunk is fetched, in plain words', async () => {
  const since = Date.now();
  own.setFaults([]);
  const { page, s, problems } = await streamTo(`${ownUrl}/index.html?data=/hostile/manifest.json`);
  assert.equal(s.state, 'error');
  assert.match(s.error, /^The dataset description \(manifest\.json\) is not usable: .*chunks\[1\]\.file/);
  assert.equal(own.requestLog.filter((r) => r.time >= since && r.url.includes('/hostile/chunks')).length, 0);
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
