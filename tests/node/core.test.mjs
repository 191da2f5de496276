// The core compiled to WebAssembly, run under node, must give exactly the native result.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import path from 'node:path';
import { root, cli, packedHarmonic } from './helpers.mjs';

function coreCheck(cmd, args) {
  const r = spawnSync(cmd[0], [...cmd.slice(1), ...args], { encoding: 'utf8', timeout: 300000 });
  assert.equal(r.status, 0, `${cmd.join(' ')} failed: ${r.stderr}`);
  return JSON.parse(r.stdout);
}

const native = [path.join(root, 'build/native/tetstream_core_check')];
// Emscripten 3.1.6's loader would try fetch() on a file path under node 20 without the flag.
const wasm = [process.execPath, '--no-experimental-fetch', path.join(root, 'build/wasm/tetstream_core_check.js')];

test('wasm isosurface, hull and slice equal native bit for bit', () => {
  const { pack } = packedHarmonic(33);
  for (const iso of ['0', '0.25', '-0.1', '0.9']) {
    const a = coreCheck(native, [pack, iso]);
    const b = coreCheck(wasm, [pack, iso]);
    for (const key of ['tets', 'triangles', 'vertices', 'area', 'positionsHash', 'indicesHash', 'normalsHash',
      'hullTriangles', 'hullLines', 'hullHash', 'linesHash', 'sliceTriangles', 'sliceArea', 'slicePositionsHash',
      'sliceIndicesHash'])
      assert.deepEqual(b[key], a[key], `${key} at isovalue ${iso}`);
    assert.ok(a.triangles > 0, 'a surface exists');
    assert.ok(a.hullTriangles > 0 && a.hullLines > 0 && a.sliceTriangles > 0, 'a hull and a slice exist');
    // And the CLI agrees with both.
    const c = cli('iso', pack, '--value', iso, '--json').json;
    assert.equal(c.triangles, a.triangles);
    assert.equal(c.vertices, a.vertices);
    assert.ok(Math.abs(c.area - a.area) <= 1e-12 * a.area);
  }
});

test('wasm core refuses a corrupt dataset with a message', async () => {
  const fs = await import('node:fs');
  const { pack } = packedHarmonic(6, 'corrupt');
  const manifest = JSON.parse(fs.readFileSync(path.join(pack, 'manifest.json'), 'utf8'));
  const chunk = path.join(pack, manifest.chunks[0].file);
  const bytes = fs.readFileSync(chunk);
  bytes[bytes.length >> 1] ^= 0x01;
  fs.writeFileSync(chunk, bytes);
  const r = spawnSync(wasm[0], [...wasm.slice(1), pack, '0'], { encoding: 'utf8' });
  assert.equal(r.status, 1);
  assert.match(r.stderr, /hash/);
});
