// Download throughput over a sliding window, from cumulative byte counts and their times (ms).
// The page owns the network: this rate and the time left go to the viewer's panel in one
// snapshot (stream.js, ts_set_network) and to stats().
const SAMPLES = 40;        // at >= 100 ms apart: 4 s of history
const MIN_SPACING_MS = 100;

export class RateMeter {
  constructor() {
    this.reset();
  }

  reset() {
    this.t = [];
    this.bytes = [];
    this.latestT = 0;
    this.latestBytes = 0;
  }

  // totalBytes: everything received so far, at nowMs.
  add(nowMs, totalBytes) {
    this.latestT = nowMs;
    this.latestBytes = totalBytes;
    const n = this.t.length;
    if (n > 0 && nowMs - this.t[n - 1] < MIN_SPACING_MS) return;
    this.t.push(nowMs);
    this.bytes.push(totalBytes);
    if (this.t.length > SAMPLES) {
      this.t.shift();
      this.bytes.shift();
    }
  }

  // Bytes per second over the last windowMs: the oldest sample inside the window is the
  // reference, bytes since then over time since then. 0 when nothing came in the window.
  bytesPerSecond(nowMs, windowMs = 2000) {
    for (let k = 0; k < this.t.length; k++) {
      if (this.t[k] < nowMs - windowMs) continue;
      const dt = Math.max(nowMs, this.latestT) - this.t[k];
      return dt > 0 ? ((this.latestBytes - this.bytes[k]) * 1000) / dt : 0;
    }
    return 0;
  }
}
