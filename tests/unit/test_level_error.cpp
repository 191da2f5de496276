// The field error each chunk reports (pack/level_error.h; FORMAT.md §1), against brute force.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "dataset.h"
#include "pack/packer.h"
#include "test_helpers.h"

using namespace tetstream;
using namespace tetstream::test;

namespace {

// Each measured chunk's field error (FORMAT.md §1: fieldRms, fieldMax; the base, the last chunk
// of each level of the tree and the last chunk) equals a brute-force measurement on the level
// the chunk leaves: every input vertex located among all of the level's tets. The meter follows
// the splits locally; the brute force knows nothing of them.
void expectMeasuredLikeBruteForce(const std::string& name, const TetMesh& in, uint32_t minBaseVertices,
                                  uint32_t leafVertices) {
  PackOptions o;
  o.chunkKb = 1;
  o.minBaseVertices = minBaseVertices;
  o.leafVertices = leafVertices;
  PackSummary s;
  const std::string dir = pack(name, in, o, &s);
  const Manifest& m = s.manifest;
  ASSERT_GE(m.chunks.size(), 4u);
  const Range r = m.fields[0].range;
  const double step = (r.max - r.min) / 65535.0;  // the input is measured on the stream's grid
  size_t measured = 0;
  for (size_t k = 1; k <= m.chunks.size(); ++k) {
    if (m.chunks[k - 1].fieldRms < 0) continue;
    ++measured;
    Dataset level;
    ASSERT_TRUE(loadPackedDir(dir, level, int(k)));
    double sum = 0, max = 0;
    for (uint32_t v = 0; v < in.vertexCount(); ++v) {
      uint32_t tet = 0;
      double w[4] = {}, value = 0;
      bestTet(level.pm.mesh, &in.positions[3 * v], tet, w);
      for (int c = 0; c < 4; ++c) value += w[c] * level.pm.mesh.fields[0].values[level.pm.mesh.tets[4 * tet + c]];
      const double d = std::abs(value - in.fields[0].values[v]);
      sum += d * d;
      max = std::max(max, d);
    }
    const double rms = std::sqrt(sum / in.vertexCount());
    const ChunkInfo& c = m.chunks[k - 1];
    EXPECT_NEAR(c.fieldRms, rms, 3 * step)
        << name << ", chunk " << k;  // (the level loaded has its positions on the grid too)
    EXPECT_NEAR(c.fieldMax, max, 3 * step) << name << ", chunk " << k;
    if (k == 1) {
      EXPECT_GT(c.fieldMax, 20 * step) << "the base is coarse";
    }
  }
  EXPECT_LE(m.chunks.back().fieldMax, step);  // the full mesh: the input, on the grid
  EXPECT_GE(measured, leafVertices ? 3u : 2u) << "the base, the levels of the tree, the full mesh";
}

}  // namespace

TEST(LevelError, MeasuredLevelErrorsMatchBruteForce) {
  expectMeasuredLikeBruteForce("measured", harmonic(12), 0, 512);  // (levels of the tree: more measured chunks)
  // A non-convex domain, with a base large enough to keep its concave creases (where a coarser
  // one cuts across, input vertices lie outside it, and the brute force takes other tets for
  // them than the meter's walk: FORMAT.md §1).
  expectMeasuredLikeBruteForce("measured-l", lShape(12), 256, 0);
}

// Large inputs are measured on two threads, each taking half of the input's vertices: the
// figures must be those of one thread, to the bit.
TEST(LevelError, MeasuredLevelErrorsAlikeOnOneThreadAndTwo) {
  const TetMesh in = harmonic(26);  // 17,576 vertices: two threads from 16,384
  std::vector<ChunkInfo> chunks[2];
  std::vector<NodeInfo> nodes[2];
  for (int threads = 1; threads <= 2; ++threads) {
    PackOptions o;
    o.chunkKb = 8;
    o.threads = threads;
    o.leafVertices = 1024;
    PackSummary s;
    pack("measured-threads-" + std::to_string(threads), in, o, &s);
    chunks[threads - 1] = s.manifest.chunks;
    nodes[threads - 1] = s.manifest.nodes;
  }
  ASSERT_EQ(chunks[0].size(), chunks[1].size());
  ASSERT_GE(chunks[0].size(), 4u);
  for (size_t k = 0; k < chunks[0].size(); ++k) {
    EXPECT_EQ(chunks[0][k].fieldRms, chunks[1][k].fieldRms) << "chunk " << k;
    EXPECT_EQ(chunks[0][k].fieldMax, chunks[1][k].fieldMax) << "chunk " << k;
  }
  ASSERT_EQ(nodes[0].size(), nodes[1].size());
  ASSERT_GE(nodes[0].size(), 8u);
  for (size_t k = 0; k < nodes[0].size(); ++k) {
    EXPECT_EQ(nodes[0][k].fieldRms, nodes[1][k].fieldRms) << "node " << k;
    EXPECT_EQ(nodes[0][k].fieldMax, nodes[1][k].fieldMax) << "node " << k;
  }
}
