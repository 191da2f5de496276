// Partial datasets (partial.h, FORMAT.md §1.1): any set of nodes that holds every node's parent,
// applied in any order that puts parents first, is a valid mesh, the same mesh whatever that
// order; all nodes give the input; the nodes an isovalue needs give its full-resolution
// isosurface exactly; a damaged node is refused and changes nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "dataset.h"
#include "io/generators.h"
#include "io/mesh_io.h"
#include "isosurface.h"
#include "isosurface_incremental.h"
#include "pack/packer.h"
#include "partial.h"
#include "test_helpers.h"

using namespace tetstream;
using namespace tetstream::test;

namespace {

// Three kinds of input: a grid, a domain with a curved concave bite out of one corner, and a
// graded grid (most vertices in thin layers at two walls) with two fields.
TetMesh bitten(uint32_t n) {
  return carved(n, [](const float* c) {
    const float dx = c[0] - 1, dy = c[1] - 1, dz = c[2] - 1;
    return dx * dx + dy * dy + dz * dz < 1.1f;
  });
}

TetMesh graded(uint32_t n) {
  TetMesh m = makeGridMesh(n);
  for (size_t v = 0; v < m.vertexCount(); ++v)
    for (int a = 0; a < 2; ++a) {
      float& x = m.positions[3 * v + a];
      x = -1 + 2 * std::pow((x + 1) / 2, 3.0f);
    }
  ScalarField wave{"wave", {}}, ramp{"ramp", {}};
  for (size_t v = 0; v < m.vertexCount(); ++v) {
    const float* p = &m.positions[3 * v];
    wave.values.push_back(std::sin(2.5f * p[0] + 1.5f * p[1]) + 0.5f * std::cos(2 * p[2]));
    ramp.values.push_back(p[2] - 0.3f * p[0]);
  }
  m.fields = {wave, ramp};
  m.name = "graded";
  return m;
}

struct Case {
  std::string name;
  TetMesh mesh;
  std::string dir;  // packed already (below); else packed here
};

// The cases, or packs made elsewhere: TETSTREAM_CHECK_PACKS="DIR=INPUT;DIR=INPUT..." runs every
// test here on those datasets against their input files (the distributed pack's test packs them
// on several processes).
std::vector<Case> cases() {
  if (const char* given = std::getenv("TETSTREAM_CHECK_PACKS")) {
    std::vector<Case> out;
    const std::string list = given;
    for (size_t at = 0; at < list.size();) {
      const size_t end = std::min(list.find(';', at), list.size()), eq = list.find('=', at);
      Case c;
      c.dir = list.substr(at, eq - at);
      c.name = c.dir;
      ReadReport report;
      const std::string input = list.substr(eq + 1, end - eq - 1);
      EXPECT_TRUE(readMesh(input, c.mesh, report)) << input;
      out.push_back(std::move(c));
      at = end + 1;
    }
    return out;
  }
  return {{"grid", harmonic(16), ""}, {"bitten", bitten(15), ""}, {"graded", graded(15), ""}};
}

std::string packCase(const Case& c) {
  if (!c.dir.empty()) return c.dir;
  PackOptions o;
  o.leafVertices = 128;
  o.chunkKb = 4;
  PackSummary s;
  const std::string dir = pack("partial-" + c.name, c.mesh, o, &s);
  EXPECT_GE(s.manifest.nodes.size(), 16u) << c.name;
  return dir;
}

ChunkSource dirSource(const std::string& dir, const Manifest& m) {
  return [dir, &m](uint32_t index, std::vector<uint8_t>& file) {
    file = loadBytes(dir + "/" + m.chunks[index].file);
    return file.empty() ? fail(Status::IoError, "cannot read chunk " + std::to_string(index)) : Result::success();
  };
}

// Opens `dir` and applies `order` (which must put parents first).
void loadInOrder(const std::string& dir, const std::vector<uint32_t>& order, PartialDataset& pd) {
  const std::string json = loadFile(dir + "/manifest.json");
  Manifest m;
  ASSERT_TRUE(parseManifest(json, m));
  ASSERT_TRUE(openPartial(pd, json, dirSource(dir, pd.manifest)));
  for (uint32_t k : order) ASSERT_TRUE(applyNode(pd, k, dirSource(dir, pd.manifest))) << "node " << k;
}

// A random order of `nodes` (closed under parents) that puts every parent before its children.
std::vector<uint32_t> randomParentFirstOrder(const Manifest& m, const std::vector<uint32_t>& nodes, std::mt19937& rng) {
  std::vector<uint8_t> wanted(m.nodes.size(), 0), done(m.nodes.size(), 0);
  for (uint32_t k : nodes) wanted[k] = 1;
  std::vector<uint32_t> ready, order;
  auto readyOnes = [&] {
    ready.clear();
    for (uint32_t k : nodes)
      if (!done[k] && (m.nodes[k].parent < 0 || done[size_t(m.nodes[k].parent)])) ready.push_back(k);
  };
  for (readyOnes(); !ready.empty(); readyOnes()) {
    const uint32_t k = ready[rng() % ready.size()];
    done[k] = 1;
    order.push_back(k);
  }
  return order;
}

// The mesh in stable vertex ids: each tet as its sorted ids and the parity of the sort (its
// orientation), sorted; each vertex's position and values by stable id.
struct StableMesh {
  std::vector<std::array<uint32_t, 5>> tets;
  std::map<uint32_t, std::vector<float>> vertices;
  bool operator==(const StableMesh&) const = default;
};

StableMesh stableMesh(const TetMesh& mesh, const std::vector<uint32_t>& stableOf) {
  StableMesh s;
  for (uint32_t t = 0; t < mesh.tetCount(); ++t) {
    std::array<uint32_t, 4> v;
    for (int k = 0; k < 4; ++k) v[size_t(k)] = stableOf[mesh.tets[4 * t + k]];
    uint32_t swaps = 0;
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b + 1 < 4 - a; ++b)
        if (v[size_t(b)] > v[size_t(b + 1)]) std::swap(v[size_t(b)], v[size_t(b + 1)]), ++swaps;
    s.tets.push_back({v[0], v[1], v[2], v[3], swaps & 1});
  }
  std::sort(s.tets.begin(), s.tets.end());
  for (uint32_t v = 0; v < mesh.vertexCount(); ++v) {
    std::vector<float>& x = s.vertices[stableOf[v]];
    x.assign(&mesh.positions[3 * v], &mesh.positions[3 * v] + 3);
    for (const ScalarField& f : mesh.fields) x.push_back(f.values[v]);
  }
  return s;
}

StableMesh stableMesh(const PartialDataset& pd) { return stableMesh(pd.pm.mesh, pd.stableVertexIds()); }

}  // namespace

// Random sets of nodes (each closed under parents) in random parent-first orders: every one is a
// valid mesh (no inverted or flat tets, conforming, a manifold boundary of the input's shape),
// and the same set in another order is the same mesh.
TEST(Partial, AnySetOfNodesWithTheirParentsIsAValidMeshInAnyOrder) {
  std::mt19937 rng(7);
  for (const Case& c : cases()) {
    const std::string dir = packCase(c);
    Manifest m;
    ASSERT_TRUE(parseManifest(loadFile(dir + "/manifest.json"), m));
    for (int trial = 0; trial < 6; ++trial) {
      std::vector<uint32_t> some;
      const double p = 0.1 + 0.15 * trial;
      for (uint32_t k = 0; k < m.nodes.size(); ++k)
        if (std::uniform_real_distribution<double>(0, 1)(rng) < p) some.push_back(k);
      const std::vector<uint32_t> set = withAncestors(m, some);
      const std::string what =
          c.name + ", " + std::to_string(set.size()) + " of " + std::to_string(m.nodes.size()) + " nodes";
      PartialDataset a, b;
      loadInOrder(dir, randomParentFirstOrder(m, set, rng), a);
      loadInOrder(dir, randomParentFirstOrder(m, set, rng), b);
      if (HasFatalFailure()) return;
      expectValidLevel(a.pm.mesh, what);
      EXPECT_TRUE(stableMesh(a) == stableMesh(b)) << what << ": two orders gave different meshes";
      uint32_t vertices = m.chunks[0].vertices;
      for (uint32_t k : set) vertices += m.nodes[k].vertexEnd - m.nodes[k].vertexBegin;
      EXPECT_EQ(a.pm.vertexCount(), vertices) << what;
    }
  }
}

// Every node, in any parent-first order, is the whole stream: the mesh a reader gets from the
// chunks in order (whose ids are the stable ones), which is the input.
TEST(Partial, AllNodesGiveTheWholeStream) {
  std::mt19937 rng(11);
  for (const Case& c : cases()) {
    const std::string dir = packCase(c);
    Dataset whole;
    ASSERT_TRUE(loadPackedDir(dir, whole));
    std::vector<uint32_t> all(whole.manifest.nodes.size());
    for (uint32_t k = 0; k < all.size(); ++k) all[k] = k;
    PartialDataset pd;
    loadInOrder(dir, randomParentFirstOrder(whole.manifest, all, rng), pd);
    std::vector<uint32_t> identity(whole.pm.vertexCount());
    for (uint32_t v = 0; v < identity.size(); ++v) identity[v] = v;
    EXPECT_TRUE(stableMesh(pd) == stableMesh(whole.pm.mesh, identity)) << c.name;
    expectSameMesh(c.mesh, pd.pm.mesh, whole.quant, false);
    EXPECT_EQ(pd.bytesLoaded, whole.manifest.totalBytes());
  }
}

// The nodes whose range holds an isovalue give the full-resolution isosurface: the same
// triangles, bit for bit, from part of the bytes. Isovalues at random, at a vertex's value and at
// the ends of the range, on every field.
TEST(Partial, TheNodesAnIsovalueNeedsGiveItsSurfaceExactly) {
  std::mt19937 rng(3);
  for (const Case& c : cases()) {
    const std::string dir = packCase(c);
    Dataset whole;
    ASSERT_TRUE(loadPackedDir(dir, whole));
    const Manifest& m = whole.manifest;
    IsoExtractor x;
    uint64_t fewest = m.totalBytes();
    for (size_t f = 0; f < m.fields.size(); ++f) {
      const Range r = m.fields[f].range;
      std::vector<float> isovalues = {r.min, r.max, whole.pm.mesh.fields[f].values[rng() % whole.pm.vertexCount()]};
      for (int k = 0; k < 6; ++k) isovalues.push_back(std::uniform_real_distribution<float>(r.min, r.max)(rng));
      for (float iso : isovalues) {
        const std::string what = c.name + ", " + m.fields[f].name + " = " + std::to_string(iso);
        PartialDataset pd;
        ASSERT_TRUE(loadPartialDir(dir, nodesForIsovalue(m, int(f), iso), pd)) << what;
        IsoSurface part, full;
        extractIsosurface(pd.pm.mesh, pd.pm.mesh.fields[f].values, iso, x, part);
        extractIsosurface(whole.pm.mesh, whole.pm.mesh.fields[f].values, iso, x, full);
        EXPECT_TRUE(sameTriangles(part, full))
            << what << ": " << part.triangleCount() << " triangles against " << full.triangleCount();
        fewest = std::min(fewest, pd.bytesLoaded);
      }
    }
    std::printf("%s: the fewest bytes an isovalue needed: %.0f%% of %llu\n", c.name.c_str(),
                100.0 * fewest / m.totalBytes(), (unsigned long long)m.totalBytes());
    EXPECT_LT(fewest, m.totalBytes()) << c.name << ": some isovalue needs less than the whole (benchmarks: how much)";
  }
}

// The viewer's surface follows nodes as they are applied and undone (isosurface_incremental.h's
// contract holds for a node's splits as for the stream's): after every node it equals a
// from-scratch extraction.
TEST(Partial, IncrementalSurfaceEqualsAFreshOneAfterEveryNode) {
  const Case c{"grid", harmonic(16)};
  const std::string dir = packCase(c);
  const std::string json = loadFile(dir + "/manifest.json");
  PartialDataset pd;
  Manifest m;
  ASSERT_TRUE(parseManifest(json, m));
  ASSERT_TRUE(openPartial(pd, json, dirSource(dir, m)));
  const float iso = 0.3f;
  IncrementalIsosurface inc;
  inc.rebuild(pd.pm.mesh, pd.pm.mesh.fields[0].values, iso);
  auto expectFresh = [&](const std::string& where) {
    IsoExtractor x;
    IsoSurface fresh, kept;
    extractIsosurface(pd.pm.mesh, pd.pm.mesh.fields[0].values, iso, x, fresh);
    inc.toIsoSurface(kept);
    EXPECT_TRUE(sameTriangles(fresh, kept)) << where;
  };
  std::mt19937 rng(5);
  std::vector<uint32_t> changed;
  const std::vector<uint32_t> order = randomParentFirstOrder(m, nodesForIsovalue(m, 0, iso), rng);
  ASSERT_GE(order.size(), 4u);
  for (size_t k = 0; k < order.size(); ++k) {
    changed.clear();
    ASSERT_TRUE(applyNode(pd, order[k], dirSource(dir, m), &changed));
    inc.updateTets(pd.pm.mesh, pd.pm.mesh.fields[0].values, changed);
    expectFresh("after node " + std::to_string(order[k]));
    if (k % 3 == 2) {  // one back and forth
      changed.clear();
      undoLastNode(pd, &changed);
      inc.updateTets(pd.pm.mesh, pd.pm.mesh.fields[0].values, changed);
      expectFresh("node " + std::to_string(order[k]) + " undone");
      changed.clear();
      ASSERT_TRUE(applyNode(pd, order[k], dirSource(dir, m), &changed));
      inc.updateTets(pd.pm.mesh, pd.pm.mesh.fields[0].values, changed);
    }
  }
  while (!pd.applied.empty()) {
    changed.clear();
    undoLastNode(pd, &changed);
    inc.updateTets(pd.pm.mesh, pd.pm.mesh.fields[0].values, changed);
  }
  expectFresh("all undone");
  EXPECT_EQ(pd.pm.vertexCount(), m.chunks[0].vertices);
}

// A node whose chunk is missing, damaged or fails its hash is refused with a message that names
// its region, and the mesh stays as it was; other nodes still apply. A node cannot come before
// its parent.
TEST(Partial, ADamagedNodeIsRefusedAndChangesNothing) {
  const Case c{"grid", harmonic(16)};
  const std::string dir = packCase(c);
  const std::string json = loadFile(dir + "/manifest.json");
  Manifest m;
  ASSERT_TRUE(parseManifest(json, m));
  PartialDataset pd;
  ASSERT_TRUE(openPartial(pd, json, dirSource(dir, m)));
  // Roots of the hierarchy first; then a child of the first, damaged in three ways.
  uint32_t root = 0, child = 0;
  for (uint32_t k = 0; k < m.nodes.size(); ++k)
    if (m.nodes[k].parent == int32_t(root) && k != root) child = k;
  ASSERT_EQ(m.nodes[root].parent, -1);
  ASSERT_GT(child, 0u);
  std::string error;
  {
    ChunkSource good = dirSource(dir, m);
    EXPECT_FALSE(applyNode(pd, child, good)) << "before its parent";
    ASSERT_TRUE(applyNode(pd, root, good));
  }
  const StableMesh before = stableMesh(pd);
  const uint32_t chunk = m.nodes[child].firstChunk;
  auto damaged = [&](int how) -> ChunkSource {
    return [&, how](uint32_t index, std::vector<uint8_t>& file) {
      if (index == chunk && how == 0) return fail(Status::IoError, "cannot read " + m.chunks[index].file);
      file = loadBytes(dir + "/" + m.chunks[index].file);
      if (index == chunk && how == 1) file[file.size() / 2] ^= 0x40;  // fails its hash
      if (index == chunk && how == 2) file.resize(file.size() - 1);   // truncated
      return Result::success();
    };
  };
  for (int how = 0; how < 3; ++how) {
    Result r = applyNode(pd, child, damaged(how));
    ASSERT_FALSE(r) << how;
    EXPECT_NE(r.message.find("node " + std::to_string(child) + " (region ["), std::string::npos) << r.message;
    EXPECT_FALSE(pd.loaded(child));
    EXPECT_TRUE(stableMesh(pd) == before) << "a refused node changed the mesh (" << how << ")";
  }
  EXPECT_TRUE(applyNode(pd, child, dirSource(dir, m)));
  expectValidLevel(pd.pm.mesh, "after the damaged node came whole");
}

// The viewer's dataset takes chunks in any order that puts each node's parent first (a plan by
// isovalue and view), and its level slider moves back and forth over them in that order.
TEST(Partial, ADatasetReceivesNodesInAnyParentFirstOrder) {
  std::mt19937 rng(13);
  const Case c{"grid", harmonic(16)};
  const std::string dir = packCase(c);
  const std::string json = loadFile(dir + "/manifest.json");
  Dataset ds;
  ASSERT_TRUE(openDataset(ds, json));
  const Manifest& m = ds.manifest;
  const std::vector<uint32_t> nodes = withAncestors(m, nodesForIsovalue(m, 0, 0.2f));
  const std::vector<uint32_t> order = randomParentFirstOrder(m, nodes, rng);
  auto file = [&](uint32_t index) { return loadBytes(dir + "/" + m.chunks[index].file); };
  ASSERT_TRUE(receiveChunk(ds, 0, file(0)));
  std::vector<uint32_t> changed;
  bool reached = false;
  for (uint32_t k : order) {
    const NodeInfo& n = m.nodes[k];
    // Out of turn: a later chunk of the node first, or a child before it.
    if (n.chunkCount > 1) {
      EXPECT_FALSE(ds.canReceive(n.firstChunk + 1));
    }
    for (uint32_t ch = n.firstChunk; ch < n.firstChunk + n.chunkCount; ++ch) {
      ASSERT_TRUE(receiveChunk(ds, ch, file(ch))) << "chunk " << ch;
      // Half the time the level follows at once, else it catches up later.
      if (rng() % 2) {
        ASSERT_TRUE(stepTowards(ds, ds.splitsReceived(), ~0u, changed, &reached));
      }
    }
  }
  ASSERT_TRUE(stepTowards(ds, ds.splitsReceived(), ~0u, changed, &reached) && reached);
  // The mesh in stable ids: each node's vertices come where its first chunk was received.
  auto stableIds = [&] {
    std::vector<uint32_t> ids(ds.pm.vertexCount());
    for (uint32_t v = 0; v < ds.pm.baseVertices; ++v) ids[v] = v;
    for (uint32_t place = 1; place < ds.received.size(); ++place) {
      const uint32_t before = m.chunks[ds.received[place] - 1].vertices;  // stable id of its first split's vertex
      for (uint32_t s = ds.chunkFirstSplit[place]; s < ds.chunkFirstSplit[place + 1]; ++s)
        if (ds.pm.baseVertices + s < ids.size()) ids[ds.pm.baseVertices + s] = before + (s - ds.chunkFirstSplit[place]);
    }
    return ids;
  };
  PartialDataset pd;
  ASSERT_TRUE(loadPartialDir(dir, nodes, pd));
  const StableMesh want = stableMesh(pd);
  EXPECT_TRUE(stableMesh(ds.pm.mesh, stableIds()) == want);
  expectValidLevel(ds.pm.mesh, "every planned node");
  // Back to the base and forward again over the same records (redo re-reads them).
  ASSERT_TRUE(stepTowards(ds, 0, ~0u, changed, &reached) && reached);
  EXPECT_EQ(ds.pm.vertexCount(), ds.pm.baseVertices);
  const uint32_t half = ds.splitsReceived() / 2;
  ASSERT_TRUE(stepTowards(ds, half, ~0u, changed, &reached) && reached);
  expectValidLevel(ds.pm.mesh, "half of the planned splits");
  ASSERT_TRUE(stepTowards(ds, ds.splitsReceived(), ~0u, changed, &reached) && reached);
  EXPECT_TRUE(stableMesh(ds.pm.mesh, stableIds()) == want);
  // A node whose parent is missing cannot come.
  for (uint32_t k = 0; k < m.nodes.size(); ++k)
    if (m.nodes[k].parent >= 0 && !ds.nodeComplete(uint32_t(m.nodes[k].parent)) && ds.nodeChunksReceived[k] == 0) {
      EXPECT_FALSE(ds.canReceive(m.nodes[k].firstChunk));
      EXPECT_FALSE(receiveChunk(ds, m.nodes[k].firstChunk, file(m.nodes[k].firstChunk)));
      break;
    }
}

namespace {

// A dataset's mesh in stable vertex ids: each place's vertices from where the manifest puts its chunk.
StableMesh stableMesh(const Dataset& ds) {
  std::vector<uint32_t> stableOf(ds.pm.vertexCount());
  for (uint32_t v = 0; v < ds.pm.baseVertices; ++v) stableOf[v] = v;
  for (uint32_t place = 1; place < ds.received.size(); ++place) {
    const uint32_t before = ds.manifest.chunks[ds.received[place] - 1].vertices;
    for (uint32_t s = ds.chunkFirstSplit[place]; s < ds.chunkFirstSplit[place + 1]; ++s)
      if (ds.pm.baseVertices + s < stableOf.size())
        stableOf[ds.pm.baseVertices + s] = before + (s - ds.chunkFirstSplit[place]);
  }
  return stableMesh(ds.pm.mesh, stableOf);
}

// Harmonic 16³ packed in regions of at most `leafVertices` vertices and chunks of `chunkKb` KB.
std::string packHarmonic16(const std::string& name, uint32_t leafVertices, uint32_t chunkKb) {
  PackOptions o;
  o.leafVertices = leafVertices;
  o.chunkKb = chunkKb;
  return pack(name, harmonic(16), o);
}

}  // namespace

// Chunks of several nodes may arrive interleaved (the loader fetches in parallel): a node of
// several chunks whose next chunk comes after another node's. Every vertex still gets the place
// its stable id names, and the level is the same mesh as the nodes loaded one after the other.
TEST(Partial, ChunksOfSeveralNodesMayInterleave) {
  Dataset ds;
  const std::string dir = packHarmonic16("partial-interleaved", 512, 1);
  ASSERT_TRUE(openDataset(ds, loadFile(dir + "/manifest.json")));
  const Manifest& m = ds.manifest;
  uint32_t multiChunk = 0;
  for (const NodeInfo& n : m.nodes) multiChunk += n.parent >= 0 && n.chunkCount > 1;
  ASSERT_GE(multiChunk, 2u) << "the case needs inner nodes of several chunks";
  auto file = [&](uint32_t index) { return loadBytes(dir + "/" + m.chunks[index].file); };
  ASSERT_TRUE(receiveChunk(ds, 0, file(0)));
  std::mt19937 rng(5);
  std::vector<uint32_t> changed;
  bool reached = false;
  // Always the receivable chunk of another node than the last, when there is one.
  int32_t lastNode = -1;
  uint32_t interleaved = 0;
  for (;;) {
    std::vector<uint32_t> ready;
    for (uint32_t k = 0; k < m.nodes.size(); ++k)
      if (ds.nodeChunksReceived[k] < m.nodes[k].chunkCount &&
          ds.canReceive(m.nodes[k].firstChunk + ds.nodeChunksReceived[k]))
        ready.push_back(k);
    if (ready.empty()) break;
    std::vector<uint32_t> others;
    for (uint32_t k : ready)
      if (int32_t(k) != lastNode) others.push_back(k);
    const std::vector<uint32_t>& from = others.empty() ? ready : others;
    const uint32_t k = from[rng() % from.size()];
    if (ds.nodeChunksReceived[k] > 0 && int32_t(k) != lastNode) ++interleaved;
    const uint32_t chunk = m.nodes[k].firstChunk + ds.nodeChunksReceived[k];
    ASSERT_TRUE(receiveChunk(ds, chunk, file(chunk))) << "chunk " << chunk;
    lastNode = int32_t(k);
    if (rng() % 2) {
      ASSERT_TRUE(stepTowards(ds, ds.splitsReceived(), ~0u, changed, &reached));
    }
  }
  EXPECT_GT(interleaved, 0u) << "no node's chunks were interleaved with another's";
  ASSERT_TRUE(stepTowards(ds, ds.splitsReceived(), ~0u, changed, &reached) && reached);
  expectValidLevel(ds.pm.mesh, "interleaved chunks");
  Dataset whole;
  ASSERT_TRUE(loadPackedDir(dir, whole));
  EXPECT_TRUE(stableMesh(ds) == stableMesh(whole)) << "(the whole stream in manifest order: stable ids are its own)";
}

// The viewer gives back regions it no longer needs (memory): a node without received children,
// its splits undone first, leaves the dataset as if it had never come. What stays is the same
// mesh as those nodes loaded on their own, the level still moves both ways, and the node can come
// again. A node with a received child, or with splits applied, is refused and nothing changes.
TEST(Partial, ADatasetForgetsNodesItNoLongerNeeds) {
  std::mt19937 rng(21);
  Dataset ds;
  const std::string dir = packHarmonic16("partial-forget", 256, 2);
  ASSERT_TRUE(openDataset(ds, loadFile(dir + "/manifest.json")));
  const Manifest& m = ds.manifest;
  auto file = [&](uint32_t index) { return loadBytes(dir + "/" + m.chunks[index].file); };
  std::vector<uint32_t> changed;
  bool reached = false;
  auto receiveNode = [&](uint32_t k) {
    for (uint32_t ch = m.nodes[k].firstChunk; ch < m.nodes[k].firstChunk + m.nodes[k].chunkCount; ++ch)
      ASSERT_TRUE(receiveChunk(ds, ch, file(ch))) << "chunk " << ch;
  };
  auto applyAll = [&] { ASSERT_TRUE(stepTowards(ds, ds.splitsReceived(), ~0u, changed, &reached) && reached); };
  ASSERT_TRUE(receiveChunk(ds, 0, file(0)));
  std::vector<uint32_t> all(m.nodes.size());
  std::iota(all.begin(), all.end(), 0u);
  for (uint32_t k : randomParentFirstOrder(m, all, rng)) receiveNode(k);
  applyAll();
  auto hasReceivedChild = [&](uint32_t k) {
    for (uint32_t c = 0; c < m.nodes.size(); ++c)
      if (m.nodes[c].parent == int32_t(k) && ds.nodeChunksReceived[c] > 0) return true;
    return false;
  };
  // Refusals change nothing.
  const StableMesh full = stableMesh(ds);
  ASSERT_TRUE(hasReceivedChild(0));
  EXPECT_FALSE(forgetNode(ds, 0)) << "the root has received children";
  uint32_t leaf = 0;
  while (hasReceivedChild(leaf) || m.nodes[leaf].parent < 0) ++leaf;
  EXPECT_FALSE(forgetNode(ds, leaf)) << "its splits are applied";
  EXPECT_TRUE(stableMesh(ds) == full);
  // Forget leaves of the received tree at random, then bring some back.
  std::vector<uint8_t> in(m.nodes.size(), 1);
  for (int round = 0; round < 12; ++round) {
    std::vector<uint32_t> leaves;
    for (uint32_t k = 0; k < m.nodes.size(); ++k)
      if (in[k] && m.nodes[k].parent >= 0 && !hasReceivedChild(k)) leaves.push_back(k);
    ASSERT_FALSE(leaves.empty());
    const uint32_t k = leaves[rng() % leaves.size()];
    ASSERT_TRUE(stepTowards(ds, nodeFirstSplit(ds, k), ~0u, changed, &reached) && reached);
    ASSERT_TRUE(forgetNode(ds, k)) << "node " << k;
    in[k] = 0;
    EXPECT_EQ(ds.nodeChunksReceived[k], 0u);
    if (round % 3 == 2) {  // the level back to the base and forward again
      ASSERT_TRUE(stepTowards(ds, 0, ~0u, changed, &reached) && reached);
    }
    applyAll();
    std::vector<uint32_t> kept;
    for (uint32_t n = 0; n < m.nodes.size(); ++n)
      if (in[n]) kept.push_back(n);
    PartialDataset pd;
    ASSERT_TRUE(loadPartialDir(dir, kept, pd));
    const std::string what = "after forgetting node " + std::to_string(k) + " (round " + std::to_string(round) + ")";
    EXPECT_TRUE(stableMesh(ds) == stableMesh(pd)) << what;
    expectValidLevel(ds.pm.mesh, what);
    if (round % 4 == 3) {  // one comes back
      receiveNode(k);
      in[k] = 1;
      applyAll();
    }
  }
  // Everything again: the whole mesh.
  for (uint32_t k : randomParentFirstOrder(m, all, rng))
    if (!in[k]) receiveNode(k);
  applyAll();
  EXPECT_TRUE(stableMesh(ds) == full);
}
