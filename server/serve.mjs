#!/usr/bin/env node
// Static server for the viewer and packed datasets (development, demos, small deployments).
// Built on serve-static (the file server behind Express): correct MIME types (application/wasm),
// ETag/Last-Modified with conditional requests, Range support, no directory listings, no path
// escape. We add CORS headers and caching suited to content-addressed chunks, and never
// compress (chunks are already zstd).
//
//   node server/serve.mjs [--host 127.0.0.1] [--port 8080] [--mount /prefix=DIR ...] [DIR]
import http from 'node:http';
import path from 'node:path';
import fs from 'node:fs';
import serveStatic from 'serve-static';
import finalhandler from 'finalhandler';

export function createServer({ mounts }) {
  const handlers = mounts.map(({ prefix, dir }) => ({
    prefix: prefix.endsWith('/') ? prefix : prefix + '/',
    serve: serveStatic(path.resolve(dir), {
      index: ['index.html'],
      dotfiles: 'deny',
      fallthrough: false,
      setHeaders(res, file) {
        // Chunk names carry their content hash: cache forever. Everything else: revalidate.
        const immutable = /[\\/]chunks[\\/][^\\/]+\.tsc$/.test(file);
        res.setHeader('Cache-Control', immutable ? 'public, max-age=31536000, immutable' : 'no-cache');
        if (file.endsWith('.tsc')) res.setHeader('Content-Type', 'application/octet-stream');
      },
    }),
  }));
  return http.createServer((req, res) => {
    res.setHeader('Access-Control-Allow-Origin', '*');
    res.setHeader('Access-Control-Expose-Headers', 'Content-Length, ETag');
    if (req.method === 'OPTIONS') {
      res.setHeader('Access-Control-Allow-Methods', 'GET, HEAD, OPTIONS');
      res.setHeader('Access-Control-Allow-Headers', 'Range, If-None-Match, If-Modified-Since');
      res.writeHead(204).end();
      return;
    }
    const done = finalhandler(req, res);
    const url = req.url || '/';
    const h = handlers.find((m) => url === m.prefix.slice(0, -1) || url.startsWith(m.prefix));
    if (!h) return done();
    req.url = '/' + url.slice(h.prefix.length);
    h.serve(req, res, done);
  });
}

function parseArgs(argv) {
  const opts = { host: '127.0.0.1', port: 8080, mounts: [] };
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    if (a === '--host') opts.host = argv[++i];
    else if (a === '--port') opts.port = Number(argv[++i]);
    else if (a === '--mount') {
      const [prefix, dir] = argv[++i].split('=');
      opts.mounts.push({ prefix, dir });
    } else if (a === '-h' || a === '--help') {
      console.log('usage: node server/serve.mjs [--host H] [--port P] [--mount /prefix=DIR ...] [DIR]');
      process.exit(0);
    } else opts.mounts.push({ prefix: '/', dir: a });
  }
  if (!opts.mounts.length) opts.mounts.push({ prefix: '/', dir: '.' });
  for (const m of opts.mounts) {
    if (!fs.existsSync(m.dir)) throw new Error(`no such folder: ${m.dir}`);
  }
  // Longest prefix first, so /data/ wins over /.
  opts.mounts.sort((a, b) => b.prefix.length - a.prefix.length);
  return opts;
}

if (import.meta.url === `file://${process.argv[1]}`) {
  try {
    const opts = parseArgs(process.argv.slice(2));
    const server = createServer(opts);
    server.listen(opts.port, opts.host, () => {
      const { port } = server.address();
      console.log(`serving on http://${opts.host}:${port}/`);
      for (const m of opts.mounts) console.log(`  ${m.prefix} -> ${path.resolve(m.dir)}`);
    });
  } catch (e) {
    console.error(`serve: ${e.message}`);
    process.exit(1);
  }
}
