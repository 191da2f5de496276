// The viewer's fetch plan (wasm/fetch_plan.h): which chunks of a dataset of nodes it asks for,
// in what order, and when it is done.
#include <gtest/gtest.h>

#include <algorithm>
#include <iterator>
#include <string>
#include <vector>

#include "io/generators.h"
#include "isosurface.h"
#include "pack/packer.h"
#include "partial.h"
#include "test_helpers.h"
#include "viewer_state.h"

using namespace tetstream;
using namespace tetstream::viewer;

namespace {

struct Packed {
  std::string manifest;
  std::vector<std::vector<uint8_t>> chunks;
};

Packed packGrid(const char* name, void (*addField)(TetMesh&), uint32_t leafVertices) {
  test::ScratchDir dir(name);
  TetMesh m = makeGridMesh(16);
  addField(m);
  PackOptions o;
  o.leafVertices = leafVertices;
  o.zstdLevel = 3;
  PackSummary s;
  EXPECT_TRUE(packMesh(m, dir.path, o, s));
  Packed out;
  out.manifest = test::loadFile(dir.path + "/manifest.json");
  for (const ChunkInfo& c : s.manifest.chunks) out.chunks.push_back(test::loadBytes(dir.path + "/" + c.file));
  return out;
}

// Harmonic 16³ in regions of at most 128 vertices.
const Packed& packedNodes() {
  static const Packed p = packGrid("fetch-plan", addHarmonicField, 128);
  return p;
}

// The distance from the centre on 16³ in regions of at most 64 vertices: a small isovalue needs
// the regions near the centre, a large one those near the corners.
const Packed& packedShells() {
  static const Packed p = packGrid("fetch-plan-shells", addDistanceField, 64);
  return p;
}

void offer(ViewerState& s, uint32_t index, const Packed& p = packedNodes()) {
  const std::vector<uint8_t>& bytes = p.chunks[index];
  auto* copy = static_cast<uint8_t*>(std::malloc(bytes.size()));
  std::copy(bytes.begin(), bytes.end(), copy);
  ASSERT_EQ(offerChunk(s, index, copy, bytes.size()), ChunkCheck::Ok) << "chunk " << index;
}

double g_ticks = 0;
double fakeNow() { return g_ticks += 1; }

// Nodes in the order the plan first asks for one of their chunks.
std::vector<uint32_t> plannedNodes(const ViewerState& s) {
  std::vector<uint32_t> nodes;
  for (uint32_t c : plannedChunks(s, ~0u)) {
    const int32_t k = s.dataset.nodeOfChunk(c);
    if (k >= 0 && (nodes.empty() || nodes.back() != uint32_t(k))) nodes.push_back(uint32_t(k));
  }
  return nodes;
}

}  // namespace

// The plan holds the base and the chunks of exactly the nodes whose range holds the isovalue
// (with their ancestors), each node after its parent; following it ends exact and complete.
TEST(FetchPlan, HoldsWhatTheIsovalueNeedsParentsFirst) {
  ViewerState s;
  ASSERT_TRUE(openManifest(s, packedNodes().manifest).ok());
  const Manifest& m = s.dataset.manifest;
  ASSERT_GE(m.nodes.size(), 16u);
  setIsovalue(s, m.fields[0].range.min + 0.8f * (m.fields[0].range.max - m.fields[0].range.min));
  const std::vector<uint32_t> plan = plannedChunks(s, ~0u);
  ASSERT_FALSE(plan.empty());
  EXPECT_EQ(plan[0], 0u) << "the base first";
  std::vector<uint8_t> seen(m.nodes.size(), 0);
  size_t chunks = 1;
  for (uint32_t k : plannedNodes(s)) {
    const NodeInfo& n = m.nodes[k];
    EXPECT_TRUE(n.parent < 0 || seen[size_t(n.parent)]) << "node " << k << " before its parent";
    seen[k] = 1;
    chunks += n.chunkCount;
  }
  EXPECT_EQ(plan.size(), chunks);
  for (uint32_t k = 0; k < m.nodes.size(); ++k) {
    const Range r = m.nodes[k].ranges[0];
    if (r.min <= s.isovalue && s.isovalue <= r.max) {
      EXPECT_TRUE(seen[k]) << "node " << k << " is needed";
    }
  }
  EXPECT_LT(plan.size(), m.chunks.size()) << "not everything";
  EXPECT_EQ(s.fetch.missing, plan.size());
  for (uint32_t c : plan) offer(s, c);
  for (int k = 0; k < 100000 && refining(s); ++k) advance(s, g_ticks + 50, fakeNow);
  EXPECT_EQ(s.state, LoadState::Complete);
  EXPECT_TRUE(exactSurface(s));
  EXPECT_TRUE(plannedChunks(s, ~0u).empty());

  // Another isovalue needs more; everything needs every chunk.
  const uint32_t version = s.fetch.version;
  setIsovalue(s, m.fields[0].range.min + 0.4f * (m.fields[0].range.max - m.fields[0].range.min));
  EXPECT_GT(s.fetch.version, version);
  EXPECT_GT(s.fetch.missing, 0u);
  EXPECT_EQ(s.state, LoadState::Streaming);
  EXPECT_FALSE(exactSurface(s));
  setFetchMode(s, FetchMode::Everything);
  EXPECT_EQ(s.fetch.missing, m.chunks.size() - s.dataset.chunksReceived);
}

// Regions out of view come after every region in view whose ancestors are in view.
TEST(FetchPlan, RegionsOutOfViewComeLast) {
  ViewerState s;
  ASSERT_TRUE(openManifest(s, packedNodes().manifest).ok());
  const Manifest& m = s.dataset.manifest;
  setFetchMode(s, FetchMode::Everything);
  auto inView = [](const Bounds& b) { return b.min[0] < 0; };  // the half x < 0 is on screen
  s.fetch.screenWeight = [&](const Bounds& b) { return inView(b) ? 1.0 : 0.0; };
  const std::vector<uint32_t> order = plannedNodes(s);
  ASSERT_EQ(order.size(), m.nodes.size());
  auto ancestorOutOfView = [&](uint32_t k) {
    for (int32_t a = m.nodes[k].parent; a >= 0; a = m.nodes[size_t(a)].parent)
      if (!inView(m.nodes[size_t(a)].bounds)) return true;
    return false;
  };
  bool outSeen = false;
  size_t inViewFirst = 0;
  for (uint32_t k : order) {
    if (!inView(m.nodes[k].bounds)) {
      outSeen = true;
      continue;
    }
    if (outSeen)
      EXPECT_TRUE(ancestorOutOfView(k)) << "node " << k << " in view waited behind one out of view";
    else
      ++inViewFirst;
  }
  EXPECT_GT(inViewFirst, order.size() / 4);
}

namespace {
uint64_t g_heapAsked = 0;
bool recordReserveHeap(uint64_t bytes) {
  g_heapAsked = std::max(g_heapAsked, bytes);
  return true;
}
}  // namespace

// The memory asked for before each chunk of a hierarchy is for what has arrived, whatever its
// place in the manifest: a plan that skips most of the dataset never asks for the rest (which
// in a 4 GB wasm heap once refused the chunks of a large dataset's deep regions).
TEST(FetchPlan, MemoryAskedForIsWhatArrived) {
  ViewerState s;
  s.memory.reserveHeap = recordReserveHeap;
  g_heapAsked = 0;
  ASSERT_TRUE(openManifest(s, packedNodes().manifest).ok());
  const Manifest& m = s.dataset.manifest;
  setIsovalue(s, m.fields[0].range.min + 0.8f * (m.fields[0].range.max - m.fields[0].range.min));
  const std::vector<uint32_t> plan = plannedChunks(s, ~0u);
  LevelCounts planned;
  for (uint32_t c : plan) addCounts(planned, chunkCounts(m, c));
  for (uint32_t c : plan) offer(s, c);
  EXPECT_LE(g_heapAsked, estimateBytes(m, planned)) << "no more than the planned chunks need";
  EXPECT_LT(estimateBytes(m, planned), estimateLevelBytes(m, plan.back() + 1))
      << "the manifest's prefix up to the last planned chunk needs more: the test tells them apart";
  EXPECT_EQ(s.memory.received.tets, planned.tets);
}

namespace {

// What the base and every chunk of `nodes` bring.
LevelCounts countsOf(const Manifest& m, const std::vector<uint32_t>& nodes) {
  LevelCounts c = chunkCounts(m, 0);
  for (uint32_t k : nodes)
    for (uint32_t i = m.nodes[k].firstChunk; i < m.nodes[k].firstChunk + m.nodes[k].chunkCount; ++i)
      addCounts(c, chunkCounts(m, i));
  return c;
}

// As the page and the worker go: a few chunks of the plan arrive, one slice of refinement (when
// the worker has any: tw_work), and again, until there is nothing to fetch, apply or give back.
// Chunks arrive while splits wait, and while regions are being given back. The memory in use,
// once the regions being given back are gone, never passes the limit.
void followPlan(ViewerState& s, const Packed& p) {
  for (int step = 0; step < 100000; ++step) {
    const std::vector<uint32_t> next = chunksToFetch(s);
    for (size_t k = 0; k < std::min<size_t>(3, next.size()); ++k) offer(s, next[k], p);
    if (refining(s)) advance(s, g_ticks + 3, fakeNow);
    ASSERT_NE(s.state, LoadState::Error) << s.error;
    ASSERT_LE(s.memory.baseBytes + estimateBytes(s.dataset.manifest, keptCounts(s)), s.memory.limitBytes);
    if (next.empty() && !refining(s) && s.evict.nodes.empty()) {
      ASSERT_LE(s.memory.baseBytes + estimateBytes(s.dataset.manifest, s.memory.received), s.memory.limitBytes);
      return;
    }
  }
  FAIL() << "the plan never settled";
}

// The surface shown is the full mesh's isosurface: the same number of triangles and area.
void expectFullResolutionSurface(const ViewerState& s, const TetMesh& full, const char* where) {
  SCOPED_TRACE(where);
  EXPECT_TRUE(exactSurface(s));
  IsoExtractor x;
  IsoSurface ref;
  extractIsosurface(full, full.fields[0].values, s.isovalue, x, ref);
  EXPECT_EQ(s.surface.triangleCount(), ref.triangleCount());
  EXPECT_NEAR(s.surface.area(), surfaceArea(ref), 1e-6 * std::max(1.0, surfaceArea(ref)));
  EXPECT_TRUE(s.surface.validate());
}

}  // namespace

// Two isovalues whose regions fit in memory one at a time but not together: moving from one to
// the other gives back regions the new one does not need (undone, latest first) and fetches the
// ones it does; each surface is exact, and the memory in use stays under the limit throughout.
// Where even the regions a view needs do not fit, what fits is shown: not an error.
TEST(FetchPlan, RegionsTheViewNoLongerNeedsAreGivenBackWhenMemoryIsShort) {
  const Packed& p = packedShells();
  Manifest m;
  ASSERT_TRUE(parseManifest(p.manifest, m).ok());
  const Range r = m.fields[0].range;
  const float a = r.min + 0.2f * (r.max - r.min), b = r.min + 0.85f * (r.max - r.min);
  const std::vector<uint32_t> needA = withAncestors(m, nodesForIsovalue(m, 0, a));
  const std::vector<uint32_t> needB = withAncestors(m, nodesForIsovalue(m, 0, b));
  std::vector<uint32_t> both;
  std::set_union(needA.begin(), needA.end(), needB.begin(), needB.end(), std::back_inserter(both));
  ViewerState s;
  s.memory.baseBytes = 1 << 20;
  const uint64_t one = std::max(estimateBytes(m, countsOf(m, needA)), estimateBytes(m, countsOf(m, needB)));
  s.memory.limitBytes = s.memory.baseBytes + one + one / 50;
  ASSERT_GT(s.memory.baseBytes + estimateBytes(m, countsOf(m, both)), s.memory.limitBytes)
      << "the two views must not fit together";
  Dataset whole;
  ASSERT_TRUE(openDataset(whole, p.manifest));
  for (uint32_t c = 0; c < p.chunks.size(); ++c) ASSERT_TRUE(applyChunk(whole, c, p.chunks[c]));

  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  setIsovalue(s, a);
  followPlan(s, p);
  EXPECT_EQ(s.state, LoadState::Complete);
  expectFullResolutionSurface(s, whole.pm.mesh, "the first isovalue");
  EXPECT_EQ(s.evict.nodesForgotten, 0u);

  setIsovalue(s, b);
  EXPECT_FALSE(s.evict.nodes.empty()) << "regions to give back are chosen at once";
  followPlan(s, p);
  EXPECT_EQ(s.state, LoadState::Complete);
  EXPECT_FALSE(s.evict.memoryFull);
  expectFullResolutionSurface(s, whole.pm.mesh, "the second isovalue");
  EXPECT_GT(s.evict.nodesForgotten, 0u);
  EXPECT_FALSE(s.evict.forgottenChunks.empty()) << "the page hears which chunks to fetch again";
  for (uint32_t k = 0; k < m.nodes.size(); ++k)
    if (s.dataset.nodeChunksReceived[k] == 0 && std::binary_search(needA.begin(), needA.end(), k) &&
        !std::binary_search(needB.begin(), needB.end(), k)) {
      EXPECT_FALSE(s.fetch.needed[k]);
    }

  setIsovalue(s, a);  // and back: what was given back comes again
  followPlan(s, p);
  expectFullResolutionSurface(s, whole.pm.mesh, "back at the first isovalue");

  // Every region does not fit: as much as fits, the surface still exact for its isovalue.
  setFetchMode(s, FetchMode::Everything);
  followPlan(s, p);
  EXPECT_EQ(s.state, LoadState::Complete);
  EXPECT_TRUE(s.evict.memoryFull);
  EXPECT_FALSE(downloading(s));
  EXPECT_LT(s.dataset.chunksReceived, m.chunks.size());
  expectFullResolutionSurface(s, whole.pm.mesh, "everything asked for");
}

// Where a plan of nodes made the mesh, the field error shown is the largest of the regions not yet
// refined, each's measured error before its splits: the base's with the base alone, what a brute
// force finds at every input vertex once the nodes an isovalue needs are in, none with everything.
TEST(FetchPlan, TheFieldErrorShownIsTheLargestOfTheRegionsNotRefined) {
  ViewerState s;
  ASSERT_TRUE(openManifest(s, packedNodes().manifest).ok());
  const Manifest& m = s.dataset.manifest;
  const Range range = m.fields[0].range;
  const double step = (range.max - range.min) / 65535.0;  // (the input is measured on the grid)
  setIsovalue(s, range.min + 0.8f * (range.max - range.min));
  offer(s, 0);
  ShownError e = shownFieldError(s);
  EXPECT_EQ(e.max, m.nodes[0].fieldMax);
  EXPECT_EQ(e.max, m.chunks[0].fieldMax) << "the root's error before its splits is the base's";
  EXPECT_EQ(e.estimate, m.nodes[0].fieldError);
  EXPECT_EQ(e.rms, m.chunks[0].fieldRms) << "the base is a level of the stream";

  for (uint32_t c : plannedChunks(s, ~0u))
    if (c != 0) offer(s, c);
  for (int k = 0; k < 100000 && refining(s); ++k) advance(s, g_ticks + 50, fakeNow);
  ASSERT_TRUE(exactSurface(s));
  TetMesh input = makeGridMesh(16);
  addHarmonicField(input);
  const TetMesh& shown = s.dataset.pm.mesh;
  double largest = 0;
  for (uint32_t v = 0; v < input.vertexCount(); ++v) {
    uint32_t tet = 0;
    double w[4] = {}, value = 0;
    test::bestTet(shown, &input.positions[3 * size_t(v)], tet, w);
    for (int c = 0; c < 4; ++c) value += w[c] * shown.fields[0].values[shown.tets[4 * size_t(tet) + size_t(c)]];
    largest = std::max(largest, std::abs(value - input.fields[0].values[v]));
  }
  e = shownFieldError(s);
  EXPECT_EQ(e.rms, -1) << "not known for a set of nodes";
  EXPECT_NEAR(e.max, largest, 3 * step);
  EXPECT_GT(e.max, 20 * step) << "regions the isovalue does not need are coarse";
  EXPECT_LT(e.max, m.nodes[0].fieldMax);

  setFetchMode(s, FetchMode::Everything);
  for (uint32_t c : plannedChunks(s, ~0u)) offer(s, c);
  for (int k = 0; k < 100000 && refining(s); ++k) advance(s, g_ticks + 50, fakeNow);
  e = shownFieldError(s);
  EXPECT_EQ(e.max, 0);
  EXPECT_EQ(e.estimate, 0);
}
