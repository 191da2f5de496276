# The golden pack: packs a small generated mesh with the default options and compares every
# output file's SHA-256 with tests/golden/harmonic28.sha256, so that any change to the bytes of a
# pack is seen. Packing on one thread and on two must give the same bytes too.
#   cmake -DTETSTREAM=build/native/tetstream -DWORK=DIR -P tests/golden/golden_pack.cmake
# Add -DUPDATE=ON to rewrite the expected hashes (only when the bytes change on purpose).
# Harmonic 28³ (21,952 vertices) is large enough for every size-dependent path of the packer:
# a tree of regions (depth 4), two threads evaluating one queue, and two threads measuring each level.
cmake_minimum_required(VERSION 3.20)
foreach(var TETSTREAM WORK)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "golden pack: -D${var}= is required")
  endif()
endforeach()
set(golden "${CMAKE_CURRENT_LIST_DIR}/harmonic28.sha256")

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "golden pack: `${ARGN}` failed (${status}):\n${out}")
  endif()
endfunction()

# "SHA256  relative/path" lines for every file of the pack in `dir`, sorted by path. The manifest's
# "generator" names the program's version, which is not part of the format: it is left out.
function(pack_hashes dir outvar)
  file(GLOB_RECURSE files RELATIVE "${dir}" "${dir}/*")
  list(SORT files)
  set(lines "")
  foreach(f IN LISTS files)
    if(f STREQUAL "manifest.json")
      file(READ "${dir}/${f}" text)
      string(REGEX REPLACE "\"generator\": *\"[^\"]*\"" "\"generator\": \"\"" text "${text}")
      string(SHA256 hash "${text}")
    else()
      file(SHA256 "${dir}/${f}" hash)
    endif()
    string(APPEND lines "${hash}  ${f}\n")
  endforeach()
  set(${outvar} "${lines}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
run("${TETSTREAM}" gen harmonic --n 28 -o "${WORK}/harmonic28.vtu")
run("${TETSTREAM}" pack "${WORK}/harmonic28.vtu" -o "${WORK}/default")
run("${TETSTREAM}" pack "${WORK}/harmonic28.vtu" -o "${WORK}/threads1" --threads 1)
run("${TETSTREAM}" pack "${WORK}/harmonic28.vtu" -o "${WORK}/threads2" --threads 2)
pack_hashes("${WORK}/default" got)
pack_hashes("${WORK}/threads1" one)
pack_hashes("${WORK}/threads2" two)

# Long messages go out with NOTICE (printed as they are), then one short FATAL_ERROR.
function(fail summary)
  string(CONCAT details ${ARGN})
  message(NOTICE "${details}")
  message(FATAL_ERROR "golden pack: ${summary}")
endfunction()

if(NOT one STREQUAL two)
  fail("--threads 1 and --threads 2 give different bytes" "one thread:\n${one}two threads:\n${two}")
endif()
if(NOT got STREQUAL one)
  fail("the default options and --threads 1 give different bytes" "default:\n${got}--threads 1:\n${one}")
endif()
if(UPDATE)
  file(WRITE "${golden}" "${got}")
  message(STATUS "golden pack: wrote ${golden}")
  return()
endif()
file(READ "${golden}" want)
if(NOT got STREQUAL want)
  fail("the bytes of `tetstream pack` changed (see above)"
    "expected (${golden}):\n${want}got:\n${got}\n"
    "Packs must stay byte-identical unless their bytes are changed on purpose (a new chunk flag, a\n"
    "different simplification). For a deliberate change, note it in CHANGELOG.md (and in core/FORMAT.md\n"
    "section 6 when readers must change), then update the expected hashes with:\n"
    "  cmake -DTETSTREAM=build/native/tetstream -DWORK=/tmp/golden -DUPDATE=ON -P tests/golden/golden_pack.cmake\n")
endif()
file(REMOVE_RECURSE "${WORK}")
