// Browser tests of the wasm viewer: headless Chromium (SwiftShader WebGL2) through playwright-core,
// against the project's static server and a dataset made by the native CLI: streaming, the
// surface against the CLI's, the controls, pause, and failures (tests/browser/support.mjs has the
// shared helpers; network.test.mjs the real servers and injected network faults).
//   node --test tests/browser/
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { createServer } from '../support/server.mjs';
import {
  webDir, outDir, checkBuilds, launchBrowser, cli, readManifest as readManifestOf, assertClose,
  openViewer as openViewerAt, listenWithSlowRoute, waitForState, waitForChunksReceived, waitForLevel, frameReport, assertSlices, frames, pictureDifference,
  cliIso as cliIsoOf,
} from './support.mjs';

let tmp, originalVtu, pack, distPack, badPack, gapPack, files, server, baseUrl, browser;
const chunkRequests = []; // url of every chunk request the server saw, in order

// The reference: the native CLI's isosurface of the same packed dataset, at any level.
function cliIso(value, { dir = pack, ...options } = {}) {
  return cliIsoOf(value, { dir, ...options });
}

function readManifest(dir = pack) {
  return readManifestOf(dir);
}

function openViewer(query, options) {
  return openViewerAt(browser, `${baseUrl}/index.html${query}`, options);
}

before(async () => {
  checkBuilds();
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'tetstream-browser-'));

  // Harmonic 32³ (~180k tets) in many small chunks, so that streaming takes a while; lossless,
  // so that the last level is the original mesh itself.
  const vtu = path.join(tmp, 'h.vtu');
  originalVtu = vtu;
  pack = path.join(tmp, 'pack');
  cli('gen', 'harmonic', '--n', '32', '-o', vtu);
  // One node (--leaf-vertices 0): every chunk streams, in manifest order, as these tests of
  // streaming and its controls expect (selective.test.mjs has a dataset of nodes).
  cli('pack', vtu, '-o', pack, '--chunk-kb', '16', '--lossless', '--leaf-vertices', '0', '--name', 'Harmonic 32³');
  const distVtu = path.join(tmp, 'd.vtu');
  distPack = path.join(tmp, 'dist');
  cli('gen', 'distance', '--n', '16', '-o', distVtu);
  cli('pack', distVtu, '-o', distPack);

  // A copy whose base chunk has one flipped byte: the viewer must refuse it in plain words.
  badPack = path.join(tmp, 'bad');
  fs.cpSync(pack, badPack, { recursive: true });
  const manifest = readManifest(badPack);
  const chunk = path.join(badPack, manifest.chunks[0].file);
  const bytes = fs.readFileSync(chunk);
  bytes[bytes.length >> 1] ^= 0x5a;
  fs.writeFileSync(chunk, bytes);

  // A copy without its sixth chunk: a 404 in the middle of the stream.
  gapPack = path.join(tmp, 'gap');
  fs.cpSync(pack, gapPack, { recursive: true });
  fs.rmSync(path.join(gapPack, readManifest(gapPack).chunks[5].file));

  files = createServer({
    mounts: [
      { prefix: '/data', dir: pack },
      { prefix: '/dist', dir: distPack },
      { prefix: '/bad', dir: badPack },
      { prefix: '/gap', dir: gapPack },
      { prefix: '/', dir: webDir },
    ],
  });
  // /slow/... serves /data/... with every chunk 600 ms late (a slow link, for pause/resume: the
  // stream must still be going when the pause button has been found and clicked, which takes a
  // slow machine with a software GL a few seconds), and every chunk request is logged.
  ({ server, baseUrl } = await listenWithSlowRoute(files, {
    slowTo: '/data',
    delayMs: 600,
    onRequest: (req) => { if (/\.tsc$/.test(req.url)) chunkRequests.push(req.url); },
  }));
  browser = await launchBrowser();
});

after(async () => {
  if (browser) await browser.close();
  if (server) await new Promise((resolve) => server.close(resolve));
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

test('streams a multi-chunk pack to complete, matches the CLI surface, and the isovalue slider drags', async (t) => {
  const manifest = readManifest();
  assert.ok(manifest.chunks.length >= 20, `a stream of many chunks (${manifest.chunks.length})`);
  const { page, problems } = await openViewer('?data=/data/manifest.json');
  const first = await waitForState(page, ['streaming', 'complete', 'error']);
  assert.equal(first.state, 'streaming', `the base is shown before the rest: ${first.state} ${first.error}`);
  assert.ok(first.triangles > 0 && first.vertices < manifest.vertices);
  const s = await waitForState(page, ['complete', 'error']);
  assert.equal(s.state, 'complete', `viewer ended in ${s.state}: ${s.error}`);
  assert.equal(s.vertices, manifest.vertices);
  assert.equal(s.tets, manifest.tets);
  assert.equal(s.chunksReceived, manifest.chunks.length);
  assert.equal(s.chunksApplied, manifest.chunks.length);
  assert.equal(s.splitsApplied, s.splitsTotal);
  assert.equal(s.level, 1);
  assert.equal(s.fieldError, 0);
  assert.equal(s.bytesReceived, s.bytesTotal);
  assert.equal(s.field, manifest.isoField);
  const range = manifest.fields.find((f) => f.name === manifest.isoField);
  assert.ok(s.isovalue > range.min && s.isovalue < range.max, 'default isovalue lies inside the field range');
  assert.ok(s.firstSurfaceMs > 0 && s.completeMs > s.firstSurfaceMs, 'first surface and completion times recorded');
  t.diagnostic(`Harmonic 32³, ${manifest.chunks.length} chunks, ${s.splitsTotal} splits: first surface ` +
    `${s.firstSurfaceMs.toFixed(0)} ms after navigation start, complete after ${s.completeMs.toFixed(0)} ms`);
  t.diagnostic(frameReport(s));
  assertSlices(s);
  // The splits were applied by the refinement worker: the page took its updates (each a
  // geometry delta), and its own heap holds the surfaces' copies, not the dataset.
  assert.equal(s.refinement, 'worker');
  assert.ok(s.worker.updates > 0 && s.worker.deltaBytes > 0, `updates from the worker: ${JSON.stringify(s.worker)}`);
  assert.ok(s.worker.commands >= 1, 'the view went to the worker');
  assert.ok(s.memory.pageHeapBytes < s.memory.heapBytes,
    `the page's heap (${s.memory.pageHeapBytes}) is smaller than the worker's (${s.memory.heapBytes})`);
  // Splits upload changed ranges: a whole buffer goes only when it has to grow (doubling).
  assert.ok(s.partialUploads > 0, 'changed ranges were uploaded');
  assert.equal(s.fullUploads, s.grownUploads, 'no whole-buffer upload while streaming except to grow a buffer');
  // SwiftShader: every frame drawn while refining is drawn at reduced resolution (how many such
  // frames there are depends on the machine; the rule is tested natively, SceneIsReduced...);
  // the picture compared below is the full-size still frame drawn once the level settled.
  if (s.softwareGl) assert.equal(s.reducedFrames, s.busyFrames, 'every frame while refining was reduced');

  // The surface after every split equals a from-scratch extraction on the original mesh.
  const ref = cliIso(s.isovalue, { dir: originalVtu });
  assert.ok(ref.triangles > 100, 'the reference surface is not trivial');
  assert.equal(s.triangles, ref.triangles);
  assert.equal(s.surfaceVertices, ref.vertices);
  assertClose(s.surfaceArea, ref.area, 1e-6, 'surface area');

  await frames(page);
  await page.screenshot({ path: path.join(outDir, 'viewer-complete.png') });

  // The picture itself: the surface built by 32k local updates draws like a surface extracted
  // from scratch (selecting the field again rebuilds it). Same triangles; vertex normals were
  // summed in a different order, and fragments at equal depth may resolve by draw order, so a
  // few pixels may differ: at most 0.01% of them by more than 8 levels, 0.1% at all.
  const view = { x: 360, y: 0, width: 920, height: 700 }; // right of the panel, above the status line
  const streamed = await page.screenshot({ clip: view });
  await page.evaluate((f) => window.tetstream.setField(f), manifest.isoField);
  await frames(page, 6);
  const rebuilt = await page.evaluate(() => window.tetstream.stats());
  assert.equal(rebuilt.triangles, s.triangles);
  const diff = await pictureDifference(page, streamed, await page.screenshot({ clip: view }));
  assert.ok(diff.differing <= 0.001 * diff.pixels && diff.large <= 0.0001 * diff.pixels,
    `streamed and rebuilt surfaces draw the same: ${JSON.stringify(diff)}`);

  // Drag the ImGui isovalue slider from its middle to 85% of its width with the mouse. (Where
  // it is now: lines of the panel above it may have changed since the stream completed.)
  const r = (await page.evaluate(() => window.tetstream.stats())).sliderRect;
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

test('the level moves between the base mesh and the newest level, by API and by slider', async (t) => {
  const manifest = readManifest();
  const base = manifest.chunks[0];
  const { page, problems } = await openViewer('?data=/data/manifest.json');
  const full = await waitForState(page, ['complete', 'error']);
  assert.equal(full.state, 'complete', full.error);

  // Back to the base mesh: every split undone, the surface following locally.
  await page.evaluate(() => window.tetstream.setLevel(0));
  let s = await waitForLevel(page);
  assert.equal(s.splitsApplied, 0);
  assert.equal(s.vertices, base.vertices);
  assert.equal(s.tets, base.tets);
  assert.equal(s.level, base.vertices / manifest.vertices);
  assert.equal(s.fieldError, base.fieldError);
  assert.equal(s.live, false);
  assert.equal(s.state, 'streaming', 'not every split is applied any more');
  const refBase = cliIso(s.isovalue, { chunks: 1 });
  assert.equal(s.triangles, refBase.triangles);
  assert.equal(s.surfaceVertices, refBase.vertices);
  assertClose(s.surfaceArea, refBase.area, 1e-6, 'surface area at the base');
  t.diagnostic(`undoing ${full.splitsApplied} splits: ${frameReport(s)}`);
  assertSlices(s);
  await frames(page);
  await page.screenshot({ path: path.join(outDir, 'viewer-base.png') });

  // Half of the vertices: equal to the CLI at --fraction 0.5.
  await page.evaluate(() => window.tetstream.setLevel(0.5));
  s = await waitForLevel(page);
  assert.equal(s.vertices, Math.round(0.5 * manifest.vertices));
  const refHalf = cliIso(s.isovalue, { fraction: 0.5 });
  assert.equal(s.tets, refHalf.tets);
  assert.equal(s.triangles, refHalf.triangles);
  assertClose(s.surfaceArea, refHalf.area, 1e-6, 'surface area at half the vertices');

  // The ImGui level slider, dragged with the mouse from its left end to the middle.
  await page.evaluate(() => window.tetstream.setLevel(0));
  s = await waitForLevel(page);
  await frames(page);
  const r = (await page.evaluate(() => window.tetstream.stats())).levelSliderRect;
  assert.ok(r.w > 50 && r.h > 5, `level slider rectangle recorded: ${JSON.stringify(r)}`);
  const y = r.y + r.h / 2;
  await page.mouse.move(r.x + 2, y);
  await frames(page, 2);
  await page.mouse.down();
  await frames(page, 2);
  for (let i = 1; i <= 5; i++) {
    await page.mouse.move(r.x + 0.1 * i * r.w, y);
    await frames(page, 2);
  }
  await page.mouse.up();
  const dragged = await waitForLevel(page);
  assert.ok(dragged.vertices > base.vertices + 0.2 * (manifest.vertices - base.vertices),
    `dragging the level slider right refined the mesh: ${base.vertices} -> ${dragged.vertices} vertices`);
  assert.ok(dragged.vertices < manifest.vertices, 'but not to the full mesh');
  assert.equal(dragged.live, false);
  const refDragged = cliIso(dragged.isovalue, { fraction: dragged.vertices / manifest.vertices });
  if (refDragged.tets === dragged.tets) assert.equal(dragged.triangles, refDragged.triangles);
  await frames(page);
  await page.screenshot({ path: path.join(outDir, 'viewer-level-dragged.png') });

  // And forward to the newest level: complete again, equal to the full mesh.
  await page.evaluate(() => window.tetstream.setLevel(1));
  s = await waitForState(page, ['complete', 'error']);
  assert.equal(s.state, 'complete');
  assert.equal(s.vertices, manifest.vertices);
  assert.equal(s.live, true);
  assert.equal(s.triangles, full.triangles);
  assertClose(s.surfaceArea, full.surfaceArea, 1e-9, 'surface area back at the full level');
  t.diagnostic(`level moves: ${frameReport(s)}`);
  assertSlices(s);
  assert.deepEqual(problems, []);
  await page.close();
});

test('pause stops fetching, resume completes the stream', async (t) => {
  const manifest = readManifest();
  // Part 6 is held (headers sent, body waiting) until the test resumes: the stream is still
  // going when the pause button has been found and clicked, however long that takes.
  files.setFaults([{ match: manifest.chunks[5].file, kind: 'hold' }]);
  const hold = files.faults[0];
  const { page, problems } = await openViewer('?data=/slow/manifest.json');
  await page.waitForFunction(() => window.tetstream.stats().chunksReceived >= 3, null, { timeout: 60000 });
  const before = await page.evaluate(() => window.tetstream.stats());
  assert.ok(before.rateBytesPerSec > 0, `a download rate is shown: ${before.rateBytesPerSec}`);
  assert.ok(before.secondsLeft > 0, `and the time left: ${before.secondsLeft}`);
  t.diagnostic(`slow link: ${(before.rateBytesPerSec / 1024).toFixed(0)} KB/s, ${before.secondsLeft.toFixed(1)} s left`);

  // Pause with the panel's button (the same path as tetstream.pause()). Rectangles are those
  // of the last drawn frame: let the panel settle first, with the pointer over it (a software GL
  // redraws a refining level only now and then, but the panel under the pointer every frame).
  await page.mouse.move(40, 300);
  await frames(page, 6);
  const b = (await page.evaluate(() => window.tetstream.stats())).pauseButtonRect;
  assert.ok(b.w > 20 && b.h > 5, `pause button recorded: ${JSON.stringify(b)}`);
  await page.mouse.move(b.x + b.w / 2, b.y + b.h / 2);
  await frames(page, 2);
  await page.mouse.down();
  await frames(page, 2);
  await page.mouse.up();
  await page.waitForFunction(() => window.tetstream.stats().paused, null, { timeout: 5000 }).catch(async (e) => {
    const st = await page.evaluate(() => window.tetstream.stats());
    throw new Error(`not paused after the click (${st.state}, ${st.chunksReceived} chunks in): ${e.message}`);
  });
  const p = await page.evaluate(() => window.tetstream.stats());
  assert.equal(p.paused, true);
  assert.ok(p.chunksReceived < manifest.chunks.length, 'paused before the end');
  await new Promise((resolve) => setTimeout(resolve, 1200)); // time for a request that should not come
  const q = await page.evaluate(() => window.tetstream.stats());
  assert.equal(q.chunksReceived, p.chunksReceived, 'no chunk arrives while paused');
  // The loader made no request after the pause, and the server saw none but those made before.
  const pause = q.requestLog.findLast((e) => e.event === 'pause');
  assert.ok(pause, 'the pause reached the loader');
  const made = q.requestLog.filter((e) => e.event === 'request');
  assert.deepEqual(made.filter((e) => e.seq > pause.seq), [], 'no request is made while paused');
  const seen = chunkRequests.filter((url) => url.startsWith('/slow/'));
  assert.ok(seen.length <= made.length, `the server saw ${seen.length} chunk requests, the loader made ${made.length}`);
  assert.equal(q.rateBytesPerSec, 0);
  assert.equal(q.splitsApplied, q.splitsReceived, 'what had arrived is still applied');
  assert.equal(q.state, 'streaming');
  await page.mouse.move(900, 500); // no tooltip in the picture
  await frames(page, 4);
  await page.screenshot({ path: path.join(outDir, 'viewer-paused.png') });

  hold.release();
  files.setFaults([]);
  await page.evaluate(() => window.tetstream.resume());
  const s = await waitForState(page, ['complete', 'error']);
  assert.equal(s.state, 'complete', s.error);
  assert.equal(s.paused, false);
  assert.equal(s.vertices, manifest.vertices);
  const ref = cliIso(s.isovalue);
  assert.equal(s.triangles, ref.triangles);
  assertClose(s.surfaceArea, ref.area, 1e-6, 'surface area after pause and resume');
  t.diagnostic(`slow link, paused ${q.chunksReceived} of ${manifest.chunks.length} chunks in: ${frameReport(s)}`);
  assertSlices(s);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a split chunk missing mid-stream: the error is shown and the level reached stays usable', async () => {
  const manifest = readManifest(gapPack);
  const { page, problems } = await openViewer('?data=/gap/manifest.json', { allow: [/Failed to load resource.*404/] });
  const s = await waitForState(page, ['complete', 'error']);
  assert.equal(s.state, 'error');
  assert.match(s.error, /part 6 of/);
  assert.match(s.error, /HTTP 404/);
  assert.match(await page.textContent('#status-text'), /HTTP 404/);
  assert.equal((await waitForChunksReceived(page, 5)).chunksReceived, 5, 'the five chunks before the gap were kept');
  // What did arrive is applied, and stays on screen.
  const t = await waitForLevel(page);
  assert.equal(t.state, 'error');
  assert.equal(t.splitsApplied, t.splitsReceived);
  assert.equal(t.vertices, manifest.chunks[4].vertices);
  assert.ok(t.triangles > 0, 'the surface of the last good level stays');
  assert.equal(t.triangles, cliIso(t.isovalue, { chunks: 5, dir: gapPack }).triangles);
  // The level slider still works over what arrived.
  await page.evaluate(() => window.tetstream.setLevel(0));
  const b = await waitForLevel(page);
  assert.equal(b.vertices, manifest.chunks[0].vertices);
  assert.equal(b.state, 'error', 'and the error stays shown');
  await page.evaluate(() => window.tetstream.setLevel(1));
  await waitForLevel(page);
  await frames(page);
  await page.screenshot({ path: path.join(outDir, 'viewer-404.png') });
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
    assert.equal(s.vertices, readManifest().vertices);
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

test('a chunk damaged at the source is fetched again, never applied, and then refused in plain words', async () => {
  const base = readManifest(badPack).chunks[0].file;
  const { page, problems } = await openViewer('?data=/bad/manifest.json');
  const s = await waitForState(page, ['complete', 'error']);
  assert.equal(s.state, 'error');
  assert.match(s.error, /^Part 1 of \d+ of the dataset arrived damaged 4 times in a row \(its content does not match the manifest's hash\)/);
  assert.equal(s.chunksRefused, 4, 'every damaged copy was refused');
  assert.equal(s.retries, 3);
  assert.equal(chunkRequests.filter((url) => url === `/bad/${base}`).length, 4, 'and fetched again each time');
  assert.equal(s.chunksReceived, 0);
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
