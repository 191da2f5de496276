// Fetching over real networks: whole files with byte progress, a stall timer, errors sorted into
// "try again" and "stop", and the backoff between tries. No retry loop lives here; callers
// decide (the chunk loader retries a chunk for as long as the link is down, the page's own
// files a few times).

// A request that receives no byte for this long is abandoned and tried again. 10 s: long enough
// for a slow server to start sending a 256 KB chunk over a bad mobile link, short enough that a
// dead connection (no RST, e.g. a laptop changing networks) is noticed. ?stallSeconds= in the
// page's URL overrides it (tests).
export const STALL_SECONDS = 10;

// Backoff between tries: 1 s doubling to 30 s, each delay drawn from its upper half (jitter,
// so that many viewers behind one failed server do not come back in step).
export const RETRY_BASE_MS = 1000;
export const RETRY_CAP_MS = 30000;

export function retryDelayMs(failures, retryAfterMs = 0) {
  const full = Math.min(RETRY_CAP_MS, RETRY_BASE_MS * 2 ** Math.max(0, failures - 1));
  const jittered = full / 2 + (Math.random() * full) / 2;
  return Math.min(RETRY_CAP_MS, Math.max(jittered, retryAfterMs));
}

// kind: 'network' (no answer, connection lost), 'stall' (no byte for the stall time), 'http'
// (an error status), 'aborted' (the caller cancelled). transient: trying again may help.
export class FetchError extends Error {
  constructor(message, { kind, status = 0, transient = false, retryAfterMs = 0 } = {}) {
    super(message);
    this.kind = kind;
    this.status = status;
    this.transient = transient;
    this.retryAfterMs = retryAfterMs;
  }
}

// 5xx, 408 (timeout) and 429 (too many requests) may pass; any other status will not.
export function httpError(response) {
  const { status } = response;
  const transient = status >= 500 || status === 408 || status === 429;
  const reason = status === 404 ? 'not found' : response.statusText || (transient ? 'server error' : 'refused');
  let retryAfterMs = 0;
  const after = Number(response.headers.get('Retry-After'));
  if (Number.isFinite(after) && after > 0) retryAfterMs = Math.min(RETRY_CAP_MS, after * 1000);
  return new FetchError(`HTTP ${status} (${reason})`, { kind: 'http', status, transient, retryAfterMs });
}

// Fetches a whole file. onProgress(n) is called with each piece's byte count as it arrives.
// `limit`: stop reading past this many bytes (the caller's size check then refuses the file).
// `response`: an already started fetch (a Promise of a Response) to use instead of a new one,
// with `abortResponse` to cancel it. Throws FetchError.
export async function fetchBytes(url, { signal, stallMs = STALL_SECONDS * 1000, limit = Infinity, cache = 'default',
  onProgress = () => {}, response: started = null, abortResponse = null } = {}) {
  const controller = new AbortController();
  let stalled = false;
  let timer = 0;
  const stop = () => {
    controller.abort();
    if (abortResponse) abortResponse();
  };
  const arm = () => {
    clearTimeout(timer);
    timer = setTimeout(() => {
      stalled = true;
      stop();
    }, stallMs);
  };
  const onAbort = () => stop();
  if (signal) {
    if (signal.aborted) throw new FetchError('cancelled', { kind: 'aborted' });
    signal.addEventListener('abort', onAbort);
  }
  arm();
  try {
    const response = await (started || fetch(url, { signal: controller.signal, cache }));
    if (!response.ok) {
      response.body?.cancel().catch(() => {});
      throw httpError(response);
    }
    arm();
    const reader = response.body.getReader();
    const parts = [];
    let received = 0;
    for (;;) {
      const step = await reader.read();
      if (step.done) break;
      arm();
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
  } catch (e) {
    if (signal && signal.aborted) throw new FetchError('cancelled', { kind: 'aborted' });
    if (stalled) throw new FetchError(`no data for ${Math.round(stallMs / 1000)} s`, { kind: 'stall', transient: true });
    if (e instanceof FetchError) throw e;
    // fetch() and reader.read() reject with a TypeError for every network failure: refused,
    // reset, cut off mid-body, DNS, and also a cross-origin answer without CORS headers.
    throw new FetchError('connection lost', { kind: 'network', transient: true });
  } finally {
    clearTimeout(timer);
    if (signal) signal.removeEventListener('abort', onAbort);
  }
}

// Passes a Response's body through, counting bytes and watching for stalls, for consumers that
// read the body themselves (WebAssembly.instantiateStreaming). The returned Response carries
// `type`; a stall, a broken connection or a cancelled `signal` errors the stream, which rejects
// the consumer (with its own error type: onError(FetchError) tells what happened).
export function countingResponse(response, { type, onProgress, onEnd = () => {}, onError = () => {}, stallMs = STALL_SECONDS * 1000, signal }) {
  const reader = response.body.getReader();
  let timer = 0;
  let controller = null;
  const fail = (error) => {
    clearTimeout(timer);
    onError(error);
    reader.cancel().catch(() => {});
    try {
      controller.error(error);
    } catch { /* already closed */ }
  };
  const arm = () => {
    clearTimeout(timer);
    timer = setTimeout(() => fail(new FetchError(`no data for ${Math.round(stallMs / 1000)} s`,
      { kind: 'stall', transient: true })), stallMs);
  };
  const body = new ReadableStream({
    start(ctl) {
      controller = ctl;
      if (signal) signal.addEventListener('abort', () => fail(new FetchError('cancelled', { kind: 'aborted' })));
      arm();
    },
    async pull(ctl) {
      let step;
      try {
        step = await reader.read();
      } catch {
        fail(new FetchError('connection lost', { kind: 'network', transient: true }));
        return;
      }
      if (step.done) {
        clearTimeout(timer);
        ctl.close();
        onEnd();
        return;
      }
      arm();
      onProgress(step.value.length);
      ctl.enqueue(step.value);
    },
    cancel() {
      clearTimeout(timer);
      return reader.cancel();
    },
  });
  return new Response(body, { headers: { 'Content-Type': type } });
}

// "4 s", "under a second", "2 min"
export function seconds(ms) {
  if (ms < 1000) return 'a moment';
  const s = Math.ceil(ms / 1000);
  return s < 90 ? `${s} s` : `${Math.round(s / 60)} min`;
}
