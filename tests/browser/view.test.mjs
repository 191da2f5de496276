// Browser tests of the ways to look at a dataset: colour by a second field with
// a colour bar, the slice plane (and that it follows refinement locally), the view as a URL that
// reopens the same picture, screenshots, the help panel, opening a packed folder from the disk
// by drag-and-drop, touch gestures, multisampling (?antialias), and that drawing makes no WebGL
// call that waits for the GPU process. Screenshots go to build/test-output/view-*.png.
//   node --test tests/browser/view.test.mjs
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { createServer } from '../../server/serve.mjs';
import {
  webDir, outDir, checkBuilds, launchBrowser, cli, readManifest, openViewer as openViewerAt, waitForState,
  waitForLevel, frames, pictureDifference, listenWithSlowRoute,
} from './support.mjs';

let tmp, pack, server, baseUrl, browser;

// A 17^3 grid over [-1, 1]^3 (Kuhn split) with two point fields, written as legacy VTK:
// "radius" (ellipsoids; the isosurface) and "height" = z + 0.3 x (the colour).
function writeTwoFieldVtk(file, n = 17) {
  const id = (i, j, k) => i + n * (j + n * k);
  const p = [];
  const radius = [], height = [];
  for (let k = 0; k < n; k++) for (let j = 0; j < n; j++) for (let i = 0; i < n; i++) {
    const x = -1 + 2 * i / (n - 1), y = -1 + 2 * j / (n - 1), z = -1 + 2 * k / (n - 1);
    p.push([x, y, z]);
    radius.push(Math.sqrt(x * x + 1.6 * y * y + 0.7 * z * z));
    height.push(z + 0.3 * x);
  }
  const tets = [];
  const perms = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
  const vol = (a, b, c, d) => {
    const u = [0, 1, 2].map((t) => p[b][t] - p[a][t]), v = [0, 1, 2].map((t) => p[c][t] - p[a][t]);
    const w = [0, 1, 2].map((t) => p[d][t] - p[a][t]);
    return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
  };
  for (let k = 0; k < n - 1; k++) for (let j = 0; j < n - 1; j++) for (let i = 0; i < n - 1; i++) {
    for (const perm of perms) {
      const c = [i, j, k];
      const t = [id(...c)];
      for (const axis of perm) {
        c[axis]++;
        t.push(id(...c));
      }
      if (vol(...t) < 0) [t[2], t[3]] = [t[3], t[2]];
      tets.push(t);
    }
  }
  const lines = ['# vtk DataFile Version 3.0', 'two fields', 'ASCII', 'DATASET UNSTRUCTURED_GRID',
    `POINTS ${p.length} float`, ...p.map((q) => q.join(' ')),
    `CELLS ${tets.length} ${5 * tets.length}`, ...tets.map((t) => `4 ${t.join(' ')}`),
    `CELL_TYPES ${tets.length}`, ...tets.map(() => '10'),
    `POINT_DATA ${p.length}`, 'SCALARS radius float 1', 'LOOKUP_TABLE default', ...radius.map(String),
    'SCALARS height float 1', 'LOOKUP_TABLE default', ...height.map(String)];
  fs.writeFileSync(file, `${lines.join('\n')}\n`);
}

function openViewer(query, options) {
  return openViewerAt(browser, `${baseUrl}/index.html${query}`, options);
}

// Every file of a packed folder as [relative path, base64 bytes].
function folderFiles(dir) {
  const out = [];
  const walk = (d, prefix) => {
    for (const e of fs.readdirSync(d, { withFileTypes: true })) {
      if (e.isDirectory()) walk(path.join(d, e.name), `${prefix}${e.name}/`);
      else out.push([`${prefix}${e.name}`, fs.readFileSync(path.join(d, e.name)).toString('base64')]);
    }
  };
  walk(dir, '');
  return out;
}

// Waits until every part is in and the level has reached its target.
async function waitSettled(page, timeout = 120000) {
  await page.waitForFunction(() => {
    const s = window.tetstream.stats();
    return s.state === 'error' || (s.chunksReceived === s.chunksTotal && s.chunksTotal > 0 && s.splitsApplied === s.targetSplits);
  }, null, { timeout });
  // The status box fades in again when the level moves off complete: pictures wait for the fade.
  await page.waitForFunction(() => document.getAnimations().every((a) => a.playState !== 'running'), null, { timeout });
  await frames(page, 4);
  return page.evaluate(() => window.tetstream.stats());
}

// Green to yellow-green pixels (viridis' middle and upper part; the two-sided tint is orange
// and blue, the background grey-blue).
async function countGreen(page, png) {
  return page.evaluate(async (src) => {
    const im = new Image();
    await new Promise((r, e) => { im.onload = r; im.onerror = e; im.src = src; });
    const c = new OffscreenCanvas(im.width, im.height);
    const g = c.getContext('2d');
    g.drawImage(im, 0, 0);
    const d = g.getImageData(0, 0, im.width, im.height).data;
    let n = 0;
    for (let k = 0; k < d.length; k += 4) if (d[k + 1] > d[k] + 30 && d[k + 1] > d[k + 2] + 10) n++;
    return n;
  }, `data:image/png;base64,${png.toString('base64')}`);
}

before(async () => {
  checkBuilds();
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'tetstream-view-'));
  const vtk = path.join(tmp, 'two.vtk');
  writeTwoFieldVtk(vtk);
  pack = path.join(tmp, 'two');
  // One node (--leaf-vertices 0): every chunk streams, in manifest order (selective.test.mjs has a
  // dataset of nodes).
  cli('pack', vtk, '-o', pack, '--chunk-kb', '8', '--lossless', '--leaf-vertices', '0', '--field', 'radius', '--name', 'Two fields');
  const files = createServer({ mounts: [{ prefix: '/two', dir: pack }, { prefix: '/', dir: webDir }] });
  // /slow/... serves /two/... with every chunk 250 ms late (so a test can act mid-stream).
  ({ server, baseUrl } = await listenWithSlowRoute(files, { slowTo: '/two', delayMs: 250 }));
  browser = await launchBrowser();
});

after(async () => {
  if (browser) await browser.close();
  if (server) await new Promise((resolve) => server.close(resolve));
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

test('colour by a second field with a colour bar, and a slice plane drawn with the isosurface', async (t) => {
  const manifest = readManifest(pack);
  assert.deepEqual(manifest.fields.map((f) => f.name).sort(), ['height', 'radius']);
  const { page, problems } = await openViewer('?data=/two/manifest.json');
  let s = await waitForState(page, ['complete', 'error']);
  assert.equal(s.state, 'complete', s.error);
  assert.equal(s.field, 'radius');
  assert.equal(s.colourField, null);
  await frames(page);
  const plain = await page.screenshot();

  assert.equal(await page.evaluate(() => window.tetstream.setColourField('height')), true);
  assert.equal(await page.evaluate(() => window.tetstream.setColourField('nonsense')), false);
  assert.equal(await page.evaluate(() => window.tetstream.setColourMap('viridis')), true);
  await frames(page);
  s = await page.evaluate(() => window.tetstream.stats());
  const height = manifest.fields.find((f) => f.name === 'height');
  assert.equal(s.colourField, 'height');
  assert.equal(s.field, 'radius', 'the isovalue keeps its own field');
  assert.equal(s.colourMap, 'viridis');
  assert.deepEqual(s.colourRange, [Math.fround(height.min), Math.fround(height.max)]);
  const coloured = await page.screenshot({ path: path.join(outDir, 'view-colour.png') });
  const green = await countGreen(page, coloured);
  const greenBefore = await countGreen(page, plain);
  t.diagnostic(`green pixels: ${green} coloured by height, ${greenBefore} before`);
  assert.ok(green > 30000 && green > 20 * greenBefore, `the map's colours show (${green} vs ${greenBefore})`);
  // "fit" (button, F key or API): the range of the values on the surface, inside the field's.
  assert.equal(await page.evaluate(() => window.tetstream.fitColourRange()), true);
  s = await page.evaluate(() => window.tetstream.stats());
  t.diagnostic(`fitted colour range ${s.colourRange} (field ${height.min} .. ${height.max})`);
  assert.ok(s.colourRange[0] >= Math.fround(height.min) && s.colourRange[1] <= Math.fround(height.max) &&
    s.colourRange[1] - s.colourRange[0] < 0.9 * (height.max - height.min), `fitted ${s.colourRange}`);
  await frames(page);
  await page.screenshot({ path: path.join(outDir, 'view-colour-fit.png') });
  await page.evaluate((h) => window.tetstream.setColourRange(h.min, h.max), height);
  await page.keyboard.press('f');
  await frames(page);
  const byKey = await page.evaluate(() => window.tetstream.stats());
  assert.deepEqual(byKey.colourRange, s.colourRange, 'the F key fits too');
  await page.evaluate((h) => window.tetstream.setColourRange(h.min, h.max), height);

  // The slice z = 0.3 through the box: a 2 x 2 square (lossless pack: the original grid).
  assert.equal(await page.evaluate(() => window.tetstream.setSlice({ on: true, normal: [0, 0, 1], offset: 0.3 })), true);
  await frames(page);
  s = await page.evaluate(() => window.tetstream.stats());
  assert.equal(s.slice.on, true);
  assert.deepEqual(s.slice.normal, [0, 0, 1]);
  assert.ok(Math.abs(s.slice.area - 4) < 1e-4, `slice area ${s.slice.area}`);
  assert.ok(s.slice.triangles > 0);
  const sliced = await page.screenshot({ path: path.join(outDir, 'view-slice.png') });
  const diff = await pictureDifference(page, coloured, sliced);
  assert.ok(diff.large > 20000, `the slice shows (${diff.large} pixels changed)`);
  // An oblique slice and the other maps.
  await page.evaluate(() => {
    window.tetstream.setSlice({ normal: [1, 1, 1], offset: 0 });
    window.tetstream.setColourMap('coolwarm');
  });
  await frames(page);
  s = await page.evaluate(() => window.tetstream.stats());
  assert.ok(Math.abs(s.slice.area - 3 * Math.sqrt(3)) < 1e-3, `hexagon area ${s.slice.area}`);
  await page.screenshot({ path: path.join(outDir, 'view-slice-oblique.png') });
  // The position slider moves the slice.
  const r = s.sliceSliderRect;
  await page.mouse.click(r.x + 0.8 * r.w, r.y + r.h / 2);
  await frames(page);
  const moved = await page.evaluate(() => window.tetstream.stats());
  assert.ok(moved.slice.offset > 0.2, `slider moved the slice to ${moved.slice.offset}`);
  // Shift + drag in the view moves it too (up = forward), without turning the camera.
  const cam = await page.evaluate(() => window.tetstream.getState().camera);
  await page.keyboard.down('Shift');
  await page.mouse.move(900, 500);
  await frames(page); // ImGui sees the mouse leave the panel before the press
  await page.mouse.down();
  for (let k = 1; k <= 5; k++) await page.mouse.move(900, 500 + 20 * k);
  await page.mouse.up();
  await page.keyboard.up('Shift');
  await frames(page);
  const dragged = await page.evaluate(() => window.tetstream.getState());
  assert.ok(dragged.slice.offset < moved.slice.offset - 0.1, `dragged the slice ${moved.slice.offset} -> ${dragged.slice.offset}`);
  assert.deepEqual(dragged.camera, cam, 'the camera stays');
  assert.deepEqual(problems, []);
  await page.close();
});

test('the slice follows refinement locally while the dataset streams in', async () => {
  const { page, problems } = await openViewer('?data=/slow/manifest.json');
  // Turned on in the page the moment the base is shown, with the download paused meanwhile:
  // a round trip from here could come after the last chunk on a fast machine.
  const early = await page.evaluate(() => new Promise((resolve) => {
    const poll = () => {
      const state = window.tetstream?.stats().state;
      if (!['streaming', 'complete', 'error'].includes(state)) return setTimeout(poll, 1);
      window.tetstream.pause();
      window.tetstream.setSlice({ on: true, normal: [0.3, -0.8, 0.5], offset: -0.1 });
      const stats = window.tetstream.stats();
      window.tetstream.resume();
      resolve(stats);
    };
    poll();
  }));
  const s = await waitForState(page, ['complete', 'error']);
  assert.equal(s.state, 'complete', s.error);
  assert.ok(early.splitsApplied < s.splitsTotal, 'the slice was on before the last splits');
  // Off and on again: extracted from scratch on the full mesh. The same slice.
  await page.evaluate(() => {
    window.tetstream.setSlice({ on: false });
    window.tetstream.setSlice({ on: true });
  });
  const fresh = await page.evaluate(() => window.tetstream.stats());
  assert.equal(fresh.slice.triangles, s.slice.triangles);
  assert.ok(Math.abs(fresh.slice.area - s.slice.area) <= 1e-9 * fresh.slice.area, `${fresh.slice.area} vs ${s.slice.area}`);
  assert.deepEqual(problems, []);
  await page.close();
});

test('the view as a link: set a state, read the URL, open it in a fresh page: same state and picture', async (t) => {
  const { page, problems } = await openViewer('?data=/two/manifest.json');
  await waitForState(page, ['complete', 'error']);
  const wanted = {
    isovalue: 0.62, colourField: 'height', colourMap: 'magma', colourRange: [-0.9, 0.75],
    slice: { on: true, normal: [0, 1, 0], offset: 0.15 }, level: 0.6,
    camera: { target: [0.1, -0.05, 0.02], distance: 4.2, yaw: -0.7, pitch: 0.5 },
  };
  await page.evaluate((w) => window.tetstream.setState(w), wanted);
  const before = await waitSettled(page);
  assert.equal(before.colourField, 'height');
  assert.equal(before.slice.on, true);
  await frames(page, 4);
  const state = await page.evaluate(() => window.tetstream.getState());
  const link = await page.evaluate(() => window.tetstream.link());
  const shown = await page.evaluate(() => location.href);
  assert.equal(shown, link, 'the address bar holds the link');
  t.diagnostic(`link: ${link}`);
  assert.ok(link.length < 400, `compact (${link.length} characters)`);
  assert.equal(state.colourMap, 'magma');
  assert.ok(Math.abs(state.isovalue - 0.62) < 1e-6);
  assert.ok(Math.abs(state.level - 0.6) < 0.01, `level ${state.level}`);
  assert.ok(Math.abs(state.camera.distance - 4.2) < 1e-5);
  const panel = before.panelRect;
  const clip = { x: Math.ceil(panel.x + panel.w + 4), y: 0, width: 0, height: 800 };
  clip.width = 1280 - clip.x;
  const a = await page.screenshot({ clip, path: path.join(outDir, 'view-link-a.png') });

  const second = await openViewerAt(browser, link);
  await waitSettled(second.page);
  await frames(second.page, 6);
  const restored = await second.page.evaluate(() => window.tetstream.getState());
  const b = await second.page.screenshot({ clip, path: path.join(outDir, 'view-link-b.png') });
  assert.deepEqual(restored, state, 'the same state');
  const diff = await pictureDifference(page, a, b);
  t.diagnostic(`pictures: ${diff.differing} pixels differ, ${diff.large} by more than 8 levels, max ${diff.maxDiff}`);
  assert.ok(diff.large < 0.001 * diff.pixels, `the same picture (${diff.large} pixels differ)`);
  assert.deepEqual(problems, []);
  assert.deepEqual(second.problems, []);
  await second.page.close();
  await page.close();
});

test('screenshot as PNG (API and key), help panel with the shortcuts, keys change the view', async () => {
  const { page, problems } = await openViewer('?data=/two/manifest.json');
  await waitForState(page, ['complete', 'error']);
  await frames(page);
  const png = await page.evaluate(async () => {
    const blob = await window.tetstream.screenshot();
    return { type: blob.type, size: blob.size, head: [...new Uint8Array(await blob.slice(0, 8).arrayBuffer())] };
  });
  assert.equal(png.type, 'image/png');
  assert.deepEqual(png.head, [137, 80, 78, 71, 13, 10, 26, 10]);
  assert.ok(png.size > 20000, `a real picture (${png.size} bytes)`);
  // The S key saves one.
  await page.mouse.click(900, 400);
  const download = page.waitForEvent('download');
  await page.keyboard.press('s');
  const file = await download;
  assert.match(file.suggestedFilename(), /^Two_fields-.*\.png$/);
  // ? opens the help panel, Esc closes it.
  await page.keyboard.press('Shift+Slash');
  await frames(page);
  assert.equal((await page.evaluate(() => window.tetstream.stats())).showHelp, true);
  await page.screenshot({ path: path.join(outDir, 'view-help.png') });
  await page.keyboard.press('Escape');
  await frames(page);
  assert.equal((await page.evaluate(() => window.tetstream.stats())).showHelp, false);
  // P turns the slice on, C colours by the next field, M the next map.
  await page.keyboard.press('p');
  await page.keyboard.press('m');
  await frames(page);
  const s = await page.evaluate(() => window.tetstream.stats());
  assert.equal(s.slice.on, true);
  assert.equal(s.colourField, 'radius', 'the slice colours by the isovalue field when there is no colour field');
  assert.equal(s.colourMap, 'magma');
  assert.deepEqual(problems, []);
  await page.close();
});

test('a packed folder dropped on the page streams to complete from the local files', async () => {
  const { page, problems } = await openViewer('');
  await page.waitForFunction(() => document.getElementById('help').style.display === 'flex');
  const files = folderFiles(pack);
  await page.evaluate((list) => {
    const dt = new DataTransfer();
    for (const [name, b64] of list) {
      const bytes = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
      // A DataTransfer built in the page holds plain files (no directory entries): their names.
      dt.items.add(new File([bytes], name.split('/').pop()));
    }
    document.getElementById('canvas').dispatchEvent(new DragEvent('drop', { dataTransfer: dt, bubbles: true, cancelable: true }));
  }, files);
  const s = await waitForState(page, ['complete', 'error']);
  assert.equal(s.state, 'complete', s.error);
  const manifest = readManifest(pack);
  assert.equal(s.vertices, manifest.vertices);
  assert.equal(s.name, 'Two fields');
  const ref = JSON.parse(cli('iso', pack, '--value', String(s.isovalue), '--json'));
  assert.equal(s.triangles, ref.triangles);
  // The folder chooser's way (paths inside the folder), over the dataset shown, with one chunk
  // damaged: refused by the content check, in plain words.
  const damaged = files.map(([name, b64]) => {
    if (name !== manifest.chunks[2].file) return [name, b64];
    const bytes = Buffer.from(b64, 'base64');
    bytes[bytes.length >> 1] ^= 0x5a;
    return [name, bytes.toString('base64')];
  });
  await page.evaluate((list) => window.tetstream.openFiles(list.map(([name, b64]) => ({
    path: `two/${name}`, file: new File([Uint8Array.from(atob(b64), (c) => c.charCodeAt(0))], name.split('/').pop()),
  }))), damaged);
  const bad = await waitForState(page, ['error', 'complete']);
  assert.equal(bad.state, 'error');
  assert.match(bad.error, /part 3 of/i);
  assert.ok(bad.triangles > 0, 'the level reached stays shown');
  assert.deepEqual(problems.filter((p) => !/damaged|Failed to load/i.test(p)), []);
  await page.close();
});

test('touch: one finger orbits, pinch zooms, two fingers pan', async () => {
  const { page, problems } = await openViewer('?data=/two/manifest.json');
  await waitForState(page, ['complete', 'error']);
  await frames(page);
  const camera = () => page.evaluate(() => window.tetstream.getState().camera);
  const touch = (type, id, x, y) => page.evaluate(([ty, i, px, py]) => {
    document.getElementById('canvas').dispatchEvent(new PointerEvent(ty, {
      pointerId: i, pointerType: 'touch', isPrimary: i === 1, clientX: px, clientY: py, bubbles: true, cancelable: true,
    }));
  }, [type, id, x, y]);
  const c0 = await camera();
  await touch('pointerdown', 1, 800, 400);
  for (let k = 1; k <= 5; k++) await touch('pointermove', 1, 800 + 20 * k, 400);
  await touch('pointerup', 1, 900, 400);
  const c1 = await camera();
  assert.ok(Math.abs(c1.yaw - c0.yaw) > 0.1, `orbit: yaw ${c0.yaw} -> ${c1.yaw}`);
  assert.equal(c1.distance, c0.distance);
  // Pinch out: fingers 100 -> 200 px apart, centre fixed: closer by a factor 2.
  await touch('pointerdown', 1, 750, 400);
  await touch('pointerdown', 2, 850, 400);
  await touch('pointermove', 1, 700, 400);
  await touch('pointermove', 2, 900, 400);
  const c2 = await camera();
  assert.ok(Math.abs(c2.distance / c1.distance - 0.5) < 0.01, `pinch: distance ${c1.distance} -> ${c2.distance}`);
  assert.equal(c2.yaw, c1.yaw, 'a pinch does not orbit');
  // Both fingers move 60 px up: a pan (the target moves), no zoom.
  await touch('pointermove', 1, 700, 340);
  await touch('pointermove', 2, 900, 340);
  await touch('pointerup', 1, 700, 340);
  await touch('pointerup', 2, 900, 340);
  const c3 = await camera();
  const moved = Math.hypot(...c3.target.map((v, i) => v - c2.target[i]));
  assert.ok(moved > 0.05, `pan: target moved ${moved}`);
  assert.ok(Math.abs(c3.distance - c2.distance) < 1e-3 * c2.distance, 'a pan does not zoom');
  assert.equal(c3.yaw, c2.yaw);
  assert.deepEqual(problems, []);
  await page.close();
});

test('high-DPI: the canvas has device pixels and the panel keeps its size in CSS pixels', async () => {
  const page = await browser.newPage({ viewport: { width: 1000, height: 700 }, deviceScaleFactor: 2 });
  const problems = [];
  page.on('pageerror', (e) => problems.push(e.message));
  await page.goto(`${baseUrl}/index.html?data=/two/manifest.json`);
  await waitForState(page, ['complete', 'error']);
  await frames(page);
  const size = await page.evaluate(() => {
    const c = document.getElementById('canvas');
    return { w: c.width, h: c.height, cssW: c.clientWidth, cssH: c.clientHeight, panel: window.tetstream.stats().panelRect };
  });
  assert.equal(size.w, 2 * size.cssW);
  assert.equal(size.h, 2 * size.cssH);
  // The panel is 320 CSS px of content wide at any ratio (ImGui scaled by 2, reported in CSS px).
  assert.ok(size.panel.w > 300 && size.panel.w < 420, `panel ${size.panel.w} CSS px wide`);
  await page.screenshot({ path: path.join(outDir, 'view-hidpi.png'), clip: { x: 0, y: 0, width: 400, height: 300 } });
  assert.deepEqual(problems, []);
  await page.close();
});

// The scene is multisampled in an offscreen target and resolved onto the canvas (the canvas has
// none of its own), by default unless WebGL renders in software, as here; ?antialias=1 or 0 says
// so explicitly. Multisampled, the picture is the same but for its edges, which are smoothed.
test('?antialias: the scene multisampled through an offscreen target, the same picture with smoothed edges', async () => {
  const view = { x: 420, y: 60, width: 520, height: 560 };
  const shots = {};
  for (const [name, query] of [['default', ''], ['on', '&antialias=1'], ['off', '&antialias=0']]) {
    const { page, problems } = await openViewer(`?data=/two/manifest.json${query}`);
    const s = await waitSettled(page);
    assert.deepEqual(problems, [], name);
    assert.equal(s.state, 'complete', name);
    const expected = name === 'on' || (name === 'default' && !s.softwareGl) ? 4 : 0;
    assert.equal(s.samples, expected, `${name}: samples`);
    shots[name] = { png: await page.screenshot({ clip: view }), triangles: s.triangles, page };
    if (name === 'on') await page.screenshot({ path: path.join(outDir, 'view-antialias.png'), clip: view });
  }
  assert.equal(shots.on.triangles, shots.off.triangles);
  const page = shots.off.page;
  const d = await pictureDifference(page, shots.off.png, shots.on.png);
  // Edges only: some pixels differ, few of them by much (the surface's outline, the box's lines).
  assert.ok(d.differing > 0.001 * d.pixels, `multisampling changed ${d.differing} of ${d.pixels} pixels`);
  assert.ok(d.large < 0.05 * d.pixels, `${d.large} of ${d.pixels} pixels changed by more than 8 levels`);
  for (const { page: p } of Object.values(shots)) await p.close();
});

// WebGL calls that make the page wait for the GPU process to finish everything queued before
// them (Chrome answers them there): once at start at most, never while frames are drawn. The
// state the viewer and Dear ImGui read back each frame are bindings, which WebGL tracks in the
// page. (Each such wait costs from a few ms to the whole previous frame on a busy GPU process.)
test('drawing frames makes no WebGL call that waits for the GPU process; starting makes few', async () => {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  await page.addInitScript(() => {
    window.__glCalls = [];
    const proto = WebGL2RenderingContext.prototype;
    for (const name of ['getParameter', 'getError', 'checkFramebufferStatus', 'getShaderParameter', 'getProgramParameter',
      'getShaderInfoLog', 'getProgramInfoLog', 'getExtension', 'getSupportedExtensions', 'readPixels', 'finish',
      'clientWaitSync', 'getBufferSubData', 'getFramebufferAttachmentParameter', 'getRenderbufferParameter']) {
      const call = proto[name];
      proto[name] = function (...args) {
        window.__glCalls.push(name === 'getParameter' || name === 'getProgramParameter' ? `${name}(${args[args.length - 1]})` : name);
        return call.apply(this, args);
      };
    }
  });
  await page.goto(`${baseUrl}/index.html?data=/two/manifest.json`);
  await waitSettled(page);
  const count = (calls, name) => calls.filter((c) => c === name || c.startsWith(`${name}(`)).length;
  const atStart = await page.evaluate(() => window.__glCalls.splice(0));
  assert.ok(count(atStart, 'getExtension') <= 1, `getExtension ${count(atStart, 'getExtension')} times (the renderer's name only)`);
  for (const name of ['getSupportedExtensions', 'getShaderParameter', 'checkFramebufferStatus', 'readPixels', 'finish'])
    assert.equal(count(atStart, name), 0, `${name} at start`);
  assert.ok(count(atStart, 'getError') <= 1, 'getError at start');
  assert.ok(count(atStart, 'getProgramParameter(35714)') <= 5, 'link status: once per program');  // LINK_STATUS
  // Frames: the camera turned, the isovalue moved, the slice on (each redraws and uploads).
  const gl = { ACTIVE_TEXTURE: 0x84e0, CURRENT_PROGRAM: 0x8b8d, TEXTURE_BINDING_2D: 0x8069, ARRAY_BUFFER_BINDING: 0x8894,
    VERTEX_ARRAY_BINDING: 0x85b5 };
  const bindings = new Set(Object.values(gl).map((pname) => `getParameter(${pname})`));
  for (let k = 0; k < 6; k++) {
    await page.mouse.move(700, 400);
    await page.mouse.down();
    await page.mouse.move(730 + 10 * k, 420);
    await page.mouse.up();
    await frames(page, 2);
  }
  await page.evaluate(() => window.tetstream.setState({ isovalue: 0.7, slice: { on: true, normal: [0, 0, 1], offset: 0.2 } }));
  await frames(page, 4);
  const drawn = await page.evaluate(() => window.__glCalls.splice(0));
  const waits = drawn.filter((c) => !bindings.has(c));
  assert.deepEqual(waits, [], 'calls that wait for the GPU process while drawing');
  assert.ok(drawn.length > 0, 'the frames read the bindings back (Dear ImGui): the check saw them');
  await page.close();
});

// The browser may take the WebGL context away (a GPU reset or switch): the page says so, keeps
// the data, and when the context comes back the viewer makes its GL objects again and shows the
// same picture.
test('a lost WebGL context: the page says so, and the same picture comes back with the context', async () => {
  const { page, problems } = await openViewer('?data=/two/manifest.json');
  const s = await waitSettled(page);
  const view = { x: 420, y: 60, width: 520, height: 560 };
  const panelTop = { x: 10, y: 10, width: 340, height: 180 };  // (its lines that do not change)
  const before = await page.screenshot({ clip: view });
  const panelBefore = await page.screenshot({ clip: panelTop });
  await page.evaluate(() => {
    window.__loseContext = document.getElementById('canvas').getContext('webgl2').getExtension('WEBGL_lose_context');
    window.__loseContext.loseContext();
  });
  await page.waitForFunction(() => window.tetstream.stats().contextLost === true);
  await page.waitForFunction(() => /graphics context/.test(document.getElementById('status-text').textContent), null,
    { timeout: 5000 });
  await page.evaluate(() => window.__loseContext.restoreContext());
  await page.waitForFunction(() => window.tetstream.stats().contextLost === false);
  await frames(page, 6);
  const after = await page.evaluate(() => window.tetstream.stats());
  assert.equal(after.triangles, s.triangles);
  assert.equal(after.state, 'complete');
  const d = await pictureDifference(page, before, await page.screenshot({ clip: view }));
  assert.ok(d.large <= 0.001 * d.pixels, `${d.large} of ${d.pixels} pixels differ by more than 8 levels after the restore`);
  const p = await pictureDifference(page, panelBefore, await page.screenshot({ clip: panelTop }));
  assert.ok(p.large <= 0.001 * p.pixels, `the panel: ${p.large} of ${p.pixels} pixels differ after the restore`);
  await page.screenshot({ path: path.join(outDir, 'view-context-restored.png') });
  assert.deepEqual(problems.filter((m) => !/context/i.test(m)), []);
  await page.close();
});
