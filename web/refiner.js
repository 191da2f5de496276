// The page's side of the refinement worker (worker.js): starts it with the program the page
// compiled, posts the dataset's chunks (transferred), the view the user chose and the network's
// pause, and takes its updates: the model's figures and a geometry delta go into the page's
// viewer (ts_take_report), the fetch plan to whoever follows it. Nothing here waits for the
// worker: each answer comes as its own message.
import { boot, copyToWasm, page } from './page.js';

export const refiner = {
  worker: null,
  offers: new Map(), // chunk index -> resolve(code) of an offer under way
  opening: null,     // resolve({ ok, chunksAllowed, plan, stats }) of the open under way
  onPlan: null,      // (plan: chunk indices) when the worker's plan changed
  onForgotten: null, // (chunk indices) the worker gave back for memory, before the plan that follows
  onAborted: null,   // (what) the worker stopped: nothing more comes from it

  // Starts the worker with the compiled program (WebAssembly.Module). onAborted: as above.
  // (index.html starts it early, so that its scripts load while the program downloads.)
  start(module, onAborted) {
    this.onAborted = onAborted;
    if (boot.workerError) {
      const why = boot.workerError === true ? '' : `: ${boot.workerError}`;
      onAborted(`its refinement worker, worker.js, could not be loaded${why}`);
      return;
    }
    try {
      this.worker = boot.worker || new Worker(new URL('worker.js', location.href));
      boot.worker = null; // (a second dataset reuses this one)
    } catch (e) {
      onAborted(`its refinement worker could not start: ${e && e.message ? e.message : e}`);
      return;
    }
    this.worker.onmessage = (e) => this.receive(e.data);
    this.worker.onerror = (e) => {
      e.preventDefault();
      this.stopped(e.message ? `its refinement worker failed: ${e.message}` : 'its refinement worker, worker.js, could not be loaded');
    };
    this.worker.postMessage({ type: 'start', module });
  },

  post(message, transfer = []) {
    if (this.worker) this.worker.postMessage(message, transfer);
  },

  stopped(what) {
    this.worker = null;
    for (const resolve of this.offers.values()) resolve(-1);
    this.offers.clear();
    if (this.opening) this.opening({ ok: false, chunksAllowed: 0, plan: [], stats: '{}' });
    this.opening = null;
    if (this.onAborted) this.onAborted(what);
  },

  // The manifest the page has read: the worker opens the dataset. Resolves with its answer.
  open(bytes, memoryLimitMB) {
    return new Promise((resolve) => {
      if (!this.worker) return resolve({ ok: false, chunksAllowed: 0, plan: [], stats: '{}' });
      this.opening = resolve;
      this.offers.clear();
      this.post({ type: 'open', bytes, memoryLimitMB });
    });
  },

  // Chunk `index`: resolves with the worker's code (1 kept, 2 wrong size, 3 wrong hash, 0 not
  // wanted, -1 the worker stopped). The bytes are transferred: the caller keeps none.
  offer(index, bytes) {
    return new Promise((resolve) => {
      if (!this.worker) return resolve(-1);
      const whole = bytes.byteOffset === 0 && bytes.byteLength === bytes.buffer.byteLength ? bytes : bytes.slice();
      this.offers.set(index, resolve);
      this.post({ type: 'offer', index, bytes: whole }, [whole.buffer]);
    });
  },

  // The view changed in the page's viewer: its command goes now (once per task, however many
  // changes came).
  commandReady() {
    if (this.commandQueued) return;
    this.commandQueued = true;
    queueMicrotask(() => {
      this.commandQueued = false;
      if (!page.viewer || page.aborted) return;
      const text = page.viewer.UTF8ToString(page.viewer._ts_take_command());
      if (text) this.post({ type: 'command', version: JSON.parse(text).version, text });
    });
  },

  receive(m) {
    if (m.type === 'aborted') return this.stopped(`its refinement worker stopped: ${m.what}`);
    if (m.type === 'opened') {
      const resolve = this.opening;
      this.opening = null;
      if (resolve) resolve(m);
      return;
    }
    if (m.type === 'offered') {
      const resolve = this.offers.get(m.index);
      this.offers.delete(m.index);
      if (resolve) resolve(m.code);
      return;
    }
    // (An update sent before the worker took a new dataset is about the old one.)
    if (m.type === 'update' && !this.opening) this.update(m);
  },

  // The model's figures and the geometry that changed, into the page's viewer; then the plan.
  update({ stats, seen, delta, plan, forgotten }) {
    const viewer = page.viewer;
    if (!viewer || page.aborted) return;
    const bytes = delta ? new Uint8Array(delta) : null;
    const ptr = bytes ? copyToWasm(bytes) : 0;
    try {
      viewer.ccall('ts_take_report', 'number', ['string', 'number', 'number', 'number'],
        [stats, seen, ptr, bytes ? bytes.length : 0]);
    } finally {
      if (ptr) viewer._free(ptr);
    }
    if (forgotten && this.onForgotten) this.onForgotten(forgotten);
    if (plan && this.onPlan) this.onPlan(plan);
  },
};
