#!/usr/bin/env bash
# The distributed pack (core/dist) under mpirun, as a user runs it: a mesh written as the pieces
# of a parallel run by VTK's own writers (write_pieces.py), and as one XDMF grid by meshio,
# packed on 1 to 4 ranks. Each pack
# must pass every check of the patch hierarchy (tests/unit/test_partial.cpp, run on these packs:
# any set of nodes with their parents is a valid mesh in any order, all nodes give the input,
# the nodes an isovalue needs give its full-resolution surface exactly, the incremental surface
# follows), be the same bytes when packed again, and give the serial pack's isosurface; a rank
# that fails stops every rank with one message, never a hang.
#   distributed_pack.sh TETSTREAM TETSTREAM_TESTS WORKDIR
set -euo pipefail
TETSTREAM=$1
TESTS=$2
WORK=$3
HERE="$(cd "$(dirname "$0")" && pwd)"
# Open MPI as root (CI) and in containers; more ranks than cores.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl_vader_single_copy_mechanism=none
MPIRUN=(mpirun --oversubscribe --bind-to none)
rm -rf "$WORK" && mkdir -p "$WORK"
"$TETSTREAM" gen harmonic --n 22 -o "$WORK/harmonic.vtu" >/dev/null
/usr/bin/python3 "$HERE/write_pieces.py" "$WORK/harmonic.vtu" "$WORK/pieces" 4
PACK=(pack --leaf-vertices 256 --chunk-kb 8 --json)

checks=""
for input in ghost.pvtu ids.pvtu; do
  for np in 1 2 4; do
    out="$WORK/${input%.*}-np$np"
    timeout 300 "${MPIRUN[@]}" -np $np "$TETSTREAM" "${PACK[@]}" "$WORK/pieces/$input" -o "$out" >"$out.json"
    echo "packed $input on $np ranks: $(tr -d ' \n' <"$out.json" | grep -o '"nodes":[0-9]*,"bytes":[0-9]*'),"\
      "$(tr -d ' \n' <"$out.json" | grep -o '"baseFieldRms":[0-9.e-]*')"
    tr -d ' \n' <"$out.json" | grep -q '"baseFieldRms":[0-9]' || { echo "FAIL: no measured base error"; exit 1; }
    # Every node's field error is measured, but for the np - 2 nodes that combine ranks' parts
    # below the root (their regions' input vertices are on several ranks).
    /usr/bin/python3 -c "
import json, sys
nodes = json.load(open(sys.argv[1]))['nodes']
unmeasured = sum(1 for n in nodes if n.get('fieldMax', -1) < 0)
sys.exit(0 if unmeasured <= max(int(sys.argv[2]) - 2, 0) else 1)" "$out/manifest.json" $np ||
      { echo "FAIL: nodes without a measured field error on $np ranks"; exit 1; }
    checks="$checks;$out=$WORK/pieces/$input"
  done
done

# Pieces that meshio wrote (a listing written by hand, as deal.II and FEniCS write theirs), on 2
# ranks: the same surface as one process's pack.
FIXTURES="$HERE/../fixtures/partitioned"
timeout 300 "${MPIRUN[@]}" -np 2 "$TETSTREAM" pack "$FIXTURES/meshio.pvtu" -o "$WORK/meshio-np2" --leaf-vertices 12 --base-vertices 20 \
  >/dev/null
"$TETSTREAM" pack "$FIXTURES/meshio.pvtu" -o "$WORK/meshio-serial" >/dev/null
for value in 2 3.5; do
  a=$("$TETSTREAM" iso "$WORK/meshio-np2" --value $value --json | tr -d ' \n' | grep -o '"triangles":[0-9]*,"vertices":[0-9]*')
  b=$("$TETSTREAM" iso "$WORK/meshio-serial" --value $value --json | tr -d ' \n' | grep -o '"triangles":[0-9]*,"vertices":[0-9]*')
  [ -n "$a" ] && [ "$a" = "$b" ] || { echo "FAIL: meshio pieces, iso $value: $a on 2 ranks, $b on one process"; exit 1; }
done
echo "ok: meshio's pieces on 2 ranks give one process's surfaces"
checks="$checks;$WORK/meshio-np2=$FIXTURES/meshio.pvtu"  # (its cell data 'region' as one process reads it)

# A VTKHDF file of partitions (each rank reads its own rows), on 3 ranks (a group of three splits
# one to two), and a time series of two partitions a step, on 2 ranks.
HPC="$HERE/../fixtures/hpc"
for input in vtkhdf_parts.vtkhdf:3 vtkhdf_series.vtkhdf:2; do
  file=${input%:*} np=${input#*:}
  out="$WORK/${file%.*}-np$np"
  timeout 300 "${MPIRUN[@]}" -np $np "$TETSTREAM" pack "$HPC/$file" -o "$out" --base-vertices 8 --leaf-vertices 4 \
    --json >"$out.json"
  grep -q '"ranks": *'$np "$out.json" || { echo "FAIL: $file on $np ranks"; cat "$out.json"; exit 1; }
  checks="$checks;$out=$HPC/$file"
done
echo "ok: VTKHDF partitions packed on 3 and 2 ranks"

# One file read in shares: packed on each rank count of RANKS, every rank says it read its share
# (NOTE, from its reader), and the isosurfaces at VALUES equal one process's pack of the file.
#   sharesLikeOneProcess NAME FILE NOTE "RANKS" "VALUES" [pack options...]
sharesLikeOneProcess() {
  local name=$1 input=$2 note=$3 ranks=$4 values=$5
  shift 5
  "$TETSTREAM" pack "$input" -o "$WORK/$name-serial" "$@" >/dev/null
  for np in $ranks; do
    local out="$WORK/$name-np$np"
    timeout 300 "${MPIRUN[@]}" -np $np "$TETSTREAM" pack "$input" -o "$out" "$@" --json >"$out.json"
    [ "$(grep -c "$note" "$out.json")" -eq $np ] ||
      { echo "FAIL: $name was not read in shares on $np ranks"; cat "$out.json"; exit 1; }
    for value in $values; do
      local a b
      a=$("$TETSTREAM" iso "$out" --value $value --json | tr -d ' \n' | grep -o '"triangles":[0-9]*,"vertices":[0-9]*')
      b=$("$TETSTREAM" iso "$WORK/$name-serial" --value $value --json | tr -d ' \n' | grep -o '"triangles":[0-9]*,"vertices":[0-9]*')
      [ -n "$a" ] && [ "$a" = "$b" ] || { echo "FAIL: $name on $np ranks, iso $value: $a, one process $b"; exit 1; }
    done
    checks="$checks;$out=$input"
  done
  echo "ok: $name read in shares on $ranks ranks gives one process's surfaces"
}

# A CGNS base of two zones: each rank reads its zone; the zones meet where their points
# coincide, as in one process.
sharesLikeOneProcess cgns "$HPC/cgns_structured.cgns" "this process's share of the file" "2" "1.05 1.35" \
  --base-vertices 8 --leaf-vertices 4
# The same two zones on 3 ranks: each rank reads a slab of both.
sharesLikeOneProcess cgns-slabs "$HPC/cgns_structured.cgns" "this process's share of the file" "3" "1.05 1.35" \
  --base-vertices 8 --leaf-vertices 4
# A CGNS base of one unstructured zone: each rank reads its elements and the vertices they use.
sharesLikeOneProcess cgns-zone "$HPC/cgns_steps.cgns" "this process's share of the file" "2" "12 14" \
  --base-vertices 8 --leaf-vertices 4

# One .vtu of several <Piece>s (as PETSc writes): each rank reads its pieces. Tets cut by VTK's
# piece extraction, and PETSc's hexahedra, whose shared faces every rank must cut alike.
sharesLikeOneProcess multi "$WORK/pieces/multi.vtu" "this process's share of the file" "2 4" "0 0.25" \
  --leaf-vertices 256 --chunk-kb 8
sharesLikeOneProcess petsc "$FIXTURES/petsc.vtu" "this process's share of the file" "3" "2 3.5" \
  --base-vertices 8 --leaf-vertices 4

# One .vtu of one piece, as most solvers and ParaView write it: each rank reads its run of the
# cells and the points they span (appended raw data as tetstream writes it; inline base64 with
# zlib blocks as meshio writes it).
sharesLikeOneProcess vtu "$WORK/harmonic.vtu" "this process's share of the file" "2 3" "0 0.25" \
  --leaf-vertices 256 --chunk-kb 8
/usr/bin/python3 -c "
import meshio, sys
meshio.read(sys.argv[1]).write(sys.argv[2], compression='zlib')" "$WORK/harmonic.vtu" "$WORK/harmonic-zlib.vtu"
sharesLikeOneProcess vtu-zlib "$WORK/harmonic-zlib.vtu" "this process's share of the file" "2" "0 0.25" \
  --leaf-vertices 256 --chunk-kb 8
# Its points shuffled (a run of the cells uses points from all over the file), as a .vtu of
# appended raw data, one XDMF grid with HDF5 heavy data and one Exodus II file: each rank reads
# only the points its cells use, far fewer than every point.
/usr/bin/python3 "$HERE/shuffle_points.py" "$WORK/harmonic.vtu" "$WORK/shuffled.vtu"
for ext in xdmf exo; do
  /usr/bin/python3 -c "
import meshio, sys
m = meshio.read(sys.argv[1])
meshio.write(sys.argv[2], meshio.Mesh(m.points, m.cells, point_data=m.point_data))" "$WORK/shuffled.vtu" "$WORK/shuffled.$ext"
done
points=$("$TETSTREAM" info "$WORK/harmonic.vtu" --json | tr -d ' \n' | grep -o '"vertices":[0-9]*' | head -1 | cut -d: -f2)
for case in "vtu:points read for them" "xdmf:points they use" "exo:nodes they use"; do
  ext=${case%%:*} note=${case#*:}
  sharesLikeOneProcess "shuffled-$ext" "$WORK/shuffled.$ext" "$note" "2 3" "0 0.25" --leaf-vertices 256 --chunk-kb 8
  for np in 2 3; do
    grep -o "the [0-9]* $note" "$WORK/shuffled-$ext-np$np.json" | while read -r _ read _; do
      [ "$read" -lt $((points * 2 / np)) ] || { echo "FAIL: a rank of $np read $read of the $points points"; exit 1; }
    done
  done
done

# One XDMF grid of Mixed cells (tets, and triangles among them: meshio writes Mixed for two cell
# types): each rank walks the type codes to its share of the cells.
/usr/bin/python3 -c "
import meshio, sys
m = meshio.read(sys.argv[1])
tets = m.cells_dict['tetra']
meshio.write(sys.argv[2], meshio.Mesh(m.points, [('tetra', tets), ('triangle', tets[::50, :3])],
                                      point_data=m.point_data))" "$WORK/shuffled.vtu" "$WORK/mixed.xdmf"
sharesLikeOneProcess mixed-xdmf "$WORK/mixed.xdmf" "points they use" "2 3" "0 0.25" --leaf-vertices 256 --chunk-kb 8

# One XDMF grid with HDF5 heavy data and one Exodus II file, as meshio writes them (DOLFINx and
# others write XDMF so: one file for the whole mesh): each rank reads its rows of the cells (HDF5
# hyperslabs; the Exodus library's partial reads) and the points they span.
for ext in xdmf exo; do
  /usr/bin/python3 -c "
import meshio, sys
m = meshio.read(sys.argv[1])
meshio.write(sys.argv[2], meshio.Mesh(m.points, m.cells, point_data=m.point_data))" "$WORK/harmonic.vtu" "$WORK/harmonic.$ext"
done
sharesLikeOneProcess xdmf "$WORK/harmonic.xdmf" "this process's share of the grid" "2 3" "0 0.25" --leaf-vertices 256 --chunk-kb 8
# An XDMF spatial collection of one grid per rank of the run that wrote it (each its own points,
# in one HDF5 file): each rank reads its grids.
/usr/bin/python3 "$HERE/write_grids.py" "$WORK/harmonic.vtu" "$WORK/grids" 4
sharesLikeOneProcess xdmf-grids "$WORK/grids.xdmf" "this process's share of the file" "2 4" "0 0.25" \
  --leaf-vertices 256 --chunk-kb 8
sharesLikeOneProcess exodus "$WORK/harmonic.exo" "this process's share of the file" "2 3" "0 0.25" --leaf-vertices 256 --chunk-kb 8

# The same bytes on a second run.
again="$WORK/again"
timeout 300 "${MPIRUN[@]}" -np 4 "$TETSTREAM" "${PACK[@]}" "$WORK/pieces/ghost.pvtu" -o "$again" >/dev/null
diff -r "$WORK/ghost-np4" "$again" >/dev/null || { echo "FAIL: two runs on 4 ranks differ"; exit 1; }
echo "ok: a second run on 4 ranks wrote the same bytes"

# Every check of the hierarchy, on every pack.
TETSTREAM_CHECK_PACKS="${checks#;}" "$TESTS" --gtest_filter='Partial.AnySet*:Partial.AllNodes*:Partial.TheNodesAn*' \
  --gtest_brief=1

# The isosurface of a distributed pack is the serial pack's (the same grid: the same values), at
# three isovalues.
"$TETSTREAM" "${PACK[@]}" "$WORK/harmonic.vtu" -o "$WORK/serial" >/dev/null
for value in 0 0.25 0.5; do
  serial=$("$TETSTREAM" iso "$WORK/serial" --value $value --json | tr -d ' \n' | grep -o '"triangles":[0-9]*')
  for np in 2 4; do
    mine=$("$TETSTREAM" iso "$WORK/ghost-np$np" --value $value --json | tr -d ' \n' | grep -o '"triangles":[0-9]*')
    [ "$serial" = "$mine" ] || { echo "FAIL: iso $value on $np ranks: $mine, serial $serial"; exit 1; }
  done
done
echo "ok: the isosurfaces equal the serial pack's"

# A piece without an array its listing declares: every rank stops, the message names the piece.
set +e
msg=$(timeout 120 "${MPIRUN[@]}" -np 4 "$TETSTREAM" pack "$WORK/pieces/lacking.pvtu" -o "$WORK/lacking" 2>&1)
code=$?
set -e
[ $code -ne 0 ] && [ $code -ne 124 ] && [ "$(echo "$msg" | grep -c "tetstream: error")" -eq 1 ] &&
  echo "$msg" | grep "tetstream: error" | grep -q "lacking_3.vtu" ||
  { echo "FAIL: a piece lacking an array gave exit $code: $msg"; exit 1; }
echo "ok: a piece lacking an array stops every rank: $(echo "$msg" | grep "tetstream: error")"

# --max-memory is per rank: too little for the whole mesh on one rank is enough for a quarter.
set +e
one=$(timeout 120 "${MPIRUN[@]}" -np 1 "$TETSTREAM" pack "$WORK/pieces/ghost.pvtu" -o "$WORK/small1" --max-memory 0.006 2>&1)
code=$?
set -e
[ $code -ne 0 ] && echo "$one" | grep -q "use more ranks" || { echo "FAIL: 1 rank within 6 MB: $one"; exit 1; }
timeout 120 "${MPIRUN[@]}" -np 4 "$TETSTREAM" pack "$WORK/pieces/ghost.pvtu" -o "$WORK/small4" --max-memory 0.006 >/dev/null
echo "ok: --max-memory 0.006 refuses 1 rank ($(echo "$one" | grep -o 'needs about [0-9]* MB')) and packs on 4"

# A missing piece: every rank stops, one message names the piece, no hang.
set +e
msg=$(timeout 120 "${MPIRUN[@]}" -np 4 "$TETSTREAM" pack "$WORK/pieces/broken.pvtu" -o "$WORK/broken" 2>&1)
code=$?
set -e
[ $code -ne 0 ] && [ $code -ne 124 ] || { echo "FAIL: a missing piece gave exit $code"; exit 1; }
echo "$msg" | grep -q "missing_3.vtu" || { echo "FAIL: the message does not name the piece: $msg"; exit 1; }
[ "$(echo "$msg" | grep -c "tetstream: error")" -eq 1 ] || { echo "FAIL: not one message: $msg"; exit 1; }
[ ! -e "$WORK/broken/manifest.json" ] || { echo "FAIL: a manifest was written"; exit 1; }
echo "ok: a missing piece stops every rank with one message: $(echo "$msg" | head -1)"

# A rank that fails in any phase, whatever its role (a leaf that sends up, a rank that combines,
# one that hands stable ids down), stops every rank with one message naming it: no hang.
for fault in 1:read 3:simplify 2:combine 2:encode 1:write; do
  rm -rf "$WORK/fault"
  set +e
  msg=$(TETSTREAM_FAULT=$fault timeout 120 "${MPIRUN[@]}" -x TETSTREAM_FAULT -np 4 "$TETSTREAM" pack \
    "$WORK/pieces/ghost.pvtu" -o "$WORK/fault" 2>&1)
  code=$?
  set -e
  [ $code -ne 0 ] && [ $code -ne 124 ] || { echo "FAIL: fault $fault gave exit $code"; exit 1; }
  [ "$(echo "$msg" | grep -c "tetstream: error: rank ${fault%%:*}: a fault injected in phase '${fault#*:}'")" -eq 1 ] ||
    { echo "FAIL: fault $fault: not one message naming the rank: $msg"; exit 1; }
  [ ! -e "$WORK/fault/manifest.json" ] || { echo "FAIL: fault $fault: a manifest was written"; exit 1; }
done
echo "ok: a rank failing in each phase stops every rank with one message"
