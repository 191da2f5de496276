// Input the page handles itself: touch gestures on the canvas (the viewer gets them as camera
// gestures; mouse, wheel and keys go to the viewer directly), and a packed folder dropped on the
// page or picked with the folder chooser (key O).
import { canvas, page, viewerReady } from './page.js';
import { peekChunks, openDataset, useLocalFiles } from './stream.js';
import { showError } from './status.js';

// ------------------------------------------------------------------ touch
// One finger orbits, two fingers pinch-zoom and pan (pointer events). Touches that start on the
// panel go to the panel (GLFW turns them into mouse input for ImGui); the others are kept from
// GLFW's touch handlers, which would turn them into a mouse drag as well.
const touches = new Map(); // pointerId -> {x, y}
let touchOnCanvas = false;

function running() {
  return viewerReady() && page.viewerStarted;
}

function inPanel(x, y) {
  if (!running()) return false;
  const c = canvas.getBoundingClientRect();
  const [rx, ry, rw, rh] = [0, 1, 2, 3].map((i) => page.viewer._ts_panel_rect(i));
  const px = x - c.left, py = y - c.top;
  return px >= rx && px < rx + rw && py >= ry && py < ry + rh;
}

function pinch() {
  const [a, b] = [...touches.values()];
  return { x: 0.5 * (a.x + b.x), y: 0.5 * (a.y + b.y), d: Math.hypot(a.x - b.x, a.y - b.y) };
}

function gesture(kind, dx, dy) {
  if (viewerReady()) page.viewer._ts_camera_gesture(kind, dx, dy);
}

canvas.addEventListener('pointerdown', (e) => {
  if (e.pointerType !== 'touch' || !running()) return;
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
    gesture(0, e.clientX - t.x, e.clientY - t.y);
    t.x = e.clientX;
    t.y = e.clientY;
  } else if (touches.size === 2) {
    const before = pinch();
    t.x = e.clientX;
    t.y = e.clientY;
    const after = pinch();
    gesture(1, after.x - before.x, after.y - before.y);
    if (before.d > 1 && after.d > 1) gesture(2, Math.log(after.d / before.d) / -Math.log(0.88), 0);
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

// ------------------------------------------------------------------ a packed folder
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
export function packedFolder(list) {
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

// What else opening a folder does, set by main.js: the old link's pending level is forgotten
// and the page's updates run.
const folderHooks = { forgetPendingLevel() {}, keepUpdating() {} };
export function setFolderHooks(hooks) {
  Object.assign(folderHooks, hooks);
}

// Opens a packed dataset from local files (a Map path -> File, relative to its folder).
export async function openFolder(files) {
  if (!files || !files.get('manifest.json')) {
    showError('That is not a packed tetstream dataset: drop the folder that holds manifest.json ' +
      '(made by tetstream pack).');
    return false;
  }
  // Which files the folder lacks, before the dataset on show is given up for it.
  const preview = peekChunks(new Uint8Array(await files.get('manifest.json').arrayBuffer()));
  const missing = preview ? preview.names.filter((name) => !files.has(name)) : [];
  if (missing.length) {
    showError(`The folder is incomplete: ${missing[0]}${missing.length > 1 ? ` and ${missing.length - 1} more parts are` : ' is'} missing.`);
    return false;
  }
  useLocalFiles(files);
  folderHooks.forgetPendingLevel();
  document.getElementById('help').style.display = 'none';
  if (location.search) history.replaceState(history.state, '', location.pathname);
  folderHooks.keepUpdating();
  await openDataset(new URL(URL.createObjectURL(files.get('manifest.json'))), 'while opening the folder');
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
  filesFromDrop(e.dataTransfer).then(openFolder, (err) => showError(`The dropped folder could not be read: ${err.message}`));
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
    openFolder(packedFolder(list));
  });
}
