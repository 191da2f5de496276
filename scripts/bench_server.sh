#!/usr/bin/env bash
# Load test of server/serve.mjs on loopback with wrk: a chunk and the manifest of a packed
# dataset, each for DURATION with THREADS threads and CONNECTIONS connections. Prints requests/s,
# transfer rate, latency and every kind of error; exits 1 if there was any error.
#   DATA=build/data/harmonic-64 DURATION=10s THREADS=2 CONNECTIONS=64 bash scripts/bench_server.sh
# Without DATA's manifest, a Harmonic 32³ dataset is packed into a temp folder (needs the CLI).
set -euo pipefail
cd "$(dirname "$0")/.."
DATA=${DATA:-build/data/harmonic-64}
DURATION=${DURATION:-10s}
THREADS=${THREADS:-2}
CONNECTIONS=${CONNECTIONS:-64}

command -v wrk >/dev/null || { echo "bench_server: wrk is not installed (bash scripts/setup.sh, or apt-get install wrk)" >&2; exit 1; }
TMP=$(mktemp -d)
SERVER_PID=
cleanup() { [ -n "$SERVER_PID" ] && kill "$SERVER_PID" 2>/dev/null; rm -rf "$TMP"; }
trap cleanup EXIT

if [ ! -f "$DATA/manifest.json" ]; then
  [ -x build/native/tetstream ] || { echo "bench_server: no $DATA/manifest.json and no build/native/tetstream to make one (npm run build)" >&2; exit 1; }
  echo "bench_server: packing Harmonic 32³ into $TMP/h32"
  build/native/tetstream gen harmonic --n 32 -o "$TMP/h32.vtu" >/dev/null
  build/native/tetstream pack "$TMP/h32.vtu" -o "$TMP/h32" >/dev/null
  DATA=$TMP/h32
fi
# A typical chunk: the middle one by name (early chunks are small, the base mesh is the largest).
mapfile -t CHUNKS < <(cd "$DATA/chunks" && ls -- *.tsc | sort)
CHUNK=${CHUNKS[$(( ${#CHUNKS[@]} / 2 ))]}

node server/serve.mjs --no-viewer --port 0 --mount "/data=$DATA" > "$TMP/server.log" 2>&1 &
SERVER_PID=$!
for _ in $(seq 100); do
  PORT=$(sed -n 's|^serving on http://[^:]*:\([0-9]*\)/$|\1|p' "$TMP/server.log")
  [ -n "$PORT" ] && break
  kill -0 "$SERVER_PID" 2>/dev/null || { cat "$TMP/server.log" >&2; exit 1; }
  sleep 0.1
done
[ -n "$PORT" ] || { echo "bench_server: the server did not start" >&2; exit 1; }

# wrk's Lua hook prints one machine-readable line at the end of each run.
cat > "$TMP/report.lua" <<'LUA'
done = function(summary, latency, requests)
  local e = summary.errors
  io.write(string.format("RESULT %d %d %d %d %d %d %d %d %.2f %.2f\n",
    summary.requests, summary.duration, summary.bytes, e.connect, e.read, e.write, e.status, e.timeout,
    latency:percentile(50) / 1000, latency:percentile(99) / 1000))
end
LUA

echo "bench_server: node $(node --version), wrk $THREADS threads, $CONNECTIONS connections, $DURATION each, $(nproc) cores"
failed=0
run() { # run LABEL PATH
  local out
  out=$(wrk -t"$THREADS" -c"$CONNECTIONS" -d"$DURATION" -s "$TMP/report.lua" "http://127.0.0.1:$PORT$2")
  read -r _ reqs us bytes connect read write status timeout p50 p99 < <(grep '^RESULT' <<<"$out")
  local size; size=$(stat -c %s "$DATA/${2#/data/}")
  awk -v l="$1" -v s="$size" -v r="$reqs" -v us="$us" -v b="$bytes" -v p50="$p50" -v p99="$p99" 'BEGIN {
    printf "  %-9s %8d bytes  %9.0f requests/s  %7.1f MB/s  latency p50 %.2f ms, p99 %.2f ms\n", l, s, r / (us / 1e6), b / (us / 1e6) / 1e6, p50, p99 }'
  echo "            non-2xx/3xx: $status  socket errors: connect $connect, read $read, write $write, timeout $timeout"
  if [ $((status + connect + read + write + timeout)) -ne 0 ]; then failed=1; fi
}
run chunk "/data/chunks/$CHUNK"
run manifest /data/manifest.json
if [ $failed = 1 ]; then echo "bench_server: errors above" >&2; exit 1; fi
echo "bench_server: ok, no errors"
