// The page's entry point: reads ?data=URL (a packed dataset's manifest.json; relative, absolute
// or cross-origin with CORS) and streams it into the viewer, or shows how to open one. The URL's
// other parameters and window.tetstream are described in docs/js-api.md.
//   page.js     shared state        program.js  the viewer program
//   stream.js   manifest, chunks and the network's figures
//   refiner.js  the refinement worker (worker.js): chunks and the view to it, updates back
//   api.js      window.tetstream and the view in the URL
//   status.js   the status line     input.js    touch and folder drop
// Imports go one way (none back up): net.js, rate.js, loader.js, page.js; program.js, status.js,
// refiner.js; stream.js; api.js, input.js; this file, which wires the hooks that point back up.
import { applyLinkState, applyPendingLevel, copyLink, forgetPendingLevel, saveScreenshot, syncUrl } from './api.js';
import { setFolderHooks } from './input.js';
import { page, params } from './page.js';
import { updateStatus, hideStatus } from './status.js';
import { fail, network, openDataset, setViewHooks } from './stream.js';

// Four times a second while a dataset is open: the network snapshot to the panel, a link's
// level as its parts arrive, the address bar, the status line.
function update() {
  if (page.state === 'idle' || page.aborted) return;
  network.report();
  applyPendingLevel();
  syncUrl();
  updateStatus(network);
}

let timer = 0;
function keepUpdating() {
  if (!timer) timer = setInterval(update, 250);
}

function showHelp() {
  page.state = 'idle';
  hideStatus();
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
  const data = params.get('data');
  if (!data) return showHelp();
  let manifestUrl;
  try {
    manifestUrl = new URL(data, location.href);
  } catch {
    return fail(`"${data}" is not a valid dataset URL.`);
  }
  addEventListener('online', () => { if (page.loader) page.loader.retryNow(); });
  keepUpdating();
  await openDataset(manifestUrl);
  update();
  if (page.state === 'error' && !page.viewer) {
    clearInterval(timer);
    timer = 0;
  }
}

setViewHooks({ applyLinkState, copyLink, saveScreenshot });
setFolderHooks({ forgetPendingLevel, keepUpdating });
start();
