#!/usr/bin/env bash
# npm test: set up, build, run every test: native unit tests (ctest, then again under ASan +
# UBSan), the wasm core and the CLI under node, and the viewer in headless Chromium.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
bash scripts/format.sh --check

echo "test: native unit tests (labels fast and slow; npm run test:fast runs the fast ones only)"
ctest --test-dir build/native --output-on-failure -j2

# The same tests (fuzz corpus replay and the golden pack included) under AddressSanitizer + UBSan
# (the "asan" preset). TETSTREAM_SKIP_ASAN=1 skips it for quick local runs; CI always runs it.
if [ "${TETSTREAM_SKIP_ASAN:-0}" != 1 ]; then
  echo "test: native unit tests under ASan + UBSan"
  cmake --preset asan >/dev/null
  cmake --build build/asan -j"${JOBS:-2}" --target tetstream_tests tetstream
  ctest --preset asan -j2
fi

echo "test: node (wasm core, CLI) and browser (headless Chromium)"
node --test --test-concurrency=1 tests/node/ tests/browser/
