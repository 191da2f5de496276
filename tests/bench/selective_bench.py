#!/usr/bin/env python3
"""What an isovalue needs of a dataset of nodes (core/FORMAT.md 1.1): for each mesh, at isovalues
at 20%, 50% and 80% of the steering field's range, the bytes and nodes `tetstream iso --selective`
loads against the whole dataset, and whether its surface equals the full mesh's.

  python3 tests/bench/selective_bench.py [--sizes 64,128] [--no-check]

Packs Harmonic n^3 for each size into build/bench/ (reused when present), and every mesh under
$TETSTREAM_DATASETS that run_bench.py packs. Writes build/bench/selective.json."""
import argparse
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CLI = os.path.join(ROOT, 'build/native/tetstream')
OUT = os.path.join(ROOT, 'build/bench')


def run(*args):
    r = subprocess.run([CLI, *args], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f'tetstream {" ".join(args)} failed:\n{r.stderr}{r.stdout}')
    return r.stdout


def packed(name, make):
    folder = os.path.join(OUT, f'selective-{name}')
    if not os.path.exists(os.path.join(folder, 'manifest.json')):
        make(folder)
    return folder


def harmonic(n):
    def make(folder):
        vtu = os.path.join(OUT, f'harmonic-{n}.vtu')
        if not os.path.exists(vtu):
            run('gen', 'harmonic', '--n', str(n), '-o', vtu)
        run('pack', vtu, '-o', folder)
    return packed(f'harmonic-{n}', make)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--sizes', default='64,128')
    ap.add_argument('--no-check', action='store_true', help='skip loading the full mesh to compare')
    args = ap.parse_args()
    os.makedirs(OUT, exist_ok=True)
    sets = [(f'Harmonic {n}^3', harmonic(int(n))) for n in args.sizes.split(',') if n]
    rows = []
    print('| dataset | isovalue (of range) | bytes needed | nodes | exact |')
    print('|---|---|---|---|---|')
    for name, folder in sets:
        m = json.load(open(os.path.join(folder, 'manifest.json')))
        f = next(x for x in m['fields'] if x['name'] == m['isoField'])
        for q in (0.2, 0.5, 0.8):
            v = f['min'] + q * (f['max'] - f['min'])
            extra = ['--no-check'] if args.no_check else []
            r = json.loads(run('iso', folder, '--value', repr(v), '--selective', '--json', *extra))
            share = r['bytes'] / r['bytesTotal']
            rows.append({'dataset': name, 'share': q, 'isovalue': v, **r})
            exact = r.get('exact', 'not checked')
            print(f"| {name} | {q:.0%} | {r['bytes'] / 1e6:.2f} of {r['bytesTotal'] / 1e6:.2f} MB ({share:.1%}) "
                  f"| {r['nodes']} of {r['nodesTotal']} | {exact} |")
    json.dump(rows, open(os.path.join(OUT, 'selective.json'), 'w'), indent=1)


if __name__ == '__main__':
    main()
