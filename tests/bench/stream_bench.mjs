#!/usr/bin/env node
// Streaming figures over a simulated slow link (docs/benchmarks.md): the project's server with a
// bandwidth cap shared by all responses and a latency before each response, the viewer in headless
// Chromium (SwiftShader: software WebGL, so frame times are those of a machine without a GPU).
//
//   node tests/bench/stream_bench.mjs [--rate 10mbit] [--latency 50] [--n 64] [--runs 1] [--timeline] [--sequence]
//                                     [--h2] [--leaf-vertices N] [--mesh FILE ...]
// --leaf-vertices N: Harmonic packed with regions of at most N vertices (the pack's default
// otherwise).
// --h2: HTTPS with HTTP/2 (a certificate made with openssl for the run), as static hosts and CDNs
// serve today; without it, HTTP/1.1 (six connections).
//
// For Harmonic N³ and the real post.vtk (postVtk below, when present) it reports:
//   first surface   ms from navigation start to the first frame drawn with an isosurface,
//                   everything included (html, scripts, wasm download and compile, manifest,
//                   base chunk, WebGL set-up)
//   all bytes in    when the last response ended (Resource Timing), against bytes ÷ bandwidth
//   complete        every chunk received and every split applied, against bytes ÷ bandwidth
//   frames          rAF intervals from the first surface to complete: how many over 33 ms,
//                   95th percentile, longest; the viewer's own longest frame callback and the
//                   worker's longest refinement slice, and all its work slices by duration
//   long tasks      tasks of the page's thread over 50 ms (Long Tasks API) before the first
//                   surface and while streaming: refinement runs in a worker, so these are
//                   start-up, drawing (SwiftShader draws on the CPU) and the browser's own
//   splits/s        the worker's rate while it refines, and splits over the time from the
//                   first surface to complete
// Writes build/bench/stream.json. Not a test: nothing is asserted; single runs unless --runs.
// EXTRA_QUERY (environment) is appended to the viewer's URL, e.g. "&boundary=0"; VW and VH set
// the window size (default 1280 x 800).
import fs from 'node:fs';
import path from 'node:path';
import { spawnSync } from 'node:child_process';
import { createServer } from '../support/server.mjs';
import { parseRate, parseMs } from '../support/link.mjs';
import { precompressDir } from '../../server/precompress.mjs';
import { root, webDir, cli, launchBrowser, checkBuilds, sliceReport } from '../browser/support.mjs';

const args = process.argv.slice(2);
const opt = (name, fallback) => {
  const i = args.indexOf(`--${name}`);
  return i >= 0 ? args[i + 1] : fallback;
};
const rate = parseRate(opt('rate', '10mbit'));
const latencyMs = parseMs(opt('latency', '50'));
const n = Number(opt('n', '64'));
const runs = Number(opt('runs', '1'));
const outDir = path.join(root, 'build/bench/stream');
// The real meshes live in the folder named by TETSTREAM_DATASETS (skipped when absent).
const postVtk = path.join(process.env.TETSTREAM_DATASETS || path.join(root, 'datasets'), 'post.vtk');

// A certificate for 127.0.0.1 made once into `dir` (openssl), for --h2.
function selfSignedCertificate(dir) {
  const key = path.join(dir, 'key.pem'), cert = path.join(dir, 'cert.pem');
  if (!fs.existsSync(cert)) {
    fs.mkdirSync(dir, { recursive: true });
    const r = spawnSync('openssl', ['req', '-x509', '-newkey', 'ec', '-pkeyopt', 'ec_paramgen_curve:prime256v1', '-nodes',
      '-keyout', key, '-out', cert, '-days', '30', '-subj', '/CN=127.0.0.1', '-addext', 'subjectAltName=IP:127.0.0.1,DNS:localhost'], { encoding: 'utf8' });
    if (r.status !== 0) throw new Error(`openssl could not make a certificate: ${r.stderr || r.error}`);
  }
  return { key: fs.readFileSync(key, 'utf8'), cert: fs.readFileSync(cert, 'utf8') };
}

// Packs once into build/bench/stream/NAME (kept between runs: packing Harmonic 64 takes ~10 s).
function packed(name, makeInput, packArgs = []) {
  const dir = path.join(outDir, name);
  if (!fs.existsSync(path.join(dir, 'manifest.json'))) {
    const input = makeInput();
    cli('pack', input, '-o', dir, ...packArgs);
  }
  return dir;
}

// Frame intervals from the page's own requestAnimationFrame, from navigation on, and every
// 50 ms what the viewer says it has (bytes, level): the loading timeline (plot_timeline.py).
function recordFrames() {
  window.__frames = [];
  window.__samples = [];
  window.__longTasks = [];
  new PerformanceObserver((list) => {
    for (const e of list.getEntries()) window.__longTasks.push([e.startTime, e.duration]);
  }).observe({ type: 'longtask', buffered: true });
  let last = performance.now();
  const tick = (t) => {
    window.__frames.push([t, t - last]);
    last = t;
    requestAnimationFrame(tick);
  };
  requestAnimationFrame(tick);
  const sample = setInterval(() => {
    const s = window.tetstream && window.tetstream.stats();
    if (!s) return;
    window.__samples.push([performance.now(), s.bytesReceived || 0, s.bytesDownloaded || 0, s.programBytesReceived || 0,
      s.splitsApplied || 0, s.splitsTotal || 0, s.level || 0, s.drawMs || 0, s.uploadBytes || 0, s.refineMs || 0]);
    if (s.state === 'complete' || s.state === 'error') clearInterval(sample);
  }, 50);
}

async function measure(browser, url) {
  const page = await browser.newPage({ viewport: { width: Number(process.env.VW || 1280), height: Number(process.env.VH || 800) } });
  await page.addInitScript(recordFrames);
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  await page.goto(url);
  await page.waitForFunction(() => ['complete', 'error'].includes(window.tetstream?.stats().state), null, { timeout: 300000 });
  const r = await page.evaluate(() => {
    const s = window.tetstream.stats();
    const resources = performance.getEntriesByType('resource');
    const nav = performance.getEntriesByType('navigation')[0];
    const bytes = resources.reduce((a, e) => a + e.encodedBodySize, nav.encodedBodySize);
    const lastByte = Math.max(...resources.map((e) => e.responseEnd));
    const wasm = resources.find((e) => e.name.endsWith('tetstream.wasm'));
    const manifest = resources.find((e) => e.name.endsWith('manifest.json'));
    const base = resources.find((e) => /chunks\/00000-/.test(e.name));
    const timeline = [nav, ...resources].map((e) => [e.name.split('/').pop(), e.startTime, e.responseStart, e.responseEnd, e.encodedBodySize]
      .map((x) => (typeof x === 'number' ? Math.round(x) : x)));
    const streaming = window.__frames.filter(([t]) => t > s.firstSurfaceMs && t <= s.completeMs).map(([, d]) => d);
    const longTasks = (from, to) => window.__longTasks.filter(([t]) => t >= from && t < to).map(([, d]) => d);
    const startupLong = longTasks(0, s.firstSurfaceMs), streamingLong = longTasks(s.firstSurfaceMs, s.completeMs);
    streaming.sort((a, b) => a - b);
    return {
      state: s.state, error: s.error, name: s.name, chunks: s.chunksTotal, splits: s.splitsTotal, tets: s.tets,
      bytes, wasmBytes: wasm ? wasm.encodedBodySize : 0,
      wasmEnd: wasm ? wasm.responseEnd : 0, manifestEnd: manifest ? manifest.responseEnd : 0,
      baseStart: base ? base.requestStart : 0, baseEnd: base ? base.responseEnd : 0,
      firstSurfaceMs: s.firstSurfaceMs, lastByteMs: lastByte, completeMs: s.completeMs,
      protocol: base ? base.nextHopProtocol : '',
      timeline,
      samples: window.__samples,
      frameTimes: window.__frames.map(([t, d]) => [Math.round(t), Math.round(d * 10) / 10]),
      frames: streaming.length,
      framesOver33: streaming.filter((d) => d > 33).length,
      frameP95: streaming.length ? streaming[Math.floor(0.95 * (streaming.length - 1))] : 0,
      frameMax: streaming.length ? streaming[streaming.length - 1] : 0,
      longTasksStartup: startupLong.length, longestStartup: Math.max(0, ...startupLong),
      longTasksStreaming: streamingLong.length, longestStreaming: Math.max(0, ...streamingLong),
      refinement: s.refinement, workerUpdates: s.worker ? s.worker.updates : 0, splitsApplied: s.splitsApplied,
      maxFrameMs: s.maxFrameMs, maxRefineMs: s.maxRefineMs, maxDrawMs: s.maxDrawMs,
      sliceEdgesMs: s.sliceEdgesMs, sliceCounts: s.sliceCounts,
      refineTotalMs: s.refineTotalMs, drawTotalMs: s.drawTotalMs, softwareGl: s.softwareGl, reducedFrames: s.reducedFrames, uploads: { bytes: s.uploadBytes, full: s.fullUploads, partial: s.partialUploads, grown: s.grownUploads },
      heapMB: s.memory.heapBytes / 1048576, pageHeapMB: (s.memory.pageHeapBytes || 0) / 1048576, dataMB: s.memory.dataBytes / 1048576, gpuMB: s.memory.gpuBytes / 1048576,
    };
  });
  await page.close();
  r.pageErrors = errors;
  r.idealMs = (r.bytes / rate) * 1000;
  return r;
}

function report(r) {
  const f = (x) => x.toFixed(0);
  return [
    `${r.name}: ${r.chunks} chunks, ${r.splits} splits, ${r.tets} tets, ${(r.bytes / 1048576).toFixed(2)} MB on the wire ` +
      `(wasm ${(r.wasmBytes / 1024).toFixed(0)} KB, ${r.protocol || 'protocol unknown'}); bytes ÷ bandwidth ${f(r.idealMs)} ms`,
    `  first surface ${f(r.firstSurfaceMs)} ms (wasm in at ${f(r.wasmEnd)}, manifest ${f(r.manifestEnd)}, ` +
      `base chunk ${f(r.baseStart)}-${f(r.baseEnd)} ms)`,
    `  all bytes in ${f(r.lastByteMs)} ms (${(r.lastByteMs / r.idealMs).toFixed(2)}× bytes ÷ bandwidth), ` +
      `complete ${f(r.completeMs)} ms (${(r.completeMs / r.idealMs).toFixed(2)}×)`,
    `  frames while streaming: ${r.frames}, ${r.framesOver33} over 33 ms, p95 ${r.frameP95.toFixed(1)} ms, ` +
      `longest ${r.frameMax.toFixed(1)} ms; viewer: longest callback ${r.maxFrameMs.toFixed(1)} ms, ` +
      `refinement ${r.maxRefineMs.toFixed(1)} ms, drawing ${(r.maxDrawMs ?? 0).toFixed(1)} ms`,
    `  ${sliceReport(r)}`,
    `  long tasks on the page's thread: ${r.longTasksStartup} before the first surface (longest ` +
      `${f(r.longestStartup)} ms), ${r.longTasksStreaming} while streaming (longest ${f(r.longestStreaming)} ms)`,
    `  refinement in the ${r.refinement || 'page'}: ${f(r.refineTotalMs)} ms for ${r.splitsApplied} splits ` +
      `(${f(r.splitsApplied / r.refineTotalMs * 1000)} splits/s while refining; ` +
      `${f(r.splitsApplied / Math.max(1, r.completeMs - r.firstSurfaceMs) * 1000)} splits/s from first surface to complete), ` +
      `${r.workerUpdates} updates to the page; page drawing ${f(r.drawTotalMs)} ms`,
    `  memory: worker heap ${r.heapMB.toFixed(0)} MB, page heap ${r.pageHeapMB.toFixed(0)} MB, data ${r.dataMB.toFixed(1)} MB, ` +
      `GPU ${r.gpuMB.toFixed(1)} MB` +
      (r.state !== 'complete' ? `\n  ENDED IN ${r.state}: ${r.error}` : '') +
      (r.pageErrors.length ? `\n  PAGE ERRORS: ${r.pageErrors.join('; ')}` : ''),
  ].join('\n');
}

async function main() {
  checkBuilds();
  fs.mkdirSync(outDir, { recursive: true });
  await precompressDir(webDir); // the wasm goes compressed (br) as any real deployment would send it
  // --sequence: packed as one sequence of chunks (no patch hierarchy), every chunk fetched.
  const sequence = args.includes('--sequence');
  const leaves = sequence ? '0' : opt('leaf-vertices', '');
  const datasets = [[`Harmonic ${n}³`, packed(`harmonic-${n}${leaves ? `-leaves-${leaves}` : ''}`, () => {
    const vtu = path.join(outDir, `harmonic-${n}.vtu`);
    if (!fs.existsSync(vtu)) cli('gen', 'harmonic', '--n', String(n), '-o', vtu);
    return vtu;
  }, ['--name', `Harmonic ${n}³`, ...(leaves ? ['--leaf-vertices', leaves] : [])])]];
  if (fs.existsSync(postVtk)) datasets.push(['post.vtk', packed('post', () => postVtk, ['--name', 'post.vtk'])]);
  else console.log(`(no ${postVtk}: the real dataset is skipped)`);
  // --mesh FILE (repeatable): any other mesh, packed as the CLI packs it by default.
  args.forEach((a, i) => {
    if (a !== '--mesh') return;
    const file = path.resolve(args[i + 1]);
    const name = path.basename(file);
    datasets.push([name, packed(name.replace(/[^0-9a-z]+/gi, '-').toLowerCase(), () => file, ['--name', name])]);
  });

  const h2 = args.includes('--h2');
  const server = createServer({
    mounts: [{ prefix: '/data', dir: outDir }, { prefix: '/', dir: webDir }],
    throttleBytesPerSec: rate,
    latencyMs,
    tls: h2 ? selfSignedCertificate(path.join(root, 'build/bench/tls')) : null,
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  const base = `${h2 ? 'https' : 'http'}://127.0.0.1:${server.address().port}`;
  const browser = await launchBrowser(h2 ? ['--ignore-certificate-errors'] : []);
  // A user's browser is running already: one page with a WebGL context first, so that the
  // figures do not include starting Chromium's GPU process.
  const warm = await browser.newPage();
  await warm.goto(`${base}/index.html`);
  await warm.evaluate(() => !!document.createElement('canvas').getContext('webgl2'));
  await warm.close();
  console.log(`link: ${(rate * 8 / 1e6).toFixed(1)} Mbit/s, ${latencyMs} ms latency per response, ` +
    `${h2 ? 'HTTPS with HTTP/2' : 'HTTP/1.1'}; Chromium with SwiftShader`);
  const results = [];
  try {
    for (const [name, dir] of datasets) {
      for (let run = 0; run < runs; run++) {
        const r = await measure(browser, `${base}/index.html?data=/data/${path.basename(dir)}/manifest.json${process.env.EXTRA_QUERY || ''}`);
        r.dataset = name;
        results.push(r);
        console.log(report(r));
        if (args.includes('--timeline')) for (const row of r.timeline) console.log(`    ${row.join('\t')}`);
      }
    }
  } finally {
    await browser.close();
    await new Promise((resolve) => server.close(resolve));
  }
  if (runs > 1) {
    for (const [name] of datasets) {
      const rs = results.filter((r) => r.dataset === name);
      const median = (key) => rs.map((r) => r[key]).sort((a, b) => a - b)[Math.floor((rs.length - 1) / 2)];
      console.log(`${name}, median of ${rs.length}: first surface ${median('firstSurfaceMs').toFixed(0)} ms, ` +
        `all bytes in ${median('lastByteMs').toFixed(0)} ms, complete ${median('completeMs').toFixed(0)} ms ` +
        `(bytes ÷ bandwidth ${median('idealMs').toFixed(0)} ms), frames over 33 ms ${median('framesOver33')} of ` +
        `${median('frames')}, longest frame ${median('frameMax').toFixed(0)} ms, long tasks while streaming ` +
        `${median('longTasksStreaming')} (longest ${median('longestStreaming').toFixed(0)} ms)`);
    }
  }
  const out = path.join(root, 'build/bench/stream.json');
  fs.writeFileSync(out, JSON.stringify({ rateBytesPerSec: rate, latencyMs, results }, null, 2));
  console.log(`wrote ${path.relative(process.cwd(), out)}`);
}

main().catch((e) => {
  console.error(e);
  process.exit(1);
});
