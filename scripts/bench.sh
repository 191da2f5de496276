#!/usr/bin/env bash
# npm run bench: release build, then the progressive-engine benchmarks (tests/bench/run_bench.py)
# and the browser streaming benchmark (tests/bench/stream_bench.mjs), with their plots.
# VTK columns need Debian's python3-vtk9 (installed here if missing, as it is large).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
# VTK for the comparison columns, matplotlib for the plots (Debian packages, for /usr/bin/python3).
for mod_pkg in vtk:python3-vtk9 matplotlib:python3-matplotlib; do
  if ! /usr/bin/python3 -c "import ${mod_pkg%%:*}" 2>/dev/null && [ "$(id -u)" = 0 ]; then
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${mod_pkg#*:}" >/dev/null || true
  fi
done
/usr/bin/python3 tests/bench/run_bench.py "$@"
# What an isovalue needs of the patch hierarchy (bytes and nodes against the whole).
/usr/bin/python3 tests/bench/selective_bench.py
# The browser over a simulated 10 Mbit/s, 50 ms link (medians of 3 loads), and its timeline plot.
node tests/bench/stream_bench.mjs --runs 3
/usr/bin/python3 tests/bench/plot_timeline.py
# docs/benchmarks.md shows the latest plots.
mkdir -p docs/bench
cp build/bench/rate_distortion.png build/bench/timeline.png docs/bench/
echo "bench: results in build/bench/ (results.md, results.json, stream.json); plots copied to docs/bench/"
