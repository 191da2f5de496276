#!/usr/bin/env node
// How long the browser takes to draw a frame of the complete Harmonic 64³ surface, without any
// streaming: the camera turns every frame and the rAF intervals are printed (ms). Run
// stream_bench.mjs first (it packs build/bench/stream/harmonic-64). VW / VH set the window size,
// Q is appended to the viewer's URL (e.g. "&boundary=0"). On SwiftShader the time grows with
// the pixels drawn: this tells what the machine's software GL can do at all.
import path from 'node:path';
import { createServer } from '../../server/serve.mjs';
import { root, webDir, launchBrowser } from '../browser/support.mjs';
const dir = path.join(root, 'build/bench/stream/harmonic-64');
const srv = createServer({ mounts: [{ prefix: '/data', dir }, { prefix: '/', dir: webDir }] });
await new Promise((r) => srv.listen(0, '127.0.0.1', r));
const url = `http://127.0.0.1:${srv.address().port}/index.html?data=/data/manifest.json${process.env.Q || ''}`;
const browser = await launchBrowser();
const page = await browser.newPage({ viewport: { width: Number(process.env.VW || 1280), height: Number(process.env.VH || 800) } });
await page.goto(url);
await page.waitForFunction(() => window.tetstream && window.tetstream.stats().state === 'complete', null, { timeout: 60000 });
await page.waitForTimeout(1500);
const res = await page.evaluate(async () => {
  const s = window.tetstream.stats();
  const out = [];
  let last = performance.now();
  for (let i = 0; i < 40; i++) {
    window.tetstream.setCamera({ yaw: i * 0.05 });
    await new Promise((r) => requestAnimationFrame(r));
    const t = performance.now();
    out.push(t - last);
    last = t;
  }
  return { tris: s.triangles, frames: out.map((x) => Math.round(x)) };
});
console.log(JSON.stringify(res));
await browser.close();
srv.close();
