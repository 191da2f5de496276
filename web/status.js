// The status line under the canvas (the panel has the details): one bar for every byte the page
// downloads (the program, then the dataset's parts), what is happening in words, and errors.
// It reads the page's own figures and a few typed getters of the viewer, never stats().
import { seconds } from './net.js';
import { formatBytes, page, stallMs, viewerReady, wasmString } from './page.js';

const statusBox = document.getElementById('status');
const statusText = document.getElementById('status-text');
const statusProgram = document.getElementById('status-program');
const statusFill = document.getElementById('status-fill');

// The viewer's load states by ts_load_state()'s number (docs/js-api.md).
const STATES = ['idle', 'loading', 'streaming', 'complete', 'error'];

// bar: [program, dataset], each a fraction of the whole bar (everything the page downloads).
export function showStatus(text, bar, kind = '') {
  statusBox.className = kind;
  statusText.textContent = text;
  if (!bar) return;
  const percent = (f) => `${(100 * Math.min(1, Math.max(0, f))).toFixed(1)}%`;
  statusProgram.style.width = percent(bar[0]);
  statusFill.style.width = percent(Math.min(bar[1], 1 - bar[0]));
}

export function showError(text) {
  showStatus(text, undefined, 'error');
}

export function hideStatus() {
  statusBox.className = 'done';
}

function capitalized(s) {
  return s ? s[0].toUpperCase() + s.slice(1) : s;
}

// A page file being fetched again, or the chunk loader's notice.
export function noticeText() {
  if (page.loader) return page.loader.notice();
  const r = page.retry;
  if (!r) return '';
  const cause = !navigator.onLine ? 'You are offline' : r.error.kind === 'network' ? 'Connection lost'
    : r.error.kind === 'stall' ? `No answer for ${Math.round(stallMs / 1000)} s`
      : r.error.kind === 'damaged' ? `${capitalized(r.what)} arrived damaged` : `The server answered ${r.error.message}`;
  return r.at ? `${cause}: retrying ${r.what} in ${seconds(r.at - performance.now())}.`
    : `${cause}: retrying ${r.what} now (attempt ${r.failures + 1}).`;
}

// What the viewer says, through its typed getters; null before it runs.
function viewerStatus() {
  if (!viewerReady()) return null;
  const v = page.viewer;
  return {
    state: STATES[v._ts_load_state()] || 'error',
    error: wasmString(v._ts_error()),
    name: wasmString(v._ts_name()),
    chunksReceived: v._ts_chunks_received(),
    chunksTotal: v._ts_chunk_count(),
    chunksAllowed: v._ts_chunks_allowed(),
    level: v._ts_level(),
    contextLost: v._ts_context_lost() === 1,
  };
}

// The line and its bar, from what the page and the viewer know now (four times a second).
// network: stream.js's (passed in, since streaming itself writes to this line).
export function updateStatus(network) {
  if (page.state === 'idle' || page.aborted) return;
  const s = viewerStatus();
  if (s && s.state === 'error') {
    if (page.loader) page.loader.stop();
    if (statusText.textContent !== s.error) showError(s.error);
    return;
  }
  if (page.state === 'error') return;
  const net = network.snapshot();
  // One bar for everything from the first byte: the program, then the dataset's parts.
  const have = net.receivedBytes;
  const total = page.programTotal + page.datasetTotal;
  const bar = total ? [Math.min(page.programBytes, page.programTotal) / total, have / total] : [0, 0];
  let text;
  if (!s || s.state === 'idle') {
    const program = page.programTotal ? ` ${Math.round(page.programBytes / 1024)} of ${Math.round(page.programTotal / 1024)} KB`
      : ` ${Math.round(page.programBytes / 1024)} KB`;
    text = `Loading the viewer:${program}…`;
  } else {
    const name = s.name || 'Dataset';
    const rate = net.bytesPerSecond > 0 ? `, ${formatBytes(net.bytesPerSecond)}/s` : '';
    const left = net.secondsLeft >= 1 ? `, about ${seconds(1000 * net.secondsLeft)} left`
      : net.secondsLeft > 0 ? ', less than a second left' : '';
    if (s.state === 'loading') {
      text = `Loading ${name}: ${formatBytes(have)} of ${formatBytes(page.datasetTotal)}${rate}…`;
    } else if (s.state === 'streaming' && s.chunksReceived < s.chunksAllowed) {
      text = `${name}: ${s.chunksReceived} parts, ${formatBytes(have)} of ` +
        `${formatBytes(page.datasetTotal)}${net.paused ? ' (paused)' : `${rate}${left}`}; level ${(100 * s.level).toFixed(1)}%`;
    } else if (s.chunksReceived < s.chunksTotal) {
      // A dataset of nodes: what the view needs is in (FORMAT.md §1.1).
      text = `${name}: ${s.chunksReceived} of ${s.chunksTotal} parts, ${formatBytes(have)} of ` +
        `${formatBytes(network.datasetBytes())}: all this view needs; level ${(100 * s.level).toFixed(1)}%`;
    } else {
      text = `${name}: all ${s.chunksTotal} parts, ${formatBytes(network.datasetBytes())}; level ${(100 * s.level).toFixed(1)}%`;
    }
  }
  if (s && s.contextLost) {
    return showStatus('The browser took the graphics context away (a GPU reset or switch): the view comes back ' +
      'when it gives it back; loading goes on.', bar, 'warn');
  }
  if (net.notice) return showStatus(net.notice, bar, 'warn');
  showStatus(text, bar, s && s.state === 'complete' ? 'done' : '');
}
