#!/usr/bin/env bash
# npm run bench: release build, then the progressive-engine benchmarks (tests/bench/run_bench.py).
# VTK columns need Debian's python3-vtk9 (installed here if missing, as it is large).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
if ! /usr/bin/python3 -c "import vtk" 2>/dev/null; then
  if [ "$(id -u)" = 0 ]; then DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-vtk9 >/dev/null || true; fi
fi
python3 tests/bench/run_bench.py "$@"
