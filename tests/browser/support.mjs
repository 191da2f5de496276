// Shared by the browser tests: headless Chromium (SwiftShader WebGL2) through playwright-core,
// the native CLI as the reference, and helpers to watch the viewer page.
// Needs build/web (wasm build) and build/native/tetstream (native build). Screenshots go to
// build/test-output/ -- look at them: a passing test here does not prove the picture is right.
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

export const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
export const webDir = path.join(root, 'build/web');
export const cliPath = process.env.TETSTREAM_CLI || path.join(root, 'build/native/tetstream');
export const outDir = path.join(root, 'build/test-output');
const chromiumPath = process.env.CHROMIUM || '/usr/bin/chromium';

// toolchain.md: WebGL2 in headless Chromium via SwiftShader. Playwright adds --headless and a
// fresh --user-data-dir itself.
const chromiumArgs = [
  '--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync', '--disable-quic',
];

// Listens on 127.0.0.1 with the project's server `files` behind a /slow/... route that serves
// `slowTo`/... with every chunk `delayMs` late (a slow link, so a test can act mid-stream).
// onRequest(req) sees every request first. Returns { server, baseUrl }.
export async function listenWithSlowRoute(files, { slowTo, delayMs, onRequest = () => {} }) {
  const server = http.createServer((req, res) => {
    onRequest(req);
    const slow = /^\/slow(\/.*)$/.exec(req.url);
    if (!slow) return files.emit('request', req, res);
    req.url = `${slowTo}${slow[1]}`;
    setTimeout(() => files.emit('request', req, res), /\.tsc$/.test(req.url) ? delayMs : 0);
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  return { server, baseUrl: `http://127.0.0.1:${server.address().port}` };
}

export function checkBuilds() {
  assert.ok(fs.existsSync(path.join(webDir, 'tetstream.wasm')), `no viewer build in ${webDir}: build the wasm target first`);
  assert.ok(fs.existsSync(cliPath), `no CLI at ${cliPath}: build the native target first`);
  fs.mkdirSync(outDir, { recursive: true });
}

export function launchBrowser(extraArgs = []) {
  return chromium.launch({ executablePath: chromiumPath, args: [...chromiumArgs, ...extraArgs] });
}

export function cli(...args) {
  const r = spawnSync(cliPath, args, { encoding: 'utf8', timeout: 120000 });
  assert.equal(r.status, 0, `tetstream ${args.join(' ')} failed:\n${r.stderr}${r.stdout}`);
  return r.stdout;
}

// A mesh made and packed by the CLI: gen harmonic|distance --n N, then pack with `packArgs`.
export function makePack(tmp, name, { kind = 'harmonic', n = 16, packArgs = [] } = {}) {
  const vtu = path.join(tmp, `${name}.vtu`);
  const dir = path.join(tmp, name);
  cli('gen', kind, '--n', String(n), '-o', vtu);
  cli('pack', vtu, '-o', dir, ...packArgs);
  return { vtu, dir };
}

// The reference: the native CLI's isosurface of a packed dataset (or a mesh file), at any level.
export function cliIso(value, { dir, field, chunks, fraction }) {
  const args = ['iso', dir, '--value', String(value), '--json'];
  if (field) args.push('--field', field);
  if (chunks !== undefined) args.push('--chunks', String(chunks));
  if (fraction !== undefined) args.push('--fraction', String(fraction));
  return JSON.parse(cli(...args));
}

export function readManifest(dir) {
  return JSON.parse(fs.readFileSync(path.join(dir, 'manifest.json'), 'utf8'));
}

export function assertClose(actual, expected, rel, what) {
  const err = Math.abs(actual - expected) / Math.max(Math.abs(expected), 1e-30);
  assert.ok(err <= rel, `${what}: ${actual} vs ${expected} (relative error ${err.toExponential(2)} > ${rel})`);
}

// The shown surface equals the CLI's at the same level: same triangles, vertices and area.
export function assertSurfaceMatches(s, ref, what) {
  assert.equal(s.triangles, ref.triangles, `${what}: triangles`);
  assert.equal(s.surfaceVertices, ref.vertices, `${what}: surface vertices`);
  assertClose(s.surfaceArea, ref.area, 1e-6, `${what}: surface area`);
}

// A page (in a fresh browser context: empty cache) that records everything that went wrong on
// it. `allow`: console errors to tolerate (the browser logs every failed request as an error, so
// tests of failures list theirs). `recordNotices`: window.__notices collects every distinct
// stats().notice, looked at every 50 ms (retry messages come and go).
export async function openViewer(browser, url, { allow = [], recordNotices = false } = {}) {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  if (recordNotices) {
    await page.addInitScript(() => {
      window.__notices = [];
      setInterval(() => {
        const n = window.tetstream && window.tetstream.stats().notice;
        if (n && window.__notices[window.__notices.length - 1] !== n) window.__notices.push(n);
      }, 50);
    });
  }
  const problems = [];
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  page.on('crash', () => problems.push('page crashed'));
  page.on('console', (m) => {
    if (m.type() === 'error' && !allow.some((re) => re.test(m.text()))) problems.push(`console error: ${m.text()}`);
  });
  await page.goto(url);
  return { page, problems };
}

export async function waitForState(page, states, timeout = 120000) {
  await page.waitForFunction((s) => window.tetstream && s.includes(window.tetstream.stats().state), states, { timeout });
  return page.evaluate(() => window.tetstream.stats());
}

// The page shows a failure as soon as the loader gives up; the refinement worker's report of
// what it holds (the model's figures in stats(), absent before its first report) may come a
// moment later. Waits for it to hold `count` chunks, or a while; the caller asserts the count.
export async function waitForChunksReceived(page, count, timeout = 30000) {
  await page.waitForFunction((n) => window.tetstream.stats().chunksReceived >= n, count, { timeout }).catch(() => {});
  return page.evaluate(() => window.tetstream.stats());
}

// Waits until the level has reached its target (the refinement worker applies splits in
// slices) with the latest view applied (viewCurrent: the worker has answered every change).
export async function waitForLevel(page, timeout = 120000) {
  await page.waitForFunction(() => {
    const s = window.tetstream.stats();
    return s.viewCurrent && s.splitsApplied === s.targetSplits;
  }, null, { timeout });
  return page.evaluate(() => window.tetstream.stats());
}

// Refinement and interval tree work run in slices that end at a deadline (8 ms; 4 while the user
// drags: wasm/platform.cpp). That a slice stops at its deadline, and how slices are binned by
// duration, is checked on a clock the test drives (tests/unit/test_viewer_state.cpp). Here every
// duration is the machine's (SwiftShader draws in software on the cores everything else uses),
// so durations of slices and frames go to the test output (sliceReport, frameReport) and only
// that the work ran in slices is asserted.
export function assertSlices(s) {
  const total = s.sliceCounts.reduce((a, b) => a + b, 0);
  assert.ok(total > 0, 'refinement ran in slices');
}

export function sliceReport(s) {
  const bins = s.sliceCounts.map((c, bin) =>
    `${bin === 0 ? '<' + s.sliceEdgesMs[0] : bin === s.sliceEdgesMs.length ? '≥' + s.sliceEdgesMs[bin - 1] : s.sliceEdgesMs[bin - 1] + '-' + s.sliceEdgesMs[bin]}: ${c}`);
  return `work slices by ms ${bins.join(', ')}`;
}

export function frameReport(s) {
  return `max frame callback ${s.maxFrameMs.toFixed(1)} ms (drawing ${s.maxDrawMs.toFixed(1)} ms; ${s.reducedFrames} reduced frames), ` +
    `max gap between frames ${s.maxFrameGapMs.toFixed(1)} ms, ` +
    `max refinement slice ${s.maxRefineMs.toFixed(1)} ms (${sliceReport(s)}); uploads ${s.partialUploads} partial / ${s.fullUploads} full ` +
    `(${s.grownUploads} to grow a buffer), ` +
    `${(s.uploadBytes / 1048576).toFixed(1)} MB`;
}

// Lets the viewer draw a few frames (ImGui reads input and applies it on the next frame).
// Waits for the refinement worker to have answered every change of the view (a surface asked
// for is in the page), then for `n` animation frames (it is drawn).
export async function frames(page, n = 4) {
  await page.waitForFunction(() => {
    const s = window.tetstream && window.tetstream.stats();
    return !s || s.viewCurrent !== false || s.state === 'error';
  }, null, { timeout: 60000 });
  for (let i = 0; i < n; i++) await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => r())));
}

// Compares two PNG screenshots in the page (the browser decodes them): how many pixels differ,
// how many by more than 8 levels, and the largest difference (per channel, 0-255).
export async function pictureDifference(page, pngA, pngB) {
  return page.evaluate(async ([a, b]) => {
    const load = (src) => new Promise((resolve, reject) => {
      const im = new Image();
      im.onload = () => resolve(im);
      im.onerror = reject;
      im.src = src;
    });
    const [ia, ib] = await Promise.all([load(a), load(b)]);
    const canvas = new OffscreenCanvas(ia.width, ia.height);
    const g = canvas.getContext('2d');
    g.drawImage(ia, 0, 0);
    const da = g.getImageData(0, 0, ia.width, ia.height).data;
    g.clearRect(0, 0, ia.width, ia.height);
    g.drawImage(ib, 0, 0);
    const db = g.getImageData(0, 0, ib.width, ib.height).data;
    let differing = 0, large = 0, maxDiff = 0;
    for (let k = 0; k < da.length; k += 4) {
      const d = Math.max(Math.abs(da[k] - db[k]), Math.abs(da[k + 1] - db[k + 1]), Math.abs(da[k + 2] - db[k + 2]));
      if (d > 0) differing++;
      if (d > 8) large++;
      maxDiff = Math.max(maxDiff, d);
    }
    return { differing, large, pixels: da.length / 4, maxDiff };
  }, [`data:image/png;base64,${pngA.toString('base64')}`, `data:image/png;base64,${pngB.toString('base64')}`]);
}
