// Replays the fuzz corpus (tests/fuzz/corpus/TARGET/*: inputs the fuzzers kept for coverage, and
// every past finding as a regression input) through the same harness the fuzzers run. A broken
// invariant aborts with the harness's message; ASan/UBSan builds (the "asan" preset) catch
// memory errors here too, without clang or libFuzzer.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>

#include "harness.h"
#include "manifest.h"

namespace fs = std::filesystem;

TEST(FuzzCorpus, EveryInputOfEveryTargetRunsClean) {
  const fs::path root = TETSTREAM_FUZZ_CORPUS;
  ASSERT_TRUE(fs::is_directory(root)) << root;
  std::set<std::string> targets;
  size_t inputs = 0;
  for (const auto& dir : fs::directory_iterator(root)) {
    if (!dir.is_directory()) continue;
    const std::string target = dir.path().filename().string();
    targets.insert(target);
    for (const auto& file : fs::directory_iterator(dir.path())) {
      std::ifstream in(file.path(), std::ios::binary);
      std::vector<uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
      SCOPED_TRACE(file.path().string());
      ASSERT_TRUE(tetstream::fuzz::runTarget(target, bytes.data(), bytes.size())) << "unknown target " << target;
      ++inputs;
    }
  }
  for (const char* t : {"manifest", "split-chunk", "node-chunk", "base-chunk", "mesh-vtu", "mesh-vtk", "mesh-vts",
                        "mesh-vti", "mesh-msh", "mesh-mesh", "mesh-xyz", "mesh-xdmf", "pair-tetgen", "pair-medit",
                        "pair-plot3d", "hpc-headers", "listing"})
    EXPECT_TRUE(targets.count(t)) << "no corpus for " << t;
  EXPECT_GT(inputs, 50u);
}

// The manifest seeds tests/fuzz/run.sh starts from are valid, one of them with nodes.
TEST(FuzzCorpus, ManifestSeedsAreValid) {
  size_t withNodes = 0;
  for (const auto& [name, bytes] : tetstream::fuzz::seeds("manifest")) {
    tetstream::Manifest m;
    tetstream::Result r =
        tetstream::parseManifest(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), m);
    EXPECT_TRUE(r) << name << ": " << r.message;
    withNodes += !m.nodes.empty();
  }
  EXPECT_GE(withNodes, 1u);
}
