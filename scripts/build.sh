#!/usr/bin/env bash
# Builds everything: the native CLI and tests (build/native) and the web app (build/web).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
JOBS=${JOBS:-2}
BUILD_TYPE=${BUILD_TYPE:-Release}

echo "build: native ($BUILD_TYPE)"
cmake -S . -B build/native -DCMAKE_BUILD_TYPE="$BUILD_TYPE" >/dev/null
cmake --build build/native -j"$JOBS"

echo "build: wasm ($BUILD_TYPE)"
export NODE_PATH=/usr/share/nodejs   # Debian's emscripten needs this to find acorn
emcmake cmake -S . -B build/wasm -DCMAKE_BUILD_TYPE="$BUILD_TYPE" >/dev/null
cmake --build build/wasm -j"$JOBS"
node server/precompress.mjs build/web   # X.gz / X.br beside the viewer's files (server/README.md)
echo "build: ok (CLI: build/native/tetstream, web app: build/web/)"
