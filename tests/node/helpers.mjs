// Shared helpers for the node tests: paths to the build outputs and a runner for the CLI.
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

export const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
export const cliPath = path.join(root, 'build/native/tetstream');

export function tempDir(name) {
  return fs.mkdtempSync(path.join(os.tmpdir(), `tetstream-${name}-`));
}

// Runs the CLI; returns {status, stdout, stderr, json} (json parsed when stdout is JSON).
export function cli(...args) {
  return cliWithEnv(process.env, ...args);
}

// The same with the given environment in place of the test's own.
export function cliWithEnv(env, ...args) {
  const r = spawnSync(cliPath, args, { encoding: 'utf8', timeout: 120000, env });
  let json;
  try { json = JSON.parse(r.stdout); } catch { json = undefined; }
  return { status: r.status, signal: r.signal, stdout: r.stdout, stderr: r.stderr, json };
}

// Generates and packs a Harmonic dataset of n³ vertices; returns the pack folder.
export function packedHarmonic(n, name = `harmonic${n}`, packArgs = []) {
  const dir = tempDir(name);
  const vtu = path.join(dir, 'h.vtu');
  const pack = path.join(dir, 'pack');
  let r = cli('gen', 'harmonic', '--n', String(n), '-o', vtu);
  if (r.status !== 0) throw new Error(`gen failed: ${r.stderr}`);
  r = cli('pack', vtu, '-o', pack, ...packArgs);
  if (r.status !== 0) throw new Error(`pack failed: ${r.stderr}`);
  return { dir, vtu, pack };
}
