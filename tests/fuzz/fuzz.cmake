# libFuzzer targets (clang only): configure with the "fuzz" preset (CMakePresets.json) or
#   CC=clang CXX=clang++ cmake -S . -B build/fuzz -DTETSTREAM_FUZZ=ON
# Every library is built with -fsanitize=fuzzer-no-link,address,undefined (CMakeLists.txt);
# each target below links the fuzzer's main. tests/fuzz/run.sh builds and runs them.
set(TETSTREAM_FUZZ_TARGETS manifest split-chunk node-chunk base-chunk
    mesh-vtu mesh-vtk mesh-vts mesh-vti mesh-msh mesh-mesh mesh-xyz mesh-xdmf pair-tetgen pair-medit pair-plot3d
    hpc-headers listing)

add_library(tetstream_fuzz_harness STATIC tests/fuzz/harness.cpp)
target_link_libraries(tetstream_fuzz_harness PUBLIC tetstream_pack)
target_include_directories(tetstream_fuzz_harness PUBLIC tests/fuzz)

foreach(target ${TETSTREAM_FUZZ_TARGETS})
  add_executable(fuzz-${target} tests/fuzz/fuzz_target.cpp)
  target_compile_definitions(fuzz-${target} PRIVATE TETSTREAM_FUZZ_TARGET="${target}")
  target_link_libraries(fuzz-${target} PRIVATE tetstream_fuzz_harness)
  target_link_options(fuzz-${target} PRIVATE -fsanitize=fuzzer)
endforeach()

add_executable(write_seeds tests/fuzz/write_seeds.cpp)
target_link_libraries(write_seeds PRIVATE tetstream_fuzz_harness)
target_link_options(write_seeds PRIVATE -fsanitize=fuzzer-no-link)
