// What the page's modules share: the URL's parameters, the elements, the wasm viewer once it is
// instantiated, and what the page itself knows about loading before and besides the viewer.
// The viewer's functions are described in docs/js-api.md.
import { STALL_SECONDS } from './net.js';

export const params = new URLSearchParams(location.search);
export const canvas = document.getElementById('canvas');
export const boot = window.tetstreamBoot || {}; // downloads index.html started before the modules ran

function positiveParam(name) {
  const v = Number(params.get(name));
  return params.get(name) !== null && Number.isFinite(v) && v > 0 ? v : 0;
}
// ?stallSeconds=S: abandon and retry a request that receives nothing for S seconds.
export const stallMs = 1000 * (positiveParam('stallSeconds') || STALL_SECONDS);
// ?maxMemoryMB=N: the most memory the dataset may take (the viewer stops at the last level that fits).
export const maxMemoryMB = positiveParam('maxMemoryMB');

// programTotal: bytes of tetstream.wasm uncompressed, from index.html (the build writes it: a
// compressed response's Content-Length would not tell).
export const page = {
  viewer: null,          // the Emscripten module once it is instantiated
  programModule: null,   // the compiled tetstream.wasm (WebAssembly.Module), for the refinement worker too
  viewerStarted: false,  // its main() has run
  loader: null,          // the ChunkLoader of the dataset being streamed
  state: 'loading',      // what stats() says before the viewer runs
  error: '',
  aborted: false,        // the wasm runtime stopped: nothing can be called any more
  retry: null,           // { what, at, error, failures }: a page file waiting to be fetched again
  pageRetries: 0,
  programBytes: 0,
  programTotal: Number(document.querySelector('meta[name="tetstream-wasm-bytes"]')?.content) || 0,
  programLoaded: false,  // the program's last byte is in
  datasetTotal: 0,       // bytes of the chunks to fetch, once the manifest is read
  datasetUrl: params.get('data'),
};

export class LoadError extends Error {}

// True while the viewer can be called.
export function viewerReady() {
  return !!page.viewer && !page.aborted;
}

// "512 KB", "1.50 MB", "12.3 MB": the page's one byte formatter.
export function formatBytes(n) {
  if (n < 1048576) return `${Math.round(n / 1024)} KB`;
  return `${(n / 1048576).toFixed(n < 10 * 1048576 ? 2 : 1)} MB`;
}

// A C string the viewer returned.
export function wasmString(ptr) {
  return page.viewer.UTF8ToString(ptr);
}

// Copies bytes into wasm memory (read HEAPU8 after _malloc: memory may have grown) and returns
// the address; the caller frees it, or hands it to a function that takes it over.
export function copyToWasm(bytes) {
  if (page.aborted) throw new LoadError(page.error);
  const viewer = page.viewer;
  const ptr = viewer._malloc(Math.max(1, bytes.length));
  if (!ptr) {
    throw new LoadError(`The browser did not give the viewer ${formatBytes(bytes.length)} of memory for the next ` +
      'part of the dataset.');
  }
  viewer.HEAPU8.set(bytes, ptr);
  return ptr;
}
