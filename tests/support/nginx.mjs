// Real static servers for tests, started on 127.0.0.1 with a free port:
//   startNginx({ mounts: [{ prefix, dir }], port })  Debian's nginx with server/nginx.conf
//   startPythonHttpServer({ dir })                   python3 -m http.server: no Range, no CORS
// Both return { url, stop() } (url ends with /); startNginx returns null when nginx is not
// installed, so a test can skip with a clear message.
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import net from 'node:net';
import os from 'node:os';
import path from 'node:path';
import http from 'node:http';
import { fileURLToPath } from 'node:url';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
export const NGINX = '/usr/sbin/nginx';
export const PYTHON = '/usr/bin/python3';
export const nginxConfPath = path.join(root, 'server/nginx.conf');

// Substitutes in the documented config only what must differ for a test: the port, the files'
// places (pid, logs, temp folders in `tmp`), and the part between the "where the files are"
// markers. Everything that shapes a response (types, headers, caching, gzip_static) is kept.
export function nginxConfig({ mounts, port, tmp }) {
  let conf = fs.readFileSync(nginxConfPath, 'utf8');
  const replace = (re, by, what) => {
    const next = conf.replace(re, by);
    if (next === conf) throw new Error(`server/nginx.conf has no ${what}: update tests/support/nginx.mjs`);
    conf = next;
  };
  replace(/^worker_processes .*;$/m, 'worker_processes 1;', 'worker_processes');
  replace(/^pid .*;$/m, `pid ${tmp}/nginx.pid;`, 'pid');
  replace(/^error_log .*;$/m, `error_log ${tmp}/error.log warn;`, 'error_log');
  replace(/^(\s*)access_log .*;$/m, `$1access_log ${tmp}/access.log;`, 'access_log');
  replace(/^(\s*)listen .*;$/m, `$1listen 127.0.0.1:${port};`, 'listen');
  // Temp folders default to /var/lib/nginx, which a non-root user cannot write.
  const temps = ['client_body', 'proxy', 'fastcgi', 'uwsgi', 'scgi']
    .map((t) => `    ${t}_temp_path ${tmp}/${t};`).join('\n');
  replace(/^http \{$/m, `http {\n${temps}`, 'http block');
  const locations = mounts.map(({ prefix, dir }) => {
    const p = prefix.endsWith('/') ? prefix : prefix + '/';
    const d = path.resolve(dir);
    // As documented: the viewer at / gets gzip_static, dataset locations do not.
    return p === '/'
      ? `        location / {\n            root ${d};\n            gzip_static on;\n        }`
      : `        location ${p} {\n            alias ${d}/;\n        }`;
  }).join('\n');
  replace(/^\s*# --- where the files are.*\n[\s\S]*?# --- end of where the files are ---$/m,
    `        root ${tmp}/empty;\n${locations}`, '"where the files are" markers');
  // A root master would switch workers to "nobody", who cannot read a test's private temp
  // folders: run the workers as the current user instead (not needed, and refused, otherwise).
  if (process.getuid?.() === 0) conf = `user root;\n${conf}`;
  return conf;
}

export async function startNginx({ mounts, port = 0 }) {
  if (!fs.existsSync(NGINX)) return null;
  const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'tetstream-nginx-'));
  fs.mkdirSync(path.join(tmp, 'empty'));
  const chosen = port || await freePort();
  const conf = path.join(tmp, 'nginx.conf');
  fs.writeFileSync(conf, nginxConfig({ mounts, port: chosen, tmp }));
  // -e: the log nginx writes before it has read the config (default /var/log/nginx/error.log).
  const child = spawn(NGINX, ['-p', tmp, '-e', `${tmp}/error.log`, '-c', conf, '-g', 'daemon off;'], { stdio: ['ignore', 'ignore', 'pipe'] });
  const url = `http://127.0.0.1:${chosen}/`;
  await waitUntilUp(child, url, () => readIfAny(`${tmp}/error.log`), 'nginx');
  return { url, port: chosen, dir: tmp, stop: () => stopChild(child, () => fs.rmSync(tmp, { recursive: true, force: true })) };
}

export async function startPythonHttpServer({ dir, port = 0 }) {
  if (!fs.existsSync(PYTHON)) return null;
  const chosen = port || await freePort();
  const child = spawn(PYTHON, ['-m', 'http.server', '--bind', '127.0.0.1', '--directory', path.resolve(dir), String(chosen)],
    { stdio: ['ignore', 'ignore', 'pipe'] });
  let stderr = '';
  child.stderr.on('data', (d) => { stderr = (stderr + d).slice(-4000); }); // it logs every request here
  const url = `http://127.0.0.1:${chosen}/`;
  await waitUntilUp(child, url, () => stderr, 'python3 -m http.server');
  return { url, port: chosen, stop: () => stopChild(child) };
}

export function freePort() {
  return new Promise((resolve, reject) => {
    const s = net.createServer();
    s.on('error', reject);
    s.listen(0, '127.0.0.1', () => {
      const { port } = s.address();
      s.close(() => resolve(port));
    });
  });
}

// Polls until the server answers any HTTP response (up to 10 s); fails early if it exits.
async function waitUntilUp(child, url, diagnostics, name) {
  let exited = null;
  child.once('exit', (code, signal) => { exited = { code, signal }; });
  const deadline = Date.now() + 10000;
  while (Date.now() < deadline) {
    if (exited) throw new Error(`${name} exited (${exited.code ?? exited.signal}): ${diagnostics()}`);
    if (await answers(url)) return;
    await new Promise((r) => setTimeout(r, 50));
  }
  child.kill('SIGKILL');
  throw new Error(`${name} did not answer on ${url} within 10 s: ${diagnostics()}`);
}

function answers(url) {
  return new Promise((resolve) => {
    const req = http.get(url, (res) => {
      res.resume();
      resolve(true);
    });
    req.on('error', () => resolve(false));
    req.setTimeout(1000, () => req.destroy());
  });
}

function stopChild(child, cleanup = () => {}) {
  return new Promise((resolve) => {
    const done = () => { cleanup(); resolve(); };
    if (child.exitCode !== null || child.signalCode !== null) return done();
    const timer = setTimeout(() => child.kill('SIGKILL'), 5000);
    child.once('exit', () => { clearTimeout(timer); done(); });
    child.kill('SIGTERM'); // nginx: fast shutdown; python: KeyboardInterrupt-free exit
  });
}

function readIfAny(file) {
  try { return fs.readFileSync(file, 'utf8').slice(-4000); } catch { return '(no log)'; }
}
