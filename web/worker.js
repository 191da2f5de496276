// The refinement worker: a second instance of the viewer program (the module the page compiled,
// handed over, not downloaded again) that holds the dataset and its model and never draws. It
// checks and adds the chunks the page downloads, applies the view the page chose, refines in
// slices and sends back, after each, what changed: the model's figures, a geometry delta
// (transferred, not copied) and the fetch plan when it changed. The page's thread keeps only
// drawing, the panel and input. Messages: docs/js-api.md ("The refinement worker").
/* global createTetstream */
importScripts('tetstream.js');

// Refinement per slice. Messages from the page (a new isovalue, a chunk) wait at most this long
// plus one full extraction. The program says after which slices the page gets an update
// (wasm/update_pacing.h): while refining, at most every 33 ms.
const SLICE_MS = 12;

let viewer = null;
const early = [];        // messages that came while the program was instantiated
let seen = 0;            // the last command applied (page_state.h: settingsVersion)
let planVersion = -1;    // the plan the page has
let lastStats = '';
let lastSeen = 0;
let queued = false;
const channel = new MessageChannel(); // a task of its own per slice, without setTimeout's clamp
channel.port1.onmessage = work;

function schedule() {
  if (queued || !viewer) return;
  queued = true;
  channel.port2.postMessage(0);
}

function aborted(what) {
  postMessage({ type: 'aborted', what: String(what && what.message ? what.message : what) });
  viewer = null;
}

function text(ptr) {
  return viewer.UTF8ToString(ptr);
}

// Bytes into the program's memory; the callee takes them over (frees them).
function copyIn(bytes) {
  const ptr = viewer._malloc(Math.max(1, bytes.length));
  if (!ptr) return 0;
  viewer.HEAPU8.set(bytes, ptr);
  return ptr;
}

function callWithString(name, value) {
  viewer.ccall(name, null, ['string'], [value]);
}

// What changed since the last update, unless nothing did.
function publish() {
  const ptr = viewer._tw_delta();
  const size = viewer._tw_delta_size();
  const delta = size ? viewer.HEAPU8.slice(ptr, ptr + size) : null;
  const stats = text(viewer._tw_stats());
  let plan = null;
  let forgotten = null; // chunks given back for memory: the page's loader may fetch them again
  if (viewer._tw_plan_version() !== planVersion) {
    planVersion = viewer._tw_plan_version();
    plan = JSON.parse(text(viewer._tw_plan()));
    forgotten = JSON.parse(text(viewer._tw_forgotten()));
    if (!forgotten.length) forgotten = null;
  }
  if (!delta && !plan && stats === lastStats && seen === lastSeen) return;
  lastStats = stats;
  lastSeen = seen;
  const message = { type: 'update', stats, seen, delta: delta ? delta.buffer : null, plan, forgotten };
  postMessage(message, delta ? [delta.buffer] : []);
}

function work() {
  queued = false;
  if (!viewer) return;
  try {
    const done = viewer._tw_work(SLICE_MS);
    if (done & 2) publish();
    if (done & 1) schedule();
  } catch (e) {
    aborted(e);
  }
}

const handlers = {
  open({ bytes, memoryLimitMB }) {
    viewer._tw_set_memory_limit(memoryLimitMB || 0);
    const ptr = copyIn(bytes);
    const ok = ptr ? viewer._tw_open(ptr, bytes.length) : 0;
    viewer._free(ptr);
    planVersion = viewer._tw_plan_version();
    const plan = JSON.parse(text(viewer._tw_plan()));
    postMessage({ type: 'opened', ok: !!ok, chunksAllowed: viewer._tw_chunks_allowed(), plan,
      stats: text(viewer._tw_stats()) });
  },
  offer({ index, bytes }) {
    const ptr = copyIn(bytes);
    const code = ptr ? viewer._tw_offer(index, ptr, bytes.length) : -1;
    postMessage({ type: 'offered', index, code });
  },
  command({ version, text: command }) {
    callWithString('tw_command', command);
    seen = version;
  },
  unavailable({ index, message }) {
    viewer.ccall('tw_chunk_unavailable', null, ['number', 'string'], [index, message]);
  },
  paused({ paused }) {
    viewer._tw_set_paused(paused ? 1 : 0);
  },
  camera({ values }) {
    viewer._tw_camera(...values);
  },
  fail({ message }) {
    callWithString('tw_fail', message);
  },
};

function handle(message) {
  if (!viewer) return early.push(message);
  handlers[message.type](message);
  schedule();
}

async function start({ module }) {
  viewer = await createTetstream({
    onAbort: aborted,
    instantiateWasm(imports, receive) {
      WebAssembly.instantiate(module, imports).then((instance) => receive(instance, module), aborted);
      return {}; // exports arrive through receive()
    },
  });
  postMessage({ type: 'started' });
  for (const message of early.splice(0)) handle(message);
}

onmessage = (e) => {
  try {
    if (e.data.type === 'start') start(e.data).catch(aborted);
    else handle(e.data);
  } catch (err) {
    aborted(err);
  }
};
