// tetstream web shell: reads ?data=URL (a packed dataset's manifest.json; relative, absolute or
// cross-origin with CORS), optional &iso=VALUE and &field=NAME, loads the wasm viewer, streams
// the manifest and then every chunk in order into it, and reports HTTP/network failures in
// plain words. The wasm functions used here are documented at the top of wasm/main.cpp.
//
// window.tetstream = {
//   stats()         -> the viewer's state (statsJson in wasm/viewer_state.h); state is one of
//                      "idle" (no dataset given), "loading", "streaming", "complete", "error".
//                      sliderRect is in CSS pixels of the page.
//   setIsovalue(v)  -> re-extracts the surface at v
//   setField(name)  -> true when the field exists
// }

const MAX_PARALLEL_FETCHES = 4;

const statusBox = document.getElementById('status');
const statusText = document.getElementById('status-text');
const statusFill = document.getElementById('status-fill');
const canvas = document.getElementById('canvas');

let viewer = null; // the Emscripten module once it is instantiated
let viewerStarted = false;
let shellState = { state: 'loading', error: '' }; // what stats() says before the module runs

function showStatus(text, fraction) {
  statusBox.className = '';
  statusText.textContent = text;
  if (fraction !== undefined) statusFill.style.width = `${Math.round(100 * Math.min(1, fraction))}%`;
}

function showError(text) {
  statusBox.className = 'error';
  statusText.textContent = text;
}

function megabytes(n) {
  return `${(n / 1048576).toFixed(n < 10 * 1048576 ? 2 : 1)} MB`;
}

class LoadError extends Error {}

// ------------------------------------------------------------------ talking to the wasm viewer
function stats() {
  if (!viewer || shellState.aborted) return { ...shellState };
  const s = JSON.parse(viewer.UTF8ToString(viewer._ts_stats_json()));
  const r = canvas.getBoundingClientRect();
  s.sliderRect = { ...s.sliderRect, x: s.sliderRect.x + r.left, y: s.sliderRect.y + r.top };
  return s;
}

// Copies bytes into wasm memory once, calls fn(ptr, len), frees them.
function withWasmBytes(bytes, fn) {
  if (shellState.aborted) throw new LoadError(shellState.error);
  const ptr = viewer._malloc(Math.max(1, bytes.length));
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
  if (!viewer || viewerStarted || shellState.aborted) return;
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
  shellState = { state: 'error', error: message, aborted: true };
  showError(message);
}

function fail(message) {
  if (shellState.aborted) return;
  if (viewer) viewer.ccall('ts_fail', null, ['string'], [message]);
  shellState = { state: 'error', error: message };
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
};

// ------------------------------------------------------------------ network
// Fetches a whole file, reporting received bytes. `limit`: stop reading after this many bytes
// (the viewer then reports the size mismatch itself).
async function fetchBytes(url, what, { signal, limit = Infinity, onProgress = () => {} } = {}) {
  let response;
  try {
    response = await fetch(url, { signal });
  } catch (e) {
    if (signal && signal.aborted) throw e;
    throw new LoadError(`Could not download ${what} from ${url}: the server did not answer or refused ` +
      `the request (network error, or another site that does not allow cross-origin access).`);
  }
  if (!response.ok) {
    const reason = response.status === 404 ? 'not found' : response.statusText || 'request failed';
    throw new LoadError(`Could not download ${what} from ${url}: HTTP ${response.status} (${reason}).`);
  }
  if (!response.body) {
    const bytes = new Uint8Array(await response.arrayBuffer());
    onProgress(bytes.length);
    return bytes;
  }
  const reader = response.body.getReader();
  const parts = [];
  let received = 0;
  for (;;) {
    let step;
    try {
      step = await reader.read();
    } catch (e) {
      if (signal && signal.aborted) throw e;
      throw new LoadError(`The download of ${what} from ${url} broke off after ${received} bytes.`);
    }
    if (step.done) break;
    parts.push(step.value);
    received += step.value.length;
    onProgress(step.value.length);
    if (received > limit) {
      reader.cancel().catch(() => {});
      break;
    }
  }
  if (parts.length === 1) return parts[0];
  const bytes = new Uint8Array(received);
  let at = 0;
  for (const p of parts) {
    bytes.set(p, at);
    at += p.length;
  }
  return bytes;
}

function loadViewer() {
  return new Promise((resolve, reject) => {
    const script = document.createElement('script');
    script.src = 'tetstream.js';
    script.onload = () => {
      // eslint-disable-next-line no-undef
      createTetstream({ canvas, onAbort: viewerAborted }).then(resolve, (e) =>
        reject(new LoadError(`The viewer program (tetstream.wasm) could not start: ${e && e.message ? e.message : e}`)));
    };
    script.onerror = () => reject(new LoadError('The viewer program (tetstream.js) could not be loaded from this site.'));
    document.head.appendChild(script);
  });
}

// ------------------------------------------------------------------ streaming a dataset
async function stream(manifestUrl, params) {
  showStatus('Loading the viewer and the dataset description…', 0);
  const viewerPromise = loadViewer();
  const manifestPromise = fetchBytes(manifestUrl.href, 'the dataset description (manifest.json)');
  manifestPromise.catch(() => {}); // awaited below; avoid an "unhandled rejection" meanwhile

  viewer = await viewerPromise; // a failure here has no viewer to report into: caught by start()
  let manifestBytes;
  try {
    manifestBytes = await manifestPromise;
  } catch (e) {
    return fail(e.message);
  }
  const opened = withWasmBytes(manifestBytes, (ptr, len) => viewer._ts_open_manifest(ptr, len));
  let s = stats();
  if (!opened) return showError(s.error);
  document.title = `tetstream — ${s.name || manifestUrl.pathname}`;

  const field = params.get('field');
  if (field !== null && !window.tetstream.setField(field))
    console.warn(`tetstream: no field named "${field}" in this dataset; showing "${s.field}"`);
  const iso = params.get('iso');
  if (iso !== null) {
    if (iso.trim() !== '' && Number.isFinite(Number(iso))) viewer._ts_set_isovalue(Number(iso));
    else console.warn(`tetstream: ignoring iso=${iso} (not a number)`);
  }

  // The manifest has been validated by the viewer; read the chunk sizes from it for progress.
  const manifest = JSON.parse(new TextDecoder().decode(manifestBytes));
  const total = s.chunksTotal;
  const files = [];
  for (let i = 0; i < total; i++) files.push(viewer.UTF8ToString(viewer._ts_chunk_file(i)));
  const totalBytes = s.bytesTotal;
  let received = 0;
  const progress = (applied) =>
    showStatus(`Streaming ${s.name || 'dataset'}: part ${Math.min(applied + 1, total)} of ${total}, ` +
      `${megabytes(received)} of ${megabytes(totalBytes)}`, totalBytes ? received / totalBytes : 0);

  // Fetch a few chunks ahead, apply strictly in order.
  const abort = new AbortController();
  const fetches = [];
  const startFetch = (i) => {
    const url = new URL(files[i], manifestUrl).href;
    const p = fetchBytes(url, `part ${i + 1} of ${total} of the dataset`, {
      signal: abort.signal,
      limit: manifest.chunks[i].bytes,
      onProgress: (n) => { received += n; progress(i); },
    });
    p.catch(() => {});
    fetches[i] = p;
  };
  progress(0);
  for (let i = 0; i < Math.min(total, MAX_PARALLEL_FETCHES); i++) startFetch(i);
  startViewer(); // WebGL setup overlaps the downloads
  for (let i = 0; i < total; i++) {
    for (let j = i; j < Math.min(total, i + MAX_PARALLEL_FETCHES); j++) if (!fetches[j]) startFetch(j);
    let bytes;
    try {
      bytes = await fetches[i];
    } catch (e) {
      abort.abort();
      return fail(e.message);
    }
    fetches[i] = null;
    const ok = withWasmBytes(bytes, (ptr, len) => viewer._ts_add_chunk(i, ptr, len));
    if (!ok) {
      abort.abort();
      return showError(stats().error);
    }
    progress(i + 1);
  }
  s = stats();
  showStatus(`${s.name || 'Dataset'}: ${total} part${total === 1 ? '' : 's'}, ${megabytes(s.bytesLoaded)} loaded`, 1);
  setTimeout(() => { if (stats().state === 'complete') statusBox.className = 'done'; }, 1500);
}

function showHelp() {
  shellState = { state: 'idle', error: '' };
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

async function start() {
  const params = new URLSearchParams(location.search);
  const data = params.get('data');
  if (!data) return showHelp();
  let manifestUrl;
  try {
    manifestUrl = new URL(data, location.href);
  } catch {
    return fail(`"${data}" is not a valid dataset URL.`);
  }
  try {
    await stream(manifestUrl, params);
  } catch (e) {
    const message = e instanceof LoadError ? e.message : `Unexpected problem while loading: ${e && e.message ? e.message : e}`;
    if (!(e instanceof LoadError)) console.error(e);
    fail(message);
  } finally {
    startViewer();
  }
}

start();
