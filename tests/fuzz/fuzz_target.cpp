// One libFuzzer target: TETSTREAM_FUZZ_TARGET names the harness function (tests/fuzz/fuzz.cmake
// builds one executable per name). Build and run them all with tests/fuzz/run.sh.
#include "harness.h"

#ifndef TETSTREAM_FUZZ_TARGET
#error "define TETSTREAM_FUZZ_TARGET"
#endif

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string name = TETSTREAM_FUZZ_TARGET;
  if (!tetstream::fuzz::runTarget(name, data, size)) __builtin_trap();
  return 0;
}
