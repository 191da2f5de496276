#!/usr/bin/env bash
# npm start: set up, build, generate and pack the built-in Harmonic dataset, serve the viewer.
#   HARMONIC_N=64 (grid size), PORT=8080, HOST=127.0.0.1
set -euo pipefail
cd "$(dirname "$0")/.."
N=${HARMONIC_N:-64}
PORT=${PORT:-8080}
HOST=${HOST:-127.0.0.1}
bash scripts/build.sh

mkdir -p build/data
if [ ! -f "build/data/harmonic-$N/manifest.json" ] || [ build/native/tetstream -nt "build/data/harmonic-$N/manifest.json" ]; then
  build/native/tetstream gen harmonic --n "$N" -o "build/data/harmonic-$N.vtu"
  build/native/tetstream pack "build/data/harmonic-$N.vtu" -o "build/data/harmonic-$N" --name "Harmonic $N³"
fi

echo
echo "Open this URL in a browser (Ctrl-C stops the server):"
echo "  http://$HOST:$PORT/index.html?data=/data/harmonic-$N/manifest.json"
echo
exec node server/serve.mjs --host "$HOST" --port "$PORT" --mount /=build/web --mount /data=build/data
