// Encoding a part's log as a unit (pack/split_encode.h: encodeUnit, finishUnitChunk): from its
// handoff in stable id order, records naming vertices by stable id. One unit with the base's ids
// is encodeStream's stream in other chunks; ids in another order or with gaps change exactly the
// ids the records write (the kept vertex, explicit new-tet vertices) and nothing a reader decodes.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "chunk.h"
#include "dataset.h"
#include "pack/chunk_encode.h"
#include "pack/region_stats.h"
#include "pack/simplify.h"
#include "pack/split_encode.h"
#include "partial.h"
#include "quantize.h"
#include "split_stream.h"
#include "test_helpers.h"
#include "varint.h"

using namespace tetstream;
using namespace tetstream::test;

namespace {

constexpr uint64_t kNoId = ~uint64_t(0);

// The input as the packer prepares it: a manifest of its bounds and ranges, positions and fields
// snapped to that grid.
struct Input {
  TetMesh mesh;
  Manifest m;
};

Manifest manifestOf(const TetMesh& mesh, bool lossless) {
  Manifest m;
  m.generator = "test";
  m.name = "unit";
  m.bounds = computeBounds(mesh.positions);
  for (const ScalarField& f : mesh.fields) m.fields.push_back({f.name, computeRange(f.values)});
  m.isoField = mesh.fields[0].name;
  m.lossless = lossless;
  return m;
}

Input snappedInput(TetMesh mesh) {
  Input in;
  in.m = manifestOf(mesh, false);
  const Quantizer q = makeQuantizer(in.m);
  for (size_t k = 0; k < mesh.positions.size(); ++k) mesh.positions[k] = q.position[k % 3].snap(mesh.positions[k]);
  for (size_t f = 0; f < mesh.fields.size(); ++f)
    for (float& x : mesh.fields[f].values) x = q.field[f].snap(x);
  in.mesh = std::move(mesh);
  return in;
}

// Harmonic 16³ simplified in a tree of small regions (about twenty nodes).
struct Simplified {
  Input in;
  SimplifyResult s;
  RegionStats stats;
};

const Simplified& simplified() {
  static const Simplified c = [] {
    Simplified c;
    c.in = snappedInput(harmonic(16));
    SimplifyOptions so;
    so.leafVertices = 128;
    so.targetVertices = c.in.mesh.vertexCount() / 50;
    EXPECT_TRUE(simplifyMesh(c.in.mesh, so, c.s));
    EXPECT_GE(c.s.tree.sectionNode.size(), 8u);
    c.stats = regionStats(c.in.mesh, c.s, c.in.m);
    return c;
  }();
  return c;
}

StreamOptions smallChunks() {
  StreamOptions o;
  o.chunkBytes = 2 << 10;
  o.firstChunkBytes = 1 << 10;
  o.zstdLevel = 3;
  return o;
}

// Stable ids as encodeStream numbers its base: alive vertices and tets in input order.
UnitEncodeOptions baseOrder(const SimplifyResult& s) {
  UnitEncodeOptions o;
  o.stream = smallChunks();
  for (uint8_t alive : s.vertexAlive) o.stableVertex.push_back(alive ? o.vertexBegin++ : kNoId);
  for (uint8_t alive : s.tetAlive) o.stableTet.push_back(alive ? o.tetBegin++ : kNoId);
  return o;
}

// A dataset in memory: the manifest (as JSON too) and every chunk file.
struct Assembled {
  Manifest m;
  std::string json;
  std::vector<std::vector<uint8_t>> files;
};

std::string fileName(uint32_t index) { return "chunks/" + std::to_string(index) + ".tsc"; }

void finishManifest(Assembled& a, std::vector<NodeInfo> nodes) {
  a.m.vertices = a.m.chunks.back().vertices;
  a.m.tets = a.m.chunks.back().tets;
  if (nodes.size() > 1) a.m.nodes = std::move(nodes);  // (one node: a plain sequence, as the packer writes)
  a.json = writeManifest(a.m);
}

// What a driver writes for units that make the whole stream, here one: `base` as chunk 0, the
// unit's chunks from 1 on, each chunk's field error the largest of the collapses after it, and a
// node per UnitNode whose parent is its nearest ancestor in the tree with a node.
Assembled assembleUnit(const Manifest& top, const TetMesh& base, UnitEncoded& u, const RegionTree& tree,
                       const RegionStats* stats) {
  Assembled a;
  a.m = top;
  const int iso = top.findField(top.isoField);
  const double range = top.fields[size_t(iso)].range.max - top.fields[size_t(iso)].range.min;
  std::vector<double> after(u.chunks.size() + 1, 0.0);  // per chunk: the largest error of the chunks after it
  for (size_t k = u.chunks.size(); k-- > 0;) after[k] = std::max(after[k + 1], double(u.chunks[k].maxCollapseError));
  a.files.resize(u.chunks.size() + 1);
  ChunkInfo info;
  EXPECT_TRUE(encodeBaseChunk(base, 0, 3, a.files[0], info));
  info.file = fileName(0);
  info.fieldError = std::min(range, after[0]);
  a.m.chunks.push_back(info);
  for (uint32_t k = 0; k < u.chunks.size(); ++k) {
    Result r = finishUnitChunk(u.chunks[k], k + 1, 3, a.files[k + 1], info);
    EXPECT_TRUE(r) << r.message;
    info.file = fileName(k + 1);
    info.fieldError = std::min(range, after[k + 1]);
    a.m.chunks.push_back(info);
  }
  std::vector<NodeInfo> nodes;
  std::vector<int32_t> indexOf(std::max<uint32_t>(tree.nodes(), 2), -1);
  for (const UnitNode& n : u.nodes) {
    NodeInfo& info = nodes.emplace_back();
    for (uint32_t up = n.node >> 1; up >= 1 && info.parent < 0; up >>= 1) info.parent = indexOf[up];
    info.firstChunk = n.firstChunk + 1;
    info.chunkCount = n.chunkCount;
    info.vertexBegin = uint32_t(n.vertexBegin);
    info.vertexEnd = uint32_t(n.vertexEnd);
    info.tetBegin = uint32_t(n.tetBegin);
    info.tetEnd = uint32_t(n.tetEnd);
    if (stats) {
      info.bounds = stats->bounds[n.node];
      info.ranges = stats->ranges[n.node];
      info.fieldError = std::min(range, double(stats->fieldError[n.node]));
    }
    indexOf[n.node] = int32_t(nodes.size() - 1);
  }
  finishManifest(a, std::move(nodes));
  return a;
}

// encodeStream's output as a dataset (as packMesh writes it).
Assembled assembleStream(const Manifest& top, EncodedStream& e) {
  Assembled a;
  a.m = top;
  a.files.push_back(e.baseFile);
  a.m.chunks.push_back(e.baseInfo);
  a.m.chunks.back().file = fileName(0);
  for (size_t c = 0; c < e.files.size(); ++c) {
    a.files.push_back(e.files[c]);
    a.m.chunks.push_back(e.chunks[c]);
    a.m.chunks.back().file = fileName(uint32_t(c + 1));
  }
  finishManifest(a, e.nodes);
  return a;
}

// Applies every chunk in order, checking the counts (and, when asked, each level).
void decodeAll(const Assembled& a, Dataset& ds, bool validLevels, const std::string& what) {
  Result r = openDataset(ds, a.json);
  ASSERT_TRUE(r) << what << ": " << r.message;
  for (uint32_t c = 0; c < a.files.size(); ++c) {
    r = applyChunk(ds, c, a.files[c]);
    ASSERT_TRUE(r) << what << ", chunk " << c << ": " << r.message;
    EXPECT_EQ(ds.pm.vertexCount(), a.m.chunks[c].vertices) << what << ", chunk " << c;
    EXPECT_EQ(ds.pm.tetCount(), a.m.chunks[c].tets) << what << ", chunk " << c;
    if (validLevels) expectValidLevel(ds.pm.mesh, what + " after chunk " + std::to_string(c));
  }
}

ChunkSource memorySource(const Assembled& a) {
  return [&a](uint32_t index, std::vector<uint8_t>& file) {
    file = a.files.at(index);
    return Result::success();
  };
}

// The nodes for an isovalue at `at` of the isoField's range, applied to a partial dataset.
void loadForIsovalue(const Assembled& a, double at, PartialDataset& pd, std::vector<uint32_t>& nodes) {
  ASSERT_TRUE(openPartial(pd, a.json, memorySource(a)));
  const Range range = a.m.fields[0].range;
  nodes = nodesForIsovalue(a.m, 0, float(range.min + at * (range.max - range.min)));
  for (uint32_t k : nodes) {
    Result r = applyNode(pd, k, memorySource(a));
    ASSERT_TRUE(r) << "node " << k << ": " << r.message;
  }
}

void expectSameArrays(const TetMesh& a, const TetMesh& b, const std::string& what) {
  EXPECT_EQ(a.positions, b.positions) << what;
  EXPECT_EQ(a.tets, b.tets) << what;
  ASSERT_EQ(a.fields.size(), b.fields.size()) << what;
  for (size_t f = 0; f < a.fields.size(); ++f) EXPECT_EQ(a.fields[f].values, b.fields[f].values) << what;
}

// The split records of a unit, over all its chunks: each record's kept vertex j, and the bytes of
// every other column (records do not straddle chunks, so these do not depend on where chunks end).
struct Records {
  std::vector<uint32_t> j;
  std::vector<uint8_t> columns[kSplitColumns];
};

Records recordsOf(const std::vector<UnitChunk>& chunks) {
  Records out;
  for (const UnitChunk& chunk : chunks) {
    ByteReader in{std::span<const uint8_t>(chunk.raw).subspan(kChunkHeaderBytes)};
    uint32_t splits = 0, flags = 0, length[kSplitColumns];
    EXPECT_TRUE(in.u32(splits) && in.u32(flags));
    EXPECT_TRUE(flags & kSplitFlagColumns);
    for (uint32_t& l : length) EXPECT_TRUE(in.u32(l));
    for (uint32_t c = 0; c < kSplitColumns; ++c) {
      const uint8_t* p = nullptr;
      EXPECT_TRUE(in.bytes(length[c], p));
      if (c > 0) {
        out.columns[c].insert(out.columns[c].end(), p, p + length[c]);
        continue;
      }
      ByteReader column{std::span<const uint8_t>(p, length[c])};
      uint32_t prev = 0, delta = 0;  // zz(j − j_prev), from 0 in each chunk
      for (uint32_t k = 0; k < splits; ++k) {
        EXPECT_TRUE(column.varint(delta));
        out.j.push_back(prev += uint32_t(unzigzag(delta)));
      }
      EXPECT_TRUE(column.atEnd());
    }
    EXPECT_TRUE(in.atEnd());
  }
  return out;
}

// A base of `vertices` and `tets` stable ids with the handoff at the given ones (ascending, per
// rank) and filler elsewhere: unused vertices at the bounds' corner, and tets made of those
// alone, which no split meets. Stands for what other units created before this one.
TetMesh baseWithGaps(const TetMesh& handoff, const std::vector<uint32_t>& vertexIds, uint32_t vertices,
                     const std::vector<uint32_t>& tetIds, uint32_t tets, const Manifest& m) {
  TetMesh b;
  b.fields.resize(handoff.fields.size());
  for (size_t f = 0; f < b.fields.size(); ++f) b.fields[f].name = handoff.fields[f].name;
  std::vector<uint32_t> filler;
  for (uint32_t x = 0, k = 0; x < vertices; ++x) {
    const bool real = k < vertexIds.size() && vertexIds[k] == x;
    for (int a = 0; a < 3; ++a) b.positions.push_back(real ? handoff.positions[3 * k + a] : m.bounds.min[a]);
    for (size_t f = 0; f < b.fields.size(); ++f)
      b.fields[f].values.push_back(real ? handoff.fields[f].values[k] : m.fields[f].range.min);
    if (real)
      ++k;
    else
      filler.push_back(x);
  }
  for (uint32_t y = 0, k = 0, d = 0; y < tets; ++y) {
    if (k < tetIds.size() && tetIds[k] == y) {
      for (int a = 0; a < 4; ++a) b.tets.push_back(vertexIds[handoff.tets[4 * k + a]]);
      ++k;
    } else {
      for (size_t a = 0; a < 4; ++a) b.tets.push_back(filler[(d + a) % filler.size()]);
      ++d;
    }
  }
  return b;
}

// A handcrafted part whose one split recreates a tet with two vertices that are no neighbours of
// the kept vertex: its record names them explicitly (L + id). Vertices 0-3 and 4-7 are two
// separate tets; collapse hec(8 → 0) removed the tet (8, 0, 4, 5).
struct Handmade {
  TetMesh mesh;
  Manifest m;
  SimplifyResult s;
};

Handmade handmade() {
  Handmade h;
  h.mesh.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 3, 0, 0, 3, 1, 0, 4, 0, 0, 3, 0, 1, 1.5f, 0, -1};
  h.mesh.tets = {0, 1, 2, 3, 4, 6, 5, 7, 8, 0, 4, 5};
  h.mesh.fields.push_back({"f", {0, 1, 2, 3, 4, 5, 6, 7, 8}});
  h.m = manifestOf(h.mesh, true);
  SimplifyResult& s = h.s;
  s.tets = h.mesh.tets;
  s.tetAlive = {1, 1, 0};
  s.vertexAlive = {1, 1, 1, 1, 1, 1, 1, 1, 0};
  s.values = h.mesh.fields[0].values;
  s.vertices = 8;
  s.tetCount = 2;
  s.log.i = {8};
  s.log.j = {0};
  s.log.fieldError = {0.25f};
  s.log.iValue = {8};
  s.log.jValue = {0};
  CollapseTets t;
  t.removed = {2};
  t.others = {4, 5};
  s.log.appendTets(t, 0);
  s.log.close(false);
  return h;
}

}  // namespace

// One unit whose handoff has encodeStream's base ids is encodeStream's stream: the same base, the
// same nodes, the same mesh at the end and for any set of nodes; only where chunks end differs
// (an assumed compression ratio instead of the measured one). Every level is valid, the last is
// the input, and startVertex/startTet are encodeStream's streamVertexOf/streamTetOf.
TEST(EncodeUnit, OneUnitWithTheBaseIdsIsTheWholeStream) {
  const Simplified& c = simplified();
  SimplifyResult s1 = c.s, s2 = c.s;
  UnitEncodeOptions o = baseOrder(c.s);
  UnitEncoded u;
  Result r = encodeUnit(c.in.mesh, s1, c.in.m, o, u);
  ASSERT_TRUE(r) << r.message;
  EncodedStream e;
  ASSERT_TRUE(encodeStream(c.in.mesh, s2, c.in.m, smallChunks(), e));

  expectSameArrays(u.handoff, e.base, "handoff and base");
  ASSERT_EQ(u.startVertex.size(), e.streamVertexOf.size());
  for (size_t v = 0; v < u.startVertex.size(); ++v)
    ASSERT_EQ(u.startVertex[v], e.streamVertexOf[v] == ~0u ? kNoId : e.streamVertexOf[v]) << "vertex " << v;
  ASSERT_EQ(u.startTet.size(), e.streamTetOf.size());
  for (size_t t = 0; t < u.startTet.size(); ++t)
    ASSERT_EQ(u.startTet[t], e.streamTetOf[t] == ~0u ? kNoId : e.streamTetOf[t]) << "tet " << t;

  // Nodes: encodeStream's, in its order; each node's chunks hold its splits, one after the other.
  const Assembled unit = assembleUnit(c.in.m, u.handoff, u, c.s.tree, &c.stats);
  const Assembled stream = assembleStream(c.in.m, e);
  ASSERT_EQ(unit.m.nodes.size(), stream.m.nodes.size());
  ASSERT_EQ(u.nodes.size(), e.nodes.size());
  uint32_t chunk = 0;
  for (size_t k = 0; k < u.nodes.size(); ++k) {
    const UnitNode& n = u.nodes[k];
    const NodeInfo& want = e.nodes[k];
    EXPECT_EQ(unit.m.nodes[k].parent, want.parent) << "node " << k;
    EXPECT_EQ(n.vertexBegin, want.vertexBegin) << "node " << k;
    EXPECT_EQ(n.vertexEnd, want.vertexEnd) << "node " << k;
    EXPECT_EQ(n.tetBegin, want.tetBegin) << "node " << k;
    EXPECT_EQ(n.tetEnd, want.tetEnd) << "node " << k;
    EXPECT_EQ(n.firstChunk, chunk) << "node " << k;
    ASSERT_GE(n.chunkCount, 1u);
    chunk += n.chunkCount;
    uint64_t splits = 0;
    float error = 0;
    for (uint32_t x = n.firstChunk; x < n.firstChunk + n.chunkCount; ++x) {
      splits += u.chunks[x].splits;
      error = std::max(error, u.chunks[x].maxCollapseError);
    }
    EXPECT_EQ(splits, n.vertexEnd - n.vertexBegin) << "node " << k;
    EXPECT_LE(std::min(error, float(c.in.m.fields[0].range.max - c.in.m.fields[0].range.min)), want.fieldError)
        << "node " << k << ": its splits' errors are among those below it";
  }
  EXPECT_EQ(chunk, u.chunks.size());
  EXPECT_GT(u.chunks.size(), u.nodes.size()) << "small chunks: several for some nodes";
  float largest = 0;
  for (const UnitChunk& x : u.chunks) largest = std::max(largest, x.maxCollapseError);
  EXPECT_EQ(largest, *std::max_element(c.s.log.fieldError.begin(), c.s.log.fieldError.end()));

  Dataset a, b;
  decodeAll(unit, a, true, "unit");
  decodeAll(stream, b, false, "stream");
  if (HasFatalFailure()) return;
  expectSameArrays(a.pm.mesh, b.pm.mesh, "the whole stream");
  expectSameMesh(c.in.mesh, a.pm.mesh, a.quant, false);

  // Any set of nodes: the same mesh from either dataset.
  for (double at : {0.2, 0.5, 0.8}) {
    PartialDataset pa, pb;
    std::vector<uint32_t> na, nb;
    loadForIsovalue(unit, at, pa, na);
    loadForIsovalue(stream, at, pb, nb);
    if (HasFatalFailure()) return;
    EXPECT_EQ(na, nb);
    EXPECT_LT(na.size(), unit.m.nodes.size());
    expectSameArrays(pa.pm.mesh, pb.pm.mesh, "the nodes of an isovalue at " + std::to_string(at));
  }
}

// Measured at every vertex (a rank's own part measures at the vertices it owns, its input at full
// resolution), a unit's nodes have encodeStream's measured field errors, to the bit: the same
// level meshes, measured at the same points. Without vertices to measure at, none.
TEST(EncodeUnit, NodesMeasuredAtTheirVerticesHaveTheStreamsErrors) {
  const Simplified& c = simplified();
  SimplifyResult s1 = c.s, s2 = c.s, s3 = c.s;
  UnitEncodeOptions o = baseOrder(c.s);
  const std::vector<uint8_t> all(c.in.mesh.vertexCount(), 1);
  o.measureAt = &all;
  UnitEncoded u, plain;
  Result r = encodeUnit(c.in.mesh, s1, c.in.m, o, u);
  ASSERT_TRUE(r) << r.message;
  EncodedStream e;
  ASSERT_TRUE(encodeStream(c.in.mesh, s2, c.in.m, smallChunks(), e));
  ASSERT_EQ(u.nodes.size(), e.nodes.size());
  for (size_t k = 0; k < u.nodes.size(); ++k) {
    EXPECT_GE(e.nodes[k].fieldMax, 0) << "node " << k;
    EXPECT_EQ(u.nodes[k].fieldRms, e.nodes[k].fieldRms) << "node " << k;
    EXPECT_EQ(u.nodes[k].fieldMax, e.nodes[k].fieldMax) << "node " << k;
  }
  EXPECT_GT(e.nodes[0].fieldMax, e.nodes.back().fieldMax) << "the base is coarser than the last level";
  o.measureAt = nullptr;
  ASSERT_TRUE(encodeUnit(c.in.mesh, s3, c.in.m, o, plain));
  for (const UnitNode& n : plain.nodes) EXPECT_EQ(n.fieldMax, -1);
}

// Stable ids with gaps (as where other units' vertices and tets come between), in the same order
// as the base's: every order by id is the same, so the records differ in the ids they write and
// nothing else. j is the gapped id of the same vertex in every record (the new vertices' ids
// shifted to the unit's range), every other column is byte for byte the same, and the dataset
// (the handoff with filler in the gaps) decodes to the same mesh under the id map.
TEST(EncodeUnit, StableIdsWithGapsChangeOnlyTheIdsRecordsWrite) {
  const Simplified& c = simplified();
  SimplifyResult s1 = c.s, s2 = c.s;
  const UnitEncodeOptions plain = baseOrder(c.s);
  const uint32_t B = uint32_t(plain.vertexBegin), BT = uint32_t(plain.tetBegin);
  // Rank k of the base goes to k + k/3 + 1 (vertices) or k + k/4 + 1 (tets): not an offset.
  auto gapVertex = [](uint64_t k) { return uint32_t(k + k / 3 + 1); };
  auto gapTet = [](uint64_t k) { return uint32_t(k + k / 4 + 1); };
  UnitEncodeOptions gapped = plain;
  for (uint64_t& id : gapped.stableVertex)
    if (id != kNoId) id = gapVertex(id);
  for (uint64_t& id : gapped.stableTet)
    if (id != kNoId) id = gapTet(id);
  gapped.vertexBegin = gapVertex(B - 1) + 2;
  gapped.tetBegin = gapTet(BT - 1) + 2;
  const uint32_t VB = uint32_t(gapped.vertexBegin), TB = uint32_t(gapped.tetBegin);
  auto mapVertex = [&](uint64_t x) { return x < B ? gapVertex(x) : VB + uint32_t(x - B); };  // plain id -> gapped
  auto mapTet = [&](uint64_t y) { return y < BT ? gapTet(y) : TB + uint32_t(y - BT); };

  UnitEncoded u, g;
  ASSERT_TRUE(encodeUnit(c.in.mesh, s1, c.in.m, plain, u));
  Result r = encodeUnit(c.in.mesh, s2, c.in.m, gapped, g);
  ASSERT_TRUE(r) << r.message;
  expectSameArrays(g.handoff, u.handoff, "the handoff (the same order)");
  for (size_t v = 0; v < u.startVertex.size(); ++v)
    ASSERT_EQ(g.startVertex[v], u.startVertex[v] == kNoId ? kNoId : mapVertex(u.startVertex[v])) << "vertex " << v;
  for (size_t t = 0; t < u.startTet.size(); ++t)
    ASSERT_EQ(g.startTet[t], u.startTet[t] == kNoId ? kNoId : mapTet(u.startTet[t])) << "tet " << t;
  ASSERT_EQ(g.nodes.size(), u.nodes.size());
  for (size_t k = 0; k < u.nodes.size(); ++k) {
    EXPECT_EQ(g.nodes[k].vertexBegin, VB + (u.nodes[k].vertexBegin - B));
    EXPECT_EQ(g.nodes[k].vertexEnd, VB + (u.nodes[k].vertexEnd - B));
    EXPECT_EQ(g.nodes[k].tetBegin, TB + (u.nodes[k].tetBegin - BT));
    EXPECT_EQ(g.nodes[k].tetEnd, TB + (u.nodes[k].tetEnd - BT));
  }
  EXPECT_EQ(g.chunks.back().vertices, VB + (u.chunks.back().vertices - B));
  EXPECT_EQ(g.chunks.back().tets, TB + (u.chunks.back().tets - BT));

  const Records ru = recordsOf(u.chunks), rg = recordsOf(g.chunks);
  ASSERT_EQ(ru.j.size(), c.s.log.size());
  ASSERT_EQ(rg.j.size(), ru.j.size());
  uint32_t fromHandoff = 0;
  for (size_t k = 0; k < ru.j.size(); ++k) {
    ASSERT_EQ(rg.j[k], mapVertex(ru.j[k])) << "split " << k;
    fromHandoff += ru.j[k] < B;
  }
  EXPECT_GT(fromHandoff, 0u);
  EXPECT_LT(fromHandoff, ru.j.size()) << "kept vertices of the handoff and new ones";
  for (uint32_t col = 1; col < kSplitColumns; ++col)
    EXPECT_EQ(rg.columns[col], ru.columns[col]) << "column " << col << " (no record of a manifold mesh names a vertex "
                                                << "explicitly: ExplicitNewTetVerticesAreStableIds has one)";

  // Decoded: the handoff with filler in the gaps, then the unit; the same mesh under the map.
  std::vector<uint32_t> vertexIds(B), tetIds(BT);
  for (uint32_t k = 0; k < B; ++k) vertexIds[k] = gapVertex(k);
  for (uint32_t k = 0; k < BT; ++k) tetIds[k] = gapTet(k);
  const TetMesh base = baseWithGaps(g.handoff, vertexIds, VB, tetIds, TB, c.in.m);
  const Assembled plainSet = assembleUnit(c.in.m, u.handoff, u, c.s.tree, &c.stats);
  const Assembled gappedSet = assembleUnit(c.in.m, base, g, c.s.tree, &c.stats);
  Dataset a, b;
  decodeAll(plainSet, a, false, "plain ids");
  decodeAll(gappedSet, b, false, "gapped ids");
  if (HasFatalFailure()) return;
  const TetMesh &x = a.pm.mesh, &y = b.pm.mesh;
  ASSERT_EQ(y.vertexCount(), VB + (x.vertexCount() - B));
  ASSERT_EQ(y.tetCount(), TB + (x.tetCount() - BT));
  for (uint32_t v = 0; v < x.vertexCount(); ++v) {
    const uint32_t w = mapVertex(v);
    for (int k = 0; k < 3; ++k) ASSERT_EQ(y.positions[3 * w + k], x.positions[3 * v + k]) << "vertex " << v;
    for (size_t f = 0; f < x.fields.size(); ++f)
      ASSERT_EQ(y.fields[f].values[w], x.fields[f].values[v]) << "vertex " << v;
  }
  for (uint32_t t = 0; t < x.tetCount(); ++t)
    for (int k = 0; k < 4; ++k) ASSERT_EQ(y.tets[4 * mapTet(t) + k], mapVertex(x.tets[4 * t + k])) << "tet " << t;
}

// Explicit new-tet vertices (L + id) are written as stable ids too: a handmade split whose new
// tet's other two vertices are no neighbours of the kept vertex, with gaps in the stable ids.
TEST(EncodeUnit, ExplicitNewTetVerticesAreStableIds) {
  Handmade h = handmade();
  UnitEncodeOptions o;
  o.stream = smallChunks();
  o.stableVertex = {1, 2, 4, 5, 7, 8, 10, 11, kNoId};  // fillers 0, 3, 6, 9 and 12
  o.stableTet = {1, 3, kNoId};                         // fillers 0, 2 and 4
  o.vertexBegin = 13;
  o.tetBegin = 5;
  UnitEncoded u;
  Result r = encodeUnit(h.mesh, h.s, h.m, o, u);
  ASSERT_TRUE(r) << r.message;
  ASSERT_EQ(u.chunks.size(), 1u);
  EXPECT_EQ(u.chunks[0].splits, 1u);
  EXPECT_EQ(u.chunks[0].vertices, 14u);
  EXPECT_EQ(u.chunks[0].tets, 6u);
  EXPECT_EQ(u.chunks[0].maxCollapseError, 0.25f);
  ASSERT_EQ(u.nodes.size(), 1u);
  EXPECT_EQ(u.nodes[0].node, 1u);
  EXPECT_EQ(u.nodes[0].vertexBegin, 13u);
  EXPECT_EQ(u.nodes[0].vertexEnd, 14u);
  EXPECT_EQ(u.nodes[0].tetBegin, 5u);
  EXPECT_EQ(u.nodes[0].tetEnd, 6u);
  EXPECT_EQ(u.startVertex, (std::vector<uint64_t>{1, 2, 4, 5, 7, 8, 10, 11, 13}));
  EXPECT_EQ(u.startTet, (std::vector<uint64_t>{1, 3, 5}));
  EXPECT_EQ(u.handoff.tets, (std::vector<uint32_t>{0, 1, 2, 3, 4, 6, 5, 7}));  // by rank

  const Records rec = recordsOf(u.chunks);
  EXPECT_EQ(rec.j, (std::vector<uint32_t>{1}));  // vertex 0
  EXPECT_EQ(rec.columns[size_t(SplitColumn::NewTetCount)], (std::vector<uint8_t>{1 << 2 | uint32_t(RingMode::Path)}));
  // The path (4, 5): neither is among the L = 3 neighbours (1, 2, 3) of vertex 0, nor a link
  // vertex to walk from: L + 7 and L + 8, their stable ids.
  EXPECT_EQ(rec.columns[size_t(SplitColumn::NewTets)], (std::vector<uint8_t>{3 + 7, 3 + 8}));

  const TetMesh base = baseWithGaps(u.handoff, {1, 2, 4, 5, 7, 8, 10, 11}, 13, {1, 3}, 5, h.m);
  const Assembled set = assembleUnit(h.m, base, u, h.s.tree, nullptr);
  Dataset ds;
  decodeAll(set, ds, false, "handmade");
  if (HasFatalFailure()) return;
  ASSERT_EQ(ds.pm.vertexCount(), 14u);
  ASSERT_EQ(ds.pm.tetCount(), 6u);
  EXPECT_EQ(std::vector<uint32_t>(ds.pm.mesh.tets.begin() + 20, ds.pm.mesh.tets.end()),
            (std::vector<uint32_t>{13, 1, 7, 8}));
  EXPECT_EQ(std::vector<float>(ds.pm.mesh.positions.begin() + 39, ds.pm.mesh.positions.end()),
            (std::vector<float>{1.5f, 0, -1}));
  EXPECT_EQ(ds.pm.mesh.fields[0].values[13], 8.0f);
}

// Handoff ids in a random order (a dense numbering, as the root unit's base): pm_ follows the
// stable order, so every level decodes valid, the last is the input, any isovalue's nodes are a
// valid mesh, and startVertex/startTet name each input vertex and tet by its id in the stream.
TEST(EncodeUnit, ShuffledStableIdsDecodeToTheInput) {
  const Simplified& c = simplified();
  SimplifyResult s = c.s;
  UnitEncodeOptions o = baseOrder(c.s);
  std::mt19937 rng(5);
  std::vector<uint64_t> vertexPerm(o.vertexBegin), tetPerm(o.tetBegin);
  std::iota(vertexPerm.begin(), vertexPerm.end(), 0);
  std::iota(tetPerm.begin(), tetPerm.end(), 0);
  std::shuffle(vertexPerm.begin(), vertexPerm.end(), rng);
  std::shuffle(tetPerm.begin(), tetPerm.end(), rng);
  for (uint64_t& id : o.stableVertex)
    if (id != kNoId) id = vertexPerm[id];
  for (uint64_t& id : o.stableTet)
    if (id != kNoId) id = tetPerm[id];
  UnitEncoded u;
  Result r = encodeUnit(c.in.mesh, s, c.in.m, o, u);
  ASSERT_TRUE(r) << r.message;
  const TetMesh& in = c.in.mesh;
  for (uint32_t v = 0; v < in.vertexCount(); ++v) {
    if (!c.s.vertexAlive[v]) continue;
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(u.handoff.positions[3 * o.stableVertex[v] + k], in.positions[3 * v + k]) << "vertex " << v;
  }
  for (uint32_t t = 0; t < in.tetCount(); ++t) {
    if (!c.s.tetAlive[t]) continue;
    for (int k = 0; k < 4; ++k)
      ASSERT_EQ(u.handoff.tets[4 * o.stableTet[t] + k], o.stableVertex[c.s.tets[4 * t + k]]) << "tet " << t;
  }

  const Assembled set = assembleUnit(c.in.m, u.handoff, u, c.s.tree, &c.stats);
  Dataset ds;
  decodeAll(set, ds, true, "shuffled");
  if (HasFatalFailure()) return;
  const TetMesh& out = ds.pm.mesh;
  expectSameMesh(in, out, ds.quant, false);
  ASSERT_EQ(u.startVertex.size(), in.vertexCount());
  for (uint32_t v = 0; v < in.vertexCount(); ++v) {
    ASSERT_LT(u.startVertex[v], out.vertexCount()) << "vertex " << v;
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(out.positions[3 * u.startVertex[v] + k], in.positions[3 * v + k]) << "vertex " << v;
  }
  ASSERT_EQ(u.startTet.size(), in.tetCount());
  for (uint32_t t = 0; t < in.tetCount(); ++t) {
    ASSERT_LT(u.startTet[t], out.tetCount()) << "tet " << t;
    std::array<uint64_t, 4> want, got;
    for (int k = 0; k < 4; ++k) {
      want[size_t(k)] = u.startVertex[in.tets[4 * t + k]];
      got[size_t(k)] = out.tets[4 * u.startTet[t] + k];
    }
    std::sort(want.begin(), want.end());
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, want) << "tet " << t;
  }
  for (double at : {0.3, 0.6}) {
    PartialDataset pd;
    std::vector<uint32_t> nodes;
    loadForIsovalue(set, at, pd, nodes);
    if (HasFatalFailure()) return;
    expectValidLevel(pd.pm.mesh, "the nodes of an isovalue at " + std::to_string(at));
  }
}

// The handmade unit's handoff: its 8 vertices and 2 tets as the first stable ids.
UnitEncodeOptions handmadeIds() {
  UnitEncodeOptions o;
  o.stableVertex = {0, 1, 2, 3, 4, 5, 6, 7, kNoId};
  o.stableTet = {0, 1, kNoId};
  o.vertexBegin = 8;
  o.tetBegin = 2;
  return o;
}

// finishUnitChunk writes the manifest index into the header (bytes 8-11, little endian) and
// nothing else, fills the manifest entry, and the file opens as that chunk and no other.
TEST(EncodeUnit, FinishUnitChunkSetsTheIndexInTheHeader) {
  Handmade h = handmade();
  UnitEncodeOptions o = handmadeIds();
  UnitEncoded u;
  ASSERT_TRUE(encodeUnit(h.mesh, h.s, h.m, o, u));
  ASSERT_EQ(u.chunks.size(), 1u);
  UnitChunk chunk = u.chunks[0];
  const std::vector<uint8_t> before = chunk.raw;
  EXPECT_EQ(std::vector<uint8_t>(before.begin() + 8, before.begin() + 12), (std::vector<uint8_t>{0, 0, 0, 0}));
  std::vector<uint8_t> file;
  ChunkInfo info;
  Result r = finishUnitChunk(chunk, 0x01020304, 3, file, info);
  ASSERT_TRUE(r) << r.message;
  ASSERT_EQ(chunk.raw.size(), before.size());
  EXPECT_EQ(std::vector<uint8_t>(chunk.raw.begin() + 8, chunk.raw.begin() + 12), (std::vector<uint8_t>{4, 3, 2, 1}));
  for (size_t k = 0; k < before.size(); ++k)
    if (k < 8 || k >= 12) {
      ASSERT_EQ(chunk.raw[k], before[k]) << "byte " << k;
    }
  EXPECT_EQ(info.kind, ChunkKind::Splits);
  EXPECT_EQ(info.splits, 1u);
  EXPECT_EQ(info.vertices, 9u);
  EXPECT_EQ(info.tets, 3u);
  EXPECT_EQ(info.bytes, file.size());
  EXPECT_EQ(info.rawBytes, before.size());

  ChunkDecoder dec;
  std::span<const uint8_t> payload;
  r = openChunk(dec, info, 0x01020304, file, payload);
  ASSERT_TRUE(r) << r.message;
  EXPECT_EQ(payload.size(), before.size() - kChunkHeaderBytes);
  EXPECT_FALSE(openChunk(dec, info, 0x01020303, file, payload)) << "a chunk opens at its own index only";

  chunk = u.chunks[0];
  chunk.vertices = uint64_t(1) << 31;
  EXPECT_FAILS(finishUnitChunk(chunk, 1, 3, file, info), Status::TooLarge, "2^31 - 1");
  chunk = u.chunks[0];
  chunk.tets = uint64_t(1) << 32;
  EXPECT_FAILS(finishUnitChunk(chunk, 1, 3, file, info), Status::TooLarge, "tets");
}

// Stable ids that cannot be a handoff's are refused before anything is encoded.
TEST(EncodeUnit, RefusesStableIdsNoHandoffCanHave) {
  auto encode = [](void (*change)(UnitEncodeOptions&)) {
    Handmade h = handmade();
    UnitEncodeOptions o = handmadeIds();
    change(o);
    UnitEncoded u;
    return encodeUnit(h.mesh, h.s, h.m, o, u);
  };
  EXPECT_TRUE(encode([](UnitEncodeOptions&) {}));
  EXPECT_FAILS(encode([](UnitEncodeOptions& o) { o.stableVertex.pop_back(); }), Status::BadArgument,
               "8 stable vertex ids");
  EXPECT_FAILS(encode([](UnitEncodeOptions& o) { o.stableVertex[3] = 5; }), Status::BadArgument,
               "two vertices of the handoff have stable id 5");
  EXPECT_FAILS(encode([](UnitEncodeOptions& o) { o.stableVertex[2] = kNoId; }), Status::BadArgument,
               "vertex 2 of the handoff has stable id none");
  EXPECT_FAILS(encode([](UnitEncodeOptions& o) { o.stableTet[1] = 2; }), Status::BadArgument,
               "not below the unit's first, 2");
  EXPECT_FAILS(encode([](UnitEncodeOptions& o) { o.vertexBegin = o.tetBegin = (uint64_t(1) << 31) - 1; }),
               Status::TooLarge, "2^31 - 1");
  EXPECT_FAILS(encode([](UnitEncodeOptions& o) { o.stream.orderSplits = true; }), Status::Unsupported,
               "kept-vertex order");
}
