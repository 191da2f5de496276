// Small HTTP clients for the server tests: one over node's http (the path sent exactly as given,
// no URL normalisation), one over a bare socket for request targets http.request refuses (NUL).
import http from 'node:http';
import net from 'node:net';

// Returns { status, headers, body (Buffer), headersMs, totalMs, error, complete }.
// Never throws: a dropped connection comes back with `error` and what arrived before it.
export function get(base, target, { method = 'GET', headers = {} } = {}) {
  const { hostname, port } = new URL(base);
  const started = performance.now();
  return new Promise((resolve) => {
    const req = http.request({ host: hostname, port, path: target, method, headers, agent: false });
    req.on('error', (e) => resolve({ status: 0, headers: {}, body: Buffer.alloc(0), error: e, totalMs: performance.now() - started }));
    req.on('response', (res) => {
      const headersMs = performance.now() - started;
      const parts = [];
      let firstByteMs = null;
      let error = null;
      res.on('data', (d) => {
        firstByteMs ??= performance.now() - started;
        parts.push(d);
      });
      res.on('error', (e) => { error = e; });
      res.on('close', () => resolve({
        status: res.statusCode,
        headers: res.headers,
        body: Buffer.concat(parts),
        headersMs,
        firstByteMs,
        totalMs: performance.now() - started,
        complete: res.complete,
        error: error ?? (res.complete ? null : new Error('connection closed before the body was complete')),
      }));
    });
    req.end();
  });
}

// Sends `target` byte for byte in a request line; returns { status, head, body } (body: Buffer).
export function rawGet(base, target) {
  const { hostname, port } = new URL(base);
  return new Promise((resolve, reject) => {
    const socket = net.connect(Number(port), hostname);
    const parts = [];
    socket.on('data', (d) => parts.push(d));
    socket.on('error', reject);
    socket.on('close', () => {
      const all = Buffer.concat(parts);
      const split = all.indexOf('\r\n\r\n');
      const head = all.subarray(0, split < 0 ? all.length : split).toString('latin1');
      const status = Number(/^HTTP\/1\.[01] (\d{3})/.exec(head)?.[1] ?? 0);
      resolve({ status, head, body: split < 0 ? Buffer.alloc(0) : all.subarray(split + 4) });
    });
    socket.end(Buffer.concat([Buffer.from('GET '), Buffer.from(target, 'latin1'),
      Buffer.from(` HTTP/1.1\r\nHost: ${hostname}\r\nConnection: close\r\n\r\n`)]));
  });
}

// A GET (or `method`) whose progress a test can watch: { headers (null until they come), received
// (body bytes so far), finished, response (Promise of the response), bytes(n) (Promise: resolves
// once n body bytes are in), done (Promise of what get() returns) }.
export function open(base, target, { method = 'GET', headers = {} } = {}) {
  const { hostname, port } = new URL(base);
  const watch = { headers: null, received: 0, finished: false };
  const waiters = [];
  const wake = () => {
    for (const w of waiters.filter((x) => watch.received >= x.n || watch.finished)) {
      waiters.splice(waiters.indexOf(w), 1);
      w.resolve();
    }
  };
  watch.bytes = (n) => new Promise((resolve) => { waiters.push({ n, resolve }); wake(); });
  let gotResponse;
  watch.response = new Promise((resolve) => { gotResponse = resolve; });
  watch.done = new Promise((resolve) => {
    const req = http.request({ host: hostname, port, path: target, method, headers, agent: false });
    const end = (result) => {
      watch.finished = true;
      wake();
      resolve(result);
    };
    req.on('error', (e) => end({ status: 0, headers: {}, body: Buffer.alloc(0), error: e }));
    req.on('response', (res) => {
      watch.headers = res.headers;
      gotResponse(res);
      const parts = [];
      let error = null;
      res.on('data', (d) => {
        parts.push(d);
        watch.received += d.length;
        wake();
      });
      res.on('error', (e) => { error = e; });
      res.on('close', () => end({
        status: res.statusCode,
        headers: res.headers,
        body: Buffer.concat(parts),
        complete: res.complete,
        error: error ?? (res.complete ? null : new Error('connection closed before the body was complete')),
      }));
    });
    req.end();
  });
  return watch;
}
