// tetstream web shell: reads ?data=URL (a packed dataset's manifest.json; relative, absolute or
// cross-origin with CORS), optional &iso=VALUE and &field=NAME, loads the wasm viewer, streams
// the manifest and then the chunks into it (a few requests in flight, handed over in order as
// they arrive), and reports HTTP/network failures in plain words. The wasm functions used here
// are documented at the top of wasm/main.cpp.
//
// window.tetstream = {
//   stats()          -> the viewer's state (statsJson in wasm/viewer_state.h). state is one of
//                       "idle" (no dataset given), "loading" (before the base mesh), "streaming"
//                       (base shown; parts still to come or splits still to apply), "complete"
//                       (every part received and every split applied), "error". Level fields:
//                       splitsApplied, splitsReceived, splitsTotal, targetSplits, level (vertices
//                       shown / full), live, paused, fieldError; network: chunksReceived,
//                       bytesReceived, bytesDownloaded, bytesTotal, rateBytesPerSec, secondsLeft;
//                       frame timing: maxFrameMs, maxFrameGapMs, maxRefineMs. sliderRect,
//                       levelSliderRect and pauseButtonRect are in CSS pixels of the page.
//   setIsovalue(v)   -> re-extracts the surface at v
//   setField(name)   -> true when the field exists
//   setLevel(f)      -> level target: fraction f of the full mesh's vertices, clamped to what has
//                       been received (0 = base mesh; 1 = newest, and it then follows new data)
//   pause(), resume() downloading; pausing drops requests under way, the level keeps refining
//                       up to what has been received
// }

const MAX_IN_FLIGHT = 4; // requests under way at once
const MAX_AHEAD = 12;    // chunks fetched past the next one the viewer needs

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
  for (const key of ['sliderRect', 'levelSliderRect', 'pauseButtonRect'])
    s[key] = { ...s[key], x: s[key].x + r.left, y: s[key].y + r.top };
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
  setLevel(fraction) {
    if (viewer) viewer._ts_set_level(Number(fraction));
  },
  pause() {
    if (viewer) viewer._ts_set_paused(1);
  },
  resume() {
    if (viewer) viewer._ts_set_paused(0);
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
// Chunks are fetched ahead, a few at a time, in the order the viewer needs them, and each is
// handed over as soon as it and every chunk before it have arrived. Handing over only verifies
// (cheap); the viewer applies the splits in its frame loop under a per-frame time budget, so
// downloading, verifying and refining overlap and the page never stalls.
class ChunkLoader {
  constructor({ files, sizes, manifestUrl, name, onDone }) {
    this.files = files;
    this.sizes = sizes;
    this.manifestUrl = manifestUrl;
    this.name = name;
    this.onDone = onDone;         // called once: every chunk handed over, or stopped
    this.total = files.length;
    this.next = 0;               // next chunk to hand to the viewer
    this.inFlight = new Map();   // index -> { controller, received }
    this.arrived = new Map();    // index -> bytes, complete but waiting for an earlier chunk
    this.deliveredBytes = 0;
    this.networkBytes = 0;       // off the wire, aborted requests included (for the rate)
    this.paused = false;
    this.stopped = false;
    this.failure = null;         // { index, message } of the first chunk that could not be had
  }

  // Keeps MAX_IN_FLIGHT requests going, never further than MAX_AHEAD chunks past the next one
  // needed (so one slow chunk cannot make the page hold the whole dataset in JS memory).
  pump() {
    if (this.paused || this.stopped || this.failure) return;
    const end = Math.min(this.total, this.next + MAX_AHEAD);
    for (let i = this.next; i < end && this.inFlight.size < MAX_IN_FLIGHT; i++) {
      if (!this.arrived.has(i) && !this.inFlight.has(i)) this.fetchChunk(i);
    }
  }

  fetchChunk(i) {
    const entry = { controller: new AbortController(), received: 0 };
    this.inFlight.set(i, entry);
    const url = new URL(this.files[i], this.manifestUrl).href;
    fetchBytes(url, `part ${i + 1} of ${this.total} of the dataset`, {
      signal: entry.controller.signal,
      limit: this.sizes[i],
      onProgress: (n) => {
        entry.received += n;
        this.networkBytes += n;
        this.report();
      },
    }).then((bytes) => {
      if (this.inFlight.get(i) !== entry) return; // aborted meanwhile (pause)
      this.inFlight.delete(i);
      this.arrived.set(i, bytes);
      this.deliver();
      this.pump();
    }, (e) => {
      if (this.inFlight.get(i) === entry) this.inFlight.delete(i);
      if (entry.controller.signal.aborted || this.stopped) return;
      this.failAt(i, e.message);
    });
  }

  // Chunk i cannot be had: the chunks before it that are still coming are used first, then the
  // error is reported. The level reached stays on screen and usable.
  failAt(i, message) {
    if (this.failure && this.failure.index <= i) return;
    this.failure = { index: i, message };
    for (const [j, e] of [...this.inFlight]) {
      if (j > i) {
        e.controller.abort();
        this.inFlight.delete(j);
      }
    }
    for (const j of [...this.arrived.keys()]) if (j > i) this.arrived.delete(j);
    this.reportFailure();
  }

  reportFailure() {
    if (!this.failure || this.next < this.failure.index || this.stopped) return;
    this.stop();
    fail(this.failure.message);
  }

  deliver() {
    while (!this.stopped && this.arrived.has(this.next)) {
      const i = this.next;
      const bytes = this.arrived.get(i);
      this.arrived.delete(i);
      const ok = withWasmBytes(bytes, (ptr, len) => viewer._ts_add_chunk(i, ptr, len));
      if (!ok) {
        this.stop();
        showError(stats().error);
        return;
      }
      this.deliveredBytes += bytes.length;
      this.next++;
      startViewer(); // the base is in: show it as soon as possible
    }
    this.report();
    if (this.next === this.total) this.stop();
    this.reportFailure();
  }

  // Network progress for the viewer's panel (rate, bytes, time left).
  report() {
    if (shellState.aborted) return;
    let have = this.deliveredBytes;
    for (const b of this.arrived.values()) have += b.length;
    for (const e of this.inFlight.values()) have += e.received;
    viewer._ts_download_progress(this.networkBytes, have);
  }

  // Pausing stops the network at once: requests under way are dropped (and fetched again on
  // resume); what arrived completely is kept.
  setPaused(paused) {
    this.paused = paused;
    if (paused) {
      for (const e of this.inFlight.values()) e.controller.abort();
      this.inFlight.clear();
      this.report();
    } else {
      this.pump();
    }
  }

  stop() {
    if (this.stopped) return;
    this.stopped = true;
    for (const e of this.inFlight.values()) e.controller.abort();
    this.inFlight.clear();
    this.onDone();
  }
}

let loader = null;

async function stream(manifestUrl, params) {
  showStatus('Loading the viewer and the dataset description…', 0);
  const viewerPromise = loadViewer();
  const manifestPromise = fetchBytes(manifestUrl.href, 'the dataset description (manifest.json)');
  manifestPromise.catch(() => {}); // awaited below; avoid an "unhandled rejection" meanwhile

  viewer = await viewerPromise; // a failure here has no viewer to report into: caught by start()
  viewer.onPauseChange = (paused) => { if (loader) loader.setPaused(paused); };
  let manifestBytes;
  try {
    manifestBytes = await manifestPromise;
  } catch (e) {
    return fail(e.message);
  }
  const opened = withWasmBytes(manifestBytes, (ptr, len) => viewer._ts_open_manifest(ptr, len));
  const s = stats();
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

  // The manifest has been validated by the viewer: chunk files come from it, sizes (to cap a
  // response that is longer than announced) from the JSON.
  const manifest = JSON.parse(new TextDecoder().decode(manifestBytes));
  const files = [];
  for (let i = 0; i < s.chunksTotal; i++) files.push(viewer.UTF8ToString(viewer._ts_chunk_file(i)));
  await new Promise((resolve) => {
    loader = new ChunkLoader({
      files,
      sizes: manifest.chunks.map((c) => c.bytes),
      manifestUrl,
      name: s.name,
      onDone: resolve,
    });
    loader.report();
    loader.pump();
    startViewer(); // WebGL setup overlaps the downloads
  });
}

// The status line under the canvas, from the viewer's state (the panel has the details).
function updateStatus() {
  if (shellState.state === 'idle' || shellState.aborted || !viewer) return;
  const s = stats();
  if (s.state === 'error') {
    if (loader) loader.stop();
    if (statusText.textContent !== s.error) showError(s.error);
    return;
  }
  if (s.state === 'idle') return;
  const name = s.name || 'Dataset';
  const have = s.chunksReceived === s.chunksTotal ? s.bytesReceived : Math.max(s.bytesReceived, s.bytesDownloaded);
  if (s.state === 'loading') {
    showStatus(`Loading ${name}…`, s.bytesTotal ? have / s.bytesTotal : 0);
  } else if (s.chunksReceived < s.chunksTotal) {
    showStatus(`${name}: ${s.chunksReceived} of ${s.chunksTotal} parts, ${megabytes(have)} of ` +
      `${megabytes(s.bytesTotal)}${s.paused ? ' (paused)' : ''}; level ${(100 * s.level).toFixed(1)}%`,
      s.bytesTotal ? have / s.bytesTotal : 0);
  } else {
    showStatus(`${name}: ${s.chunksTotal} part${s.chunksTotal === 1 ? '' : 's'}, ${megabytes(s.bytesTotal)} received`, 1);
    statusBox.className = 'done';
  }
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
  const statusTimer = setInterval(updateStatus, 250);
  try {
    await stream(manifestUrl, params);
    updateStatus();
  } catch (e) {
    clearInterval(statusTimer);
    const message = e instanceof LoadError ? e.message : `Unexpected problem while loading: ${e && e.message ? e.message : e}`;
    if (!(e instanceof LoadError)) console.error(e);
    fail(message);
  } finally {
    startViewer();
  }
}

start();
