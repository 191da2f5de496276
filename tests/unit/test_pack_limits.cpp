// What keeps a pack of any size within what a reader takes (FORMAT.md §5): the leaf size grows
// on meshes that would make more than PackOptions::maxLeaves leaves, and a manifest past the
// limits is refused before anything in the output folder changes.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "io/generators.h"
#include "manifest.h"
#include "pack/pack_output.h"
#include "pack/packer.h"
#include "test_helpers.h"

using namespace tetstream;

namespace {

TEST(PackLimits, LeafSizeGrowsOnlyPastTheMostLeaves) {
  PackOptions o;  // leaves of 2,048 vertices, at most 16,384 of them
  std::vector<std::string> notes;
  EXPECT_EQ(leafVerticesFor(1'000'000, 1, o, notes), 2048u);
  EXPECT_EQ(leafVerticesFor(16384ull * 2048, 1, o, notes), 2048u);
  EXPECT_TRUE(notes.empty());
  EXPECT_EQ(leafVerticesFor(16384ull * 2048 + 1, 1, o, notes), 2049u);
  EXPECT_EQ(leafVerticesFor(1'000'000'000, 1, o, notes), 61036u);
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_NE(notes[1].find("regions of up to 61036 vertices instead of 2048"), std::string::npos) << notes[1];
  // Three ranks' trees: at most 4,096 leaves each (12,288 in all), so the largest part of
  // 20M vertices needs leaves of 4,883.
  EXPECT_EQ(leafVerticesFor(20'000'000, 3, o, notes), 4883u);
  EXPECT_EQ(leafVerticesFor(8'000'000, 3, o, notes), 2048u);
  o.leafVertices = 0;  // one region: nothing to cap
  EXPECT_EQ(leafVerticesFor(1'000'000'000, 1, o, notes), 0u);
}

// Harmonic 16³ (4,096 vertices) in leaves of 64 vertices would make 64 leaves; with at most 4
// the leaves hold 1,024 vertices: at most 7 nodes, every level still a valid mesh.
TEST(PackLimits, APackKeepsToTheMostLeaves) {
  const TetMesh m = test::harmonic(16);
  PackOptions o;
  o.leafVertices = 64;
  PackSummary free, capped;
  test::pack("limits-free", m, o, &free);
  o.maxLeaves = 4;
  test::roundTrip("limits-capped", m, o);
  test::pack("limits-capped-summary", m, o, &capped);
  EXPECT_GT(free.manifest.nodes.size(), 20u);
  EXPECT_GE(capped.manifest.nodes.size(), 3u);
  EXPECT_LE(capped.manifest.nodes.size(), 7u);
  bool noted = false;
  for (const std::string& n : capped.notes)
    noted |= n.find("regions of up to 1024 vertices instead of 64") != std::string::npos;
  EXPECT_TRUE(noted);
}

// A manifest of more chunks than a reader takes is not written, and the pack already in the
// folder stays whole.
TEST(PackLimits, TooManyChunksAreRefusedAndTheEarlierPackStays) {
  const std::string dir = test::pack("limits-refused", test::harmonic(6), PackOptions{});
  const std::string before = test::loadFile(dir + "/manifest.json");
  Manifest m;
  ASSERT_TRUE(parseManifest(before, m));
  const size_t files = size_t(std::distance(std::filesystem::directory_iterator(dir + "/chunks"), {}));
  m.chunks.resize(kManifestMaxChunks + 1, m.chunks.back());
  Result r = writeManifestFiles(dir, m);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.status, Status::TooLarge);
  EXPECT_NE(r.message.find("more than the 262144 a reader takes"), std::string::npos) << r.message;
  EXPECT_EQ(test::loadFile(dir + "/manifest.json"), before);
  EXPECT_EQ(size_t(std::distance(std::filesystem::directory_iterator(dir + "/chunks"), {})), files);
}

}  // namespace
