// Browser tests of the wasm viewer: headless Chromium (SwiftShader WebGL2) through playwright-core,
// against the real static server and a dataset made by the native CLI.
//   node --test tests/browser/
// Needs build/web (wasm build) and build/native/tetstream (native build). Writes screenshots to
// build/test-output/ -- look at them: a passing test here does not prove the picture is right.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { createServer } from '../../server/serve.mjs';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const webDir = path.join(root, 'build/web');
const cliPath = process.env.TETSTREAM_CLI || path.join(root, 'build/native/tetstream');
const outDir = path.join(root, 'build/test-output');
const chromiumPath = process.env.CHROMIUM || '/usr/bin/chromium';

// toolchain.md: WebGL2 in headless Chromium via SwiftShader. Playwright adds --headless and a
// fresh --user-data-dir itself.
const chromiumArgs = [
  '--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync', '--disable-quic',
];

let tmp, pack, distPack, badPack, server, baseUrl, browser;

function cli(...args) {
  const r = spawnSync(cliPath, args, { encoding: 'utf8', timeout: 120000 });
  assert.equal(r.status, 0, `tetstream ${args.join(' ')} failed:\n${r.stderr}${r.stdout}`);
  return r.stdout;
}

// The reference: the native CLI's isosurface of the same packed dataset.
function cliIso(value, { field, dir = pack } = {}) {
  const args = ['iso', dir, '--value', String(value), '--json'];
  if (field) args.push('--field', field);
  return JSON.parse(cli(...args));
}

function assertClose(actual, expected, rel, what) {
  const err = Math.abs(actual - expected) / Math.max(Math.abs(expected), 1e-30);
  assert.ok(err <= rel, `${what}: ${actual} vs ${expected} (relative error ${err.toExponential(2)} > ${rel})`);
}

// A page that records everything that went wrong on it. `allow`: console errors to tolerate.
async function openViewer(query, { allow = [] } = {}) {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  const problems = [];
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  page.on('crash', () => problems.push('page crashed'));
  page.on('console', (m) => {
    if (m.type() === 'error' && !allow.some((re) => re.test(m.text()))) problems.push(`console error: ${m.text()}`);
  });
  await page.goto(`${baseUrl}/index.html${query}`);
  return { page, problems };
}

async function waitForState(page, states, timeout = 60000) {
  await page.waitForFunction((s) => window.tetstream && s.includes(window.tetstream.stats().state), states, { timeout });
  return page.evaluate(() => window.tetstream.stats());
}

// Lets the viewer draw a few frames (ImGui reads input and applies it on the next frame).
async function frames(page, n = 4) {
  for (let i = 0; i < n; i++) await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => r())));
}

before(async () => {
  assert.ok(fs.existsSync(path.join(webDir, 'tetstream.wasm')), `no viewer build in ${webDir}: build the wasm target first`);
  assert.ok(fs.existsSync(cliPath), `no CLI at ${cliPath}: build the native target first`);
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'tetstream-browser-'));
  fs.mkdirSync(outDir, { recursive: true });

  const vtu = path.join(tmp, 'h.vtu');
  pack = path.join(tmp, 'pack');
  cli('gen', 'harmonic', '--n', '24', '-o', vtu);
  cli('pack', vtu, '-o', pack, '--name', 'Harmonic 24³');
  const distVtu = path.join(tmp, 'd.vtu');
  distPack = path.join(tmp, 'dist');
  cli('gen', 'distance', '--n', '16', '-o', distVtu);
  cli('pack', distVtu, '-o', distPack);

  // A copy whose base chunk has one flipped byte: the viewer must refuse it in plain words.
  badPack = path.join(tmp, 'bad');
  fs.cpSync(pack, badPack, { recursive: true });
  const manifest = JSON.parse(fs.readFileSync(path.join(badPack, 'manifest.json'), 'utf8'));
  const chunk = path.join(badPack, manifest.chunks[0].file);
  const bytes = fs.readFileSync(chunk);
  bytes[bytes.length >> 1] ^= 0x5a;
  fs.writeFileSync(chunk, bytes);

  server = createServer({
    mounts: [
      { prefix: '/data', dir: pack },
      { prefix: '/dist', dir: distPack },
      { prefix: '/bad', dir: badPack },
      { prefix: '/', dir: webDir },
    ],
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  baseUrl = `http://127.0.0.1:${server.address().port}`;
  browser = await chromium.launch({ executablePath: chromiumPath, args: chromiumArgs });
});

after(async () => {
  if (browser) await browser.close();
  if (server) await new Promise((resolve) => server.close(resolve));
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

test('streams a packed dataset, matches the CLI surface, and the isovalue slider drags', async (t) => {
  const { page, problems } = await openViewer('?data=/data/manifest.json');
  const s = await waitForState(page, ['complete', 'error']);
  assert.equal(s.state, 'complete', `viewer ended in ${s.state}: ${s.error}`);
  const manifest = JSON.parse(fs.readFileSync(path.join(pack, 'manifest.json'), 'utf8'));
  assert.equal(s.vertices, manifest.vertices);
  assert.equal(s.tets, manifest.tets);
  assert.equal(s.chunksLoaded, manifest.chunks.length);
  assert.equal(s.field, manifest.isoField);
  const range = manifest.fields.find((f) => f.name === manifest.isoField);
  assert.ok(s.isovalue > range.min && s.isovalue < range.max, 'default isovalue lies inside the field range');
  assert.ok(s.firstSurfaceMs > 0, 'first surface time recorded');
  t.diagnostic(`first isosurface drawn ${s.firstSurfaceMs.toFixed(0)} ms after navigation start; ` +
    `extraction ${s.extractMs.toFixed(1)} ms, ${s.triangles} triangles`);

  const ref = cliIso(s.isovalue);
  assert.ok(ref.triangles > 100, 'the reference surface is not trivial');
  assert.equal(s.triangles, ref.triangles);
  assert.equal(s.surfaceVertices, ref.vertices);
  assertClose(s.surfaceArea, ref.area, 1e-6, 'surface area');

  await frames(page);
  await page.screenshot({ path: path.join(outDir, 'viewer.png') });

  // Drag the ImGui slider from its middle to 85% of its width with the mouse.
  const r = s.sliderRect;
  assert.ok(r.w > 50 && r.h > 5, `slider rectangle recorded: ${JSON.stringify(r)}`);
  const y = r.y + r.h / 2;
  await page.mouse.move(r.x + 0.5 * r.w, y);
  await frames(page, 2);
  await page.mouse.down();
  await frames(page, 2);
  for (let i = 1; i <= 5; i++) {
    await page.mouse.move(r.x + (0.5 + 0.07 * i) * r.w, y);
    await frames(page, 2);
  }
  await page.mouse.up();
  await frames(page);
  const d = await page.evaluate(() => window.tetstream.stats());
  assert.ok(d.isovalue > s.isovalue + 0.1 * (range.max - range.min),
    `dragging right raised the isovalue: ${s.isovalue} -> ${d.isovalue}`);
  assert.notEqual(d.triangles, s.triangles, 'the surface was re-extracted');
  const ref2 = cliIso(d.isovalue);
  assert.equal(d.triangles, ref2.triangles);
  assertClose(d.surfaceArea, ref2.area, 1e-6, 'surface area after the drag');

  // Orbit and zoom over the canvas (away from the panel): camera only, the surface stays.
  await page.mouse.move(900, 500);
  await page.mouse.down();
  await page.mouse.move(980, 460, { steps: 4 });
  await page.mouse.up();
  await page.mouse.wheel(0, -200);
  await frames(page);
  const o = await page.evaluate(() => window.tetstream.stats());
  assert.equal(o.isovalue, d.isovalue, 'camera input does not touch the isovalue');
  await page.screenshot({ path: path.join(outDir, 'viewer-dragged.png') });

  assert.deepEqual(problems, []);
  await page.close();
});

test('?iso= and ?field= choose the surface', async () => {
  {
    const { page, problems } = await openViewer('?data=/data/manifest.json&iso=0.5');
    const s = await waitForState(page, ['complete', 'error']);
    assert.equal(s.state, 'complete', s.error);
    assert.equal(s.isovalue, Math.fround(0.5));
    const ref = cliIso(0.5);
    assert.equal(s.triangles, ref.triangles);
    assertClose(s.surfaceArea, ref.area, 1e-6, 'surface area at iso=0.5');
    assert.deepEqual(problems, []);
    await page.close();
  }
  {
    const { page, problems } = await openViewer('?data=/dist/manifest.json&field=distance&iso=0.8');
    const s = await waitForState(page, ['complete', 'error']);
    assert.equal(s.state, 'complete', s.error);
    assert.equal(s.field, 'distance');
    assert.equal(s.isovalue, Math.fround(0.8));
    const ref = cliIso(0.8, { field: 'distance', dir: distPack });
    assert.equal(s.triangles, ref.triangles);
    assertClose(s.surfaceArea, ref.area, 1e-6, 'sphere area');
    assertClose(s.surfaceArea, 4 * Math.PI * 0.64, 0.05, 'a sphere of radius 0.8');
    assert.deepEqual(problems, []);
    await page.close();
  }
});

test('a missing manifest ends in a readable error, without crashing', async () => {
  const { page, problems } = await openViewer('?data=/data/missing/manifest.json', {
    allow: [/Failed to load resource.*404/],
  });
  const s = await waitForState(page, ['complete', 'error']);
  assert.equal(s.state, 'error');
  assert.match(s.error, /manifest\.json/);
  assert.match(s.error, /HTTP 404/);
  assert.match(await page.textContent('#status-text'), /HTTP 404/);
  await frames(page);
  const again = await page.evaluate(() => window.tetstream.stats());
  assert.equal(again.state, 'error', 'the page keeps running and keeps the error');
  await page.screenshot({ path: path.join(outDir, 'viewer-missing.png') });
  assert.deepEqual(problems, []);
  await page.close();
});

test('a corrupted chunk is refused in plain words', async () => {
  const { page, problems } = await openViewer('?data=/bad/manifest.json');
  const s = await waitForState(page, ['complete', 'error']);
  assert.equal(s.state, 'error');
  assert.match(s.error, /hash/i);
  assert.equal(s.triangles, 0);
  assert.deepEqual(problems, []);
  await page.close();
});

test('without ?data= the page explains itself', async () => {
  const { page, problems } = await openViewer('');
  const s = await page.evaluate(() => window.tetstream.stats());
  assert.equal(s.state, 'idle');
  assert.ok(await page.isVisible('#help-url'), 'a field to paste a dataset URL');
  assert.deepEqual(problems, []);
  await page.close();
});
