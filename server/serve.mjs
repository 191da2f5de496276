#!/usr/bin/env node
// Static server for the viewer and packed datasets (development, demos, small deployments).
// `node server/serve.mjs --help` lists the options; server/README.md explains them and how to
// deploy on nginx, object stores and CDNs. In code: import { createServer } from
// './server/serve.mjs' (see app.mjs for the options); main(argv, { plugins }) runs the command
// line with plugins installed.
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { createServer } from './app.mjs';

export { createServer };

const here = path.dirname(fileURLToPath(import.meta.url));
const defaultViewer = path.resolve(here, '../build/web');

export const HELP = `usage: node server/serve.mjs [options] [DIR]
       npm run serve -- [options] [DIR]

Serves DIR (default: the current folder) at /, or the folders given with --mount.
If DIR holds packed datasets (DIR/manifest.json or DIR/*/manifest.json) and no index.html,
the viewer (build/web) is served at / and DIR at /data/, and a viewer URL is printed for each
dataset.

  --host HOST           address to listen on (default 127.0.0.1; 0.0.0.0 for every interface)
  --port PORT           port (default 8080; 0 picks a free one)
  --mount /PREFIX=DIR   serve DIR under /PREFIX/ (repeatable; the longest prefix wins)
  --viewer DIR          the viewer folder used with a dataset DIR (default build/web)
  --no-viewer           serve a dataset DIR alone, at /
  --max-connections N   sockets open at once (default 512; more are closed at once)
  --tls-cert FILE       serve HTTPS with this certificate (PEM; with --tls-key): HTTP/2 for
  --tls-key FILE        browsers that speak it (many chunks at once on one connection), HTTP/1.1
                        for the rest
  --log                 print one line per request
  -h, --help            this text

Every response has CORS headers (Access-Control-Allow-Origin: *); chunks/*.tsc are sent as
application/octet-stream with Cache-Control immutable and never compressed; other files get
Cache-Control no-cache and ETag/Last-Modified revalidation; X.br / X.gz next to a .wasm or .js
(server/precompress.mjs writes them) are sent to clients that accept them.`;

export class UsageError extends Error {}

export function parseArgs(argv) {
  const opts = { host: '127.0.0.1', port: 8080, mounts: [], viewer: defaultViewer, maxConnections: 512, log: false };
  const positional = [];
  const value = (i, name) => {
    if (i >= argv.length) throw new UsageError(`${name}: missing value`);
    return argv[i];
  };
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    if (a === '--host') opts.host = value(++i, a);
    else if (a === '--port') {
      const v = value(++i, a);
      if (!/^\d+$/.test(v) || Number(v) > 65535) throw new UsageError(`--port: cannot read "${v}"; write a number from 0 to 65535`);
      opts.port = Number(v);
    } else if (a === '--mount') {
      const v = value(++i, a);
      const eq = v.indexOf('=');
      if (eq < 1 || !v.startsWith('/')) throw new UsageError(`--mount: cannot read "${v}"; write /PREFIX=DIR, e.g. /data=build/data`);
      opts.mounts.push({ prefix: v.slice(0, eq), dir: v.slice(eq + 1) });
    } else if (a === '--viewer') opts.viewer = value(++i, a);
    else if (a === '--no-viewer') opts.viewer = null;
    else if (a === '--max-connections') {
      const v = value(++i, a);
      if (!/^[1-9]\d*$/.test(v)) throw new UsageError(`--max-connections: cannot read "${v}"; write a positive number`);
      opts.maxConnections = Number(v);
    } else if (a === '--tls-cert') opts.tlsCert = value(++i, a);
    else if (a === '--tls-key') opts.tlsKey = value(++i, a);
    else if (a === '--log') opts.log = true;
    else if (a === '-h' || a === '--help') opts.help = true;
    else if (a.startsWith('-')) throw new UsageError(`unknown option ${a} (see --help)`);
    else positional.push(a);
  }
  if (!opts.tlsCert !== !opts.tlsKey) throw new UsageError('--tls-cert and --tls-key go together');
  if (opts.tlsCert) opts.tls = { cert: readPem(opts.tlsCert, '--tls-cert'), key: readPem(opts.tlsKey, '--tls-key') };
  if (positional.length > 1) throw new UsageError(`one DIR at most (got ${positional.join(' ')}); use --mount /PREFIX=DIR for more`);
  for (const m of opts.mounts) checkFolder(m.dir, '--mount');

  if (positional.length || !opts.mounts.length) {
    const dir = positional[0] ?? '.';
    checkFolder(dir, 'DIR');
    const isData = !fs.existsSync(path.join(dir, 'index.html')) && findManifests(dir).length > 0;
    if (isData && opts.viewer && !opts.mounts.some((m) => m.prefix === '/')) {
      if (fs.existsSync(path.join(opts.viewer, 'index.html'))) {
        opts.mounts.push({ prefix: '/', dir: opts.viewer }, { prefix: '/data', dir });
      } else {
        opts.notes = [`no viewer at ${opts.viewer} (run npm run build): serving the data alone`];
        opts.mounts.push({ prefix: '/', dir });
      }
    } else opts.mounts.push({ prefix: '/', dir });
  }
  return opts;
}

function readPem(file, what) {
  let text;
  try { text = fs.readFileSync(file, 'utf8'); } catch { throw new UsageError(`${what}: cannot read ${file}`); }
  if (!text.includes('-----BEGIN ')) throw new UsageError(`${what}: ${file} is not a PEM file`);
  return text;
}

function checkFolder(dir, what) {
  let st;
  try { st = fs.statSync(dir); } catch { throw new UsageError(`${what}: no such folder: ${dir}`); }
  if (!st.isDirectory()) throw new UsageError(`${what}: not a folder: ${dir}`);
}

// DIR/manifest.json and DIR/*/manifest.json, sorted; enough to point people at their datasets.
function findManifests(dir) {
  const out = [];
  if (fs.existsSync(path.join(dir, 'manifest.json'))) out.push('manifest.json');
  let entries = [];
  try { entries = fs.readdirSync(dir, { withFileTypes: true }); } catch { /* unreadable: none */ }
  for (const e of entries.sort((a, b) => a.name.localeCompare(b.name))) {
    if (e.name.startsWith('.')) continue;
    if ((e.isDirectory() || e.isSymbolicLink()) && fs.existsSync(path.join(dir, e.name, 'manifest.json'))) {
      out.push(`${e.name}/manifest.json`);
    }
  }
  return out;
}

// Viewer URLs for the datasets of every mount, if some mount is a viewer.
function viewerUrls(base, mounts, limit = 8) {
  const viewer = mounts.find((m) => fs.existsSync(path.join(m.dir, 'index.html')));
  if (!viewer) return [];
  const vprefix = viewer.prefix.endsWith('/') ? viewer.prefix : viewer.prefix + '/';
  const urls = [];
  for (const m of mounts) {
    if (m === viewer) continue;
    const prefix = m.prefix.endsWith('/') ? m.prefix : m.prefix + '/';
    for (const rel of findManifests(m.dir)) {
      urls.push(`${base}${vprefix.slice(1)}index.html?data=${prefix}${rel}`);
    }
  }
  if (urls.length > limit) return [...urls.slice(0, limit), `… and ${urls.length - limit} more`];
  return urls;
}

// Runs the command line. plugins: installed in the server (see app.mjs); notes: extra lines
// printed under the mounts (what the plugins do).
export function main(argv = process.argv.slice(2), { plugins = [], notes = [] } = {}) {
  let opts;
  try {
    opts = parseArgs(argv);
  } catch (e) {
    console.error(`serve: ${e.message}`);
    process.exit(e instanceof UsageError ? 2 : 1);
  }
  if (opts.help) {
    console.log(HELP);
    return;
  }
  let server;
  try {
    server = createServer({
      ...opts,
      plugins,
      log: opts.log ? (e) => console.log(`${new Date(e.time).toISOString()} ${e.method} ${e.url} ${e.status}${e.note ? ` (${e.note})` : ''}${e.aborted ? ' aborted' : ''} ${e.ms} ms`) : null,
    });
  } catch (e) { // a key that does not match its certificate, and the like
    console.error(`serve: ${e.message}`);
    process.exit(1);
  }
  server.on('error', (e) => {
    console.error(`serve: ${e.code === 'EADDRINUSE' ? `port ${opts.port} on ${opts.host} is in use; try --port 0` : e.message}`);
    process.exit(1);
  });
  server.listen(opts.port, opts.host, () => {
    const { port } = server.address();
    const shown = ['0.0.0.0', '::'].includes(opts.host) ? 'localhost' : opts.host.includes(':') ? `[${opts.host}]` : opts.host;
    const base = `${opts.tls ? 'https' : 'http'}://${shown}:${port}/`;
    console.log(`serving on ${base}`);
    for (const m of [...opts.mounts].sort((a, b) => a.prefix.length - b.prefix.length)) {
      console.log(`  ${m.prefix.padEnd(8)} -> ${path.resolve(m.dir)}`);
    }
    for (const n of opts.notes ?? []) console.log(`note: ${n}`);
    for (const n of notes) console.log(n);
    const urls = viewerUrls(base, opts.mounts);
    if (urls.length) {
      console.log('\nOpen in a browser (Ctrl-C stops the server):');
      for (const u of urls) console.log(`  ${u}`);
    }
  });
  const stop = () => {
    server.close(() => process.exit(0));
    server.closeAllConnections();
  };
  process.on('SIGINT', stop);
  process.on('SIGTERM', stop);
}

if (process.argv[1] && fileURLToPath(import.meta.url) === fs.realpathSync(process.argv[1])) main();
