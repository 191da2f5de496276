// Packs end to end: pack (simplify + encode), then decode every prefix. Every prefix is a valid
// conforming mesh with no inverted or flat tets; all chunks give back the input (bit-exact
// lossless, within half a grid step otherwise); packing is deterministic; chunk sizes taper.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "dataset.h"
#include "pack/packer.h"
#include "test_helpers.h"
#include "validate.h"

using namespace tetstream;
using namespace tetstream::test;

TEST(PackRoundTrip, HarmonicLosslessRoundTripIsBitExact) {
  PackOptions o;
  o.lossless = true;
  roundTrip("harmonic-lossless", harmonic(12), o);
}

TEST(PackRoundTrip, HarmonicQuantizedRoundTripWithinHalfAStep) {
  roundTrip("harmonic-16bit", harmonic(12), PackOptions{});
}

TEST(PackRoundTrip, NonConvexDomainWithCreases) {
  PackOptions o;
  o.lossless = true;
  roundTrip("lshape", lShape(11), o);
}

TEST(PackRoundTrip, PackingIsDeterministic) {
  TetMesh m = harmonic(10);
  PackOptions o;
  o.chunkKb = 2;
  std::string a = pack("det-a", m, o), b = pack("det-b", m, o);
  expectSamePack(a, b);
}

// pack --compact: inside each chunk the splits go by kept vertex (split_order.h). Every level
// must still be valid, also between chunk boundaries, split by split (each split meets the
// neighbourhood it met in cost order), the last level must be the input, and the pack
// deterministic.
TEST(PackRoundTrip, SplitsInKeptVertexOrderRoundTripExactly) {
  PackOptions o;
  o.lossless = true;
  o.orderSplits = true;
  roundTrip("ordered-lossless", harmonic(12), o);
  roundTrip("ordered-lshape", lShape(11), o);
  o.chunkKb = 2;
  const TetMesh m = harmonic(10);
  std::string a = pack("ordered-a", m, o), b = pack("ordered-b", m, o);
  expectSamePack(a, b);
  Dataset ds;
  ASSERT_TRUE(loadPackedDir(a, ds, 1));
  ASSERT_GE(ds.manifest.chunks.size(), 4u);
  for (uint32_t c = 1; c < ds.manifest.chunks.size(); ++c)
    ASSERT_TRUE(receiveChunk(ds, c, test::loadBytes(a + "/" + ds.manifest.chunks[c].file)));
  std::vector<uint32_t> changed;
  bool reached;
  while (ds.splitsApplied() < ds.splitsReceived()) {
    ASSERT_TRUE(stepTowards(ds, ds.splitsApplied() + 3, ~0u, changed, &reached));
    const ValidationReport r = validateMesh(ds.pm.mesh);
    ASSERT_EQ(r.negativeTets + r.zeroVolumeTets + r.nonManifoldFaces + r.duplicateTets, 0u)
        << "after " << ds.splitsApplied() << " splits";
  }
}

// Tets given in the other orientation are turned around before packing, and the face adjacency
// the validation built is turned with them for the simplifier: the pack must not change.
TEST(PackRoundTrip, FlippedInputTetsPackAsTheOriginal) {
  TetMesh m = harmonic(10), flipped = m;
  for (uint32_t t = 0; t < flipped.tetCount(); t += 3) std::swap(flipped.tets[4 * t + 2], flipped.tets[4 * t + 3]);
  PackOptions o;
  PackSummary a, b;
  std::string da = pack("flip-a", m, o, &a), db = pack("flip-b", flipped, o, &b);
  EXPECT_EQ(b.flippedTets, (m.tetCount() + 2) / 3);
  expectSamePack(da, db);
}

// Chunk sizes (FORMAT.md): split chunks double up to --chunk-kb, then halve again towards the
// end, so that the last chunk a viewer has to apply after the last byte is small; a rest smaller
// than the first chunk's size stays in the chunk before it.
TEST(PackRoundTrip, LastChunksHalveTowardsTheEnd) {
  PackOptions o;
  o.chunkKb = 64;
  o.minBaseVertices = 0;
  o.leafVertices = 0;  // (one node, the root, whose chunks taper: packer.h)
  const std::string dir = pack("taper", harmonic(36), o);
  Dataset d;
  ASSERT_TRUE(loadPackedDir(dir, d, 0));
  std::vector<uint64_t> bytes;
  for (size_t c = 1; c < d.manifest.chunks.size(); ++c) bytes.push_back(d.manifest.chunks[c].bytes);
  ASSERT_GE(bytes.size(), 6u);
  std::string sizes;
  for (uint64_t b : bytes) sizes += std::to_string(b) + " ";
  RecordProperty("chunk_bytes", sizes);
  const uint64_t largest = *std::max_element(bytes.begin(), bytes.end());
  size_t top = 0;  // the last chunk of the largest size class
  for (size_t c = 0; c < bytes.size(); ++c)
    if (bytes[c] * 10 >= largest * 9) top = c;
  ASSERT_LE(top + 3, bytes.size()) << "at least two smaller chunks after the large ones";
  for (size_t c = top + 1; c + 1 < bytes.size(); ++c)
    EXPECT_LT(bytes[c + 1], bytes[c]) << "chunk " << c + 2 << " after " << c + 1;
  EXPECT_LT(bytes.back(), 40u << 10) << "the last chunk is small (the first split chunk aims at 16 KB)";
}
