// Clocks for the simulated link and the faults (link.mjs, faults.mjs): the real one, and a fake
// one whose time moves only when a test says so, so that a test checks what the code scheduled
// (how long it chose to wait) instead of measuring how long something took.
import { setTimeout as sleep } from 'node:timers/promises';

export const realClock = {
  now: () => performance.now(),
  sleep: (ms, signal) => sleep(ms, null, { signal }),
};

// time: ms since the clock was made. sleep(ms, signal) waits until advance() moves the time past
// its end. With { auto: true } the clock jumps to the next timer's end by itself whenever one is
// waiting (time then only moves as far as the code under test asks it to wait).
export class FakeClock {
  constructor({ auto = false } = {}) {
    this.time = 0;
    this.auto = auto;
    this.timers = []; // { end, ms, resolve }
    this.watchers = [];
  }

  now() {
    return this.time;
  }

  sleep(ms, signal) {
    return new Promise((resolve, reject) => {
      const abort = () => reject(new DOMException('The operation was aborted', 'AbortError'));
      if (signal?.aborted) return abort();
      const timer = { end: this.time + ms, ms, resolve };
      signal?.addEventListener('abort', () => {
        this.timers = this.timers.filter((t) => t !== timer);
        abort();
      }, { once: true });
      this.timers.push(timer);
      for (const w of this.watchers.splice(0)) w();
      if (this.auto) setImmediate(() => this.#next());
    });
  }

  // Durations (ms) of the sleeps waiting now, in the order they were asked for.
  pending() {
    return this.timers.map((t) => t.ms);
  }

  // Resolves once some sleep is waiting.
  async whenWaiting() {
    while (!this.timers.length) await new Promise((resolve) => this.watchers.push(resolve));
  }

  advance(ms) {
    this.time += ms;
    this.#fire();
  }

  #next() {
    if (!this.timers.length) return;
    this.time = Math.max(this.time, Math.min(...this.timers.map((t) => t.end)));
    this.#fire();
  }

  #fire() {
    const due = this.timers.filter((t) => t.end <= this.time).sort((a, b) => a.end - b.end);
    this.timers = this.timers.filter((t) => t.end > this.time);
    for (const t of due) t.resolve();
  }
}
