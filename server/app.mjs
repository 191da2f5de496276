// The HTTP side of server/serve.mjs: mounts, headers and precompressed files around serve-static
// (which does MIME types, ETag/Last-Modified, conditional requests, Range and HEAD) and
// finalhandler (error pages). Node's http module parses HTTP.
import http from 'node:http';
import http2 from 'node:http2';
import fs from 'node:fs';
import path from 'node:path';
import serveStatic from 'serve-static';
import finalhandler from 'finalhandler';
import { checkRequestPath, resolveInRoot } from './paths.mjs';

// Files the viewer downloads that compress well: served from a precompressed sibling (X.br,
// X.gz, written by server/precompress.mjs) when the client accepts it. Chunks (.tsc) are zstd
// already and are never encoded.
const PRECOMPRESSIBLE = {
  '.wasm': 'application/wasm',
  '.js': 'text/javascript; charset=utf-8',
  '.mjs': 'text/javascript; charset=utf-8',
  '.html': 'text/html; charset=utf-8',
  '.css': 'text/css; charset=utf-8',
  '.json': 'application/json; charset=utf-8',
  '.svg': 'image/svg+xml',
};
const ENCODINGS = [['br', '.br'], ['gzip', '.gz']]; // preferred first

// Chunk names carry their content hash: a browser may keep them forever. Everything else
// (manifest, viewer) is revalidated with ETag/Last-Modified on every use.
const IMMUTABLE_CHUNK = /[\\/]chunks[\\/][^\\/]+\.tsc$/;
export const CACHE_IMMUTABLE = 'public, max-age=31536000, immutable, no-transform';
export const CACHE_REVALIDATE = 'no-cache';

const LOG_LIMIT = 10000; // requestLog keeps the newest entries only: bounded memory on long runs

// plugins: functions (req, res, { path, entry }) called in order for every request, once its
// CORS headers are set and before it is served. `path` is the decoded request path (null when
// the target is refused), `entry` its requestLog entry (a plugin may set entry.note, which --log
// prints). A plugin may wrap `res` (to change how the body goes out) or answer the request
// itself and return true (or a Promise of true): then nothing else serves it. This is the one
// seam for behaviour that is not static file serving, so the server itself stays just that.
// tls: { key, cert } (PEM): HTTPS, with HTTP/2 for clients that speak it and HTTP/1.1 for the
// rest. Over HTTP/2 a browser asks for many chunks at once on one connection instead of six at a
// time, which is what a view of many small regions needs on a slow link.
export function createServer({
  mounts,
  plugins = [],
  maxConnections = 512,
  tls = null,
  log = null, // a function called with each finished entry of requestLog (the CLI's --log)
} = {}) {
  if (!Array.isArray(mounts) || !mounts.length) throw new Error('createServer: give at least one mount {prefix, dir}');
  const table = mounts.map(({ prefix, dir }) => makeMount(prefix, dir));
  table.sort((a, b) => b.prefix.length - a.prefix.length); // longest prefix first: /data/ wins over /

  const respond = (req, res) => {
    handle(server, table, plugins, req, res).catch((e) => {
      if (!res.headersSent) plain(res, 500, 'internal error');
      else res.destroy(e);
    });
  };
  const server = tls
    ? http2.createSecureServer({ key: tls.key, cert: tls.cert, allowHTTP1: true }, respond)
    : http.createServer(respond);
  if (tls) {
    // As an HTTP/1.1 server has: closing every socket at once (stopping the command line).
    const sockets = new Set();
    server.on('secureConnection', (socket) => {
      sockets.add(socket);
      socket.on('close', () => sockets.delete(socket));
    });
    server.closeAllConnections = () => { for (const socket of sockets) socket.destroy(); };
  }
  server.requestLog = [];
  server.logger = log;
  // Bounded resource use: slow or idle clients cannot hold sockets for long, and the number of
  // sockets is capped (further connections are closed at once until some finish).
  server.headersTimeout = 10_000;
  server.requestTimeout = 30_000; // receiving the request, not sending the (maybe slow) response
  server.keepAliveTimeout = 5_000;
  server.timeout = 120_000; // a socket with no traffic at all for 2 minutes is closed
  server.maxConnections = maxConnections;
  server.maxHeadersCount = 100;
  return server;
}

function makeMount(prefix, dir) {
  if (typeof prefix !== 'string' || !prefix.startsWith('/')) throw new Error(`mount prefix must start with /: ${prefix}`);
  if (/[?#%\\]|\/\/|(^|\/)\.\.?(\/|$)/.test(prefix)) throw new Error(`mount prefix must be a plain path: ${prefix}`);
  let root;
  try {
    root = fs.realpathSync(dir);
  } catch {
    throw new Error(`no such folder: ${dir}`);
  }
  if (!fs.statSync(root).isDirectory()) throw new Error(`not a folder: ${dir}`);
  return {
    prefix: prefix.endsWith('/') ? prefix : prefix + '/',
    root,
    serve: serveStatic(root, {
      index: ['index.html'],
      dotfiles: 'deny',
      fallthrough: false,
      redirect: false, // a folder without its slash is simply not found: no redirects to build
      setHeaders(res, file) {
        if (!res.getHeader('Cache-Control')) {
          res.setHeader('Cache-Control', IMMUTABLE_CHUNK.test(file) ? CACHE_IMMUTABLE : CACHE_REVALIDATE);
        }
        if (file.endsWith('.tsc')) res.setHeader('Content-Type', 'application/octet-stream');
      },
    }),
  };
}

async function handle(server, table, plugins, req, res) {
  const entry = { time: Date.now(), method: req.method, url: req.url, status: null };
  logRequest(server, entry, res);
  setCorsHeaders(req, res);

  const checked = checkRequestPath(req.url);
  for (const plugin of plugins) {
    if (await plugin(req, res, { path: checked.decoded ?? null, entry })) return;
  }

  if (req.method === 'OPTIONS') return preflight(req, res);
  if (req.method !== 'GET' && req.method !== 'HEAD') {
    res.setHeader('Allow', 'GET, HEAD, OPTIONS');
    return plain(res, 405, 'method not allowed');
  }
  if (!checked.decoded) return plain(res, checked.status, checked.reason);

  const notFound = () => plain(res, 404, 'not found');
  const mount = table.find((m) => checked.rawPath.startsWith(m.prefix) || checked.rawPath + '/' === m.prefix);
  if (!mount) return notFound();
  const rawRest = '/' + checked.rawPath.slice(mount.prefix.length);
  const rel = '/' + checked.decoded.slice(mount.prefix.length);
  const found = await resolveInRoot(mount.root, rel);
  if (!found) return notFound();

  let url = rawRest + checked.query;
  const type = PRECOMPRESSIBLE[path.extname(found.file)];
  if (type) {
    res.setHeader('Vary', 'Accept-Encoding');
    const sibling = !rel.endsWith('/') && await precompressedSibling(mount.root, rel, found, req.headers['accept-encoding']);
    if (sibling) {
      // serve-static sends the sibling's bytes, ETag and length; we say what they are.
      url = rawRest + sibling.suffix + checked.query;
      res.setHeader('Content-Encoding', sibling.encoding);
      res.setHeader('Content-Type', type);
      res.setHeader('Cache-Control', CACHE_REVALIDATE);
    }
  }
  req.url = url;
  mount.serve(req, res, (err) => {
    // Errors (404, 416...) are never cached and show no stack traces or file paths.
    res.setHeader('Cache-Control', 'no-store');
    finalhandler(req, res, { env: 'production', onerror: null })(err);
  });
}

// Picks br or gzip if the client accepts it and a sibling exists inside the root that is not
// older than the file (a stale .gz from an earlier build must never win over a new .wasm).
async function precompressedSibling(root, rel, found, acceptEncoding) {
  const accepted = parseAcceptEncoding(acceptEncoding);
  const ranked = ENCODINGS
    .map(([encoding, suffix], i) => ({ encoding, suffix, q: accepted.get(encoding) ?? accepted.get('*') ?? 0, i }))
    .filter((e) => e.q > 0)
    .sort((a, b) => b.q - a.q || a.i - b.i);
  for (const e of ranked) {
    const sib = await resolveInRoot(root, rel + e.suffix);
    if (sib && sib.stat.mtimeMs >= found.stat.mtimeMs) return e;
  }
  return null;
}

// "gzip, deflate, br;q=0.5, *;q=0" -> Map { gzip: 1, deflate: 1, br: 0.5, '*': 0 }
export function parseAcceptEncoding(header) {
  const out = new Map();
  for (const part of String(header ?? '').split(',')) {
    const [name, ...params] = part.trim().toLowerCase().split(';');
    if (!name) continue;
    let q = 1;
    for (const p of params) {
      const m = /^\s*q\s*=\s*([0-9.]+)\s*$/.exec(p);
      if (m) q = Number(m[1]);
    }
    out.set(name.trim(), Number.isFinite(q) ? q : 0);
  }
  return out;
}

// Every response, errors included, is readable from another origin (the viewer may live
// elsewhere than the data), and its timing is visible to the viewer's rate measurement.
function setCorsHeaders(req, res) {
  res.setHeader('Access-Control-Allow-Origin', '*');
  res.setHeader('Access-Control-Expose-Headers', 'Content-Length, Content-Range, Content-Encoding, Accept-Ranges, ETag, Last-Modified');
  res.setHeader('Timing-Allow-Origin', '*');
  res.setHeader('X-Content-Type-Options', 'nosniff');
}

function preflight(req, res) {
  res.setHeader('Access-Control-Allow-Methods', 'GET, HEAD, OPTIONS');
  // Allow whatever request headers the page asks for (Range, If-None-Match, Cache-Control...):
  // the server only reads files, so no header can do harm. Only header-name characters pass.
  const asked = String(req.headers['access-control-request-headers'] ?? '').replace(/[^A-Za-z0-9!#$%&'*+.^_`|~, -]/g, '');
  if (asked) res.setHeader('Access-Control-Allow-Headers', asked);
  res.setHeader('Access-Control-Max-Age', '86400');
  res.setHeader('Vary', 'Access-Control-Request-Headers');
  res.writeHead(204).end();
}

function plain(res, status, message) {
  const body = `${status} ${message}\n`;
  res.statusCode = status;
  res.setHeader('Content-Type', 'text/plain; charset=utf-8');
  res.setHeader('Content-Length', Buffer.byteLength(body));
  res.setHeader('Cache-Control', 'no-store');
  res.end(body);
}

function logRequest(server, entry, res) {
  server.requestLog.push(entry);
  if (server.requestLog.length > LOG_LIMIT) server.requestLog.splice(0, server.requestLog.length - LOG_LIMIT);
  const started = performance.now();
  res.on('close', () => {
    entry.status = res.statusCode;
    entry.ms = Math.round(performance.now() - started);
    if (!res.writableFinished) entry.aborted = true;
    server.logger?.(entry);
  });
}
