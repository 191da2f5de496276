// Streaming a dataset into the viewer: the manifest (read by the viewer, which validates it and
// answers the chunk names and sizes), the chunk loader (loader.js: a few requests in flight,
// failures retried with backoff) handing each chunk to the viewer once (ts_offer_chunk), and the
// network's figures: the page owns the network (rate, time left, retries, notices, pause) and
// hands the panel one snapshot (ts_set_network). Functions of the viewer: docs/js-api.md.
import { ChunkLoader, damageText } from './loader.js';
import { fetchBytes } from './net.js';
import { boot, copyToWasm, LoadError, maxMemoryMB, page, stallMs, viewerReady, wasmString } from './page.js';
import { loadProgram, prepareWebGl, withRetries } from './program.js';
import { RateMeter } from './rate.js';
import { refiner } from './refiner.js';
import { noticeText, showError, showStatus } from './status.js';

const MANIFEST_LIMIT = 64 << 20; // FORMAT.md §1
const ERROR_STATE = 4;           // ts_load_state()

// ------------------------------------------------------------------ the network, owned here
export const network = {
  meter: new RateMeter(),
  paused: false,
  chunkSizes: [], // of the open dataset, from the viewer

  // Bytes of the whole dataset (every chunk).
  datasetBytes() {
    return this.chunkSizes.reduce((a, b) => a + b, 0);
  },

  // Chunks still to come, not paused, no error.
  downloading() {
    const l = page.loader;
    return !!l && !l.stopped && !this.paused && page.state !== 'error' && !page.aborted;
  },

  // What the panel, the status line and stats() show.
  snapshot(now = performance.now()) {
    const l = page.loader;
    const receivedBytes = l ? l.haveBytes() : 0;
    const totalBytes = page.datasetTotal;
    const bytesPerSecond = this.downloading() ? this.meter.bytesPerSecond(now) : 0;
    const secondsLeft = bytesPerSecond > 0
      ? (receivedBytes >= totalBytes ? 0 : (totalBytes - receivedBytes) / bytesPerSecond) : -1;
    return { receivedBytes, totalBytes, bytesPerSecond, secondsLeft, paused: this.paused, notice: noticeText() };
  },

  // Takes a sample of the bytes off the wire and hands the panel the snapshot.
  report() {
    const now = performance.now();
    if (page.loader) this.meter.add(now, page.loader.networkBytes);
    if (!viewerReady() || !page.loader || !page.loader.attached) return;
    const n = this.snapshot(now);
    page.viewer.ccall('ts_set_network', null, ['number', 'number', 'number', 'number', 'number', 'string'],
      [n.receivedBytes, n.totalBytes, n.bytesPerSecond, n.secondsLeft, n.paused ? 1 : 0, n.notice]);
  },

  // Pausing drops the requests under way; the level keeps refining up to what has arrived. The
  // panel's button comes here too (Module.onPauseChange).
  setPaused(paused) {
    if (!page.loader || page.loader.stopped) return;
    this.paused = !!paused;
    page.loader.setPaused(this.paused);
    refiner.post({ type: 'paused', paused: this.paused });
    this.report();
  },
};

// ------------------------------------------------------------------ the viewer program
// Runs the viewer's main() (WebGL, ImGui, frame loop) once. Called as soon as the chunk
// downloads are under way, or when loading stops early, so the panel can show the error.
export function startViewer() {
  if (!page.viewer || page.viewerStarted || page.aborted) return;
  page.viewerStarted = true;
  try {
    page.viewer.callMain([]);
  } catch (e) {
    viewerAborted(e && e.message ? e.message : String(e));
  }
}

// The wasm runtime stopped (out of memory, a bug): nothing can be called any more.
function viewerAborted(what) {
  const message = `The viewer stopped unexpectedly (${what || 'aborted'}); reload the page to try again.`;
  Object.assign(page, { state: 'error', error: message, aborted: true });
  if (page.loader) page.loader.stop();
  showError(message);
}

export function fail(message) {
  if (page.aborted) return;
  if (page.loader) page.loader.stop();
  if (page.viewer) page.viewer.ccall('ts_fail', null, ['string'], [message]);
  refiner.post({ type: 'fail', message });
  Object.assign(page, { state: 'error', error: message });
  showError(message);
}

// What is left of the program would come in while a new request waits for its first byte: the
// first chunk after the base is asked for now, so that the link does not idle for a round trip
// when the program's last byte is in. (Decoded bytes left, at least the bytes on the wire.)
function programNearlyIn() {
  if (page.programLoaded || !page.loader || !page.programTotal) return;
  if (page.programTotal - page.programBytes < page.loader.lead()) page.loader.nearlyWarm();
}

// The program's last byte is in (the counting stream's end, on every attempt): the link is free
// for more than the base chunk, well before the program has compiled.
function programIn() {
  if (page.programLoaded) return;
  page.programLoaded = true;
  if (page.loader) page.loader.warm();
}

// What the page does with the viewer besides streaming into it, set by main.js (api.js's
// functions, which read the network from here): the view a link asked for, once the manifest is
// open, and the panel's "copy link" and screenshot buttons.
const viewHooks = { applyLinkState() {}, copyLink() {}, saveScreenshot: async () => {} };
export function setViewHooks(hooks) {
  Object.assign(viewHooks, hooks);
}

let programLoad = null; // the program is loaded once, whatever number of datasets the page opens

// ------------------------------------------------------------------ the manifest
function loadManifest(manifestUrl) {
  return withRetries('the dataset description (manifest.json)', manifestUrl.href, async (failures) => {
    const early = failures === 0 ? boot.manifest : null;
    const bytes = await fetchBytes(manifestUrl.href, {
      stallMs,
      limit: MANIFEST_LIMIT,
      cache: failures ? 'reload' : 'default',
      response: early ? early.promise : null,
      abortResponse: early ? () => early.controller.abort() : null,
    });
    if (bytes.length > MANIFEST_LIMIT) throw new LoadError(`The dataset description (manifest.json) at ${manifestUrl.href} is larger than 64 MB: not a tetstream manifest.`);
    return bytes;
  });
}

// FORMAT.md §1: a chunk's file is "chunks/" and a name of [0-9a-z.-] (no "..").
const CHUNK_FILE = /^chunks\/[0-9a-z.-]+$/;
const MAX_CHUNKS = 262144; // FORMAT.md §5

// The chunk names and sizes of a manifest the viewer has not read yet, when every name passes
// the file rule: used only to start fetching the base while the program still downloads and
// compiles (the first picture comes a base download sooner). Once the viewer has validated the
// manifest, the names and sizes come from it; a loader started from different ones starts again.
// null when it does not look like a tetstream manifest.
export function peekChunks(bytes) {
  try {
    const m = JSON.parse(new TextDecoder().decode(bytes));
    // Versions 1 and 2 list their chunk files alike (FORMAT.md §1); nodes are the viewer's to read.
    if (m.format !== 'tetstream' || ![1, 2].includes(m.formatVersion) || !Array.isArray(m.chunks)) return null;
    if (!m.chunks.length || m.chunks.length > MAX_CHUNKS) return null;
    const names = [], sizes = [];
    for (const c of m.chunks) {
      if (typeof c.file !== 'string' || !CHUNK_FILE.test(c.file) || c.file.includes('..')) return null;
      if (!Number.isInteger(c.bytes) || c.bytes < 1 || c.bytes > 256 << 20) return null;
      names.push(c.file);
      sizes.push(c.bytes);
    }
    return { names, sizes };
  } catch {
    return null;
  }
}

// ------------------------------------------------------------------ a dataset from the local disk
// A packed folder dropped on the page (or picked with the folder chooser): its files become blob:
// URLs, so the manifest and the chunks go through the same fetches, checks (size, content hash)
// and hand-over as a dataset on the network. localFiles: path inside the folder -> File.
let localFiles = null;
const localUrls = new Map();

function chunkUrl(name, manifestUrl) {
  if (!localFiles) return new URL(name, manifestUrl).href;
  if (!localUrls.has(name)) {
    const file = localFiles.get(name);
    // A file missing from the folder: a URL that fails like a 404 would (cannot pass).
    localUrls.set(name, file ? URL.createObjectURL(file) : 'data:,missing');
  }
  return localUrls.get(name);
}

// Chunk files come from `files` (path inside the folder -> File) from now on; the page's own
// ?data= request is not this dataset.
export function useLocalFiles(files) {
  if (page.loader) page.loader.stop();
  page.loader = null;
  for (const url of localUrls.values()) if (url.startsWith('blob:')) URL.revokeObjectURL(url);
  localUrls.clear();
  localFiles = files;
  boot.manifest = null;
  page.datasetUrl = null;
  Object.assign(page, { state: 'loading', error: '', retry: null });
}

// ------------------------------------------------------------------ streaming
let loaderDone = null; // resolves when the loader has delivered every allowed chunk, or stopped

function startLoader({ names, sizes }, manifestUrl) {
  let resolve;
  loaderDone = new Promise((r) => { resolve = r; });
  network.meter.reset();
  network.paused = false;
  page.loader = new ChunkLoader({
    urls: names.map((name) => chunkUrl(name, manifestUrl)),
    names,
    sizes,
    stallMs,
    fail,
    done: resolve,
  });
  page.datasetTotal = sizes.reduce((a, b) => a + b, 0);
  if (page.programLoaded) page.loader.warm();
  page.loader.pump();
}

// The chunk names and sizes of the open dataset, as the viewer read them from the manifest.
function chunksOfViewer() {
  const v = page.viewer;
  const names = [], sizes = [];
  for (let i = 0; i < v._ts_chunk_count(); i++) {
    names.push(wasmString(v._ts_chunk_file(i)));
    sizes.push(v._ts_chunk_bytes(i));
  }
  return { names, sizes };
}

// A dataset of nodes (FORMAT.md §1.1): the loader fetches what the viewer's plan says (the
// nodes the view needs, most important first) and follows it as the view changes; a chunk that
// cannot be had leaves its region coarse instead of stopping the stream.
// The plan is the worker's (it knows what is in); it sends a new one whenever it changes.
function followPlan(viewer, loader, firstPlan) {
  const follow = (plan) => {
    if (page.loader !== loader || loader.stopped) return;
    loader.replan(plan);
    page.datasetTotal = viewer._ts_needed_bytes() || page.datasetTotal;
    network.report();
  };
  loader.onIdle = () => network.report();
  loader.onChunkFailed = (i, message) => refiner.post({ type: 'unavailable', index: i, message });
  refiner.onForgotten = (chunks) => loader.forget(chunks);
  refiner.onPlan = follow;
  follow(firstPlan);
}

// The viewer said no: its error, on the page too.
function viewerStopped() {
  const error = wasmString(page.viewer._ts_error());
  Object.assign(page, { state: 'error', error });
  showError(error);
}

async function stream(manifestUrl) {
  showStatus('Loading the viewer…', [0, 0]);
  const programPromise = programLoad ||
    (programLoad = loadProgram({ onNearlyIn: programNearlyIn, onIn: programIn, onAbort: viewerAborted }));
  const manifestPromise = loadManifest(manifestUrl);
  manifestPromise.catch(() => {}); // awaited below; avoid an "unhandled rejection" meanwhile
  manifestPromise.then((bytes) => {
    const early = peekChunks(bytes);
    if (early && !page.loader && page.state !== 'error') {
      startLoader(early, manifestUrl);
      prepareWebGl();
    }
  }, () => {});

  const viewer = page.viewer = await programPromise; // a failure here has no viewer to report into
  if (!refiner.worker && !page.aborted) refiner.start(page.programModule, viewerAborted);
  viewer.onCommandReady = () => refiner.commandReady();
  viewer.onCameraChanged = (values) => refiner.post({ type: 'camera', values });
  viewer.onPauseChange = (paused) => network.setPaused(paused);
  viewer.onCopyLink = () => { viewHooks.copyLink(); };
  viewer.onScreenshot = () => { viewHooks.saveScreenshot().catch((e) => console.warn(`tetstream: screenshot: ${e.message}`)); };
  let manifestBytes;
  try {
    manifestBytes = await manifestPromise;
  } catch (e) {
    return fail(e.message);
  }
  const ptr = copyToWasm(manifestBytes);
  let opened;
  try {
    opened = viewer._ts_open_manifest(ptr, manifestBytes.length);
  } finally {
    viewer._free(ptr);
  }
  if (!opened) {
    if (page.loader) page.loader.stop();
    return viewerStopped();
  }
  document.title = `tetstream — ${wasmString(viewer._ts_name()) || manifestUrl.pathname}`;
  if (page.state === 'error') return fail(page.error); // the base could not be had: say so in the panel too

  const { names, sizes } = chunksOfViewer();
  network.chunkSizes = sizes;
  if (page.loader && page.loader.names.join('\n') !== names.join('\n')) {
    page.loader.stop();
    page.loader = null;
  }
  if (!page.loader) startLoader({ names, sizes }, manifestUrl);
  const selective = viewer._ts_node_count() > 0;
  // The worker reads the manifest too and answers with how much of it memory allows and, with
  // nodes, the first plan. Until then only what is surely wanted is handed over: every chunk of
  // one sequence (unless a memory limit may end it sooner), else the base alone.
  const opening = refiner.open(manifestBytes, maxMemoryMB);
  viewHooks.applyLinkState();
  refiner.commandReady(); // the view the dataset starts with
  const surelyWanted = !selective && !maxMemoryMB ? names.length : 1;
  page.datasetTotal = sizes.slice(0, surelyWanted).reduce((a, b) => a + b, 0);
  if (surelyWanted < names.length) page.loader.onIdle = () => {}; // the answer brings the rest
  page.loader.attach({
    allowed: surelyWanted,
    provisional: selective, // the first plan says which of the chunks fetched so far are wanted
    // The one hand-over: transferred to the worker, checked (size, hash) there once, kept by
    // its model and added in order. The answer comes as a message.
    async check(i, bytes) {
      const size = bytes.length;
      const code = await refiner.offer(i, bytes);
      if (code < 0) throw new LoadError(page.error || 'The viewer stopped.');
      network.report(); // the rate counts these bytes now, not at the next status tick
      return code === 1 ? null : damageText(code, size, sizes[i]);
    },
    // The loader's turn for chunk i: the worker added it when it came in turn (a chunk it could
    // not add puts the model in error, which its next report says).
    deliver() {
      startViewer(); // the base is in: show it as soon as possible
      if (viewer._ts_load_state() !== ERROR_STATE) return true;
      viewerStopped();
      return false;
    },
  });
  network.report();
  // WebGL and the panel are set up now (main() holds the page's thread for a few hundred ms on a
  // software GL) while the worker starts, opens the dataset and takes the base.
  startViewer();
  const answer = await opening;
  if (!answer.ok) {
    if (page.loader) page.loader.stop();
    let error = '';
    try {
      error = JSON.parse(answer.stats).error || '';
    } catch { /* the worker stopped: viewerAborted has said so */ }
    return page.aborted ? undefined : fail(error || 'The viewer could not open this dataset.');
  }
  page.datasetTotal = sizes.slice(0, answer.chunksAllowed).reduce((a, b) => a + b, 0);
  if (selective) followPlan(viewer, page.loader, answer.plan);
  else page.loader.onIdle = null; // one sequence: its end is the end
  page.loader.setAllowed(selective ? Infinity : answer.chunksAllowed); // (the worker's plan holds what memory allows)
  network.report();
  await loaderDone;
}

// Streams the dataset at manifestUrl into the viewer; failures end in words on the page and in
// the panel. `what`: for an unexpected failure's message.
export async function openDataset(manifestUrl, what = 'while loading') {
  try {
    await stream(manifestUrl);
  } catch (e) {
    const message = e instanceof LoadError ? e.message : `Unexpected problem ${what}: ${e && e.message ? e.message : e}`;
    if (!(e instanceof LoadError)) console.error(e);
    fail(message);
  } finally {
    startViewer();
  }
}

