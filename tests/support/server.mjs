// The project's static server (server/serve.mjs) with a simulated link and fault injection
// plugged in through its `plugins` seam, for tests and benchmarks:
//
//   const server = createServer({
//     mounts: [{ prefix: '/', dir: 'build/web' }, { prefix: '/data', dir: packDir }],
//     throttleBytesPerSec: 1.25e6,   // optional: a 10 Mbit/s link shared by all responses
//     latencyMs: 50,                 // optional: before the first byte of every response
//     faults: [{ match: 'chunks/00003-', kind: 'status', status: 503, times: 2 }],
//   });
//   server.setFaults([...]);        // replace the rules between steps (server.faults: the live list)
//
// Other options go to the production createServer. Fault rules: faults.mjs; the link: link.mjs.
import { createServer as createStaticServer } from '../../server/serve.mjs';
import { TokenBucket, Throttle, Latency } from './link.mjs';
import { normalizeFaults, takeFault, answerStatus, FaultStream } from './faults.mjs';
import { tapBody } from './tap.mjs';
import { realClock } from './clock.mjs';

// The plugin: picks the request's fault, then routes the body through the link and the fault
// (latency, throttle, fault, in that order before the socket). plugin.faults is the live list.
// clock: whose time the link and the faults wait on (clock.mjs; a test may give a fake one).
export function simulation({ throttleBytesPerSec = 0, latencyMs = 0, faults = [], clock = realClock } = {}) {
  const bucket = throttleBytesPerSec > 0 ? new TokenBucket(throttleBytesPerSec, { clock }) : null;
  const plugin = (req, res, { path, entry }) => {
    const fault = path ? takeFault(plugin.faults, req.method, path) : null;
    if (fault) {
      entry.fault = fault.kind;
      entry.note = `fault: ${fault.kind}`;
    }
    const shapers = [];
    if (latencyMs > 0) shapers.push(new Latency(latencyMs, clock));
    if (bucket) shapers.push(new Throttle(bucket));
    if (fault && fault.kind !== 'status') shapers.push(new FaultStream(fault, res, clock));
    tapBody(res, shapers);
    // A status fault stands in for the file, after the method and path checks would have
    // passed (takeFault only picks GET requests with a usable path).
    if (fault?.kind === 'status') {
      answerStatus(res, fault);
      return true;
    }
    return false;
  };
  plugin.faults = normalizeFaults(faults);
  return plugin;
}

export function createServer({ throttleBytesPerSec, latencyMs, faults, clock, plugins = [], ...options } = {}) {
  const sim = simulation({ throttleBytesPerSec, latencyMs, faults, clock });
  const server = createStaticServer({ ...options, plugins: [...plugins, sim] });
  Object.defineProperty(server, 'faults', { get: () => sim.faults });
  server.setFaults = (list) => { sim.faults = normalizeFaults(list); };
  return server;
}
