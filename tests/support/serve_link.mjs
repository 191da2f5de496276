#!/usr/bin/env node
// `node server/serve.mjs` over a simulated link, with faults: to watch the viewer load as over a
// slow line, or to try a failure by hand.
//   node tests/support/serve_link.mjs --throttle 10mbit --latency 50 build/data/harmonic-64
// Every option of server/serve.mjs works too.
import fs from 'node:fs';
import { fileURLToPath } from 'node:url';
import { main, HELP } from '../../server/serve.mjs';
import { parseRate, parseMs } from './link.mjs';
import { normalizeFaults } from './faults.mjs';
import { simulation } from './server.mjs';

const LINK_HELP = `usage: node tests/support/serve_link.mjs [link options] [server options] [DIR]

Link options:
  --throttle RATE       cap the bandwidth of all responses together, like one shared link:
                        10mbit, 500kbit, 10Mbps (bits) or 2MB, 1.5mbyte, 64KiB (bytes), per second
  --latency MS          wait MS milliseconds before the first byte of every response (50, 50ms, 0.2s)
  --fault JSON          make matching requests fail (repeatable; an object or an array), e.g.
                        '{"match":"chunks/00003","kind":"status","status":503,"times":2}'
                        kinds: status, truncate, corrupt, drop, slow; fields: match (substring of
                        the path) or regexp, status, times, delayMs, afterBytes (faults.mjs)

Server options (server/serve.mjs):`;

// Takes the link options out of argv; returns them and the rest (for server/serve.mjs).
export function parseLinkArgs(argv) {
  const link = { throttleBytesPerSec: 0, latencyMs: 0, faults: [] };
  const rest = [];
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    const wrap = (fn) => {
      try { return fn(); } catch (e) { throw new Error(`${a}: ${e.message}`); }
    };
    const value = () => {
      if (++i >= argv.length) throw new Error(`${a}: missing value`);
      return argv[i];
    };
    if (a === '--throttle') {
      const v = value();
      link.throttleBytesPerSec = wrap(() => parseRate(v));
    } else if (a === '--latency') {
      const v = value();
      link.latencyMs = wrap(() => parseMs(v));
    } else if (a === '--fault') {
      const v = value();
      const parsed = wrap(() => JSON.parse(v));
      link.faults.push(...wrap(() => normalizeFaults(Array.isArray(parsed) ? parsed : [parsed])));
    } else if (a === '-h' || a === '--help') link.help = true;
    else rest.push(a);
  }
  return { link, rest };
}

function formatRate(bytesPerSec) {
  const mbit = (bytesPerSec * 8) / 1e6;
  return mbit >= 1 ? `${+mbit.toFixed(2)} Mbit/s` : `${+(mbit * 1000).toFixed(1)} kbit/s`;
}

function run() {
  let parsed;
  try {
    parsed = parseLinkArgs(process.argv.slice(2));
  } catch (e) {
    console.error(`serve: ${e.message}`);
    process.exit(2);
  }
  const { link, rest } = parsed;
  if (link.help) {
    console.log(`${LINK_HELP}\n\n${HELP}`);
    return;
  }
  const notes = [];
  if (link.throttleBytesPerSec || link.latencyMs) {
    const parts = [];
    if (link.throttleBytesPerSec) parts.push(`${formatRate(link.throttleBytesPerSec)} shared by all responses`);
    if (link.latencyMs) parts.push(`${link.latencyMs} ms before each response`);
    notes.push(`simulated link: ${parts.join(', ')}`);
  }
  if (link.faults.length) notes.push(`fault injection: ${link.faults.length} rule(s)`);
  main(rest, { plugins: [simulation(link)], notes });
}

if (process.argv[1] && fileURLToPath(import.meta.url) === fs.realpathSync(process.argv[1])) run();
