#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan) and fuzzes each for SECONDS (default 300),
# starting from real inputs, then merges what raised coverage into tests/fuzz/corpus/TARGET
# (committed; tests/unit/test_fuzz_corpus.cpp replays it on every npm test). Nothing else in the
# tree is written: logs, work folders and findings stay in build/fuzz.
#   bash tests/fuzz/run.sh [SECONDS] [TARGET ...]
# Findings are written to build/fuzz/findings/TARGET/; fix them, then copy each input into the
# target's corpus folder as a regression input (name it regress-WHAT).
# Needs clang and libFuzzer: apt-get install clang libclang-rt-14-dev (installed here if missing).
set -euo pipefail
cd "$(dirname "$0")/../.."
SECONDS_EACH=${1:-300}
shift || true
if ! command -v clang++ >/dev/null || ! ls /usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
  as_root() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends clang libclang-rt-14-dev >/dev/null
fi
cmake --preset fuzz >/dev/null
cmake --build build/fuzz -j2 >/dev/null
TARGETS=("$@")
[ ${#TARGETS[@]} -gt 0 ] || TARGETS=(manifest split-chunk base-chunk mesh-vtu mesh-vtk mesh-vts mesh-vti mesh-msh
  mesh-mesh mesh-xyz mesh-xdmf pair-tetgen pair-medit pair-plot3d hpc-headers listing)
# A two-file seed: 4-byte little-endian length of the first file, then both files.
pair_seed() { python3 -c 'import sys,struct; a=open(sys.argv[1],"rb").read(); b=open(sys.argv[2],"rb").read(); sys.stdout.buffer.write(struct.pack("<I",len(a))+a+b)' "$1" "$2"; }

for t in "${TARGETS[@]}"; do
  work=build/fuzz/work/$t seeds=build/fuzz/seeds/$t found=build/fuzz/findings/$t corpus=tests/fuzz/corpus/$t
  rm -rf "$found"
  mkdir -p "$work" "$seeds" "$found" "$corpus"
  F=tests/fixtures/formats
  case $t in
    mesh-xyz) cp $F/*.xyz $F/*.x $F/*.g "$seeds"/ ;;
    # From bytes only XML data items are read (HDF and binary ones are refused): the XML-data file
    # and the XML around the others.
    mesh-xdmf) cp tests/fixtures/hpc/xdmf_*.x*mf "$seeds"/ ;;
    mesh-*) cp tests/fixtures/*."${t#mesh-}" $F/*."${t#mesh-}" "$seeds"/ 2>/dev/null || true
            [ "$t" != mesh-vtu ] || cp tests/fixtures/partitioned/petsc.vtu "$seeds"/ ;;
    pair-tetgen) for n in $F/*.node; do pair_seed "$n" "${n%.node}.ele" > "$seeds/$(basename "${n%.node}")"; done ;;
    pair-medit) pair_seed $F/grid.mesh $F/grid.sol > "$seeds/grid"; pair_seed $F/mixed.mesh /dev/null > "$seeds/mixed" ;;
    pair-plot3d) for g in $F/p3d_*; do [[ $g == *.q ]] || pair_seed "$g" "${g%.*}.q" > "$seeds/$(basename "$g")"; done ;;
    hpc-headers) for h in tests/fixtures/hpc/exo_blocks.exo tests/fixtures/hpc/*.adf.cgns; do head -c 8192 "$h" > "$seeds/$(basename "$h")"; done ;;
    listing) for l in tests/fixtures/partitioned/*.pvt? tests/fixtures/partitioned/*.vtm; do
               python3 tests/fuzz/listing_seed.py "$l" > "$seeds/$(basename "$l")"; done ;;
    *) build/fuzz/write_seeds "$t" "$seeds" ;;
  esac
  echo "fuzz: $t for ${SECONDS_EACH}s"
  # -rss_limit_mb: a parser that allocates more than this on a small input is a finding.
  # -max_len: a listing carries its pieces, which need more room than one file.
  # -timeout is wall time: a fuzzer run under `nice` on a busy machine can be starved for many
  # seconds, which at 10 s ended runs early with timeouts that did not reproduce.
  build/fuzz/fuzz-"$t" "$work" "$corpus" "$seeds" -max_total_time="$SECONDS_EACH" -rss_limit_mb=1024 \
    -max_len="${MAX_LEN:-$([ "$t" = listing ] && echo 65536 || echo 8192)}" -timeout=60 -report_slow_units=60 -artifact_prefix="$found/" -print_final_stats=1 \
    2>build/fuzz/$t.log || true
  grep -E "stat::number_of_executed_units|stat::peak_rss_mb" build/fuzz/$t.log | sed "s/^/  /"
  # A finding must reproduce: a slow unit or timeout can also come from the machine being busy
  # (or the fuzzer being paused); one that runs cleanly on its own is reported and dropped.
  for f in "$found"/*; do
    [ -e "$f" ] || continue
    if timeout 60 build/fuzz/fuzz-"$t" "$f" >/dev/null 2>&1; then
      echo "  not reproduced (dropped): $(basename "$f")"
      rm "$f"
    fi
  done
  ls "$found" | sed "s/^/  finding: /"
  # Keep a minimal set that covers every edge the whole work folder covers. Edges only
  # (-use_counters=0): with hit counts as features the merge keeps nearly every input. The work
  # folder, with all of them, stays in build/fuzz for the next run.
  mkdir -p "$corpus.new"
  build/fuzz/fuzz-"$t" -merge=1 -use_counters=0 "$corpus.new" "$corpus" "$work" "$seeds" 2>/dev/null >/dev/null
  for f in "$corpus"/regress-*; do  # past findings stay, whatever they cover, once, by name
    [ -e "$f" ] || continue
    rm -f "$corpus.new/$(sha1sum "$f" | cut -c1-40)"
    cp "$f" "$corpus.new"/
  done
  rm -rf "$corpus" && mv "$corpus.new" "$corpus"
  # The corpus is committed: keep the smallest inputs up to CORPUS_KB (regression inputs always).
  budget=$(( ${CORPUS_KB:-400} * 1024 )) used=0
  while read -r f; do
    size=$(stat -c %s "$f")
    if [ $((used + size)) -gt $budget ] && [[ $(basename "$f") != regress-* ]]; then rm "$f"; else used=$((used + size)); fi
  done < <(ls -1Sr "$corpus"/* 2>/dev/null)
  echo "  corpus: $(ls "$corpus" | wc -l) inputs, $(( $(cat "$corpus"/* | wc -c) / 1024 )) KB"
done
