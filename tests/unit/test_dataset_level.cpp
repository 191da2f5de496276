// Level control of a dataset (dataset.h: stepTowards): undo and redo, and a chunk dropped when a
// record turns out bad while applying.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "dataset.h"
#include "pack/packer.h"
#include "test_helpers.h"

using namespace tetstream;
using namespace tetstream::test;

TEST(Level, UndoAndRedoReachTheSameMeshes) {
  TetMesh m = harmonic(9);
  PackOptions o;
  o.chunkKb = 1;
  std::string dir = pack("level", m, o);
  Dataset ds;
  ASSERT_TRUE(loadPackedDir(dir, ds, 1));
  for (uint32_t c = 1; c < ds.manifest.chunks.size(); ++c)
    ASSERT_TRUE(receiveChunk(ds, c, test::loadBytes(dir + "/" + ds.manifest.chunks[c].file)));
  const uint32_t total = ds.splitsReceived();
  ASSERT_EQ(ds.pm.baseVertices + total, m.vertexCount());
  std::vector<uint32_t> changed;
  bool reached;
  for (uint32_t target : {total, 0u, total / 3, total / 2, total / 5, total}) {
    ASSERT_TRUE(stepTowards(ds, target, ~0u, changed, &reached));
    ASSERT_TRUE(reached);
    Dataset fresh;
    ASSERT_TRUE(loadPackedDir(dir, fresh, -1, ds.pm.baseVertices + target));
    EXPECT_EQ(ds.pm.mesh.positions, fresh.pm.mesh.positions) << target;
    EXPECT_EQ(ds.pm.mesh.tets, fresh.pm.mesh.tets) << target;
    EXPECT_EQ(ds.pm.mesh.fields[0].values, fresh.pm.mesh.fields[0].values) << target;
    EXPECT_EQ(ds.chunksApplied(), fresh.chunksApplied()) << target;
  }
  EXPECT_EQ(ds.chunksApplied(), ds.manifest.chunks.size());
}

// A chunk whose hash matches a lying manifest: the bad record is found while applying, the
// chunk's splits are undone, it is dropped, and the level stays where the last good chunk ended.
TEST(Level, BadRecordInAHashedChunkUndoesItsChunk) {
  std::string dir = pack("bad-record", harmonic(9), [] {
    PackOptions o;
    o.chunkKb = 1;
    return o;
  }());
  Dataset ds;
  ASSERT_TRUE(loadPackedDir(dir, ds, 2));
  const uint32_t goodVertices = ds.pm.vertexCount(), goodTets = ds.pm.tetCount();
  ChunkInfo& info = ds.manifest.chunks[2];
  std::vector<uint8_t> bad = test::forgeTruncatedChunk(test::loadBytes(dir + "/" + info.file), info);
  ASSERT_FALSE(bad.empty());
  ASSERT_TRUE(receiveChunk(ds, 2, bad));
  std::vector<uint32_t> changed;
  bool reached;
  Result r = stepTowards(ds, ~0u, ~0u, changed, &reached);
  EXPECT_TRUE(r.status == Status::Truncated || r.status == Status::Corrupt) << r.message;
  EXPECT_NE(r.message.find("chunk 2"), std::string::npos) << r.message;
  EXPECT_EQ(ds.chunksReceived, 2u);
  EXPECT_EQ(ds.pm.vertexCount(), goodVertices);
  EXPECT_EQ(ds.pm.tetCount(), goodTets);
  expectValidLevel(ds.pm.mesh, "after the dropped chunk");
}
