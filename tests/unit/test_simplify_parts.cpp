// Simplification in parts (SimplifyPart, pack/part.h): a part that owns everything is the whole
// mesh; two halves with their halo collapse only their inner vertices, merge, and the root of
// the merged part finishes a valid mesh; one thread and two alike; a part's bytes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "pack/part.h"
#include "pack/simplify.h"
#include "test_helpers.h"
#include "validate.h"

using namespace tetstream;
using namespace tetstream::test;

namespace {

// The part of `m` that owns the vertices `mine` selects: every tet with an owned vertex and
// every vertex of those, in input order, with input ids.
PartMesh partOf(const TetMesh& m, const std::vector<uint8_t>& mine) {
  const uint32_t V = m.vertexCount(), T = m.tetCount();
  std::vector<uint8_t> used(V, 0);
  std::vector<uint32_t> tets;
  for (uint32_t t = 0; t < T; ++t) {
    const uint32_t* v = &m.tets[4 * t];
    if (!(mine[v[0]] || mine[v[1]] || mine[v[2]] || mine[v[3]])) continue;
    tets.push_back(t);
    for (int k = 0; k < 4; ++k) used[v[k]] = 1;
  }
  PartMesh p;
  p.mesh.fields.resize(m.fields.size());
  for (size_t f = 0; f < m.fields.size(); ++f) p.mesh.fields[f].name = m.fields[f].name;
  std::vector<uint32_t> local(V, ~0u);
  for (uint32_t v = 0; v < V; ++v) {
    if (!used[v]) continue;
    local[v] = uint32_t(p.vertexId.size());
    p.vertexId.push_back(v);
    p.owned.push_back(mine[v]);
    p.mesh.positions.insert(p.mesh.positions.end(), &m.positions[3 * v], &m.positions[3 * v] + 3);
    for (size_t f = 0; f < m.fields.size(); ++f) p.mesh.fields[f].values.push_back(m.fields[f].values[v]);
  }
  for (uint32_t t : tets) {
    for (int k = 0; k < 4; ++k) p.mesh.tets.push_back(local[m.tets[4 * t + k]]);
    p.tetId.push_back(t);
  }
  return p;
}

// Per vertex of `m`: 1 where x < c.
std::vector<uint8_t> below(const TetMesh& m, float c) {
  std::vector<uint8_t> side(m.vertexCount());
  for (uint32_t v = 0; v < m.vertexCount(); ++v) side[v] = m.positions[3 * v] < c;
  return side;
}

// The range of field 0 over the owned vertices of p.
Range ownedRange(const PartMesh& p) {
  Range r{INFINITY, -INFINITY};
  for (uint32_t v = 0; v < p.mesh.vertexCount(); ++v)
    if (p.owned[v]) {
      r.min = std::min(r.min, p.mesh.fields[0].values[v]);
      r.max = std::max(r.max, p.mesh.fields[0].values[v]);
    }
  return r;
}

// Part p of `whole` simplified as a region of the tree of ranks (topIsRegion), to its share of
// `target` by owned vertices.
void simplifyRegion(const TetMesh& whole, const PartMesh& p, uint32_t target, int threads, SimplifyPart& sp,
                    SimplifyResult& s) {
  sp = wholeMeshPart(whole, 0);
  const Range r = ownedRange(p);
  sp.topMin = r.min;
  sp.topMax = r.max;
  sp.owned = &p.owned;
  sp.carried = p.carried.fit.empty() ? nullptr : &p.carried;
  sp.topIsRegion = true;
  SimplifyOptions o;
  const uint32_t owned = uint32_t(std::count(p.owned.begin(), p.owned.end(), 1));
  o.targetVertices = uint32_t(uint64_t(target) * owned / whole.vertexCount());
  o.leafVertices = 128;
  o.threads = threads;
  o.part = &sp;
  ASSERT_TRUE(simplifyMesh(p.mesh, o, s));
}

// Per vertex of p: it or a neighbour is not owned (it is in a tet with a halo vertex).
std::vector<uint8_t> nextToHalo(const PartMesh& p) {
  std::vector<uint8_t> near(p.mesh.vertexCount(), 0);
  for (uint32_t t = 0; t < p.mesh.tetCount(); ++t) {
    const uint32_t* v = &p.mesh.tets[4 * t];
    if (p.owned[v[0]] && p.owned[v[1]] && p.owned[v[2]] && p.owned[v[3]]) continue;
    for (int k = 0; k < 4; ++k) near[v[k]] = 1;
  }
  return near;
}

void expectSameLog(const SimplifyResult& a, const SimplifyResult& b) {
  EXPECT_EQ(a.log.i, b.log.i);
  EXPECT_EQ(a.log.j, b.log.j);
  EXPECT_EQ(a.log.fieldError, b.log.fieldError);
  EXPECT_EQ(a.log.iValue, b.log.iValue);
  EXPECT_EQ(a.log.jValue, b.log.jValue);
  EXPECT_EQ(a.values, b.values);
  EXPECT_EQ(a.tree.sectionNode, b.tree.sectionNode);
  EXPECT_EQ(a.tree.sectionEnd, b.tree.sectionEnd);
}

void expectSamePart(const PartMesh& a, const PartMesh& b) {
  EXPECT_EQ(a.mesh.name, b.mesh.name);
  EXPECT_EQ(a.mesh.positions, b.mesh.positions);
  EXPECT_EQ(a.mesh.tets, b.mesh.tets);
  ASSERT_EQ(a.mesh.fields.size(), b.mesh.fields.size());
  for (size_t f = 0; f < a.mesh.fields.size(); ++f) {
    EXPECT_EQ(a.mesh.fields[f].name, b.mesh.fields[f].name);
    EXPECT_EQ(a.mesh.fields[f].values, b.mesh.fields[f].values);
  }
  EXPECT_EQ(a.vertexId, b.vertexId);
  EXPECT_EQ(a.tetId, b.tetId);
  EXPECT_EQ(a.owned, b.owned);
  EXPECT_EQ(a.carried.fit, b.carried.fit);
  EXPECT_EQ(a.carried.represented, b.carried.represented);
  EXPECT_EQ(a.carried.boundary, b.carried.boundary);
  ASSERT_EQ(a.carried.boundaryQuadric.size(), b.carried.boundaryQuadric.size());
  ASSERT_EQ(a.carried.fieldQuadric.size(), b.carried.fieldQuadric.size());
  for (size_t v = 0; v < a.carried.boundaryQuadric.size(); ++v) {
    EXPECT_EQ(0, std::memcmp(&a.carried.boundaryQuadric[v], &b.carried.boundaryQuadric[v], sizeof(Quadric)));
    EXPECT_EQ(0, std::memcmp(&a.carried.fieldQuadric[v], &b.carried.fieldQuadric[v], sizeof(FieldQuadric)));
  }
}

}  // namespace

// A part that owns every vertex, with no state carried and its top as the root, is the whole
// mesh: the same collapses in the same order (values not refitted on either side: a part never
// refits).
TEST(SimplifyParts, AllOwnedIsTheWholeMesh) {
  const TetMesh m = harmonic(14);
  for (uint32_t leaf : {0u, 256u}) {
    SimplifyOptions o;
    o.targetVertices = 150;
    o.refitValues = false;
    o.leafVertices = leaf;
    SimplifyResult whole, part;
    ASSERT_TRUE(simplifyMesh(m, o, whole));
    const std::vector<uint8_t> owned(m.vertexCount(), 1);
    SimplifyPart sp = wholeMeshPart(m, 0);
    sp.owned = &owned;
    o.part = &sp;
    ASSERT_TRUE(simplifyMesh(m, o, part));
    ASSERT_GT(whole.log.size(), 1000u);
    expectSameLog(whole, part);
    EXPECT_EQ(whole.tree.depth, part.tree.depth);
    EXPECT_EQ(whole.stopReason, part.stopReason);
    EXPECT_EQ(part.carried.fit.size(), part.vertices) << "the state of the vertices left alive";
  }
}

// Two halves of a grid (x < c and the rest), each with its halo, simplified as regions in their
// own trees, merged, and the merged part simplified as the root to the target: no collapse
// touches a halo vertex or a vertex next to the halo, fitted values keep to each half's range,
// and the result is a valid mesh of the same volume.
TEST(SimplifyParts, TwoHalvesThenTheRoot) {
  const TetMesh m = harmonic(16);
  const uint32_t target = 300;
  const std::vector<uint8_t> left = below(m, 0.37f);
  std::vector<uint8_t> right(left.size());
  for (size_t v = 0; v < left.size(); ++v) right[v] = !left[v];
  const PartMesh parts[2] = {partOf(m, left), partOf(m, right)};
  PartMesh after[2];
  for (int k = 0; k < 2; ++k) {
    const PartMesh& p = parts[k];
    ASSERT_LT(std::count(p.owned.begin(), p.owned.end(), 1), std::ptrdiff_t(p.owned.size()));
    SimplifyPart sp;
    SimplifyResult s;
    simplifyRegion(m, p, target, 2, sp, s);
    ASSERT_GT(s.tree.depth, 0u);
    ASSERT_GT(s.log.size(), 200u);
    EXPECT_EQ(s.tree.sectionNode.back(), 1u);
    EXPECT_EQ(s.tree.sectionEnd.back(), s.log.size());
    EXPECT_EQ(s.stopReason, "level cost reached");
    const std::vector<uint8_t> near = nextToHalo(p);
    for (uint32_t c = 0; c < s.log.size(); ++c) {
      for (uint32_t v : {s.log.i[c], s.log.j[c]}) {
        ASSERT_TRUE(p.owned[v]) << "collapse " << c;
        ASSERT_FALSE(near[v]) << "collapse " << c;
      }
      EXPECT_GE(s.log.jValue[c], sp.topMin);
      EXPECT_LE(s.log.jValue[c], sp.topMax);
    }
    for (uint32_t v = 0; v < p.mesh.vertexCount(); ++v) {
      if (!p.owned[v]) {
        EXPECT_TRUE(s.vertexAlive[v]);
        EXPECT_EQ(s.tree.leafOf[v], ~0u);
        continue;
      }
      EXPECT_NE(s.tree.leafOf[v], ~0u);
      if (!s.vertexAlive[v]) continue;
      EXPECT_GE(s.values[v], sp.topMin);
      EXPECT_LE(s.values[v], sp.topMax);
    }
    after[k] = partAfter(p, s);
    EXPECT_EQ(after[k].mesh.vertexCount(), s.vertices);
    EXPECT_EQ(after[k].mesh.tetCount(), s.tetCount);
    expectValid(after[k].mesh, "a half after its levels");
  }
  const PartMesh merged = mergeParts(after[0], after[1]);
  EXPECT_TRUE(std::all_of(merged.owned.begin(), merged.owned.end(), [](uint8_t o) { return o == 1; }));
  EXPECT_TRUE(std::is_sorted(merged.vertexId.begin(), merged.vertexId.end()));
  EXPECT_EQ(merged.mesh.vertexCount(),
            after[0].mesh.vertexCount() + after[1].mesh.vertexCount() -
                (parts[0].mesh.vertexCount() + parts[1].mesh.vertexCount() - m.vertexCount()));
  expectValid(merged.mesh, "the halves merged");
  EXPECT_NEAR(meshVolume(merged.mesh), meshVolume(m), 1e-6 * meshVolume(m));

  SimplifyPart sp = wholeMeshPart(m, 0);
  sp.owned = &merged.owned;
  sp.carried = &merged.carried;
  SimplifyOptions o;
  o.targetVertices = target;
  o.leafVertices = 128;
  o.part = &sp;
  SimplifyResult root;
  ASSERT_TRUE(simplifyMesh(merged.mesh, o, root));
  EXPECT_TRUE(root.vertices <= target || root.stopReason != "target reached") << root.stopReason;
  EXPECT_LE(root.vertices, target + 50) << root.stopReason;
  const PartMesh end = partAfter(merged, root);
  expectValid(end.mesh, "the root's result");
  for (uint32_t t = 0; t < end.mesh.tetCount(); ++t) ASSERT_GT(tetVolume(end.mesh, t), 0.0) << "tet " << t;
  EXPECT_NEAR(meshVolume(end.mesh), meshVolume(m), 1e-6 * meshVolume(m));
  for (uint32_t v = 0; v < merged.mesh.vertexCount(); ++v)
    if (root.vertexAlive[v]) {
      EXPECT_GE(root.values[v], sp.topMin);
      EXPECT_LE(root.values[v], sp.topMax);
    }
  // Each vertex stands for as many input vertices as were collapsed into it, all together every
  // input vertex once.
  uint64_t represented = 0;
  for (uint32_t v = 0; v < end.mesh.vertexCount(); ++v) represented += end.carried.represented[v];
  EXPECT_EQ(represented, m.vertexCount());

  // Not far from the whole mesh simplified on one process (to the same count).
  SimplifyOptions wo;
  wo.targetVertices = root.vertices;
  wo.refitValues = false;
  SimplifyResult whole;
  ASSERT_TRUE(simplifyMesh(m, wo, whole));
  const double inParts = fieldRms(merged.mesh, coarseMesh(merged.mesh, root), 0);
  const double atOnce = fieldRms(m, coarseMesh(m, whole), 0);
  EXPECT_LT(inParts, 1.5 * atOnce) << inParts << " vs " << atOnce;
}

// One thread and two give the same collapses, in the parts and at the root.
TEST(SimplifyParts, SameOnOneThreadAndTwo) {
  const TetMesh m = harmonic(14);
  const std::vector<uint8_t> left = below(m, 0.5f);
  const PartMesh p = partOf(m, left);
  SimplifyPart sp1, sp2;
  SimplifyResult one, two;
  simplifyRegion(m, p, 200, 1, sp1, one);
  simplifyRegion(m, p, 200, 2, sp2, two);
  ASSERT_GT(one.log.size(), 100u);
  expectSameLog(one, two);
  EXPECT_EQ(one.tets, two.tets);
  EXPECT_EQ(one.carried.fit, two.carried.fit);
  EXPECT_EQ(one.carried.represented, two.carried.represented);
  expectSamePart(partAfter(p, one), partAfter(p, two));
}

// A part with a halo simplified as the root (topIsRegion false) still leaves its halo and the
// vertices next to it alone, and goes on as far as that allows.
TEST(SimplifyParts, RootWithAHaloKeepsItsHalo) {
  const TetMesh m = harmonic(12);
  const PartMesh p = partOf(m, below(m, 0.1f));
  SimplifyPart sp = wholeMeshPart(m, 0);
  sp.owned = &p.owned;
  SimplifyOptions o;
  o.targetVertices = 10;
  o.leafVertices = 128;
  o.part = &sp;
  SimplifyResult s;
  ASSERT_TRUE(simplifyMesh(p.mesh, o, s));
  ASSERT_GT(s.log.size(), 300u);
  EXPECT_EQ(s.stopReason, "no legal collapse left");
  const std::vector<uint8_t> near = nextToHalo(p);
  for (uint32_t c = 0; c < s.log.size(); ++c)
    for (uint32_t v : {s.log.i[c], s.log.j[c]}) ASSERT_TRUE(p.owned[v] && !near[v]) << "collapse " << c;
  expectValid(partAfter(p, s).mesh, "a part simplified as the root");
}

// A part's bytes read back to the same part, with and without carried state; every truncation
// and a tet naming a vertex past the end are refused.
TEST(SimplifyParts, BytesRoundTrip) {
  const TetMesh m = harmonic(4);
  const std::vector<uint8_t> left = below(m, 0.5f);
  PartMesh p = partOf(m, left);
  p.mesh.name = "left";
  std::vector<uint8_t> bytes;
  writePart(p, bytes);
  PartMesh back;
  ASSERT_TRUE(readPart(bytes, back));
  expectSamePart(p, back);

  SimplifyPart sp;
  SimplifyResult s;
  simplifyRegion(m, p, 20, 1, sp, s);
  const PartMesh after = partAfter(p, s);
  ASSERT_FALSE(after.carried.fit.empty());
  writePart(after, bytes);
  ASSERT_TRUE(readPart(bytes, back));
  expectSamePart(after, back);

  for (size_t n = 0; n < bytes.size(); ++n) {
    const std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + ptrdiff_t(n));
    ASSERT_FALSE(readPart(cut, back)) << n << " of " << bytes.size();
  }
  std::vector<uint8_t> longer = bytes;
  longer.push_back(0);
  EXPECT_FALSE(readPart(longer, back));
  PartMesh bad = after;
  bad.mesh.tets[5] = bad.mesh.vertexCount();
  writePart(bad, bytes);
  EXPECT_FALSE(readPart(bytes, back));
  bad = after;
  std::swap(bad.vertexId[0], bad.vertexId[1]);
  writePart(bad, bytes);
  EXPECT_FALSE(readPart(bytes, back));
  // Counts far beyond the bytes (a vertex count near 2^32) are refused before anything is
  // allocated.
  writePart(after, bytes);
  for (int k = 0; k < 4; ++k) bytes[4 + k] = 0xff;
  EXPECT_FALSE(readPart(bytes, back));
}
