// The static server (server/serve.mjs) and the documented nginx config (server/nginx.conf):
// no way out of the served folders, the headers the viewer and caches rely on, precompressed
// viewer files; and the test tools plugged into it (tests/support/server.mjs): the simulated
// link and every kind of injected fault.
import { test, describe, before, after } from 'node:test';
import assert from 'node:assert/strict';
import crypto from 'node:crypto';
import fs from 'node:fs';
import http2 from 'node:http2';
import https from 'node:https';
import path from 'node:path';
import zlib from 'node:zlib';
import { spawn, spawnSync } from 'node:child_process';
import { createServer } from '../support/server.mjs';
import { parseRate } from '../support/link.mjs';
import { precompressDir } from '../../server/precompress.mjs';
import { startNginx, startPythonHttpServer } from '../support/nginx.mjs';
import { get, rawGet, open } from '../support/http.mjs';
import { FakeClock } from '../support/clock.mjs';
import { root, tempDir } from './helpers.mjs';

const SECRET = `top-secret-${crypto.randomBytes(8).toString('hex')}`;
const CHUNK = '00000-0123456789abcdef.tsc';
const SMALL = '00001-fedcba9876543210.tsc';

// tmp/secret.txt            outside every root
// tmp/www/                  mounted at /      (viewer-like: index.html, app.js + .gz/.br, wasm)
// tmp/data/ds/              mounted at /data/ (manifest.json, chunks/*.tsc)
const fixtures = [];
after(() => {
  for (const dir of fixtures) fs.rmSync(dir, { recursive: true, force: true });
});

function makeFixture() {
  const dir = tempDir('server');
  fixtures.push(dir);
  const www = path.join(dir, 'www');
  const data = path.join(dir, 'data');
  const ds = path.join(data, 'ds');
  fs.mkdirSync(path.join(www, 'sub'), { recursive: true });
  fs.mkdirSync(path.join(ds, 'chunks'), { recursive: true });
  fs.writeFileSync(path.join(dir, 'secret.txt'), SECRET);
  fs.writeFileSync(path.join(www, '.env'), SECRET);
  fs.writeFileSync(path.join(www, 'index.html'), '<!doctype html><title>viewer</title>\n'.repeat(60));
  fs.writeFileSync(path.join(www, 'app.js'), 'export const answer = 42; // compressible text\n'.repeat(200));
  const wasm = Buffer.concat([Buffer.from([0, 0x61, 0x73, 0x6d, 1, 0, 0, 0]), Buffer.alloc(20000, 7)]);
  fs.writeFileSync(path.join(www, 'tetstream.wasm'), wasm);
  fs.writeFileSync(path.join(www, 'sub', 'file.txt'), 'in a subfolder\n');
  fs.symlinkSync('../secret.txt', path.join(www, 'link-out'));
  fs.symlinkSync('..', path.join(www, 'dirlink'));
  fs.symlinkSync(path.join(dir, 'secret.txt'), path.join(www, 'abs-link-out'));
  fs.symlinkSync('index.html', path.join(www, 'link-in'));
  fs.symlinkSync(path.join(dir, 'secret.txt'), path.join(ds, 'chunks', '00009-0000000000000000.tsc'));
  fs.writeFileSync(path.join(ds, 'manifest.json'), JSON.stringify({ formatVersion: 1, chunks: [CHUNK, SMALL] }));
  const chunk = crypto.randomBytes(1 << 20); // 1 MiB, incompressible like zstd output
  fs.writeFileSync(path.join(ds, 'chunks', CHUNK), chunk);
  const small = crypto.randomBytes(5000);
  fs.writeFileSync(path.join(ds, 'chunks', SMALL), small);
  // A .gz next to a chunk must never be sent in its place: chunks are zstd and never encoded.
  fs.writeFileSync(path.join(ds, 'chunks', SMALL + '.gz'), zlib.gzipSync(small));
  return { dir, www, data, chunk, small, wasm };
}

// At least 20 ways out of the root; none may return the secret (or /etc/passwd).
const TRAVERSALS = [
  '/../secret.txt',
  '/../../../../../../etc/passwd',
  '/%2e%2e/secret.txt',
  '/%2E%2E/%2E%2E/%2E%2E/etc/passwd',
  '/.%2e/secret.txt',
  '/%2e./secret.txt',
  '/%252e%252e/secret.txt',
  '/%25%32%65%25%32%65/secret.txt',
  '/..%2fsecret.txt',
  '/%2e%2e%2fsecret.txt',
  '/..\\secret.txt',
  '/..%5csecret.txt',
  '/%5c..%5csecret.txt',
  '/..%255csecret.txt',
  '/index.html%00/../../secret.txt',
  '/..%00/secret.txt',
  '//etc/passwd',
  '/%2fetc%2fpasswd',
  '/data/../../secret.txt',
  '/data/ds/../../../secret.txt',
  '/sub/../../secret.txt',
  '/index.html/../../secret.txt',
  '/%c0%ae%c0%ae/secret.txt',
  '/%u002e%u002e/secret.txt',
  '/..;/secret.txt',
  '/....//secret.txt',
  '/.%2e/.%2e/.%2e/etc/passwd',
  '/link-out',
  '/abs-link-out',
  '/dirlink/secret.txt',
  '/dirlink/dirlink/secret.txt',
  '/data/ds/chunks/00009-0000000000000000.tsc',
  '/.env',
  '/%2eenv',
  '/sub/',
  '/data/',
  '/data/ds/chunks/',
];

function assertNoLeak(r, target) {
  assert.ok([400, 403, 404].includes(r.status), `${target}: status ${r.status}`);
  const text = r.body.toString('latin1');
  assert.ok(!text.includes(SECRET), `${target}: the secret leaked`);
  assert.ok(!text.includes('root:x:0:0'), `${target}: /etc/passwd leaked`);
  assert.ok(!/<a href|Index of/i.test(text), `${target}: a folder listing`);
}

const mime = (r) => String(r.headers['content-type']).split(';')[0].trim();

// Checks shared by our server and nginx with server/nginx.conf.
function headerChecks(name, ctx) {
  // ctx.base is set in before(); without a server (nginx not installed) the checks are skipped.
  const check = (title, fn) => test(title, (t) => (ctx.base ? fn() : t.skip(ctx.skipReason)));
  check(`${name}: MIME types`, async () => {
    const { base, fx } = ctx;
    assert.equal(mime(await get(base, '/tetstream.wasm')), 'application/wasm');
    assert.equal(mime(await get(base, '/data/ds/manifest.json')), 'application/json');
    assert.equal(mime(await get(base, `/data/ds/chunks/${CHUNK}`)), 'application/octet-stream');
    assert.match(mime(await get(base, '/app.js')), /^(text|application)\/javascript$/);
    assert.equal(mime(await get(base, '/index.html')), 'text/html');
    const r = await get(base, `/data/ds/chunks/${CHUNK}`);
    assert.ok(r.body.equals(fx.chunk), 'chunk bytes');
  });

  check(`${name}: CORS on GET, on errors and on preflight`, async () => {
    const { base } = ctx;
    const origin = { Origin: 'http://viewer.example' };
    for (const t of ['/data/ds/manifest.json', `/data/ds/chunks/${CHUNK}`, '/data/ds/missing.tsc']) {
      const r = await get(base, t, { headers: origin });
      assert.equal(r.headers['access-control-allow-origin'], '*', t);
    }
    const pre = await get(base, `/data/ds/chunks/${CHUNK}`, {
      method: 'OPTIONS',
      headers: { ...origin, 'Access-Control-Request-Method': 'GET', 'Access-Control-Request-Headers': 'range, if-none-match' },
    });
    assert.ok([200, 204].includes(pre.status), `preflight ${pre.status}`);
    assert.equal(pre.headers['access-control-allow-origin'], '*');
    assert.match(pre.headers['access-control-allow-methods'], /GET/);
    assert.match(pre.headers['access-control-allow-headers'], /range/i);
    assert.equal(pre.body.length, 0);
  });

  check(`${name}: caching: chunks immutable, manifest and viewer revalidated, 304s`, async () => {
    const { base } = ctx;
    const chunk = await get(base, `/data/ds/chunks/${CHUNK}`);
    assert.match(chunk.headers['cache-control'], /immutable/);
    assert.match(chunk.headers['cache-control'], /max-age=31536000/);
    for (const t of ['/data/ds/manifest.json', '/tetstream.wasm', '/index.html']) {
      const r = await get(base, t);
      assert.equal(r.headers['cache-control'], 'no-cache', t);
      assert.ok(r.headers.etag && r.headers['last-modified'], `${t}: ETag and Last-Modified`);
      const byEtag = await get(base, t, { headers: { 'If-None-Match': r.headers.etag } });
      assert.equal(byEtag.status, 304, `${t}: If-None-Match`);
      assert.equal(byEtag.body.length, 0);
      const byDate = await get(base, t, { headers: { 'If-Modified-Since': r.headers['last-modified'] } });
      assert.equal(byDate.status, 304, `${t}: If-Modified-Since`);
      const other = await get(base, t, { headers: { 'If-None-Match': '"something-else"' } });
      assert.equal(other.status, 200, `${t}: a different ETag gets the file`);
    }
    const missing = await get(base, '/data/ds/chunks/00042-0000000000000000.tsc');
    assert.equal(missing.status, 404);
    assert.doesNotMatch(String(missing.headers['cache-control'] ?? ''), /immutable/, 'a 404 is never cached for a year');
  });

  check(`${name}: Range requests and HEAD`, async () => {
    const { base, fx } = ctx;
    const t = `/data/ds/chunks/${SMALL}`;
    const r = await get(base, t, { headers: { Range: 'bytes=100-199' } });
    assert.equal(r.status, 206);
    assert.equal(r.headers['content-range'], `bytes 100-199/${fx.small.length}`);
    assert.ok(r.body.equals(fx.small.subarray(100, 200)));
    const tail = await get(base, t, { headers: { Range: 'bytes=-10' } });
    assert.equal(tail.status, 206);
    assert.ok(tail.body.equals(fx.small.subarray(-10)));
    const bad = await get(base, t, { headers: { Range: `bytes=${fx.small.length}-` } });
    assert.equal(bad.status, 416);
    assert.equal(bad.headers['content-range'], `bytes */${fx.small.length}`);
    const head = await get(base, t, { method: 'HEAD' });
    assert.equal(head.status, 200);
    assert.equal(Number(head.headers['content-length']), fx.small.length);
    assert.equal(head.body.length, 0);
  });

  check(`${name}: precompressed viewer files; chunks never encoded`, async () => {
    const { base, fx, brotli } = ctx;
    const original = fs.readFileSync(path.join(fx.www, 'tetstream.wasm'));
    const gz = await get(base, '/tetstream.wasm', { headers: { 'Accept-Encoding': 'gzip' } });
    assert.equal(gz.headers['content-encoding'], 'gzip');
    assert.equal(mime(gz), 'application/wasm', 'the type of the original, not of the .gz');
    assert.match(gz.headers.vary, /Accept-Encoding/i);
    assert.ok(zlib.gunzipSync(gz.body).equals(original));
    assert.ok(gz.body.length < original.length / 4);
    if (brotli) {
      const br = await get(base, '/app.js', { headers: { 'Accept-Encoding': 'gzip, deflate, br' } });
      assert.equal(br.headers['content-encoding'], 'br');
      assert.ok(zlib.brotliDecompressSync(br.body).equals(fs.readFileSync(path.join(fx.www, 'app.js'))));
      const notBr = await get(base, '/app.js', { headers: { 'Accept-Encoding': 'br;q=0, gzip' } });
      assert.equal(notBr.headers['content-encoding'], 'gzip');
    }
    const plain = await get(base, '/tetstream.wasm');
    assert.equal(plain.headers['content-encoding'], undefined, 'no Accept-Encoding: identity');
    assert.ok(plain.body.equals(original));
    for (const t of [`/data/ds/chunks/${SMALL}`, `/data/ds/chunks/${CHUNK}`]) {
      const c = await get(base, t, { headers: { 'Accept-Encoding': 'gzip, deflate, br' } });
      assert.equal(c.headers['content-encoding'], undefined, t);
    }
    const c = await get(base, `/data/ds/chunks/${SMALL}`, { headers: { 'Accept-Encoding': 'gzip' } });
    assert.ok(c.body.equals(fx.small));
  });

  check(`${name}: ${TRAVERSALS.length} path traversal forms never escape the root`, async () => {
    const { base } = ctx;
    for (const t of TRAVERSALS) assertNoLeak(await get(base, t), t);
    for (const t of ['/\0../secret.txt', '/../secret.txt\0', '/..\0/..\0/etc/passwd']) assertNoLeak(await rawGet(base, t), JSON.stringify(t));
    // A path that is fine still works.
    assert.equal((await get(base, '/sub/file.txt')).status, 200);
  });
}

describe('our server (server/serve.mjs)', () => {
  const ctx = { brotli: true };
  let server;
  before(async () => {
    ctx.fx = makeFixture();
    await precompressDir(ctx.fx.www);
    server = await listen({ mounts: [{ prefix: '/', dir: ctx.fx.www }, { prefix: '/data', dir: ctx.fx.data }] });
    ctx.base = url(server);
  });
  after(() => close(server));

  headerChecks('serve.mjs', ctx);

  test('serve.mjs: more refusals: absolute-form target, methods, symlink inside the root', async () => {
    const { base, fx } = ctx;
    assert.equal((await rawGet(base, 'http://127.0.0.1/../secret.txt')).status, 400);
    assert.equal((await rawGet(base, '*')).status, 400);
    assert.equal((await get(base, '/index.html', { method: 'POST' })).status, 405);
    assert.equal((await get(base, '/index.html', { method: 'DELETE' })).status, 405);
    const inside = await get(base, '/link-in');
    assert.equal(inside.status, 200, 'a symlink to a file inside the root is served');
    assert.ok(inside.body.equals(fs.readFileSync(path.join(fx.www, 'index.html'))));
    assert.equal((await get(base, '/')).status, 200, 'index.html of the root');
    assert.equal((await get(base, '/sub')).status, 404, 'a folder is not a file');
  });

  test('serve.mjs: a precompressed file older than its original is not used', async () => {
    const { base, fx } = ctx;
    const js = path.join(fx.www, 'app.js');
    const later = new Date(Date.now() + 60000);
    fs.utimesSync(js, later, later);
    try {
      const r = await get(base, '/app.js', { headers: { 'Accept-Encoding': 'gzip, br' } });
      assert.equal(r.headers['content-encoding'], undefined);
      assert.ok(r.body.equals(fs.readFileSync(js)));
    } finally {
      fs.utimesSync(js, new Date(), new Date(Date.now() - 60000));
    }
  });

  test('serve.mjs: requestLog records method, url and status', async () => {
    const before = server.requestLog.length;
    await get(ctx.base, '/data/ds/manifest.json');
    await get(ctx.base, '/nothing-here');
    const [a, b] = server.requestLog.slice(before);
    assert.deepEqual([a.method, a.url, a.status, b.url, b.status], ['GET', '/data/ds/manifest.json', 200, '/nothing-here', 404]);
    assert.ok(a.time > 0 && Number.isFinite(a.time));
  });
});

// A certificate for 127.0.0.1 made for the test (openssl, from the project's setup).
function testCertificate() {
  const dir = tempDir('tls');
  fixtures.push(dir);
  const key = path.join(dir, 'key.pem'), cert = path.join(dir, 'cert.pem');
  const r = spawnSync('openssl', ['req', '-x509', '-newkey', 'ec', '-pkeyopt', 'ec_paramgen_curve:prime256v1', '-nodes',
    '-keyout', key, '-out', cert, '-days', '1', '-subj', '/CN=127.0.0.1', '-addext', 'subjectAltName=IP:127.0.0.1,DNS:localhost'], { encoding: 'utf8' });
  assert.equal(r.status, 0, r.stderr);
  return { key, cert };
}

// One GET over HTTP/2 (TLS, the test's certificate trusted): status, headers, body.
function http2Get(base, target, ca) {
  return new Promise((resolve, reject) => {
    const client = http2.connect(base, { ca });
    client.on('error', reject);
    const req = client.request({ ':path': target });
    const parts = [];
    let headers;
    req.on('response', (h) => { headers = h; });
    req.on('data', (d) => parts.push(d));
    req.on('end', () => {
      client.close();
      resolve({ status: headers[':status'], headers, body: Buffer.concat(parts) });
    });
    req.on('error', reject);
    req.end();
  });
}

describe('our server over HTTPS (--tls-cert, --tls-key)', () => {
  test('HTTP/2 for clients that speak it, HTTP/1.1 for the rest, with the same files and headers', async () => {
    const fx = makeFixture();
    const files = testCertificate();
    const tls = { key: fs.readFileSync(files.key, 'utf8'), cert: fs.readFileSync(files.cert, 'utf8') };
    const server = await listen({ mounts: [{ prefix: '/', dir: fx.www }, { prefix: '/data', dir: fx.data }], tls });
    try {
      const base = `https://127.0.0.1:${server.address().port}`;
      const chunk = await http2Get(base, `/data/ds/chunks/${CHUNK}`, tls.cert);
      assert.equal(chunk.status, 200);
      assert.ok(chunk.body.equals(fs.readFileSync(path.join(fx.data, 'ds', 'chunks', CHUNK))));
      assert.equal(chunk.headers['cache-control'], 'public, max-age=31536000, immutable, no-transform');
      assert.equal(chunk.headers['access-control-allow-origin'], '*');
      assert.equal((await http2Get(base, '/data/ds/nothing.tsc', tls.cert)).status, 404);
      assert.equal((await http2Get(base, '/../secret.txt', tls.cert)).status, 400, 'no way out over HTTP/2 either');
      const old = await new Promise((resolve, reject) => {
        https.get(`${base}/data/ds/manifest.json`, { ca: tls.cert }, (res) => {
          const parts = [];
          res.on('data', (d) => parts.push(d));
          res.on('end', () => resolve({ version: res.httpVersion, status: res.statusCode, body: Buffer.concat(parts) }));
        }).on('error', reject);
      });
      assert.deepEqual([old.version, old.status], ['1.1', 200]);
      assert.ok(old.body.equals(fs.readFileSync(path.join(fx.data, 'ds', 'manifest.json'))));
    } finally {
      await close(server);
    }
  });

  test('the CLI says https, and refuses a key without a certificate or a file that is not PEM', async () => {
    const run = (...args) => spawnSync(process.execPath, [path.join(root, 'server/serve.mjs'), ...args], { encoding: 'utf8' });
    const files = testCertificate();
    assert.match(run('--tls-key', files.key).stderr, /serve: --tls-cert and --tls-key go together/);
    assert.match(run('--tls-cert', files.cert, '--tls-key', path.join(root, 'README.md')).stderr, /--tls-key: .* is not a PEM file/);
    const fx = makeFixture();
    const child = spawn(process.execPath, [path.join(root, 'server/serve.mjs'), '--port', '0', '--tls-cert', files.cert,
      '--tls-key', files.key, '--viewer', fx.www, fx.data], { stdio: ['ignore', 'pipe', 'pipe'] });
    try {
      let out = '';
      await new Promise((resolve, reject) => {
        child.stdout.on('data', (d) => { out += d; if (out.includes('index.html?data=')) resolve(); });
        child.on('exit', () => reject(new Error(`serve.mjs exited: ${out}`)));
      });
      assert.match(out, /serving on https:\/\/127\.0\.0\.1:\d+\//);
      assert.match(out, /https:\/\/127\.0\.0\.1:\d+\/index\.html\?data=\/data\/ds\/manifest\.json/);
    } finally {
      child.kill();
    }
  });
});

describe('link simulation', () => {
  let fx;
  before(() => { fx = makeFixture(); });

  test('rates are read as people write them', () => {
    assert.equal(parseRate('10mbit'), 1.25e6);
    assert.equal(parseRate('10Mbps'), 1.25e6);
    assert.equal(parseRate('500kbit'), 62500);
    assert.equal(parseRate('2MB'), 2e6);
    assert.equal(parseRate('1.5mbyte'), 1.5e6);
    assert.equal(parseRate('64KiB/s'), 65536);
    assert.equal(parseRate('1000'), 1000);
    assert.throws(() => parseRate('10 mbits'), /cannot read "10 mbits"; write e\.g\. 10mbit/);
    assert.throws(() => parseRate('2mb'), /ambiguous/);
    assert.throws(() => parseRate('fast'), /cannot read/);
    assert.throws(() => parseRate('0'), /below/);
  });

  // The link waits on a fake clock that jumps to the end of each wait it is asked for: the time
  // on it when the bodies are in is the link time the throttle scheduled, whatever the speed of
  // the machine.
  test('--throttle: 1 MiB at 2 MB/s takes at least 0.4 s; two responses share the rate', async () => {
    const clock = new FakeClock({ auto: true });
    const server = await listen({ mounts: [{ prefix: '/', dir: fx.data }], throttleBytesPerSec: 2e6, clock });
    try {
      const t = `/ds/chunks/${CHUNK}`;
      const start = clock.now();
      const one = await get(url(server), t);
      assert.ok(one.body.equals(fx.chunk));
      const oneMs = clock.now() - start;
      // 1 MiB at 2 MB/s is 524 ms; the link starts with one piece (16 KB, 8 ms) of credit.
      assert.ok(oneMs >= 400 && oneMs <= 530, `1 MiB in ${oneMs.toFixed(0)} ms of link time`);
      // One link: two at once take as long as 2 MiB, not as long as 1 MiB.
      const started = clock.now();
      const both = await Promise.all([get(url(server), t), get(url(server), t)]);
      const ms = clock.now() - started;
      for (const r of both) assert.ok(r.body.equals(fx.chunk));
      assert.ok(ms >= 900 && ms <= 1060, `2 MiB in ${ms.toFixed(0)} ms of link time`);
    } finally {
      await close(server);
    }
  });

  test('--latency: the first byte waits', async () => {
    const clock = new FakeClock();
    const server = await listen({ mounts: [{ prefix: '/', dir: fx.data }], latencyMs: 200, clock });
    try {
      for (const [t, method] of [['/ds/manifest.json', 'GET'], ['/ds/missing.json', 'GET'], ['/ds/manifest.json', 'HEAD']]) {
        const r = open(url(server), t, { method });
        // The response is held on a 200 ms wait (an empty HEAD body too), and nothing has come.
        await clock.whenWaiting();
        assert.deepEqual(clock.pending(), [200], `${method} ${t}: waits 200 ms before the first byte`);
        await new Promise((resolve) => setImmediate(resolve));
        assert.equal(r.headers, null, `${method} ${t}: nothing sent during the wait`);
        clock.advance(200);
        const done = await r.done;
        assert.ok(done.status === 200 || done.status === 404, `${method} ${t}: ${done.status}`);
      }
    } finally {
      await close(server);
    }
  });

  test('npm run serve -- DATA: the viewer at /, the data at /data/, a URL per dataset', async () => {
    const child = spawn(process.execPath, [path.join(root, 'server/serve.mjs'), '--port', '0', '--viewer', fx.www, fx.data],
      { stdio: ['ignore', 'pipe', 'inherit'] });
    try {
      let out = '';
      await new Promise((resolve, reject) => {
        child.stdout.on('data', (d) => {
          out += d;
          if (out.includes('manifest.json')) resolve();
        });
        child.on('exit', () => reject(new Error(`serve exited: ${out}`)));
      });
      const viewerUrl = /(http:\/\/\S+\/index\.html\?data=(\S+))/.exec(out);
      assert.ok(viewerUrl, out);
      assert.equal(viewerUrl[2], '/data/ds/manifest.json');
      const page = new URL(viewerUrl[1]);
      assert.equal((await get(page.origin, '/index.html')).status, 200);
      const manifest = await get(page.origin, viewerUrl[2]);
      assert.equal(manifest.status, 200);
      assert.equal(mime(manifest), 'application/json');
    } finally {
      child.kill();
    }
  });

  test('the CLI refuses bad options with a clear message', () => {
    const run = (...args) => spawnSync(process.execPath, [path.join(root, 'server/serve.mjs'), ...args], { encoding: 'utf8' });
    const r = run('--port', 'http');
    assert.equal(r.status, 2);
    assert.match(r.stderr, /serve: --port: cannot read "http"/);
    assert.match(run('/no/such/folder').stderr, /serve: DIR: no such folder/);
    assert.match(run('--frobnicate').stderr, /unknown option --frobnicate/);
    assert.match(run('--throttle', '10mbit').stderr, /unknown option --throttle/, 'the link is simulated by test support only');
    const help = run('--help');
    assert.equal(help.status, 0);
    for (const o of ['--mount', '--max-connections']) assert.ok(help.stdout.includes(o), `--help mentions ${o}`);
  });

  test("the simulated link's command line (tests/support/serve_link.mjs) refuses bad options with a clear message", () => {
    const run = (...args) => spawnSync(process.execPath, [path.join(root, 'tests/support/serve_link.mjs'), ...args], { encoding: 'utf8' });
    const r = run('--throttle', '10 mbits');
    assert.equal(r.status, 2);
    assert.match(r.stderr, /^serve: --throttle: cannot read "10 mbits"; write e\.g\. 10mbit/);
    assert.match(run('--latency', 'soon').stderr, /serve: --latency: cannot read "soon"/);
    assert.match(run('--fault', '{"kind":"melt","match":"x"}').stderr, /serve: --fault: fault 1: "kind" must be one of/);
    assert.match(run('--port', 'http').stderr, /serve: --port: cannot read "http"/);
    assert.match(run('--frobnicate').stderr, /unknown option --frobnicate/);
    const help = run('--help');
    assert.equal(help.status, 0);
    for (const o of ['--mount', '--throttle', '--latency', '--fault', '--max-connections', 'truncate', 'corrupt', 'drop', 'slow']) {
      assert.ok(help.stdout.includes(o), `--help mentions ${o}`);
    }
  });
});

describe('fault injection', () => {
  let fx;
  let server;
  let base;
  const t = `/ds/chunks/${CHUNK}`;
  const clock = new FakeClock(); // the waits of 'slow' and 'drop'
  before(async () => {
    fx = makeFixture();
    server = await listen({ mounts: [{ prefix: '/', dir: fx.data }], clock });
    base = url(server);
  });
  after(() => close(server));

  test('status: fails `times` times, then the file comes through', async () => {
    server.setFaults([{ match: 'chunks/00000', kind: 'status', status: 503, times: 2 }]);
    const statuses = [];
    for (let i = 0; i < 3; i++) statuses.push((await get(base, t)).status);
    assert.deepEqual(statuses, [503, 503, 200]);
    assert.equal(server.faults[0].times, 0, 'times counted down');
    assert.equal(server.faults[0].hits, 2);
    assert.equal((await get(base, '/ds/manifest.json')).status, 200, 'other paths unaffected');
    const log = server.requestLog.slice(-4);
    assert.deepEqual(log.map((e) => e.status), [503, 503, 200, 200]);
    assert.deepEqual(log.map((e) => e.fault), ['status', 'status', undefined, undefined]);
  });

  test('status 404 by RegExp, on every request when `times` is not given; HEAD unaffected', async () => {
    server.setFaults([{ match: /chunks\/0000[01]-/, kind: 'status', status: 404 }]);
    for (const c of [CHUNK, SMALL, CHUNK]) {
      const r = await get(base, `/ds/chunks/${c}`);
      assert.equal(r.status, 404);
      assert.equal(r.headers['access-control-allow-origin'], '*', 'the viewer can read the status');
    }
    assert.equal((await get(base, t, { method: 'HEAD' })).status, 200);
  });

  test('truncate: half the body with a matching Content-Length', async () => {
    server.setFaults([{ match: CHUNK, kind: 'truncate', times: 1 }]);
    const r = await get(base, t);
    assert.equal(r.status, 200);
    assert.equal(r.error, null, 'a short but complete-looking response');
    assert.equal(Number(r.headers['content-length']), fx.chunk.length / 2);
    assert.ok(r.body.equals(fx.chunk.subarray(0, fx.chunk.length / 2)));
    assert.ok((await get(base, t)).body.equals(fx.chunk), 'times: 1');
  });

  test('corrupt: same length, some bits flipped', async () => {
    server.setFaults([{ match: CHUNK, kind: 'corrupt', times: 1 }]);
    const r = await get(base, t);
    assert.equal(r.status, 200);
    assert.equal(r.body.length, fx.chunk.length);
    assert.ok(!r.body.equals(fx.chunk));
    let differing = 0;
    for (let i = 0; i < r.body.length; i++) if (r.body[i] !== fx.chunk[i]) differing++;
    assert.ok(differing >= 1 && differing < 1000, `${differing} bytes changed`);
    // A small file is corrupted too (at least one bit).
    server.setFaults([{ match: SMALL, kind: 'corrupt', times: 1 }]);
    assert.ok(!(await get(base, `/ds/chunks/${SMALL}`)).body.equals(fx.small));
  });

  test('drop: the connection dies mid-body', async () => {
    server.setFaults([{ match: CHUNK, kind: 'drop', times: 1 }]);
    const r = await get(base, t);
    assert.equal(r.status, 200);
    assert.ok(r.error, 'the client sees an error');
    assert.ok(r.body.length < fx.chunk.length, `${r.body.length} bytes arrived`);
    assert.ok(r.body.equals(fx.chunk.subarray(0, r.body.length)));
    server.setFaults([{ match: CHUNK, kind: 'drop', afterBytes: 1000, times: 1 }]);
    const early = await get(base, t);
    assert.ok(early.error);
    assert.equal(early.body.length, 1000);
    assert.ok(server.requestLog.at(-1).aborted, 'logged as aborted');
    assert.ok((await get(base, t)).body.equals(fx.chunk), 'the next request is fine');
  });

  test('slow: the headers come, the body waits delayMs', async () => {
    server.setFaults([{ match: CHUNK, kind: 'slow', delayMs: 400, times: 1 }]);
    const r = open(base, t);
    await r.response;
    await clock.whenWaiting();
    assert.deepEqual(clock.pending(), [400], 'the body waits 400 ms');
    assert.equal(r.received, 0, 'the headers came, no body yet');
    clock.advance(400);
    const done = await r.done;
    assert.ok(done.body.equals(fx.chunk));
  });

  test('hold: the headers and afterBytes come, the rest waits for release()', async () => {
    server.setFaults([{ match: CHUNK, kind: 'hold', afterBytes: 1000, times: 1 }]);
    const rule = server.faults[0];
    const r = open(base, t);
    await rule.whenHeld(1);
    await r.response;
    await r.bytes(1000);
    assert.equal(r.finished, false, 'held');
    rule.release();
    const done = await r.done;
    assert.ok(done.body.equals(fx.chunk));
    assert.ok((await get(base, t)).body.equals(fx.chunk), 'times: 1');
  });

  test('regexp given as a string (the --fault JSON form); drop after a delay', async () => {
    server.setFaults([{ regexp: '/chunks/0000[1]-', kind: 'status', status: 500, times: 1 }]);
    assert.equal((await get(base, `/ds/chunks/${SMALL}`)).status, 500);
    assert.equal((await get(base, `/ds/chunks/${SMALL}`)).status, 200);
    server.setFaults([{ match: SMALL, kind: 'drop', afterBytes: 10, delayMs: 300, times: 1 }]);
    const r = open(base, `/ds/chunks/${SMALL}`);
    await clock.whenWaiting();
    assert.deepEqual(clock.pending(), [300], 'dropped after a 300 ms wait');
    await r.bytes(10);
    assert.equal(r.finished, false, 'the connection is still open during the wait');
    clock.advance(300);
    const done = await r.done;
    assert.ok(done.error && done.body.length === 10);
  });

  test('bad fault lists are refused', () => {
    assert.throws(() => server.setFaults([{ match: 'x', kind: 'explode' }]), /"kind" must be one of/);
    assert.throws(() => server.setFaults([{ kind: 'drop' }]), /"match" must be/);
    assert.throws(() => server.setFaults([{ match: 'x', kind: 'status', status: 42 }]), /bad "status"/);
    server.setFaults([]);
  });
});

describe('nginx with server/nginx.conf', () => {
  // Debian's nginx has no brotli module.
  const ctx = { brotli: false, skipReason: 'nginx is not installed (apt-get install nginx): skipped' };
  let nginx;
  before(async () => {
    ctx.fx = makeFixture();
    await precompressDir(ctx.fx.www);
    nginx = await startNginx({ mounts: [{ prefix: '/', dir: ctx.fx.www }, { prefix: '/data/', dir: ctx.fx.data }] });
    ctx.base = nginx?.url;
  });
  after(() => nginx?.stop());

  headerChecks('nginx', ctx);
});

describe('python3 -m http.server (no Range, no CORS)', () => {
  test('serves a packed folder byte for byte', async (t) => {
    const fx = makeFixture();
    const py = await startPythonHttpServer({ dir: fx.data });
    if (!py) return t.skip('python3 not installed');
    try {
      const m = await get(py.url, '/ds/manifest.json');
      assert.equal(m.status, 200);
      assert.equal(mime(m), 'application/json');
      const c = await get(py.url, `/ds/chunks/${CHUNK}`, { headers: { Range: 'bytes=0-9' } });
      assert.equal(c.status, 200, 'Range is ignored: the whole file');
      assert.ok(c.body.equals(fx.chunk));
      assert.equal(c.headers['access-control-allow-origin'], undefined, 'no CORS: same origin only');
    } finally {
      await py.stop();
    }
  });
});

function listen(options) {
  const server = createServer(options);
  return new Promise((resolve) => server.listen(0, '127.0.0.1', () => resolve(server)));
}
function url(server) {
  return `http://127.0.0.1:${server.address().port}/`;
}
function close(server) {
  return new Promise((resolve) => {
    server.close(resolve);
    server.closeAllConnections();
  });
}
