// Streams a packed dataset's chunks: fetched ahead a few at a time, each checked against the
// manifest (size, content hash) before it is handed over, handed over strictly in order. A chunk
// that fails in a way that may pass (connection lost, no data for the stall time, HTTP 5xx,
// 408, 429, damaged bytes) is fetched again after a backoff, bypassing caches; one that cannot
// pass (404 and other 4xx, damaged every time) stops the stream after every chunk before it has
// been handed over, so the viewer keeps the level it reached. Nothing here blocks: every step
// runs in a network callback and takes well under a millisecond (the check hashes in wasm).
//
// The loader may start before the viewer program is ready, from the manifest's chunk names
// alone (the shell checks each against FORMAT.md's file rule first): the base chunk at once,
// more once the program's bytes are in (warm()), so the link is busy while the browser compiles
// the program. attach() then brings the checks and the hand-over; nothing is handed over, or
// kept past the check, before it.
import { fetchBytes, retryDelayMs, seconds, STALL_SECONDS } from './net.js';

// Chunks should arrive one after another, each at the link's full rate: chunks sharing a link
// finish together, so the viewer waits for the whole batch and then gets all of its work at
// once, which it is still applying long after the last byte. So a request starts when the bytes
// still to come of those under way drop below the lead: what the link delivers while a request
// waits for its first byte (measured: rate of finished responses, time to their first byte),
// with a margin, so that the next response starts as the last one ends and the link never idles.
// At most MAX_IN_FLIGHT requests (many small chunks on a long link).
export const MAX_IN_FLIGHT = 6;
export const MIN_LEAD_BYTES = 4 << 10;
export const MAX_LEAD_BYTES = 1 << 20;
export const FIRST_LEAD_BYTES = 256 << 10;  // before anything is measured
export const LEAD_MARGIN = 1.25;
export const STARTUP_SECONDS = 1;
// ... until the base is in: it alone decides when the first surface appears, so it shares the
// link with one more request only (which keeps the link busy while the base's last bytes come).
export const MAX_IN_FLIGHT_BEFORE_BASE = 2;
export const MAX_AHEAD = 12;                // chunks fetched past the next one the viewer needs
export const MAX_AHEAD_BYTES = 64 << 20;    // ... and at most this much held in the page
export const MAX_DAMAGED = 4;               // a chunk damaged this often in a row is broken at the source
export const LOG_LIMIT = 2000;              // entries kept in ChunkLoader.log (the newest)

const grouped = (n) => n.toLocaleString('en-US');

// The network's timing of a finished request (Resource Timing; the project's server and the
// documented nginx config send Timing-Allow-Origin for other origins): time to the first byte
// and transfer time, which a busy main thread does not stretch as it does callback times.
export function networkTiming(url) {
  if (typeof performance === 'undefined' || !performance.getEntriesByName || typeof location === 'undefined') return null;
  const entries = performance.getEntriesByName(new URL(url, location.href).href, 'resource');
  const e = entries[entries.length - 1];
  if (!e || !(e.responseStart > e.startTime) || !(e.responseEnd > e.responseStart)) return null;
  return { firstByteMs: e.responseStart - e.startTime, transferMs: e.responseEnd - e.responseStart };
}

// What the loader waits on: the page's clock and timers (tests give a fake one).
const pageClock = {
  now: () => performance.now(),
  setTimeout: (fn, ms) => setTimeout(fn, ms),
  clearTimeout: (id) => clearTimeout(id),
};

export class ChunkLoader {
  // urls, names (as the manifest gives them, for messages), sizes: per chunk.
  // fail(message): the stream cannot go on (called once, after the chunks before the bad one
  // have been delivered). done(): every allowed chunk delivered, or stopped.
  // check, deliver, allowed: see attach(); given here, the loader is attached from the start.
  // fetch, clock, timing: the network, the clock and timers, and the network's timing of a
  // finished request (net.js fetchBytes, the page's clock, Resource Timing unless given).
  constructor({ urls, names = urls, sizes, allowed = urls.length, stallMs = STALL_SECONDS * 1000, check = null,
    deliver = null, fail, done, fetch = fetchBytes, clock = pageClock, timing = networkTiming }) {
    Object.assign(this, { urls, names, sizes, allowed, stallMs, check, deliver, failed: fail, done });
    Object.assign(this, { fetch, clock, timing });
    this.attached = !!check;
    this.warmed = this.attached;   // before: the program is still downloading, only the base
    this.programNearlyIn = false;  // its last bytes are coming: the first split chunk too
    this.unchecked = new Set();    // arrived before attach()
    this.total = urls.length;
    this.next = 0;                 // next chunk to hand over
    this.inFlight = new Map();     // index -> { controller, received }
    this.arrived = new Map();      // index -> bytes, checked, waiting for an earlier chunk
    this.waiting = new Map();      // index -> { at, timer }: to be fetched again at time `at`
    this.trouble = new Map();      // index -> { failures, damaged, last }: chunks that failed
    this.deliveredBytes = 0;
    this.networkBytes = 0;         // off the wire, failed and aborted requests included
    this.retries = 0;              // requests made again after a failure
    this.refused = 0;              // responses the check refused (never handed over)
    this.rate = 0;                 // bytes/s of the last finished response, first byte to last
    this.firstByteMs = 0;          // time to the first byte of the last response that had one
    this.paused = false;
    this.stopped = false;
    this.failure = null;           // { index, message }: the first chunk that cannot be had
    // What the loader decided, in order (the newest LOG_LIMIT entries), for the panel's
    // diagnostics and for tests, which check decisions instead of timing them:
    //   { event: 'request', index, reason, cause?, attempt, others, outstanding, lead, attached }
    //     reason: 'first'; 'retry' (its backoff ran out; cause: what failed); 'online' (the
    //     browser's online event ended its backoff); 'resume' (dropped by a pause). others: the
    //     chunks under way then, outstanding: their bytes still to come, lead: see lead().
    //   { event: 'response', index, bytes }   { event: 'failure', index, cause, transient }
    //   { event: 'refused', index, cause }    { event: 'backoff', index, delayMs }
    //   { event: 'online', waiting }          { event: 'pause' }   { event: 'resume' }
    // Each has `seq`, its place in the whole log.
    this.log = [];
    this.logged = 0;
    this.wokenOnline = new Set();  // waiting chunks the online event sent off
    this.dropped = new Set();      // chunks a pause dropped while under way
  }

  note(entry) {
    this.log.push({ seq: this.logged++, ...entry });
    if (this.log.length > LOG_LIMIT) this.log.splice(0, this.log.length - LOG_LIMIT);
  }

  part(i) {
    return `part ${i + 1} of ${this.total}`;
  }

  // The viewer is ready. check(i, bytes): null when the bytes are chunk i, else what is wrong in
  // words. deliver(i, bytes): hands chunk i over; false = the viewer stopped (it says why
  // itself). allowed: chunks to fetch (fewer than urls.length when memory is short).
  attach({ check, deliver, allowed = this.urls.length }) {
    Object.assign(this, { check, deliver, allowed, attached: true, warmed: true });
    for (const [j, e] of [...this.inFlight]) {
      if (j >= allowed) {
        e.controller.abort();
        this.inFlight.delete(j);
      }
    }
    for (const j of [...this.arrived.keys()]) if (j >= allowed) this.arrived.delete(j);
    for (const i of [...this.unchecked].sort((a, b) => a - b)) {
      this.unchecked.delete(i);
      if (this.stopped) return;
      if (this.failure && i > this.failure.index) this.arrived.delete(i);
      else if (this.arrived.has(i)) this.accept(i, this.arrived.get(i));
    }
    this.deliverReady();
    this.pump();
  }

  // The program's bytes are in: the link is free for more than the base.
  warm() {
    this.warmed = true;
    this.pump();
  }

  // The program's last bytes are coming: one more request (the first split chunk, the smallest)
  // now keeps the link busy over the round trip after them, and takes little from the program
  // the first surface waits for.
  nearlyWarm() {
    if (this.warmed || this.programNearlyIn) return;
    this.programNearlyIn = true;
    this.pump();
  }

  // Link rate and time to first byte from a finished response: the network's own timing when
  // the browser gives it, else callback times (the least time to a first byte seen, as a busy
  // main thread only adds to it).
  measure(i, entry, bytes) {
    const t = this.timing(this.urls[i]);
    const firstByteMs = t ? t.firstByteMs : entry.firstByte - entry.start;
    const transferMs = t ? t.transferMs : this.clock.now() - entry.firstByte;
    if (entry.firstByte && firstByteMs > 0) this.firstByteMs = t || !this.firstByteMs ? firstByteMs : Math.min(this.firstByteMs, firstByteMs);
    if (transferMs > 0 && bytes >= MIN_LEAD_BYTES) this.rate = bytes / (transferMs / 1000);
  }

  // Bytes still to come of the requests under way below which the next one starts (see above).
  lead() {
    if (!this.rate || !this.firstByteMs) return FIRST_LEAD_BYTES;
    // Until the viewer is attached its program is starting, and the main thread may run no
    // callbacks for a while (compiling, the base, the first surface: 0.3 s to over 1 s here):
    // requests not opened before would wait with the link idle.
    const seconds = this.attached ? this.firstByteMs / 1000 * LEAD_MARGIN : STARTUP_SECONDS;
    return Math.min(MAX_LEAD_BYTES, Math.max(MIN_LEAD_BYTES, this.rate * seconds));
  }

  pump() {
    if (this.paused || this.stopped || this.failure) return;
    const end = Math.min(this.allowed, this.warmed ? this.next + MAX_AHEAD : this.programNearlyIn ? 2 : 1);
    let ahead = 0, outstanding = 0;
    for (const b of this.arrived.values()) ahead += b.length;
    for (const [j, e] of this.inFlight) {
      ahead += this.sizes[j];
      outstanding += Math.max(0, this.sizes[j] - e.received);
    }
    // Once the program is in, the base has at most a few round trips left: open the other
    // requests now, as the main thread may be busy starting the program for a while (no
    // callbacks run then, so requests not opened before it would wait).
    const limit = this.next === 0 && !this.arrived.has(0) && !this.warmed ? MAX_IN_FLIGHT_BEFORE_BASE : MAX_IN_FLIGHT;
    for (let i = this.next; i < end && this.inFlight.size < limit; i++) {
      if (this.arrived.has(i) || this.inFlight.has(i) || this.waiting.has(i)) continue;
      if (i > this.next && ahead + this.sizes[i] > MAX_AHEAD_BYTES) break;
      if (this.inFlight.size > 0 && outstanding >= this.lead()) break;
      this.fetchChunk(i, outstanding);
      ahead += this.sizes[i];
      outstanding += this.sizes[i];
    }
  }

  // outstanding: bytes still to come of the requests under way (for the log).
  fetchChunk(i, outstanding = 0) {
    const trouble = this.trouble.get(i);
    let reason = 'first';
    if (this.dropped.delete(i)) reason = 'resume';
    else if (this.wokenOnline.delete(i)) reason = 'online';
    else if (trouble) reason = 'retry';
    this.note({
      event: 'request', index: i, reason, ...(trouble ? { cause: causeOf(trouble.last) } : {}),
      attempt: trouble ? trouble.failures + 1 : 1, others: [...this.inFlight.keys()], outstanding,
      lead: this.lead(), attached: this.attached,
    });
    const entry = { controller: new AbortController(), received: 0, start: this.clock.now(), firstByte: 0 };
    this.inFlight.set(i, entry);
    if (trouble) this.retries++;
    this.fetch(this.urls[i], {
      signal: entry.controller.signal,
      stallMs: this.stallMs,
      limit: this.sizes[i],
      // After a failure, past any cache: a proxy or the browser may hold the damaged copy.
      cache: trouble ? 'reload' : 'default',
      onProgress: (n) => {
        if (!entry.firstByte) entry.firstByte = this.clock.now();
        entry.received += n;
        this.networkBytes += n;
        if (this.inFlight.size < MAX_IN_FLIGHT) this.pump(); // outstanding bytes dropped
      },
    }).then((bytes) => {
      if (this.inFlight.get(i) !== entry) return; // dropped meanwhile (pause, stop)
      this.inFlight.delete(i);
      this.note({ event: 'response', index: i, bytes: bytes.length });
      this.measure(i, entry, bytes.length);
      if (this.attached) {
        this.accept(i, bytes);
      } else {
        this.arrived.set(i, bytes);
        this.unchecked.add(i);
      }
      this.pump();
    }, (e) => {
      if (this.inFlight.get(i) === entry) this.inFlight.delete(i);
      if (e.kind === 'aborted' || this.stopped) return;
      this.note({ event: 'failure', index: i, cause: causeOf(e), transient: !!e.transient });
      if (e.transient) this.retryLater(i, e);
      else this.failAt(i, `Could not download ${this.part(i)} of the dataset (${this.names[i]}): ${e.message}.`);
      this.pump();
    });
  }

  // Checks chunk i; keeps it for the hand-over, or fetches it again when damaged.
  accept(i, bytes) {
    this.arrived.delete(i);
    let damage;
    try {
      damage = this.check(i, bytes);
    } catch (e) { // the viewer could not even look at it (no memory): stop here
      this.failAt(i, e.message);
      return;
    }
    if (damage) {
      this.refused++;
      this.note({ event: 'refused', index: i, cause: 'damaged' });
      this.retryLater(i, { kind: 'damaged', message: damage, transient: true });
    } else {
      this.trouble.delete(i);
      this.arrived.set(i, bytes);
      this.deliverReady();
    }
  }

  retryLater(i, error) {
    const t = this.trouble.get(i) || { failures: 0, damaged: 0, last: null };
    t.failures++;
    t.damaged = error.kind === 'damaged' ? t.damaged + 1 : 0;
    t.last = error;
    this.trouble.set(i, t);
    if (t.damaged >= MAX_DAMAGED) {
      this.failAt(i, `${this.part(i)[0].toUpperCase()}${this.part(i).slice(1)} of the dataset arrived damaged ` +
        `${t.damaged} times in a row (${error.message}): the copy on the server does not match its manifest.`);
      return;
    }
    const delay = retryDelayMs(t.failures, error.retryAfterMs);
    this.note({ event: 'backoff', index: i, delayMs: delay });
    const timer = this.clock.setTimeout(() => {
      this.waiting.delete(i);
      this.pump();
    }, delay);
    this.waiting.set(i, { at: this.clock.now() + delay, timer });
  }

  // The link is back (the browser's `online` event): every waiting chunk goes now.
  retryNow() {
    this.note({ event: 'online', waiting: [...this.waiting.keys()] });
    for (const [i, w] of this.waiting) {
      this.clock.clearTimeout(w.timer);
      this.waiting.delete(i);
      this.wokenOnline.add(i);
    }
    this.pump();
  }

  // Chunk i cannot be had: the chunks before it that are still coming are delivered first,
  // then the failure is reported. Nothing after it is fetched any more.
  failAt(i, message) {
    if (this.failure && this.failure.index <= i) return;
    this.failure = { index: i, message };
    for (const [j, e] of [...this.inFlight]) {
      if (j > i) {
        e.controller.abort();
        this.inFlight.delete(j);
      }
    }
    for (const [j, w] of [...this.waiting]) {
      if (j >= i) {
        this.clock.clearTimeout(w.timer);
        this.waiting.delete(j);
      }
    }
    for (const j of [...this.arrived.keys()]) {
      if (j > i) {
        this.arrived.delete(j);
        this.unchecked.delete(j);
      }
    }
    this.reportFailure();
  }

  reportFailure() {
    if (!this.failure || this.next < this.failure.index || this.stopped) return;
    if (!this.attached && this.failure.index > 0) return; // the chunks before it first
    const { index, message } = this.failure;
    this.stop();
    this.failed(index > 0 ? `${message} Showing the last complete level.` : message);
  }

  deliverReady() {
    if (!this.attached) return;
    while (!this.stopped && this.arrived.has(this.next) && !this.unchecked.has(this.next)) {
      const i = this.next;
      const bytes = this.arrived.get(i);
      this.arrived.delete(i);
      let accepted;
      try {
        accepted = this.deliver(i, bytes);
      } catch (e) {
        this.stop();
        this.failed(e.message);
        return;
      }
      if (!accepted) {
        this.stop();
        return;
      }
      this.deliveredBytes += bytes.length;
      this.next++;
    }
    if (this.next >= this.allowed) this.stop();
    this.reportFailure();
  }

  // Bytes of the dataset in hand: delivered, arrived and partly downloaded.
  haveBytes() {
    let have = this.deliveredBytes;
    for (const b of this.arrived.values()) have += b.length;
    for (const e of this.inFlight.values()) have += e.received;
    return have;
  }

  // What the network side is doing, in plain words, or '' when all is well: the earliest chunk
  // that failed and is waiting or being fetched again.
  notice(now = this.clock.now()) {
    if (this.stopped || this.failure || this.paused || !this.trouble.size) return '';
    const i = Math.min(...this.trouble.keys());
    const { last, failures } = this.trouble.get(i);
    const what = this.part(i);
    let cause;
    if (!navigator.onLine) cause = 'You are offline';
    else if (last.kind === 'network') cause = 'Connection lost';
    else if (last.kind === 'stall') cause = `No data for ${Math.round(this.stallMs / 1000)} s`;
    else if (last.kind === 'damaged') cause = `${what[0].toUpperCase()}${what.slice(1)} arrived damaged (${last.message})`;
    else cause = `The server answered ${last.message}`;
    const w = this.waiting.get(i);
    if (w) return `${cause}: retrying ${what} in ${seconds(w.at - now)}.`;
    return `${cause}: retrying ${what} now (attempt ${failures + 1}).`;
  }

  // Pausing stops the network at once: requests under way are dropped (and fetched again on
  // resume, with their failure counts kept); what arrived completely is kept.
  setPaused(paused) {
    this.paused = paused;
    this.note({ event: paused ? 'pause' : 'resume' });
    if (paused) {
      for (const [i, e] of this.inFlight) {
        e.controller.abort();
        this.dropped.add(i);
      }
      this.inFlight.clear();
      for (const w of this.waiting.values()) this.clock.clearTimeout(w.timer);
      this.waiting.clear();
    } else {
      this.pump();
    }
  }

  stop() {
    if (this.stopped) return;
    this.stopped = true;
    for (const e of this.inFlight.values()) e.controller.abort();
    this.inFlight.clear();
    for (const w of this.waiting.values()) this.clock.clearTimeout(w.timer);
    this.waiting.clear();
    this.done();
  }
}

// What failed, for the log: 'http 503', 'network', 'stall', 'damaged'.
function causeOf(e) {
  return e.kind === 'http' ? `http ${e.status}` : e.kind;
}

// "2,345 of 16,384 bytes" / "its content does not match the manifest's hash", for check().
export function damageText(code, got, expected) {
  if (code === 2) return `${grouped(got)} bytes instead of ${grouped(expected)}`;
  if (code === 3) return "its content does not match the manifest's hash";
  return 'not a part of this dataset';
}
