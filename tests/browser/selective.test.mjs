// A dataset of nodes (core/FORMAT.md §1.1) in the viewer, headless Chromium: by default the page
// fetches only the nodes the isovalue needs, reaches the full-resolution surface exactly (the
// same triangles as `tetstream iso` on the whole mesh) from part of the bytes, fetches more when
// the isovalue moves and reaches it again; "load everything" still fetches every node; a node
// that cannot be had leaves its region coarse while the rest of the view goes on.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { createServer } from '../support/server.mjs';
import {
  webDir, outDir, checkBuilds, launchBrowser, cli, makePack, cliIso, readManifest, assertSurfaceMatches, openViewer,
} from './support.mjs';

let tmp, dir, manifest, browser;
const NETWORK_ERRORS = [/Failed to load resource/, /net::ERR_/];

function listen(server) {
  return new Promise((resolve) => server.listen(0, '127.0.0.1', () => resolve(`http://127.0.0.1:${server.address().port}`)));
}

// The viewer's state once the surface is exact for the current isovalue, or for `iso` once it
// has been set (exact is false until the worker has applied the latest view), and nothing is
// coming. (Waiting for exact to turn false first would miss a change made between two polls.)
async function waitForExact(page, iso = null) {
  await page.waitForFunction((v) => {
    const s = window.tetstream && window.tetstream.stats();
    return s && s.exact && s.state === 'complete' && (v === null || s.isovalue === v);
  }, iso === null ? null : Math.fround(iso), { timeout: 120000 });
  return page.evaluate(() => window.tetstream.stats());
}

function selectiveIso(value) {
  return JSON.parse(cli('iso', dir, '--value', String(value), '--selective', '--json'));
}

before(() => {
  checkBuilds();
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'tetstream-selective-'));
  // Harmonic 40³ (64,000 vertices) in leaves of 512 vertices: 7 levels of regions.
  ({ dir } = makePack(tmp, 'h40', { n: 40, packArgs: ['--leaf-vertices', '512'] }));
  manifest = readManifest(dir);
  assert.ok(manifest.nodes.length >= 64, `a hierarchy of nodes (${manifest.nodes.length})`);
  browser = launchBrowser();
});

after(async () => {
  await (await browser).close();
  fs.rmSync(tmp, { recursive: true, force: true });
});

test('only the nodes the isovalue needs are fetched; the surface is exact, and again after the isovalue moves', async () => {
  const server = createServer({ mounts: [{ prefix: '/data', dir }, { prefix: '/', dir: webDir }] });
  const url = await listen(server);
  const { min, max } = manifest.fields[0];
  const high = min + 0.8 * (max - min), low = min + 0.35 * (max - min);
  try {
    const { page, problems } = await openViewer(await browser, `${url}/index.html?data=/data/manifest.json&iso=${high}`);
    let s = await waitForExact(page);
    assertSurfaceMatches(s, cliIso(s.isovalue, { dir }), `exact at ${s.isovalue}`);
    const need = selectiveIso(s.isovalue);
    assert.equal(s.bytesReceived, need.bytes, 'the bytes of the needed nodes, no more');
    assert.equal(s.nodesLoaded, need.nodes, 'the nodes the CLI needed');
    assert.ok(s.bytesReceived < 0.8 * s.bytesTotal, `part of the dataset: ${s.bytesReceived} of ${s.bytesTotal}`);
    assert.equal(s.nodesTotal, manifest.nodes.length);
    // The field error shown: the largest measured of the regions not refined, below the base's.
    assert.ok(s.fieldMax > 0 && s.fieldMax < manifest.chunks[0].fieldMax, `field error ${s.fieldMax}`);
    assert.equal(s.fieldRms, null, 'no RMS for a set of nodes');
    await page.screenshot({ path: path.join(outDir, 'viewer-selective-exact.png') });
    const first = s.bytesReceived;

    // Dragging the isovalue re-plans: more nodes come and the surface is exact again.
    await page.evaluate((v) => window.tetstream.setIsovalue(v), low);
    s = await waitForExact(page, low);
    assertSurfaceMatches(s, cliIso(s.isovalue, { dir }), `exact at ${s.isovalue}`);
    assert.ok(s.bytesReceived > first, 'the new isovalue needed more nodes');
    const log = s.requestLog;
    assert.ok(log.some((e) => e.event === 'replan'), 'the loader was given a new plan');

    // Load everything: every node comes; the surface stays exact.
    await page.evaluate(() => window.tetstream.setFetchEverything(true));
    await page.waitForFunction(() => {
      const t = window.tetstream.stats();
      return t.state === 'complete' && t.chunksReceived === t.chunksTotal;
    }, null, { timeout: 120000 });
    s = await page.evaluate(() => window.tetstream.stats());
    assert.equal(s.nodesLoaded, s.nodesTotal);
    assert.equal(s.bytesReceived, s.bytesTotal);
    assert.ok(s.exact);
    assert.equal(s.fieldMax, 0, 'every region refined');
    assertSurfaceMatches(s, cliIso(s.isovalue, { dir }), 'everything');
    assert.deepEqual(problems, []);
    await page.close();
  } finally {
    await new Promise((resolve) => server.close(resolve));
  }
});

test('a node whose chunk is missing leaves its region coarse, in words, and the rest of the view goes on', async () => {
  const { min, max } = manifest.fields[0];
  const iso = min + 0.5 * (max - min);
  // A needed leaf (no node names it as parent) whose chunk the server does not have.
  const needed = manifest.nodes.map((n, k) => k).filter((k) => {
    const [lo, hi] = manifest.nodes[k].ranges[0];
    return lo <= iso && iso <= hi && !manifest.nodes.some((n) => n.parent === k);
  });
  assert.ok(needed.length > 2);
  const lost = manifest.chunks[manifest.nodes[needed[1]].chunks[0]].file;
  const server = createServer({
    mounts: [{ prefix: '/data', dir }, { prefix: '/', dir: webDir }],
    faults: [{ match: lost, kind: 'status', status: 404 }],
  });
  const url = await listen(server);
  try {
    const { page, problems } = await openViewer(await browser, `${url}/index.html?data=/data/manifest.json&iso=${iso}`,
      { allow: NETWORK_ERRORS });
    await page.waitForFunction(() => {
      const s = window.tetstream.stats();
      return s.state === 'complete' && s.unavailable !== '';
    }, null, { timeout: 120000 });
    const s = await page.evaluate(() => window.tetstream.stats());
    assert.match(s.unavailable, /^The region \[.*\] stays coarse: /);
    assert.equal(s.exact, false, 'a needed region is missing');
    assert.equal(s.error, '');
    assert.equal(s.nodesLoaded, selectiveIso(iso).nodes - 1, 'every other needed node');
    assert.deepEqual(problems, []);
    await page.close();
  } finally {
    await new Promise((resolve) => server.close(resolve));
  }
});

test('the slice plane fetches the regions it crosses: the slice is at full resolution too', async () => {
  const server = createServer({ mounts: [{ prefix: '/data', dir }, { prefix: '/', dir: webDir }] });
  const url = await listen(server);
  const { min, max } = manifest.fields[0];
  const iso = min + 0.85 * (max - min);
  try {
    const { page, problems } = await openViewer(await browser, `${url}/index.html?data=/data/manifest.json&iso=${iso}`);
    const before = await waitForExact(page);
    await page.evaluate(() => window.tetstream.setSlice({ on: true, normal: [0, 0, 1], offset: 0.1 }));
    await page.waitForFunction((n) => window.tetstream.stats().nodesLoaded > n, before.nodesLoaded, { timeout: 120000 });
    const sliced = await waitForExact(page);
    assert.ok(sliced.slice.triangles > 0);
    // Every node: the slice does not change (the regions it crosses were all in already).
    await page.evaluate(() => window.tetstream.setFetchEverything(true));
    await page.waitForFunction(() => {
      const t = window.tetstream.stats();
      return t.state === 'complete' && t.chunksReceived === t.chunksTotal;
    }, null, { timeout: 120000 });
    const all = await page.evaluate(() => window.tetstream.stats());
    assert.equal(sliced.slice.triangles, all.slice.triangles, 'the slice at full resolution');
    assert.ok(Math.abs(sliced.slice.area - all.slice.area) <= 1e-9 * all.slice.area);
    assert.ok(sliced.bytesReceived < all.bytesReceived);
    assert.deepEqual(problems, []);
    await page.close();
  } finally {
    await new Promise((resolve) => server.close(resolve));
  }
});

// Memory for two views, one at a time: with ?maxMemoryMB= below what both isovalues' regions
// take together, moving from one to the other gives back regions the new one does not need,
// fetches those it does, and reaches its exact surface; the memory counted stays under the limit.
test('short of memory, the regions the view no longer needs are given back and each surface is still exact', async () => {
  const shells = makePack(tmp, 'd32', { kind: 'distance', n: 32, packArgs: ['--leaf-vertices', '256'] });
  const { min, max } = readManifest(shells.dir).fields[0];
  const near = min + 0.2 * (max - min), far = min + 0.85 * (max - min);
  const server = createServer({ mounts: [{ prefix: '/data', dir: shells.dir }, { prefix: '/', dir: webDir }] });
  const url = await listen(server);
  const open = async (iso, extra = '') => openViewer(await browser, `${url}/index.html?data=/data/manifest.json&iso=${iso}${extra}`);
  try {
    // What each view takes alone, and both together, without a limit.
    const alone = [];
    for (const iso of [near, far]) {
      const { page } = await open(iso);
      alone.push((await waitForExact(page)).memory.budgetedBytes);
      if (iso === far) {
        await page.evaluate((v) => window.tetstream.setIsovalue(v), near);
        alone.push((await waitForExact(page, near)).memory.budgetedBytes);
      }
      await page.close();
    }
    const [, , both] = alone;
    const limitMB = Math.ceil((Math.max(alone[0], alone[1]) * 1.02) / 1048576 * 10) / 10;
    assert.ok(both > limitMB * 1048576, `both views (${both} bytes) must not fit in ${limitMB} MB`);

    const { page, problems } = await open(far, `&maxMemoryMB=${limitMB}`);
    let s = await waitForExact(page);
    assertSurfaceMatches(s, cliIso(s.isovalue, { dir: shells.dir }), `exact at ${s.isovalue}`);
    for (const iso of [near, far]) {
      await page.evaluate((v) => window.tetstream.setIsovalue(v), iso);
      s = await waitForExact(page, iso);
      assertSurfaceMatches(s, cliIso(s.isovalue, { dir: shells.dir }), `exact at ${s.isovalue} within ${limitMB} MB`);
      assert.ok(s.memory.budgetedBytes <= s.memory.limitBytes, `${s.memory.budgetedBytes} of ${s.memory.limitBytes}`);
      assert.equal(s.memory.full, false);
    }
    assert.ok(s.memory.nodesForgotten > 0, 'regions were given back');
    assert.ok(s.requestLog.some((e) => e.event === 'forget'), 'the loader heard which chunks to fetch again');
    assert.equal(s.state, 'complete');
    assert.deepEqual(problems, []);
    await page.close();
  } finally {
    await new Promise((resolve) => server.close(resolve));
  }
});
