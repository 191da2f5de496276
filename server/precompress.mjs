#!/usr/bin/env node
// Writes X.gz (gzip -9) and X.br (brotli, quality 11) next to the viewer's files, so that a
// static server sends them compressed without compressing on every request: server/serve.mjs
// picks them by Accept-Encoding, nginx with `gzip_static on` (server/nginx.conf), and object
// stores get them uploaded with Content-Encoding set (server/README.md). The wasm shrinks to
// about a third, which is most of the viewer's first download over a slow link.
//
//   node server/precompress.mjs [DIR ...]     (default: build/web)
//
// Only .wasm .js .mjs .css .html .svg files of 1 KB or more; never .tsc (zstd already). A sibling
// newer than its file is kept (a second run is quick); files are written whole, then renamed,
// so a running server never sends half a file.
import fs from 'node:fs';
import path from 'node:path';
import zlib from 'node:zlib';
import { promisify } from 'node:util';
import { fileURLToPath } from 'node:url';

const gzip = promisify(zlib.gzip);
const brotli = promisify(zlib.brotliCompress);
const EXTENSIONS = new Set(['.wasm', '.js', '.mjs', '.css', '.html', '.svg']);
const MIN_BYTES = 1024;

const ENCODERS = {
  '.gz': (data) => gzip(data, { level: 9 }),
  '.br': (data) => brotli(data, {
    params: {
      [zlib.constants.BROTLI_PARAM_QUALITY]: zlib.constants.BROTLI_MAX_QUALITY,
      [zlib.constants.BROTLI_PARAM_SIZE_HINT]: data.length,
    },
  }),
};

export async function precompressDir(dir) {
  const results = [];
  for (const name of fs.readdirSync(dir).sort()) {
    const file = path.join(dir, name);
    const st = fs.statSync(file);
    if (!st.isFile() || !EXTENSIONS.has(path.extname(name)) || st.size < MIN_BYTES) continue;
    let data = null;
    for (const [suffix, encode] of Object.entries(ENCODERS)) {
      const out = file + suffix;
      const old = fs.statSync(out, { throwIfNoEntry: false });
      if (old && old.mtimeMs >= st.mtimeMs) {
        results.push({ file: out, bytes: old.size, original: st.size, kept: true });
        continue;
      }
      data ??= fs.readFileSync(file);
      const packed = await encode(data);
      const tmp = `${out}.tmp-${process.pid}`;
      fs.writeFileSync(tmp, packed);
      fs.renameSync(tmp, out);
      results.push({ file: out, bytes: packed.length, original: st.size, kept: false });
    }
  }
  return results;
}

async function main() {
  const here = path.dirname(fileURLToPath(import.meta.url));
  const dirs = process.argv.slice(2);
  if (dirs.includes('-h') || dirs.includes('--help')) {
    console.log('usage: node server/precompress.mjs [DIR ...]   (default build/web)\n' +
      'writes X.gz and X.br next to each .wasm/.js/.mjs/.css/.html/.svg of 1 KB or more');
    return;
  }
  if (!dirs.length) dirs.push(path.resolve(here, '../build/web'));
  for (const dir of dirs) {
    if (!fs.statSync(dir, { throwIfNoEntry: false })?.isDirectory()) {
      console.error(`precompress: no such folder: ${dir}`);
      process.exit(1);
    }
    for (const r of await precompressDir(dir)) {
      const pct = ((100 * r.bytes) / r.original).toFixed(0);
      console.log(`precompress: ${path.relative(process.cwd(), r.file)} ${r.bytes} bytes (${pct}%)${r.kept ? ', up to date' : ''}`);
    }
  }
}

if (process.argv[1] && fileURLToPath(import.meta.url) === fs.realpathSync(process.argv[1])) {
  main().catch((e) => {
    console.error(`precompress: ${e.message}`);
    process.exit(1);
  });
}
