// The viewer program (tetstream.js + tetstream.wasm): downloaded with its bytes counted for the
// progress bar, compiled while it streams, retried while failures may pass, and started.
import { countingResponse, FetchError, httpError, retryDelayMs } from './net.js';
import { boot, canvas, LoadError, page, params, stallMs } from './page.js';

const PAGE_FILE_TRIES = 4; // the program and the manifest: then the page gives up and says why

// Waits `ms`, or less when the browser says the network is back.
function waitOrOnline(ms) {
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
export async function withRetries(what, url, attempt) {
  for (let failures = 0; ;) {
    try {
      const result = await attempt(failures);
      page.retry = null;
      return result;
    } catch (e) {
      if (e instanceof LoadError) throw e;
      const reason = !(e instanceof FetchError) ? String(e && e.message ? e.message : e)
        : e.kind === 'network' ? 'the server did not answer or refused the request (network error, or another ' +
          'site that does not allow cross-origin access)' : e.message;
      failures++;
      if (!(e instanceof FetchError) || !e.transient || failures >= PAGE_FILE_TRIES) {
        page.retry = null;
        throw new LoadError(`Could not download ${what} from ${url}: ${reason}` +
          `${failures > 1 ? ` (tried ${failures} times)` : ''}.`);
      }
      const delay = retryDelayMs(failures, e.retryAfterMs);
      page.retry = { what, at: performance.now() + delay, error: e, failures };
      page.pageRetries++;
      await waitOrOnline(delay);
      page.retry.at = 0;
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
// through Module.instantiateWasm. onNearlyIn / onIn: the program's last bytes are coming / in.
async function instantiateProgram(imports, { onNearlyIn, onIn }) {
  const url = new URL('tetstream.wasm', location.href).href;
  return withRetries('the viewer program (tetstream.wasm)', url, async (failures) => {
    const early = failures === 0 ? boot.wasm : null;
    const controller = new AbortController();
    const request = early ? early.promise : fetch(url, { signal: controller.signal, credentials: 'same-origin',
      cache: failures ? 'reload' : 'default' });
    const response = await withStall(request, stallMs, () => (early ? early.controller : controller).abort());
    if (!response.ok) throw httpError(response);
    if (!page.programTotal && !response.headers.get('Content-Encoding'))
      page.programTotal = Number(response.headers.get('Content-Length')) || 0;
    page.programBytes = 0;
    let streamError = null;
    const counted = countingResponse(response, {
      type: 'application/wasm',
      stallMs,
      onProgress: (n) => {
        page.programBytes += n;
        onNearlyIn();
      },
      onEnd: onIn,
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

// ?antialias=0 or 1: multisample the scene or not (by default the viewer does, unless WebGL
// renders in software).
function antialiasOption() {
  const a = params.get('antialias');
  return a === '0' ? false : a === '1' ? true : undefined;
}

// The Emscripten module, instantiated (main() not run yet). `hooks`: onNearlyIn, onIn (above),
// onAbort(what): the runtime stopped.
export async function loadProgram(hooks) {
  const scriptUrl = new URL('tetstream.js', location.href).href;
  await withRetries('the viewer program (tetstream.js)', scriptUrl, (failures) => (failures === 0 && boot.script
    ? boot.script.catch(() => { throw new FetchError('could not be loaded', { kind: 'network', transient: true }); })
    : loadScript(scriptUrl)));
  return new Promise((resolve, reject) => {
    // eslint-disable-next-line no-undef
    createTetstream({
      canvas,
      antialias: antialiasOption(),
      onAbort: hooks.onAbort,
      instantiateWasm(imports, receive) {
        instantiateProgram(imports, hooks).then((r) => {
          page.programModule = r.module; // the refinement worker instantiates it too
          receive(r.instance, r.module);
        }, reject);
        return {}; // exports arrive through receive()
      },
    }).then(resolve, (e) => reject(new LoadError(`The viewer program (tetstream.wasm) could not start: ${e && e.message ? e.message : e}`)));
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
export function prepareWebGl() {
  if (webGlPrepared) return;
  webGlPrepared = true;
  try {
    const box = canvas.getBoundingClientRect();
    canvas.width = Math.max(1, Math.round(box.width * (window.devicePixelRatio || 1)));
    canvas.height = Math.max(1, Math.round(box.height * (window.devicePixelRatio || 1)));
    canvas.getContext('webgl2', { antialias: false, alpha: true, depth: true, stencil: true });
  } catch { /* main() reports a missing WebGL 2 */ }
}
