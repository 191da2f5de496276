// tetstream web shell: reads ?data=URL (a packed dataset's manifest.json; relative, absolute or
// cross-origin with CORS), optional &iso=VALUE and &field=NAME (the isosurface), &colour=NAME,
// &map=viridis|magma|turbo|coolwarm|grey and &range=LO,HI (colour by a field), loads the wasm viewer with a
// progress bar from its first byte, streams the manifest and then the chunks into it
// (loader.js: a few requests in flight, every chunk checked before it is handed over, failures
// retried with backoff), and reports what happens in plain words. The wasm functions used here
// are documented at the top of wasm/main.cpp.
//
// URL options besides data, iso and field: maxMemoryMB=N (the most memory the dataset may take;
// the viewer stops at the last level that fits; default the browser's wasm limit, 4 GB) and
// stallSeconds=S (abandon and retry a request that receives nothing for S seconds; default 10).
//
// window.tetstream = {
//   stats()          -> the viewer's state (statsJson in wasm/viewer_state.h) plus the shell's
//                       figures. state is one of "idle" (no dataset given), "loading" (before
//                       the base mesh), "streaming" (base shown; parts still to come or splits
//                       still to apply), "complete" (every part received and every split
//                       applied), "error" (stopped: error says why; the level reached stays
//                       usable). notice: a network problem being retried, in words. Level:
//                       splitsApplied, splitsReceived, splitsTotal, targetSplits, level
//                       (vertices shown / full), live, paused, fieldError (estimate), fieldRms and fieldMax (measured; null in older packs); network:
//                       chunksReceived, chunksAllowed, bytesReceived, bytesDownloaded,
//                       bytesTotal, rateBytesPerSec, secondsLeft, retries (requests made again
//                       after a failure), chunksRefused (downloads that failed the size/hash
//                       check), requestLog (the chunk loader's decisions, in order: which
//                       chunk it requested and why; web/loader.js ChunkLoader.log),
//                       programBytesReceived / programBytesTotal (tetstream.wasm);
//                       memory: {heapBytes, dataBytes, gpuBytes, limitBytes, neededBytes,
//                       allowedBytes}, memoryLimited; frame timing: maxFrameMs, maxFrameGapMs,
//                       maxRefineMs, sliceCounts (work slices by duration, bins split at
//                       sliceEdgesMs). sliderRect, levelSliderRect and pauseButtonRect are in CSS
//                       pixels of the page.
//   setIsovalue(v)   -> re-extracts the surface at v
//   setField(name)   -> true when the field exists (the field that defines the isosurface)
//   setColourField(name) -> colour the isosurface by this field (null or "none": no colouring);
//                       the range becomes the field's range. true when the field exists
//   setColourMap(name)   -> viridis, magma, turbo, coolwarm, grey; true when known
//   setColourRange(lo, hi) -> the values at the colour map's two ends
//   fitColourRange()     -> the range of the colour values on the visible surface; false if none
//   (stats() has colourField, colourMap, colourRange: [lo, hi])
//   setLevel(f)      -> level target: fraction f of the full mesh's vertices, clamped to what has
//                       been received (0 = base mesh; 1 = newest, and it then follows new data)
//   pause(), resume() downloading; pausing drops requests under way, the level keeps refining
//                       up to what has been received
// }
import { fetchBytes, countingResponse, httpError, retryDelayMs, seconds, FetchError, STALL_SECONDS } from './net.js';
import { ChunkLoader, damageText } from './loader.js';

const MANIFEST_LIMIT = 16 << 20; // FORMAT.md §1
const COLOUR_MAPS = ['viridis', 'magma', 'turbo', 'coolwarm', 'grey'];
const PAGE_FILE_TRIES = 4;       // the program and the manifest: then the page gives up and says why

const statusBox = document.getElementById('status');
const statusText = document.getElementById('status-text');
const statusProgram = document.getElementById('status-program');
const statusFill = document.getElementById('status-fill');
const canvas = document.getElementById('canvas');
const params = new URLSearchParams(location.search);
const boot = window.tetstreamBoot || {}; // downloads index.html started before this module ran

function positiveParam(name) {
  const v = Number(params.get(name));
  return params.get(name) !== null && Number.isFinite(v) && v > 0 ? v : 0;
}
const stallMs = 1000 * (positiveParam('stallSeconds') || STALL_SECONDS);
const maxMemoryMB = positiveParam('maxMemoryMB');

let viewer = null; // the Emscripten module once it is instantiated
let viewerStarted = false;
let loader = null;
let earlyProgress = []; // [networkBytes, datasetBytes, time] taken before the viewer had the dataset
// What stats() says before the module runs, and the shell's own figures. programTotal: bytes of
// tetstream.wasm uncompressed, from index.html (the build writes it: a compressed response's
// Content-Length would not tell).
const shell = {
  state: 'loading', error: '', aborted: false,
  retry: null, // { what, at, error, failures }: a page file waiting to be fetched again
  programBytes: 0,
  programTotal: Number(document.querySelector('meta[name="tetstream-wasm-bytes"]')?.content) || 0,
  datasetTotal: 0, // bytes of the chunks to fetch, once the manifest is read
};

class LoadError extends Error {}

// bar: [program, dataset], each a fraction of the whole bar (everything the page downloads).
function showStatus(text, bar, kind = '') {
  statusBox.className = kind;
  statusText.textContent = text;
  if (!bar) return;
  const percent = (f) => `${(100 * Math.min(1, Math.max(0, f))).toFixed(1)}%`;
  statusProgram.style.width = percent(bar[0]);
  statusFill.style.width = percent(Math.min(bar[1], 1 - bar[0]));
}

function showError(text) {
  showStatus(text, undefined, 'error');
}

function megabytes(n) {
  return `${(n / 1048576).toFixed(n < 10 * 1048576 ? 2 : 1)} MB`;
}

function capitalized(s) {
  return s ? s[0].toUpperCase() + s.slice(1) : s;
}

// ------------------------------------------------------------------ talking to the wasm viewer
function stats() {
  const extra = {
    retries: (loader ? loader.retries : 0) + (shell.pageRetries || 0),
    chunksRefused: loader ? loader.refused : 0,
    requestLog: loader ? loader.log : [], // what the chunk loader decided (loader.js)
    programBytesReceived: shell.programBytes,
    programBytesTotal: shell.programTotal,
  };
  if (!viewer || shell.aborted) return { state: shell.state, error: shell.error, notice: noticeText(), ...extra };
  const s = JSON.parse(viewer.UTF8ToString(viewer._ts_stats_json()));
  const r = canvas.getBoundingClientRect();
  for (const key of ['sliderRect', 'levelSliderRect', 'pauseButtonRect', 'sliceSliderRect', 'panelRect'])
    s[key] = { ...s[key], x: s[key].x + r.left, y: s[key].y + r.top };
  return { ...s, ...extra };
}

// Copies bytes into wasm memory once, calls fn(ptr, len), frees them.
function withWasmBytes(bytes, fn) {
  if (shell.aborted) throw new LoadError(shell.error);
  const ptr = viewer._malloc(Math.max(1, bytes.length));
  if (!ptr) {
    throw new LoadError(`The browser did not give the viewer ${megabytes(bytes.length)} of memory for the next ` +
      'part of the dataset.');
  }
  viewer.HEAPU8.set(bytes, ptr); // read HEAPU8 after _malloc: memory may have grown
  try {
    return fn(ptr, bytes.length);
  } finally {
    viewer._free(ptr);
  }
}

// Runs the viewer's main() (WebGL, ImGui, frame loop) once. Called as soon as the chunk
// downloads are under way, or when loading stops early, so the panel can show the error.
function startViewer() {
  if (!viewer || viewerStarted || shell.aborted) return;
  viewerStarted = true;
  try {
    viewer.callMain([]);
  } catch (e) {
    viewerAborted(e && e.message ? e.message : String(e));
  }
}

// The wasm runtime stopped (out of memory, a bug): nothing can be called any more.
function viewerAborted(what) {
  const message = `The viewer stopped unexpectedly (${what || 'aborted'}); reload the page to try again.`;
  Object.assign(shell, { state: 'error', error: message, aborted: true });
  if (loader) loader.stop();
  showError(message);
}

function fail(message) {
  if (shell.aborted) return;
  if (loader) loader.stop();
  if (viewer) viewer.ccall('ts_fail', null, ['string'], [message]);
  Object.assign(shell, { state: 'error', error: message });
  showError(message);
}

window.tetstream = {
  stats,
  setIsovalue(v) {
    if (viewer) viewer._ts_set_isovalue(Number(v));
  },
  setField(name) {
    return viewer ? viewer.ccall('ts_set_field', 'number', ['string'], [String(name)]) === 1 : false;
  },
  setColourField(name) {
    const n = name === null || name === undefined ? '' : String(name);
    return viewer ? viewer.ccall('ts_set_colour_field', 'number', ['string'], [n]) === 1 : false;
  },
  setColourMap(name) {
    return viewer ? viewer.ccall('ts_set_colour_map', 'number', ['string'], [String(name)]) === 1 : false;
  },
  setColourRange(lo, hi) {
    if (viewer) viewer._ts_set_colour_range(Number(lo), Number(hi));
  },
  fitColourRange() {
    return viewer ? viewer._ts_fit_colour_range() === 1 : false;
  },
  setLevel(fraction) {
    setLevel(fraction);
  },
  setSlice(slice) {
    return setSlice(slice);
  },
  setCamera(camera) {
    return setCamera(camera);
  },
  colourMaps: COLOUR_MAPS,
  openFiles(files) {
    // files: [{path, file}] or File objects with webkitRelativePath (the folder chooser's)
    const list = [...files].map((f) => (f instanceof File ? { path: f.webkitRelativePath || f.name, file: f } : f));
    return openLocal(packedFolder(list));
  },
  getState,
  setState,
  link,
  copyLink,
  screenshot,
  showHelp(on = true) {
    if (viewer) viewer.ccall('ts_set_view_option', null, ['string', 'number'], ['help', on ? 1 : 0]);
  },
  pause() {
    if (viewer) viewer._ts_set_paused(1);
  },
  resume() {
    if (viewer) viewer._ts_set_paused(0);
  },
};

// ------------------------------------------------------------------ shareable state
// The view as one object (getState), settable in parts (setState), and as a URL (link): the page
// keeps its address bar at link() so that copying it, or the "copy link" button, shares the view.
// URL parameters: data, field, iso, colour, map, range=LO,HI, slice=NX,NY,NZ,OFFSET (present =
// on), level (fraction of the full mesh's vertices, absent = newest), cam=TX,TY,TZ,DISTANCE,YAW,
// PITCH, boundary=0; numbers as the shortest decimals that give back the same float.
let datasetUrl = params.get('data');
let pendingLevel = null; // a level asked for before its parts arrived: applied as they do

function shortFloat(v) {
  const f = Math.fround(Number(v));
  if (!Number.isFinite(f)) return '0';
  for (let p = 1; p <= 9; p++) {
    const t = Number(f.toPrecision(p));
    if (Math.fround(t) === f) return String(t);
  }
  return String(f);
}

function numbers(text, count) {
  if (text === null) return null;
  const v = text.split(',').map((x) => (x.trim() === '' ? NaN : Number(x)));
  return v.length === count && v.every(Number.isFinite) ? v : null;
}

function readCamera() {
  const c = [0, 1, 2, 3, 4, 5].map((i) => viewer._ts_camera_get(i));
  return { target: c.slice(0, 3), distance: c[3], yaw: c[4], pitch: c[5] };
}

function getState() {
  const s = stats();
  const ready = viewer && !shell.aborted && Array.isArray(s.fields);
  return {
    dataset: datasetUrl,
    field: ready ? s.field : null,
    isovalue: ready ? s.isovalue : null,
    colourField: ready ? s.colourField : null,
    colourMap: ready ? s.colourMap : null,
    colourRange: ready ? s.colourRange : null,
    slice: ready ? { on: s.slice.on, normal: s.slice.normal, offset: s.slice.offset } : null,
    level: ready ? (pendingLevel !== null ? pendingLevel : s.targetLevel) : null,
    camera: ready ? readCamera() : null,
    showBoundary: ready ? s.showBoundary : null,
  };
}

function setLevel(fraction) {
  const f = Number(fraction);
  if (!viewer || !Number.isFinite(f)) return;
  viewer._ts_set_level(f);
  const s = stats();
  pendingLevel = f < 1 && s.chunksReceived < s.chunksTotal ? f : null;
}

// Parts arrive after a link's level was set: the target moves up with them until it is reached.
function applyPendingLevel() {
  if (pendingLevel === null || !viewer || shell.aborted) return;
  viewer._ts_set_level(pendingLevel);
  const s = stats();
  if (s.chunksReceived >= s.chunksTotal || s.state === 'error') pendingLevel = null;
}

function setSlice(slice = {}) {
  if (!viewer) return false;
  const cur = stats().slice;
  const on = slice.on !== undefined ? !!slice.on : cur.on;
  const n = Array.isArray(slice.normal) && slice.normal.length === 3 ? slice.normal.map(Number) : cur.normal;
  const offset = slice.offset !== undefined ? Number(slice.offset) : cur.offset;
  if (!n.every(Number.isFinite) || !Number.isFinite(offset)) return false;
  viewer._ts_set_slice(on ? 1 : 0, n[0], n[1], n[2], offset);
  return true;
}

function setCamera(c = {}) {
  if (!viewer || !c) return false;
  const cur = readCamera();
  const t = Array.isArray(c.target) && c.target.length === 3 ? c.target.map(Number) : cur.target;
  const v = [...t, c.distance ?? cur.distance, c.yaw ?? cur.yaw, c.pitch ?? cur.pitch].map(Number);
  if (!v.every(Number.isFinite)) return false;
  viewer._ts_camera_set(...v);
  return true;
}

// Applies the given parts of a state, in an order that keeps them (the isovalue after its
// field, the colour range after its field). true when the viewer was there to take it.
function setState(p = {}) {
  if (!viewer || shell.aborted) return false;
  const t = window.tetstream;
  if (p.field !== undefined && p.field !== null) t.setField(p.field);
  if (p.isovalue !== undefined && p.isovalue !== null) viewer._ts_set_isovalue(Number(p.isovalue));
  if (p.colourField !== undefined) t.setColourField(p.colourField);
  if (p.colourMap) t.setColourMap(p.colourMap);
  if (Array.isArray(p.colourRange) && p.colourRange.length === 2) t.setColourRange(p.colourRange[0], p.colourRange[1]);
  if (p.slice) setSlice(p.slice);
  if (p.level !== undefined && p.level !== null) setLevel(p.level);
  if (p.camera) setCamera(p.camera);
  if (p.showBoundary !== undefined && p.showBoundary !== null)
    viewer.ccall('ts_set_view_option', null, ['string', 'number'], ['boundary', p.showBoundary ? 1 : 0]);
  syncUrl();
  return true;
}

function stateQuery(st) {
  const q = new URLSearchParams();
  if (st.dataset) q.set('data', st.dataset);
  for (const keep of ['maxMemoryMB', 'stallSeconds', 'antialias']) if (params.get(keep) !== null) q.set(keep, params.get(keep));
  if (st.field === null) return q;
  q.set('field', st.field);
  q.set('iso', shortFloat(st.isovalue));
  if (st.colourField) {
    q.set('colour', st.colourField);
    q.set('map', st.colourMap);
    q.set('range', st.colourRange.map(shortFloat).join(','));
  }
  if (st.slice && st.slice.on) q.set('slice', [...st.slice.normal, st.slice.offset].map(shortFloat).join(','));
  if (st.level !== null && st.level < 1) q.set('level', String(Number(st.level.toPrecision(9))));
  if (st.camera) {
    const c = st.camera;
    q.set('cam', [...c.target, c.distance, c.yaw, c.pitch].map(shortFloat).join(','));
  }
  if (st.showBoundary === false) q.set('boundary', '0');
  return q;
}

function link() {
  return `${location.origin}${location.pathname}?${stateQuery(getState()).toString()}`;
}

// Keeps the address bar at link() (a few times a second, with the status).
function syncUrl() {
  if (!viewer || shell.aborted || !datasetUrl || !Array.isArray(stats().fields)) return;
  const q = `?${stateQuery(getState()).toString()}`;
  if (q !== location.search) history.replaceState(history.state, '', q);
}

async function copyLink() {
  const l = link();
  if (!datasetUrl) {
    // A dataset from the disk has no address others could open.
    if (viewer && !shell.aborted) viewer.ccall('ts_set_link_note', null, ['string'], ['no link: opened from the disk']);
    return null;
  }
  let note = 'link copied';
  try {
    await navigator.clipboard.writeText(l);
  } catch {
    note = 'the link is in the address bar (the clipboard refused)';
  }
  if (viewer && !shell.aborted) viewer.ccall('ts_set_link_note', null, ['string'], [note]);
  return l;
}

// The picture as a PNG Blob: the next frame, read back as soon as it is drawn.
function screenshot() {
  if (!viewer || !viewerStarted || shell.aborted) return Promise.reject(new Error('the viewer is not running'));
  return new Promise((resolve, reject) => {
    viewer.onCapture = () => {
      viewer.onCapture = null;
      canvas.toBlob((blob) => (blob ? resolve(blob) : reject(new Error('no picture'))), 'image/png');
    };
    viewer._ts_request_capture();
  });
}

async function saveScreenshot() {
  const blob = await screenshot();
  const a = document.createElement('a');
  const name = (stats().name || 'tetstream').replace(/[^\w.-]+/g, '_');
  a.download = `${name}-${new Date().toISOString().replace(/[:.]/g, '-')}.png`;
  a.href = URL.createObjectURL(blob);
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 10000);
}

// The view a link asked for (after the manifest is open; field and iso are done by the caller).
function applyLinkState() {
  const colour = params.get('colour');
  if (colour !== null && !window.tetstream.setColourField(colour))
    console.warn(`tetstream: no field named "${colour}" to colour by`);
  const map = params.get('map');
  if (map !== null && !window.tetstream.setColourMap(map)) console.warn(`tetstream: unknown colour map "${map}"`);
  const range = numbers(params.get('range'), 2);
  if (range) window.tetstream.setColourRange(range[0], range[1]);
  const slice = numbers(params.get('slice'), 4);
  if (slice) setSlice({ on: true, normal: slice.slice(0, 3), offset: slice[3] });
  const level = numbers(params.get('level'), 1);
  if (level) setLevel(level[0]);
  const cam = numbers(params.get('cam'), 6);
  if (cam) setCamera({ target: cam.slice(0, 3), distance: cam[3], yaw: cam[4], pitch: cam[5] });
  if (params.get('boundary') === '0') viewer.ccall('ts_set_view_option', null, ['string', 'number'], ['boundary', 0]);
}

// ------------------------------------------------------------------ touch
// One finger orbits, two fingers pinch-zoom and pan (pointer events). Touches that start on the
// panel go to the panel (GLFW turns them into mouse input for ImGui); the others are kept from
// GLFW's touch handlers, which would turn them into a mouse drag as well.
const touches = new Map(); // pointerId -> {x, y}
let touchOnCanvas = false;
function inPanel(x, y) {
  const r = viewer && viewerStarted && !shell.aborted ? stats().panelRect : null;
  return !!r && x >= r.x && x < r.x + r.w && y >= r.y && y < r.y + r.h;
}
function pinch() {
  const [a, b] = [...touches.values()];
  return { x: 0.5 * (a.x + b.x), y: 0.5 * (a.y + b.y), d: Math.hypot(a.x - b.x, a.y - b.y) };
}
canvas.addEventListener('pointerdown', (e) => {
  if (e.pointerType !== 'touch' || !viewer || !viewerStarted) return;
  if (touches.size === 0 && inPanel(e.clientX, e.clientY)) return;
  touches.set(e.pointerId, { x: e.clientX, y: e.clientY });
  touchOnCanvas = true;
  try { canvas.setPointerCapture(e.pointerId); } catch { /* synthetic events have no capture */ }
  e.preventDefault();
}, { passive: false });
canvas.addEventListener('pointermove', (e) => {
  const t = touches.get(e.pointerId);
  if (!t) return;
  e.preventDefault();
  if (touches.size === 1) {
    viewer._ts_camera_gesture(0, e.clientX - t.x, e.clientY - t.y);
    t.x = e.clientX;
    t.y = e.clientY;
  } else if (touches.size === 2) {
    const before = pinch();
    t.x = e.clientX;
    t.y = e.clientY;
    const after = pinch();
    viewer._ts_camera_gesture(1, after.x - before.x, after.y - before.y);
    if (before.d > 1 && after.d > 1) viewer._ts_camera_gesture(2, Math.log(after.d / before.d) / -Math.log(0.88), 0);
  }
}, { passive: false });
for (const type of ['pointerup', 'pointercancel']) {
  canvas.addEventListener(type, (e) => {
    touches.delete(e.pointerId);
    if (touches.size === 0) touchOnCanvas = false;
  });
}
for (const type of ['touchstart', 'touchmove', 'touchend', 'touchcancel']) {
  addEventListener(type, (e) => {
    if (e.target === canvas && (touchOnCanvas || touches.size > 0)) e.stopPropagation();
  }, { capture: true });
}

// ------------------------------------------------------------------ the page's own files
// Waits `ms`, or less when the browser says the network is back.
function pause(ms) {
  return new Promise((resolve) => {
    const done = () => {
      clearTimeout(timer);
      removeEventListener('online', done);
      resolve();
    };
    const timer = setTimeout(done, ms);
    addEventListener('online', done);
  });
}

// Runs attempt(failuresSoFar) until it succeeds, waiting between tries while the failures may
// pass; after PAGE_FILE_TRIES tries, or at once for one that cannot pass, throws a LoadError.
async function withRetries(what, url, attempt) {
  for (let failures = 0; ;) {
    try {
      const result = await attempt(failures);
      shell.retry = null;
      return result;
    } catch (e) {
      if (e instanceof LoadError) throw e;
      const reason = !(e instanceof FetchError) ? String(e && e.message ? e.message : e)
        : e.kind === 'network' ? 'the server did not answer or refused the request (network error, or another ' +
          'site that does not allow cross-origin access)' : e.message;
      failures++;
      if (!(e instanceof FetchError) || !e.transient || failures >= PAGE_FILE_TRIES) {
        shell.retry = null;
        throw new LoadError(`Could not download ${what} from ${url}: ${reason}` +
          `${failures > 1 ? ` (tried ${failures} times)` : ''}.`);
      }
      const delay = retryDelayMs(failures, e.retryAfterMs);
      shell.retry = { what, at: performance.now() + delay, error: e, failures };
      shell.pageRetries = (shell.pageRetries || 0) + 1;
      await pause(delay);
      shell.retry.at = 0;
    }
  }
}

// Resolves with `promise`, or rejects with a stall after `ms` without an answer (then `onStall`
// cancels the request).
function withStall(promise, ms, onStall) {
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => {
      onStall();
      reject(new FetchError(`no answer for ${Math.round(ms / 1000)} s`, { kind: 'stall', transient: true }));
    }, ms);
    promise.then((v) => {
      clearTimeout(timer);
      resolve(v);
    }, (e) => {
      clearTimeout(timer);
      reject(e instanceof FetchError ? e : new FetchError('connection lost', { kind: 'network', transient: true }));
    });
  });
}

// tetstream.wasm, counted byte by byte as it arrives and compiled while it streams
// (instantiateStreaming on a Response wrapping the counting stream). Emscripten calls this
// through Module.instantiateWasm.
async function instantiateProgram(imports) {
  const url = new URL('tetstream.wasm', location.href).href;
  return withRetries('the viewer program (tetstream.wasm)', url, async (failures) => {
    const early = failures === 0 ? boot.wasm : null;
    const controller = new AbortController();
    const request = early ? early.promise : fetch(url, { signal: controller.signal, credentials: 'same-origin',
      cache: failures ? 'reload' : 'default' });
    const response = await withStall(request, stallMs, () => (early ? early.controller : controller).abort());
    if (!response.ok) throw httpError(response);
    if (!shell.programTotal && !response.headers.get('Content-Encoding'))
      shell.programTotal = Number(response.headers.get('Content-Length')) || 0;
    shell.programBytes = 0;
    let streamError = null;
    const counted = countingResponse(response, {
      type: 'application/wasm',
      stallMs,
      onProgress: (n) => {
        shell.programBytes += n;
        programNearlyDownloaded();
      },
      onEnd: programDownloaded,
      onError: (e) => { streamError = e; },
    });
    try {
      return await WebAssembly.instantiateStreaming(counted, imports);
    } catch (e) {
      if (streamError) throw streamError;
      // The bytes arrived but do not compile: damaged on the way (or a broken deployment).
      throw new FetchError(`it does not compile (${e && e.message ? e.message : e})`, { kind: 'damaged', transient: true });
    }
  });
}

function loadScript(src) {
  return new Promise((resolve, reject) => {
    const script = document.createElement('script');
    script.src = src;
    script.onload = resolve;
    script.onerror = () => reject(new FetchError('could not be loaded', { kind: 'network', transient: true }));
    document.head.appendChild(script);
  });
}

// Setting up WebGL takes the GPU process a while (~0.3 s on a software renderer, and the page
// waits for it): asked for as soon as the base chunk is requested, it overlaps the program's
// download instead of following it. main() later gets this same context (a canvas keeps its
// first WebGL 2 context, whatever is asked again), so these are the attributes its GLFW window
// asks for (Emscripten's library_glfw.js with the viewer's hints). The canvas gets the size in
// device pixels that main() gives it (syncCanvasSize), so that its drawing buffer is made once
// (a resize waited ~180 ms for the GPU process on SwiftShader).
let webGlPrepared = false;
function prepareWebGl() {
  if (webGlPrepared) return;
  webGlPrepared = true;
  try {
    const box = canvas.getBoundingClientRect();
    canvas.width = Math.max(1, Math.round(box.width * (window.devicePixelRatio || 1)));
    canvas.height = Math.max(1, Math.round(box.height * (window.devicePixelRatio || 1)));
    canvas.getContext('webgl2', { antialias: false, alpha: true, depth: true, stencil: true });
  } catch { /* main() reports a missing WebGL 2 */ }
}

// ?antialias=0 or 1: multisample the scene or not (by default the viewer does, unless WebGL
// renders in software).
function antialiasOption() {
  const a = params.get('antialias');
  return a === '0' ? false : a === '1' ? true : undefined;
}

async function loadViewer() {
  const scriptUrl = new URL('tetstream.js', location.href).href;
  await withRetries('the viewer program (tetstream.js)', scriptUrl, (failures) => (failures === 0 && boot.script
    ? boot.script.catch(() => { throw new FetchError('could not be loaded', { kind: 'network', transient: true }); })
    : loadScript(scriptUrl)));
  return new Promise((resolve, reject) => {
    // eslint-disable-next-line no-undef
    createTetstream({
      canvas,
      antialias: antialiasOption(),
      onAbort: viewerAborted,
      instantiateWasm(imports, receive) {
        instantiateProgram(imports).then((r) => receive(r.instance, r.module), reject);
        return {}; // exports arrive through receive()
      },
    }).then(resolve, (e) => reject(new LoadError(`The viewer program (tetstream.wasm) could not start: ${e && e.message ? e.message : e}`)));
  });
}

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
    if (bytes.length > MANIFEST_LIMIT) throw new LoadError(`The dataset description (manifest.json) at ${manifestUrl.href} is larger than 16 MB: not a tetstream manifest.`);
    return bytes;
  });
}

// ------------------------------------------------------------------ streaming a dataset
// FORMAT.md §1: a chunk's file is "chunks/" and a name of [0-9a-z.-] (no "..").
const CHUNK_FILE = /^chunks\/[0-9a-z.-]+$/;

// The chunk names and sizes of a manifest that the viewer has not validated yet, when every
// name passes the file rule: enough to start fetching (the viewer validates everything before
// anything is used). null when it does not look like a tetstream manifest.
function previewManifest(bytes) {
  try {
    const m = JSON.parse(new TextDecoder().decode(bytes));
    if (m.format !== 'tetstream' || m.formatVersion !== 1 || !Array.isArray(m.chunks)) return null;
    if (!m.chunks.length || m.chunks.length > 65536) return null;
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

let loaderDone = null; // resolves when the loader has delivered every allowed chunk, or stopped

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
    localUrls.set(name, file ? URL.createObjectURL(file) : `data:,missing`);
  }
  return localUrls.get(name);
}

// Every file under a dropped directory entry, with its path relative to `prefix`.
async function readEntry(entry, prefix, out) {
  if (entry.isFile) {
    const file = await new Promise((resolve, reject) => entry.file(resolve, reject));
    out.push({ path: prefix + entry.name, file });
  } else if (entry.isDirectory) {
    const reader = entry.createReader();
    for (;;) {
      const batch = await new Promise((resolve, reject) => reader.readEntries(resolve, reject));
      if (!batch.length) break;
      for (const e of batch) await readEntry(e, `${prefix}${entry.name}/`, out);
    }
  }
}

// From files with their paths: the folder that holds manifest.json, as path -> File relative to
// it. null when there is no manifest.json.
function packedFolder(list) {
  const manifests = list.filter((f) => /(^|\/)manifest\.json$/.test(f.path))
    .sort((a, b) => a.path.split('/').length - b.path.split('/').length);
  if (!manifests.length) return null;
  const base = manifests[0].path.slice(0, -'manifest.json'.length);
  const files = new Map();
  for (const f of list) if (f.path.startsWith(base)) files.set(f.path.slice(base.length), f.file);
  // Files dropped loose (the manifest and the chunk files selected together, or a DataTransfer
  // without directory entries): a chunk file is found by its name.
  for (const [name, file] of [...files]) {
    if (!name.includes('/') && name !== 'manifest.json' && !files.has(`chunks/${name}`)) files.set(`chunks/${name}`, file);
  }
  return files;
}

// Opens a packed dataset from local files (a Map path -> File, relative to its folder).
async function openLocal(files) {
  if (!files || !files.get('manifest.json')) {
    const message = 'That is not a packed tetstream dataset: drop the folder that holds manifest.json ' +
      '(made by tetstream pack).';
    showError(message);
    return false;
  }
  const preview = previewManifest(new Uint8Array(await files.get('manifest.json').arrayBuffer()));
  const missing = preview ? preview.names.filter((name) => !files.has(name)) : [];
  if (missing.length) {
    showError(`The folder is incomplete: ${missing[0]}${missing.length > 1 ? ` and ${missing.length - 1} more parts are` : ' is'} missing.`);
    return false;
  }
  if (loader) loader.stop();
  loader = null;
  for (const url of localUrls.values()) if (url.startsWith('blob:')) URL.revokeObjectURL(url);
  localUrls.clear();
  localFiles = files;
  boot.manifest = null; // the page's own ?data= request is not this dataset
  datasetUrl = null;
  pendingLevel = null;
  Object.assign(shell, { state: 'loading', error: '', retry: null });
  document.getElementById('help').style.display = 'none';
  if (location.search) history.replaceState(history.state, '', location.pathname);
  const manifestUrl = new URL(URL.createObjectURL(files.get('manifest.json')));
  if (!statusTimer) statusTimer = setInterval(updateStatus, 250);
  try {
    await stream(manifestUrl);
    updateStatus();
  } catch (e) {
    const message = e instanceof LoadError ? e.message : `Unexpected problem while opening the folder: ${e && e.message ? e.message : e}`;
    fail(message);
  } finally {
    startViewer();
  }
  return true;
}

async function filesFromDrop(dataTransfer) {
  const list = [];
  const entries = [...dataTransfer.items].map((item) => (item.webkitGetAsEntry ? item.webkitGetAsEntry() : null));
  if (entries.some(Boolean)) {
    for (const e of entries) if (e) await readEntry(e, '', list);
  } else {
    for (const file of dataTransfer.files) list.push({ path: file.name, file });
  }
  return packedFolder(list);
}

addEventListener('dragover', (e) => {
  if (![...(e.dataTransfer?.types || [])].includes('Files')) return;
  e.preventDefault();
  e.dataTransfer.dropEffect = 'copy';
});
addEventListener('drop', (e) => {
  if (!e.dataTransfer) return;
  e.preventDefault();
  filesFromDrop(e.dataTransfer).then(openLocal, (err) => showError(`The dropped folder could not be read: ${err.message}`));
});
// The folder chooser (<input type=file webkitdirectory>): paths come as webkitRelativePath.
const folderInput = document.getElementById('folder-input');
addEventListener('keydown', (e) => {
  // O: the folder chooser (a key press lets the page open it).
  if (/^(INPUT|TEXTAREA|SELECT)$/.test(e.target && e.target.tagName)) return; // typing a URL
  if ((e.key === 'o' || e.key === 'O') && !e.ctrlKey && !e.metaKey && !e.altKey && folderInput) folderInput.click();
});
if (folderInput) {
  folderInput.addEventListener('change', () => {
    const list = [...folderInput.files].map((file) => ({ path: file.webkitRelativePath || file.name, file }));
    openLocal(packedFolder(list));
  });
}

function startLoader({ names, sizes }, manifestUrl) {
  let resolve;
  loaderDone = new Promise((r) => { resolve = r; });
  earlyProgress = [];
  loader = new ChunkLoader({
    urls: names.map((name) => chunkUrl(name, manifestUrl)),
    names,
    sizes,
    stallMs,
    fail,
    done: resolve,
  });
  shell.datasetTotal = sizes.reduce((a, b) => a + b, 0);
  if (shell.programLoaded) loader.warm();
  loader.pump();
}

// What is left of the program would come in while a new request waits for its first byte: the
// first chunk after the base is asked for now, so that the link does not idle for a round trip
// when the program's last byte is in. (Decoded bytes left, at least the bytes on the wire.)
function programNearlyDownloaded() {
  if (shell.programLoaded || !loader || !shell.programTotal) return;
  if (shell.programTotal - shell.programBytes < loader.lead()) loader.nearlyWarm();
}

// The program's last byte is in (the counting stream's end, on every attempt): the link is free
// for more than the base chunk, well before the program has compiled.
function programDownloaded() {
  if (shell.programLoaded) return;
  shell.programLoaded = true;
  if (loader) loader.warm();
}

let viewerLoad = null; // the program is loaded once, whatever number of datasets the page opens
async function stream(manifestUrl) {
  showStatus('Loading the viewer…', [0, 0]);
  const viewerPromise = viewerLoad || (viewerLoad = loadViewer());
  const manifestPromise = loadManifest(manifestUrl);
  manifestPromise.catch(() => {}); // awaited below; avoid an "unhandled rejection" meanwhile
  // The base chunk is fetched as soon as the manifest is in, while the program downloads and
  // compiles: the first picture comes a round trip and a base download sooner.
  manifestPromise.then((bytes) => {
    const preview = previewManifest(bytes);
    if (preview && !loader && shell.state !== 'error') {
      startLoader(preview, manifestUrl);
      prepareWebGl();
    }
  }, () => {});

  viewer = await viewerPromise; // a failure here has no viewer to report into: caught by start()
  viewer.onPauseChange = (paused) => { if (loader) loader.setPaused(paused); };
  viewer.onCopyLink = () => { copyLink(); };
  viewer.onScreenshot = () => { saveScreenshot().catch((e) => console.warn(`tetstream: screenshot: ${e.message}`)); };
  let manifestBytes;
  try {
    manifestBytes = await manifestPromise;
  } catch (e) {
    return fail(e.message);
  }
  if (maxMemoryMB) viewer._ts_set_memory_limit(maxMemoryMB);
  const opened = withWasmBytes(manifestBytes, (ptr, len) => viewer._ts_open_manifest(ptr, len));
  const s = stats();
  if (!opened) {
    if (loader) loader.stop();
    Object.assign(shell, { state: 'error', error: s.error });
    return showError(s.error);
  }
  document.title = `tetstream — ${s.name || manifestUrl.pathname}`;
  if (shell.state === 'error') return fail(shell.error); // the base could not be had: say so in the panel too

  const field = params.get('field');
  if (field !== null && !window.tetstream.setField(field))
    console.warn(`tetstream: no field named "${field}" in this dataset; showing "${s.field}"`);
  const iso = params.get('iso');
  if (iso !== null) {
    if (iso.trim() !== '' && Number.isFinite(Number(iso))) viewer._ts_set_isovalue(Number(iso));
    else console.warn(`tetstream: ignoring iso=${iso} (not a number)`);
  }
  applyLinkState();

  // The manifest has been validated by the viewer: chunk files come from it, sizes from the JSON.
  // A loader started early read the same names (the same JSON); if not, it starts again.
  const manifest = JSON.parse(new TextDecoder().decode(manifestBytes));
  const sizes = manifest.chunks.map((c) => c.bytes);
  const names = [];
  for (let i = 0; i < s.chunksTotal; i++) names.push(viewer.UTF8ToString(viewer._ts_chunk_file(i)));
  if (loader && loader.names.join('\n') !== names.join('\n')) {
    loader.stop();
    loader = null;
  }
  if (!loader) startLoader({ names, sizes }, manifestUrl);
  shell.datasetTotal = sizes.slice(0, s.chunksAllowed).reduce((a, b) => a + b, 0);
  loader.attach({
    allowed: s.chunksAllowed,
    check(i, bytes) {
      const code = withWasmBytes(bytes, (ptr, len) => viewer._ts_check_chunk(i, ptr, len));
      return code === 1 ? null : damageText(code, bytes.length, sizes[i]);
    },
    deliver(i, bytes) {
      const ok = withWasmBytes(bytes, (ptr, len) => viewer._ts_add_chunk(i, ptr, len));
      reportProgress(); // the rate counts these bytes now, not at the next status tick
      startViewer(); // the base is in: show it as soon as possible
      const after = stats();
      if (ok && after.state !== 'error') return true;
      Object.assign(shell, { state: 'error', error: after.error });
      showError(after.error);
      return false;
    },
  });
  reportProgress();
  startViewer(); // WebGL setup overlaps the downloads
  await loaderDone;
}

// Network figures for the viewer's panel (rate, bytes, time left). The loader starts while the
// program compiles: what it takes in meanwhile is kept with its times (earlyProgress) and handed
// over once the viewer has the dataset, so the first chunks do not arrive as one burst with no rate.
function reportProgress() {
  if (!loader || shell.aborted) return;
  const sample = [loader.networkBytes, loader.haveBytes(), performance.now()];
  if (!viewer || !loader.attached) {
    earlyProgress.push(sample);
    if (earlyProgress.length > 40) earlyProgress.shift();
    return;
  }
  for (const early of earlyProgress) viewer._ts_download_progress(...early);
  earlyProgress = [];
  viewer._ts_download_progress(...sample);
}

// A page file being fetched again, or the chunk loader's notice.
function noticeText() {
  if (loader) return loader.notice();
  const r = shell.retry;
  if (!r) return '';
  const cause = !navigator.onLine ? 'You are offline' : r.error.kind === 'network' ? 'Connection lost'
    : r.error.kind === 'stall' ? `No answer for ${Math.round(stallMs / 1000)} s`
      : r.error.kind === 'damaged' ? `${capitalized(r.what)} arrived damaged` : `The server answered ${r.error.message}`;
  return r.at ? `${cause}: retrying ${r.what} in ${seconds(r.at - performance.now())}.`
    : `${cause}: retrying ${r.what} now (attempt ${r.failures + 1}).`;
}

// The status line under the canvas (the panel has the details), four times a second.
let lastNotice = '';
function updateStatus() {
  if (shell.state === 'idle' || shell.aborted) return;
  reportProgress();
  applyPendingLevel();
  syncUrl();
  const notice = noticeText();
  if (viewer && notice !== lastNotice) viewer.ccall('ts_set_notice', null, ['string'], [notice]);
  lastNotice = notice;
  const s = viewer ? stats() : null;
  if (s && s.state === 'error') {
    if (loader) loader.stop();
    if (statusText.textContent !== s.error) showError(s.error);
    return;
  }
  if (shell.state === 'error') return;
  // One bar for everything from the first byte: the program, then the dataset's parts.
  const have = loader ? loader.haveBytes() : 0;
  const total = shell.programTotal + shell.datasetTotal;
  const bar = total ? [Math.min(shell.programBytes, shell.programTotal) / total, have / total] : [0, 0];
  let text;
  if (!s || s.state === 'idle') {
    const program = shell.programTotal ? ` ${Math.round(shell.programBytes / 1024)} of ${Math.round(shell.programTotal / 1024)} KB`
      : ` ${Math.round(shell.programBytes / 1024)} KB`;
    text = `Loading the viewer:${program}…`;
  } else {
    const name = s.name || 'Dataset';
    const rate = s.rateBytesPerSec > 0 ? `, ${megabytes(s.rateBytesPerSec)}/s` : '';
    const left = s.secondsLeft >= 1 ? `, about ${seconds(1000 * s.secondsLeft)} left`
      : s.secondsLeft > 0 ? ', less than a second left' : '';
    if (s.state === 'loading') {
      text = `Loading ${name}: ${megabytes(have)} of ${megabytes(shell.datasetTotal)}${rate}…`;
    } else if (s.chunksReceived < s.chunksAllowed) {
      text = `${name}: ${s.chunksReceived} of ${s.chunksTotal} parts, ${megabytes(have)} of ` +
        `${megabytes(shell.datasetTotal)}${s.paused ? ' (paused)' : `${rate}${left}`}; level ${(100 * s.level).toFixed(1)}%`;
    } else {
      text = `${name}: all ${s.chunksTotal} parts, ${megabytes(s.bytesTotal)}; level ${(100 * s.level).toFixed(1)}%`;
    }
  }
  if (s && s.contextLost) {
    return showStatus('The browser took the graphics context away (a GPU reset or switch): the view comes back ' +
      'when it gives it back; loading goes on.', bar, 'warn');
  }
  if (notice) return showStatus(notice, bar, 'warn');
  showStatus(text, bar, s && s.state === 'complete' ? 'done' : '');
}

function showHelp() {
  shell.state = 'idle';
  statusBox.className = 'done';
  document.getElementById('help').style.display = 'flex';
  const form = document.getElementById('help-form');
  const input = document.getElementById('help-url');
  input.focus();
  form.addEventListener('submit', (e) => {
    e.preventDefault();
    const url = input.value.trim();
    if (url) location.search = `?data=${encodeURIComponent(url)}`;
  });
}

let statusTimer = 0;
async function start() {
  const data = params.get('data');
  if (!data) return showHelp();
  let manifestUrl;
  try {
    manifestUrl = new URL(data, location.href);
  } catch {
    return fail(`"${data}" is not a valid dataset URL.`);
  }
  addEventListener('online', () => { if (loader) loader.retryNow(); });
  statusTimer = setInterval(updateStatus, 250);
  try {
    await stream(manifestUrl);
    updateStatus();
  } catch (e) {
    const message = e instanceof LoadError ? e.message : `Unexpected problem while loading: ${e && e.message ? e.message : e}`;
    if (!(e instanceof LoadError)) console.error(e);
    fail(message);
  } finally {
    if (shell.state === 'error' && !viewer) clearInterval(statusTimer);
    startViewer();
  }
}

start();
