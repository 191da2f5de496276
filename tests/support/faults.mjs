// Fault injection for tests: make chosen requests fail the way real networks and servers fail
// (server.mjs plugs it into the project's server).
//
//   { match, kind, status, times, delayMs, afterBytes }
//   match       string (a substring of the request path) or RegExp (tested against the path)
//   kind        'status'    answer `status` (default 503) instead of the file
//               'truncate'  send the first half of the body with a Content-Length of that half:
//                           a short response that looks successful
//               'corrupt'   same length, one bit flipped in every 1000th byte of the second half
//               'drop'      send `afterBytes` (default half the body), wait `delayMs` (default 0),
//                           then destroy the socket: the client sees the connection die mid-body
//               'slow'      send the headers, then hold the body for `delayMs` (default 2000)
//               'hold'      send the headers and the first `afterBytes` (default 0) of the body,
//                           then hold the rest until the test calls rule.release(); rule.held
//                           counts the responses that got there, rule.whenHeld(n) waits for n
//   times       how many matching GET requests are affected (default: every one); counts down
//
// Only GET requests are affected (not HEAD, not CORS preflights). The first fault whose `match`
// fits and whose `times` is not used up applies; the list may be changed while the server runs.
import { Transform } from 'node:stream';
import { realClock } from './clock.mjs';

const KINDS = new Set(['status', 'truncate', 'corrupt', 'drop', 'slow', 'hold']);

// Checks a fault list (from code or from serve_link.mjs --fault JSON) and fills in defaults; throws on mistakes.
export function normalizeFaults(list) {
  if (!Array.isArray(list)) throw new Error('faults must be an array');
  return list.map((f, i) => {
    const where = `fault ${i + 1}`;
    if (!f || typeof f !== 'object') throw new Error(`${where}: not an object`);
    let { match } = f;
    if (match === undefined && typeof f.regexp === 'string') match = new RegExp(f.regexp);
    if (typeof match !== 'string' && !(match instanceof RegExp)) {
      throw new Error(`${where}: "match" must be a string or RegExp (or give "regexp" as a string)`);
    }
    if (!KINDS.has(f.kind)) throw new Error(`${where}: "kind" must be one of ${[...KINDS].join(', ')}`);
    const num = (name, ok) => {
      if (f[name] === undefined) return undefined;
      if (typeof f[name] !== 'number' || !ok(f[name])) throw new Error(`${where}: bad "${name}": ${f[name]}`);
      return f[name];
    };
    const out = {
      match,
      kind: f.kind,
      status: num('status', (v) => Number.isInteger(v) && v >= 100 && v <= 599) ?? 503,
      times: num('times', (v) => (Number.isInteger(v) && v >= 0) || v === Infinity) ?? Infinity,
      delayMs: num('delayMs', (v) => v >= 0),
      afterBytes: num('afterBytes', (v) => Number.isInteger(v) && v >= 0),
    };
    out.hits = 0; // how many requests this fault has affected
    if (out.kind === 'hold') addGate(out);
    return out;
  });
}

// A 'hold' rule's gate: responses wait on `opened` until release(); whenHeld(n) resolves once n
// responses have reached it, so a test acts on an event, not after a guessed time.
function addGate(rule) {
  let open;
  rule.opened = new Promise((resolve) => { open = resolve; });
  rule.release = () => open();
  rule.held = 0;
  const watchers = [];
  rule.arrive = () => {
    rule.held += 1;
    for (const w of watchers.filter((x) => x.n <= rule.held)) {
      watchers.splice(watchers.indexOf(w), 1);
      w.resolve();
    }
  };
  rule.whenHeld = (n = 1) => (rule.held >= n ? Promise.resolve() : new Promise((resolve) => watchers.push({ n, resolve })));
}

// Finds the fault for a request path and uses up one of its `times`.
export function takeFault(faults, method, pathname) {
  if (method !== 'GET' || !faults) return null;
  for (const f of faults) {
    const fits = typeof f.match === 'string' ? pathname.includes(f.match) : f.match.test(pathname);
    if (!fits || !(f.times > 0)) continue;
    f.times -= 1;
    f.hits += 1;
    return f;
  }
  return null;
}

// 'status' answers at once, without touching the file.
export function answerStatus(res, fault) {
  const body = `fault injected: ${fault.status}\n`;
  res.statusCode = fault.status;
  res.setHeader('Content-Type', 'text/plain; charset=utf-8');
  res.setHeader('Content-Length', Buffer.byteLength(body));
  res.setHeader('Cache-Control', 'no-store');
  res.end(body);
}

// The body-changing faults, as the last stream before the socket (see tap.mjs). The declared
// length is read from the response when the first byte arrives, so it works for 200 and 206.
export class FaultStream extends Transform {
  constructor(fault, res, clock = realClock) {
    super();
    this.fault = fault;
    this.res = res;
    this.clock = clock;
    this.offset = 0; // body bytes seen so far
    this.total = null;
    this.stopped = false;
    this.abort = new AbortController();
  }

  _transform(chunk, _encoding, callback) {
    if (this.total === null) this.#start();
    const begin = this.offset;
    this.offset += chunk.length;
    if (this.stopped) return callback();
    const { kind } = this.fault;
    if (kind === 'truncate' || kind === 'drop') {
      const keep = Math.max(0, Math.min(chunk.length, this.limit - begin));
      if (keep > 0) this.push(chunk.subarray(0, keep));
      if (begin + keep >= this.limit) {
        this.stopped = true;
        if (kind === 'drop') this.#drop();
      }
      return callback();
    }
    if (kind === 'corrupt') return callback(null, this.#flip(chunk, begin));
    if (kind === 'hold' && !this.released) {
      const keep = Math.max(0, Math.min(chunk.length, this.limit - begin));
      if (keep > 0) this.push(chunk.subarray(0, keep));
      if (begin + chunk.length < this.limit) return callback();
      return this.#hold().then(() => callback(null, keep < chunk.length ? chunk.subarray(keep) : undefined), () => callback());
    }
    if (kind === 'slow' && begin === 0) {
      this.res.flushHeaders();
      return this.clock.sleep(this.fault.delayMs ?? 2000, this.abort.signal)
        .then(() => callback(null, chunk), () => callback());
    }
    callback(null, chunk);
  }

  _flush(callback) {
    if (this.fault.kind === 'hold' && !this.released) {
      return this.#hold().then(() => callback(), () => callback());
    }
    // A dropped response never ends cleanly: the socket dies instead (an empty body drops too).
    if (this.fault.kind === 'drop') {
      if (!this.stopped) {
        this.stopped = true;
        this.#drop();
      }
      return; // the stream is destroyed with the response
    }
    callback();
  }

  #start() {
    const declared = Number(this.res.getHeader('Content-Length'));
    this.total = Number.isFinite(declared) ? declared : Infinity;
    const half = Number.isFinite(this.total) ? Math.floor(this.total / 2) : 65536;
    if (this.fault.kind === 'truncate') {
      this.limit = half;
      if (!this.res.headersSent) this.res.setHeader('Content-Length', half);
    } else if (this.fault.kind === 'drop') {
      this.limit = this.fault.afterBytes ?? half;
    } else if (this.fault.kind === 'hold') {
      this.limit = this.fault.afterBytes ?? 0;
    }
    this.mid = Number.isFinite(this.total) ? Math.floor(this.total / 2) : 0;
  }

  #flip(chunk, begin) {
    const out = Buffer.from(chunk); // a copy: the file stream's buffer is not ours to change
    for (let p = Math.max(begin, this.mid); p < begin + chunk.length; p++) {
      if ((p - this.mid) % 1000 === 0) out[p - begin] ^= 0x10;
    }
    return out;
  }

  // Sends the headers (and what was pushed), tells the rule, waits for its release.
  async #hold() {
    if (this.total === null) this.#start();
    this.res.flushHeaders();
    this.fault.arrive();
    await new Promise((resolve, reject) => {
      this.abort.signal.addEventListener('abort', reject, { once: true });
      this.fault.opened.then(resolve);
    });
    this.released = true;
  }

  // Lets what was sent reach the kernel, waits delayMs, then kills the connection.
  async #drop() {
    try {
      await new Promise((resolve) => setImmediate(resolve));
      const socket = this.res.socket;
      if (socket && socket.writableLength > 0) await new Promise((resolve) => socket.once('drain', resolve));
      if (this.fault.delayMs) await this.clock.sleep(this.fault.delayMs, this.abort.signal);
      this.res.dropped = true;
      (this.res.socket ?? socket)?.destroy();
    } catch { /* the client left first */ }
  }

  _destroy(err, callback) {
    this.abort.abort();
    callback(err);
  }
}
