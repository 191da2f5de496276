// write_seeds TARGET DIR: writes real inputs for a fuzz target into DIR (tests/fuzz/run.sh).
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "harness.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: write_seeds TARGET DIR\n");
    return 2;
  }
  std::filesystem::create_directories(argv[2]);
  for (const auto& [name, bytes] : tetstream::fuzz::seeds(argv[1])) {
    std::ofstream out(std::filesystem::path(argv[2]) / ("seed-" + name), std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  }
  return 0;
}
