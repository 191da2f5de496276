// window.tetstream (docs/js-api.md) and the view in the URL: getState() as one object, settable
// in parts (setState), and as a link. The page keeps its address bar at link(), so that copying
// it, or the "copy link" button, shares the view.
// URL parameters: data, field, iso, colour, map, range=LO,HI, slice=NX,NY,NZ,OFFSET (present =
// on), level (fraction of the full mesh's vertices, absent = newest), cam=TX,TY,TZ,DISTANCE,YAW,
// PITCH, boundary=0; numbers as the shortest decimals that give back the same float.
import { canvas, page, params, viewerReady, wasmString } from './page.js';
import { openFolder, packedFolder } from './input.js';
import { network } from './stream.js';

let pendingLevel = null; // a level asked for before its parts arrived: applied as they do

// Everything, as one object: the viewer's stats plus the page's own figures (network, program).
// For tests and scripts: the page itself never calls it on a timer.
export function stats() {
  const net = network.snapshot();
  const extra = {
    retries: (page.loader ? page.loader.retries : 0) + page.pageRetries,
    chunksRefused: page.loader ? page.loader.refused : 0,
    requestLog: page.loader ? page.loader.log : [], // what the chunk loader decided (web/loader.js)
    programBytesReceived: page.programBytes,
    programBytesTotal: page.programTotal,
  };
  if (!viewerReady()) return { state: page.state, error: page.error, notice: net.notice, ...extra };
  const s = JSON.parse(wasmString(page.viewer._ts_stats_json()));
  const r = canvas.getBoundingClientRect();
  for (const key of ['sliderRect', 'levelSliderRect', 'pauseButtonRect', 'sliceSliderRect', 'panelRect'])
    s[key] = { ...s[key], x: s[key].x + r.left, y: s[key].y + r.top };
  return {
    ...s,
    bytesDownloaded: page.loader ? page.loader.networkBytes : 0,
    rateBytesPerSec: net.bytesPerSecond,
    secondsLeft: net.secondsLeft >= 0 ? net.secondsLeft : null,
    paused: net.paused,
    notice: net.notice,
    ...extra,
  };
}

function call(name, ret, types, args) {
  return page.viewer.ccall(name, ret, types, args);
}

// The colour maps the viewer knows, in its order.
function colourMaps() {
  const names = [];
  if (!viewerReady()) return names;
  for (let i = 0; ; i++) {
    const name = wasmString(page.viewer._ts_colour_map_name(i));
    if (!name) return names;
    names.push(name);
  }
}

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
  const c = [0, 1, 2, 3, 4, 5].map((i) => page.viewer._ts_camera_get(i));
  return { target: c.slice(0, 3), distance: c[3], yaw: c[4], pitch: c[5] };
}

function view() {
  return JSON.parse(wasmString(page.viewer._ts_view_json()));
}

function getState() {
  const ready = viewerReady();
  const v = ready ? view() : null;
  return {
    dataset: page.datasetUrl,
    field: ready ? v.field : null,
    isovalue: ready ? v.isovalue : null,
    colourField: ready ? v.colourField : null,
    colourMap: ready ? v.colourMap : null,
    colourRange: ready ? v.colourRange : null,
    slice: ready ? v.slice : null,
    level: ready ? (pendingLevel !== null ? pendingLevel : v.level) : null,
    camera: ready ? readCamera() : null,
    showBoundary: ready ? v.showBoundary : null,
  };
}

// Parts of what the view needs are still to come.
function partsComing() {
  return page.viewer._ts_chunks_missing() > 0;
}

function setLevel(fraction) {
  const f = Number(fraction);
  if (!viewerReady() || !Number.isFinite(f)) return;
  page.viewer._ts_set_level(f);
  pendingLevel = f < 1 && partsComing() ? f : null;
}

// Parts arrive after a link's level was set: the target moves up with them until it is reached.
export function applyPendingLevel() {
  if (pendingLevel === null || !viewerReady()) return;
  page.viewer._ts_set_level(pendingLevel);
  if (!partsComing() || page.viewer._ts_load_state() === 4) pendingLevel = null;
}

export function forgetPendingLevel() {
  pendingLevel = null;
}

function setSlice(slice = {}) {
  if (!viewerReady()) return false;
  const cur = view().slice;
  const on = slice.on !== undefined ? !!slice.on : cur.on;
  const n = Array.isArray(slice.normal) && slice.normal.length === 3 ? slice.normal.map(Number) : cur.normal;
  const offset = slice.offset !== undefined ? Number(slice.offset) : cur.offset;
  if (!n.every(Number.isFinite) || !Number.isFinite(offset)) return false;
  page.viewer._ts_set_slice(on ? 1 : 0, n[0], n[1], n[2], offset);
  return true;
}

function setCamera(c = {}) {
  if (!viewerReady() || !c) return false;
  const cur = readCamera();
  const t = Array.isArray(c.target) && c.target.length === 3 ? c.target.map(Number) : cur.target;
  const v = [...t, c.distance ?? cur.distance, c.yaw ?? cur.yaw, c.pitch ?? cur.pitch].map(Number);
  if (!v.every(Number.isFinite)) return false;
  page.viewer._ts_camera_set(...v);
  return true;
}

function setField(name) {
  return viewerReady() ? call('ts_set_field', 'number', ['string'], [String(name)]) === 1 : false;
}

function setIsovalue(v) {
  if (viewerReady()) page.viewer._ts_set_isovalue(Number(v));
}

function setColourField(name) {
  const n = name === null || name === undefined ? '' : String(name);
  return viewerReady() ? call('ts_set_colour_field', 'number', ['string'], [n]) === 1 : false;
}

function setColourMap(name) {
  return viewerReady() ? call('ts_set_colour_map', 'number', ['string'], [String(name)]) === 1 : false;
}

function setColourRange(lo, hi) {
  if (viewerReady()) page.viewer._ts_set_colour_range(Number(lo), Number(hi));
}

function setViewOption(name, on) {
  if (viewerReady()) call('ts_set_view_option', null, ['string', 'number'], [name, on ? 1 : 0]);
}

// Applies the given parts of a state, in an order that keeps them (the isovalue after its
// field, the colour range after its field). true when the viewer was there to take it.
function setState(p = {}) {
  if (!viewerReady()) return false;
  if (p.field !== undefined && p.field !== null) setField(p.field);
  if (p.isovalue !== undefined && p.isovalue !== null) setIsovalue(p.isovalue);
  if (p.colourField !== undefined) setColourField(p.colourField);
  if (p.colourMap) setColourMap(p.colourMap);
  if (Array.isArray(p.colourRange) && p.colourRange.length === 2) setColourRange(p.colourRange[0], p.colourRange[1]);
  if (p.slice) setSlice(p.slice);
  if (p.level !== undefined && p.level !== null) setLevel(p.level);
  if (p.camera) setCamera(p.camera);
  if (p.showBoundary !== undefined && p.showBoundary !== null) setViewOption('boundary', p.showBoundary);
  syncUrl();
  return true;
}

function stateQuery(st) {
  const q = new URLSearchParams();
  if (st.dataset) q.set('data', st.dataset);
  for (const keep of ['maxMemoryMB', 'stallSeconds', 'antialias', 'fetch']) if (params.get(keep) !== null) q.set(keep, params.get(keep));
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
export function syncUrl() {
  if (!viewerReady() || !page.datasetUrl) return;
  const q = `?${stateQuery(getState()).toString()}`;
  if (q !== location.search) history.replaceState(history.state, '', q);
}

function setLinkNote(note) {
  if (viewerReady()) call('ts_set_link_note', null, ['string'], [note]);
}

export async function copyLink() {
  const l = link();
  if (!page.datasetUrl) {
    setLinkNote('no link: opened from the disk'); // a dataset from the disk has no address others could open
    return null;
  }
  let note = 'link copied';
  try {
    await navigator.clipboard.writeText(l);
  } catch {
    note = 'the link is in the address bar (the clipboard refused)';
  }
  setLinkNote(note);
  return l;
}

// The picture as a PNG Blob: the next frame, read back as soon as it is drawn.
function screenshot() {
  if (!viewerReady() || !page.viewerStarted) return Promise.reject(new Error('the viewer is not running'));
  return new Promise((resolve, reject) => {
    page.viewer.onCapture = () => {
      page.viewer.onCapture = null;
      canvas.toBlob((blob) => (blob ? resolve(blob) : reject(new Error('no picture'))), 'image/png');
    };
    page.viewer._ts_request_capture();
  });
}

export async function saveScreenshot() {
  const blob = await screenshot();
  const a = document.createElement('a');
  const name = (wasmString(page.viewer._ts_name()) || 'tetstream').replace(/[^\w.-]+/g, '_');
  a.download = `${name}-${new Date().toISOString().replace(/[:.]/g, '-')}.png`;
  a.href = URL.createObjectURL(blob);
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 10000);
}

// The view a link asked for, once the manifest is open.
export function applyLinkState() {
  const field = params.get('field');
  if (field !== null && !setField(field))
    console.warn(`tetstream: no field named "${field}" in this dataset; showing "${view().field}"`);
  const iso = params.get('iso');
  if (iso !== null) {
    if (iso.trim() !== '' && Number.isFinite(Number(iso))) setIsovalue(iso);
    else console.warn(`tetstream: ignoring iso=${iso} (not a number)`);
  }
  const colour = params.get('colour');
  if (colour !== null && !setColourField(colour)) console.warn(`tetstream: no field named "${colour}" to colour by`);
  const map = params.get('map');
  if (map !== null && !setColourMap(map)) console.warn(`tetstream: unknown colour map "${map}"`);
  const range = numbers(params.get('range'), 2);
  if (range) setColourRange(range[0], range[1]);
  const slice = numbers(params.get('slice'), 4);
  if (slice) setSlice({ on: true, normal: slice.slice(0, 3), offset: slice[3] });
  const level = numbers(params.get('level'), 1);
  if (level) setLevel(level[0]);
  const cam = numbers(params.get('cam'), 6);
  if (cam) setCamera({ target: cam.slice(0, 3), distance: cam[3], yaw: cam[4], pitch: cam[5] });
  if (params.get('boundary') === '0') setViewOption('boundary', false);
  if (params.get('fetch') === 'all') setFetchEverything(true);
}

// A dataset of nodes (FORMAT.md §1.1): fetch every node (true) or only what the view needs (the
// default). ?fetch=all asks for everything from the start.
function setFetchEverything(on) {
  if (viewerReady()) page.viewer._ts_set_fetch_everything(on ? 1 : 0);
}

window.tetstream = {
  stats,
  setIsovalue,
  setField,
  setColourField,
  setColourMap,
  setColourRange,
  fitColourRange() {
    return viewerReady() ? page.viewer._ts_fit_colour_range() === 1 : false;
  },
  setLevel,
  setSlice,
  setCamera,
  setFetchEverything,
  get colourMaps() {
    return colourMaps();
  },
  openFiles(files) {
    // files: [{path, file}] or File objects with webkitRelativePath (the folder chooser's)
    const list = [...files].map((f) => (f instanceof File ? { path: f.webkitRelativePath || f.name, file: f } : f));
    return openFolder(packedFolder(list));
  },
  getState,
  setState,
  link,
  copyLink,
  screenshot,
  showHelp(on = true) {
    setViewOption('help', on);
  },
  pause() {
    network.setPaused(true);
  },
  resume() {
    network.setPaused(false);
  },
};
