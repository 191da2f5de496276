// Link simulation for tests and benchmarks (server.mjs plugs it into the project's server): a
// bandwidth cap shared by every response of a server (one token bucket, as a real link is one
// pipe) and a latency before each response's first byte. Both are Transform
// streams that the response body flows through (see tap.mjs), so backpressure holds end to end:
// a throttled response reads its file only as fast as the link lets it out.
import { Transform } from 'node:stream';
import { realClock } from './clock.mjs';

// "10mbit", "500kbit", "2MB", "1.5mbyte", "1.25MB/s", "10Mbps", "64KiB", "1000000" (bytes).
// Upper-case B or "byte" means bytes, "bit" or "bps" means bits; a bare lower-case "b" ("2mb")
// is refused as ambiguous rather than guessed.
const PREFIX = { '': 1, k: 1e3, m: 1e6, g: 1e9, ki: 1024, mi: 1024 ** 2, gi: 1024 ** 3 };

export function parseRate(text) {
  const s = String(text ?? '');
  const m = /^(\d+(?:\.\d+)?|\.\d+)([a-zA-Z]*)(?:\/s)?$/.exec(s);
  const hint = 'write e.g. 10mbit, 500kbit, 2MB or 1.5mbyte (per second)';
  if (!m) throw new Error(`cannot read "${s}"; ${hint}`);
  const value = Number(m[1]);
  const unit = m[2];
  let prefix;
  let bits;
  let u;
  if ((u = /^([kmg]i?)?(bits?|bps)$/i.exec(unit))) { prefix = u[1] || ''; bits = true; }
  else if ((u = /^([kmg]i?)?bytes?$/i.exec(unit))) { prefix = u[1] || ''; bits = false; }
  else if ((u = /^([kKmMgG]i?)?B$/.exec(unit))) { prefix = u[1] || ''; bits = false; }
  else if (unit === '') { prefix = ''; bits = false; }
  else if (/^[kmg]?b$/i.test(unit)) {
    throw new Error(`"${s}" is ambiguous; write ${m[1]}${unit.slice(0, -1)}bit (bits) or ${m[1]}${unit.slice(0, -1).toUpperCase()}B (bytes)`);
  } else throw new Error(`cannot read "${s}"; ${hint}`);
  const factor = PREFIX[prefix.toLowerCase()];
  const bytes = (value * factor) / (bits ? 8 : 1);
  if (!(bytes >= 1)) throw new Error(`"${s}" is below 1 byte per second`);
  return bytes;
}

// "50", "50ms", "0.2s" -> milliseconds.
export function parseMs(text) {
  const m = /^(\d+(?:\.\d+)?)(ms|s)?$/.exec(String(text ?? ''));
  if (!m) throw new Error(`cannot read "${text}"; write milliseconds, e.g. 50 or 50ms or 0.2s`);
  return Number(m[1]) * (m[2] === 's' ? 1000 : 1);
}

// A token bucket kept as a virtual clock: `free` is when the link has sent everything promised
// so far. Reservations are granted in call order, so concurrent responses share the rate fairly
// (piece by piece) and the total never exceeds it. Idle time builds at most `burst` bytes of credit.
export class TokenBucket {
  constructor(bytesPerSec, { burst, clock = realClock } = {}) {
    this.rate = bytesPerSec;
    this.clock = clock;
    // Pieces small enough that several responses interleave smoothly, large enough that timers
    // (about 1 ms resolution) do not dominate: 1/50 s of the link, between 1 KB and 16 KB.
    this.piece = Math.max(1024, Math.min(16384, Math.floor(bytesPerSec / 50)));
    this.burstMs = ((burst ?? this.piece) / bytesPerSec) * 1000;
    this.free = 0;
  }

  // Reserves n bytes of link time; returns how many ms to wait before sending them.
  reserve(n, now = this.clock.now()) {
    this.free = Math.max(this.free, now - this.burstMs) + (n / this.rate) * 1000;
    return Math.max(0, this.free - now);
  }
}

// Paces the bytes through `bucket`: each piece waits for its slot before it is pushed on.
// The callback of _transform is held until the last piece is out, which is what makes the
// writer upstream (the file stream) wait: backpressure, no buffering beyond one chunk.
export class Throttle extends Transform {
  constructor(bucket) {
    super();
    this.bucket = bucket;
    this.abort = new AbortController();
  }

  _transform(chunk, _encoding, callback) {
    this.#send(chunk).then(() => callback(), (e) => callback(e.name === 'AbortError' ? null : e));
  }

  async #send(chunk) {
    for (let at = 0; at < chunk.length; at += this.bucket.piece) {
      const piece = chunk.subarray(at, at + this.bucket.piece);
      const wait = this.bucket.reserve(piece.length);
      if (wait >= 1) await this.bucket.clock.sleep(wait, this.abort.signal);
      this.push(piece);
    }
  }

  _destroy(err, callback) {
    this.abort.abort();
    callback(err);
  }
}

// Holds the first byte (or, for an empty body, the end) for `ms`: one round trip of a real link.
export class Latency extends Transform {
  constructor(ms, clock = realClock) {
    super();
    this.ms = ms;
    this.clock = clock;
    this.waited = false;
    this.abort = new AbortController();
  }

  #wait() {
    if (this.waited) return Promise.resolve();
    this.waited = true;
    return this.clock.sleep(this.ms, this.abort.signal);
  }

  _transform(chunk, _encoding, callback) {
    this.#wait().then(() => callback(null, chunk), () => callback());
  }

  _flush(callback) {
    this.#wait().then(() => callback(), () => callback());
  }

  _destroy(err, callback) {
    this.abort.abort();
    callback(err);
  }
}
