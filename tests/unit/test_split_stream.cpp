// Split chunk records (split_stream.h, pack/split_encode.h): flags, columns and rows, moved
// tets and ring walks, and every malformed record refused with the level left as it was.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "chunk.h"
#include "dataset.h"
#include "pack/chunk_encode.h"
#include "pack/packer.h"
#include "split_stream.h"
#include "test_helpers.h"

using namespace tetstream;
using namespace tetstream::test;

TEST(SplitStream, CorruptSplitChunkKeepsTheLastCompleteLevel) {
  PackOptions o;
  o.chunkKb = 2;
  std::string dir = pack("corrupt-splits", harmonic(10), o);
  Dataset ds;
  ASSERT_TRUE(loadPackedDir(dir, ds, 2));
  const uint32_t v = ds.pm.vertexCount(), t = ds.pm.tetCount();
  const ChunkInfo info = ds.manifest.chunks[2];
  std::vector<uint8_t> bytes = test::loadBytes(dir + "/" + info.file);
  bytes[bytes.size() / 3] ^= 4;
  EXPECT_EQ(applyChunk(ds, 2, bytes).status, Status::HashMismatch);
  EXPECT_EQ(ds.pm.vertexCount(), v);
  EXPECT_EQ(ds.pm.tetCount(), t);
}

// Split flag bit 2: records carry p_j's kept value of the isoField only. Bit 1 (the first packers
// with fitted values) carried one per field; with one field the two read the same. Both at once is refused.
TEST(SplitStream, KeptValueFlagsAreReadAsDocumented) {
  PackOptions o;
  o.chunkKb = 2;
  TetMesh m = harmonic(10);
  m.fields.resize(1);
  std::string dir = pack("kept-flags", m, o);
  Dataset ref;
  ASSERT_TRUE(loadPackedDir(dir, ref, 2));
  // Chunk 1 with its flags word replaced, re-compressed, and the manifest entry to match.
  auto withFlags = [&](Dataset& ds, uint32_t flags) {
    const ChunkInfo info = ds.manifest.chunks[1];
    std::vector<uint8_t> file, raw = rawChunk(dir, info);
    EXPECT_EQ(raw.size(), info.rawBytes);
    uint32_t old;
    std::memcpy(&old, &raw[kChunkHeaderBytes + 4], 4);
    const uint32_t layout = kSplitFlagColumns | kSplitFlagImpliedMoved | kSplitFlagRingWalk;  // how records are stored
    EXPECT_EQ(old, kSplitFlagKeptIsoValue | layout);
    flags |= layout;
    std::memcpy(&raw[kChunkHeaderBytes + 4], &flags, 4);
    ChunkInfo& entry = ds.manifest.chunks[1];
    EXPECT_TRUE(finishChunk(raw, 3, file, entry));
    return applyChunk(ds, 1, file);
  };
  Dataset both;
  ASSERT_TRUE(loadPackedDir(dir, both, 1));
  EXPECT_EQ(withFlags(both, kSplitFlagKeptValues | kSplitFlagKeptIsoValue).status, Status::Corrupt);
  EXPECT_EQ(both.pm.vertexCount(), ref.manifest.chunks[0].vertices);
  Dataset old;
  ASSERT_TRUE(loadPackedDir(dir, old, 1));
  Result r = withFlags(old, kSplitFlagKeptValues);
  ASSERT_TRUE(r) << r.message;
  EXPECT_EQ(old.pm.mesh.tets, ref.pm.mesh.tets);
  EXPECT_EQ(old.pm.mesh.fields[0].values, ref.pm.mesh.fields[0].values);
}

static void readRowsAndColumns(bool lossless);

// The packer writes split records in columns (flag bit 3), most without a mask of T_moved (bit
// 4); packs written before that hold them one record after the other, each with its mask, and
// readers still read those. Rewriting every chunk of a pack that way, record by record (the
// mask made from the tets that moved), gives the same mesh at every chunk.
TEST(SplitStream, SplitRecordsReadTheSameInRowsWithMasks) {
  for (bool lossless : {false, true}) {
    SCOPED_TRACE(lossless ? "lossless" : "quantized");
    readRowsAndColumns(lossless);
  }
}

static void readRowsAndColumns(bool lossless) {
  PackOptions o;
  o.chunkKb = 1;
  o.lossless = lossless;
  const TetMesh m = harmonic(10);
  const std::string dir = pack(lossless ? "rows-lossless" : "rows", m, o);
  Dataset cols;
  ASSERT_TRUE(loadPackedDir(dir, cols, 1));
  std::string json;
  {
    std::vector<uint8_t> bytes = test::loadBytes(dir + "/manifest.json");
    json.assign(bytes.begin(), bytes.end());
  }
  Dataset rows;
  ASSERT_TRUE(openDataset(rows, json));
  ASSERT_TRUE(applyChunk(rows, 0, test::loadBytes(dir + "/" + rows.manifest.chunks[0].file)));
  ASSERT_GE(cols.manifest.chunks.size(), 4u);
  for (uint32_t c = 1; c < cols.manifest.chunks.size(); ++c) {
    const ChunkInfo info = cols.manifest.chunks[c];
    const std::vector<uint8_t> file = test::loadBytes(dir + "/" + info.file), raw = rawChunk(dir, info);
    ASSERT_EQ(raw.size(), info.rawBytes);
    uint32_t flags, length[kSplitColumns];
    std::memcpy(&flags, &raw[kChunkHeaderBytes + 4], 4);
    ASSERT_TRUE(flags & kSplitFlagColumns);
    std::memcpy(length, &raw[kChunkHeaderBytes + 8], sizeof length);
    size_t columnAt[kSplitColumns], at = kChunkHeaderBytes + 8 + sizeof length;
    for (uint32_t k = 0; k < kSplitColumns; ++k) {
      columnAt[k] = at;
      at += length[k];
    }
    ASSERT_EQ(at, raw.size());
    // Each record's bytes in each column, from where the reader was before and after it.
    std::vector<uint8_t> row(raw.begin(), raw.begin() + kChunkHeaderBytes + 8);
    ASSERT_TRUE(flags & kSplitFlagImpliedMoved);
    flags &= ~(kSplitFlagColumns | kSplitFlagImpliedMoved);
    std::memcpy(&row[kChunkHeaderBytes + 4], &flags, 4);
    ASSERT_TRUE(receiveChunk(cols, c, file));
    const uint32_t first = cols.splitsApplied();
    for (uint32_t g = first; g < first + info.splits; ++g) {
      std::vector<uint32_t> changed, starAfter;
      bool reached;
      ASSERT_TRUE(stepTowards(cols, g + 1, 1, changed, &reached));
      // The tets around p_j before the split: those still around it but new, and the moved
      // ones, which now hold p_i instead.
      const ProgressiveMesh& pm = cols.pm;
      const uint32_t i = pm.vertexCount() - 1, j = pm.splitJ[g], before = pm.splitTetsBefore[g];
      std::vector<uint32_t> star, moved;
      starOf(pm, j, starAfter);
      for (uint32_t t : starAfter)
        if (t < before) star.push_back(t);
      starOf(pm, i, starAfter);
      for (uint32_t t : starAfter)
        if (t < before) moved.push_back(t);
      star.insert(star.end(), moved.begin(), moved.end());
      std::sort(star.begin(), star.end());
      std::vector<uint8_t> mask((star.size() + 7) / 8, 0);
      for (size_t k = 0; k < star.size(); ++k)
        if (std::binary_search(moved.begin(), moved.end(), star[k])) mask[k >> 3] |= uint8_t(1u << (k & 7));
      for (uint32_t k = 0; k < kSplitColumns; ++k) {
        if (SplitColumn(k) == SplitColumn::Moved) {
          row.insert(row.end(), mask.begin(), mask.end());
          continue;
        }
        const uint32_t from = g == first ? 0 : cols.recordStart[kSplitColumns * g + k];
        const uint32_t to = cols.recordStart[kSplitColumns * (g + 1) + k];
        row.insert(row.end(), raw.begin() + long(columnAt[k] + from), raw.begin() + long(columnAt[k] + to));
      }
    }
    std::vector<uint8_t> rowFile;
    ASSERT_TRUE(finishChunk(row, 3, rowFile, rows.manifest.chunks[c]));
    Result r = applyChunk(rows, c, rowFile);
    ASSERT_TRUE(r) << "chunk " << c << ": " << r.message;
    EXPECT_EQ(rows.pm.mesh.tets, cols.pm.mesh.tets) << "chunk " << c;
    EXPECT_EQ(rows.pm.mesh.positions, cols.pm.mesh.positions) << "chunk " << c;
    for (size_t f = 0; f < m.fields.size(); ++f)
      EXPECT_EQ(rows.pm.mesh.fields[f].values, cols.pm.mesh.fields[f].values) << "chunk " << c << ", field " << f;
  }
  EXPECT_EQ(rows.pm.vertexCount(), m.vertexCount());
}

// A chunk whose column lengths do not add up to its payload is refused when it arrives.
TEST(SplitStream, SplitColumnsThatDoNotFillThePayloadAreRefused) {
  PackOptions o;
  o.chunkKb = 2;
  const std::string dir = pack("columns-bad", harmonic(8), o);
  for (int change : {-1, +1}) {
    Dataset ds;
    ASSERT_TRUE(loadPackedDir(dir, ds, 1));
    const ChunkInfo info = ds.manifest.chunks[1];
    std::vector<uint8_t> file, raw = rawChunk(dir, info);
    ASSERT_EQ(raw.size(), info.rawBytes);
    uint32_t length;
    const size_t at = kChunkHeaderBytes + 8 + 4 * uint32_t(SplitColumn::NewTets);
    std::memcpy(&length, &raw[at], 4);
    length += uint32_t(change);
    std::memcpy(&raw[at], &length, 4);
    ASSERT_TRUE(finishChunk(raw, 3, file, ds.manifest.chunks[1]));
    const uint32_t v = ds.pm.vertexCount();
    Result r = applyChunk(ds, 1, file);
    EXPECT_TRUE(r.status == Status::Corrupt || r.status == Status::Truncated) << r.message;
    EXPECT_NE(r.message.find("column"), std::string::npos) << r.message;
    EXPECT_EQ(ds.pm.vertexCount(), v);
    EXPECT_EQ(ds.chunksReceived, 1u);
  }
}

// T_moved follows from T_new (vertex_link.h) for all but a few splits of real packs: on a
// cube, on a mesh with a non-convex boundary and creases, and with flat input tets.
TEST(SplitStream, MovedTetsFollowFromNewTetsOnAlmostEverySplit) {
  TetMesh flat = harmonic(12);  // one vertex pushed onto the layer below: flat tets around it
  flat.positions[3 * gridVertex(12, 5, 5, 5) + 2] = flat.positions[3 * gridVertex(12, 5, 5, 4) + 2];
  PackOptions o;
  for (const auto& [name, mesh] :
       {std::pair{"moved-cube", harmonic(12)}, std::pair{"moved-l", lShape(12)}, std::pair{"moved-flat", flat}}) {
    PackSummary s;
    pack(name, mesh, o, &s);
    EXPECT_GT(s.splits, 500u) << name;
    EXPECT_LE(s.movedMasks, s.splits / 100) << name;
  }
}

// Rings as walks in p_j's link (flag bit 5) and as places among all of p_j's neighbours (packs
// before that flag) decode to the same mesh; the walks take fewer bytes.
TEST(SplitStream, RingWalksDecodeLikePlainRingsInFewerBytes) {
  const TetMesh m = lShape(12);
  PackOptions o;
  o.lossless = true;
  PackSummary walk, plain;
  const std::string a = pack("ring-walk", m, o, &walk);
  o.ringWalk = false;
  const std::string b = pack("ring-plain", m, o, &plain);
  Dataset da, db;
  ASSERT_TRUE(loadPackedDir(a, da));
  ASSERT_TRUE(loadPackedDir(b, db));
  EXPECT_EQ(da.pm.mesh.tets, db.pm.mesh.tets);
  EXPECT_EQ(da.pm.mesh.positions, db.pm.mesh.positions);
  EXPECT_EQ(da.pm.vertexCount(), m.vertexCount());
  EXPECT_LT(walk.manifest.totalBytes(), plain.manifest.totalBytes() * 0.97);
}

// The moved marker is 0 or 1; anything else is refused, and the chunk leaves the level as it was.
TEST(SplitStream, AMovedMarkerOtherThanZeroOrOneIsRefused) {
  PackOptions o;
  o.chunkKb = 2;
  const std::string dir = pack("moved-marker", harmonic(8), o);
  Dataset ds;
  ASSERT_TRUE(loadPackedDir(dir, ds, 1));
  const ChunkInfo info = ds.manifest.chunks[1];
  std::vector<uint8_t> file, raw = rawChunk(dir, info);
  ASSERT_EQ(raw.size(), info.rawBytes);
  uint32_t length[kSplitColumns];
  std::memcpy(length, &raw[kChunkHeaderBytes + 8], sizeof length);
  size_t at = kChunkHeaderBytes + 8 + sizeof length;  // the Moved column follows the KeptVertex one
  at += length[uint32_t(SplitColumn::KeptVertex)];
  ASSERT_EQ(raw[at], 0) << "the first record's T_moved follows from T_new";
  raw[at] = 2;
  ASSERT_TRUE(finishChunk(raw, 3, file, ds.manifest.chunks[1]));
  const uint32_t v = ds.pm.vertexCount(), t = ds.pm.tetCount();
  Result r = applyChunk(ds, 1, file);
  EXPECT_EQ(r.status, Status::Corrupt) << r.message;
  EXPECT_NE(r.message.find("marker"), std::string::npos) << r.message;
  EXPECT_EQ(ds.pm.vertexCount(), v);
  EXPECT_EQ(ds.pm.tetCount(), t);
}

// The undo log holds one value a split, the isoField's, however many fields there are (none
// with --samples); a chunk whose records carry another kind of kept values than the splits
// before it is refused and leaves the level as it was.
TEST(SplitStream, UndoLogKeepsOnlyTheFittedFieldsValue) {
  PackOptions o;
  o.chunkKb = 2;
  const TetMesh m = harmonic(10);
  ASSERT_EQ(m.fields.size(), 2u);
  std::string dir = pack("undo-log", m, o);
  Dataset ds;
  ASSERT_TRUE(loadPackedDir(dir, ds, 3));
  ASSERT_GT(ds.pm.splitsApplied(), 0u);
  EXPECT_EQ(ds.pm.splitJValues.size(), ds.pm.splitsApplied());
  EXPECT_EQ(ds.pm.keptFirst, uint32_t(ds.manifest.findField(ds.manifest.isoField)));
  // Chunk 3 written without kept values (as --samples would), after two chunks with them.
  const ChunkInfo info = ds.manifest.chunks[3];
  std::vector<uint8_t> file, raw = rawChunk(dir, info);
  ASSERT_EQ(raw.size(), info.rawBytes);
  const uint32_t none = kSplitFlagColumns | kSplitFlagImpliedMoved | kSplitFlagRingWalk;
  std::memcpy(&raw[kChunkHeaderBytes + 4], &none, 4);
  ASSERT_TRUE(finishChunk(raw, 3, file, ds.manifest.chunks[3]));
  const uint32_t v = ds.pm.vertexCount();
  Result r = applyChunk(ds, 3, file);
  EXPECT_EQ(r.status, Status::Corrupt) << r.message;
  EXPECT_NE(r.message.find("kept values"), std::string::npos) << r.message;
  EXPECT_EQ(ds.pm.vertexCount(), v);

  PackOptions samples = o;
  samples.fitValues = false;
  std::string plain = pack("undo-log-samples", m, samples);
  Dataset ps;
  ASSERT_TRUE(loadPackedDir(plain, ps));
  EXPECT_GT(ps.pm.splitsApplied(), 0u);
  EXPECT_TRUE(ps.pm.splitJValues.empty());
}
