#!/usr/bin/env bash
# npm run test:fast: the quick tier. Builds the native CLI and unit tests incrementally
# (build/native) and runs every ctest test labelled `fast`: the unit tests that take a few seconds
# at most and the golden pack; then the page's pure-JS units (loader, rate meter) under node and
# the format check. No sanitizer build, no wasm, no browser; `npm test` runs everything, the tests
# labelled `slow` included.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -f build/native/CMakeCache.txt ]; then
  cmake -S . -B build/native -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-Release}" >/dev/null
fi
cmake --build build/native -j"${JOBS:-2}" --target tetstream tetstream_tests
ctest --test-dir build/native --output-on-failure -j2 -L fast
node --test tests/node/loader.test.mjs tests/node/rate.test.mjs
bash scripts/format.sh --check
