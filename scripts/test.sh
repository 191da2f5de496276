#!/usr/bin/env bash
# npm test: set up, build, run every test: native unit tests (ctest), the wasm core and the CLI
# under node, and the viewer in headless Chromium.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh

echo "test: native unit tests"
ctest --test-dir build/native --output-on-failure -j2

echo "test: node (wasm core, CLI) and browser (headless Chromium)"
node --test --test-concurrency=1 tests/node/ tests/browser/
