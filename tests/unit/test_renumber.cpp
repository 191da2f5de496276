// Renumbering for locality (pack/renumber.h): scattered vertex numbering is found, renumbered into
// the same mesh, and packs like any mesh; a broken scattered mesh is refused by the validation.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "dataset.h"
#include "pack/packer.h"
#include "pack/renumber.h"
#include "test_helpers.h"

using namespace tetstream;
using namespace tetstream::test;

namespace {

// The mesh with its vertices and tets in a shuffled order (each tet keeps its slot order).
TetMesh shuffled(const TetMesh& m, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<uint32_t> vOrder(m.vertexCount()), tOrder(m.tetCount()), newId(m.vertexCount());
  for (uint32_t k = 0; k < vOrder.size(); ++k) vOrder[k] = k;
  for (uint32_t k = 0; k < tOrder.size(); ++k) tOrder[k] = k;
  std::shuffle(vOrder.begin(), vOrder.end(), rng);
  std::shuffle(tOrder.begin(), tOrder.end(), rng);
  TetMesh out;
  out.name = m.name;
  for (uint32_t r = 0; r < vOrder.size(); ++r) {
    newId[vOrder[r]] = r;
    out.positions.insert(out.positions.end(), &m.positions[3 * vOrder[r]], &m.positions[3 * vOrder[r]] + 3);
  }
  for (const ScalarField& f : m.fields) {
    ScalarField g{f.name, {}};
    for (uint32_t v : vOrder) g.values.push_back(f.values[v]);
    out.fields.push_back(g);
  }
  for (uint32_t t : tOrder)
    for (int k = 0; k < 4; ++k) out.tets.push_back(newId[m.tets[4 * t + k]]);
  return out;
}

}  // namespace

// A grid numbered layer by layer keeps a tet's vertex ids close; a shuffled one does not, and is
// renumbered into the same mesh (every tet with its orientation) numbered as closely as the grid.
TEST(Renumber, ScatteredNumberingIsFoundAndRenumbered) {
  const TetMesh grid = harmonic(12);
  TetMesh m = shuffled(grid, 7);
  EXPECT_LT(numberingSpread(grid), 0.1);
  EXPECT_GT(numberingSpread(m), kScatteredNumbering);
  EXPECT_TRUE(renumberable(m));
  TetMesh broken = m;
  broken.tets[5] = broken.vertexCount();
  EXPECT_FALSE(renumberable(broken));
  broken = m;
  broken.positions[7] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(renumberable(broken));
  const TetMesh before = m;
  renumberForLocality(m);
  EXPECT_LT(numberingSpread(m), 0.1);
  ASSERT_EQ(m.vertexCount(), before.vertexCount());
  ASSERT_EQ(m.tetCount(), before.tetCount());
  // The same tets in slot order, vertices matched by position (unique on a grid), and values.
  std::map<std::array<float, 3>, uint32_t> old;
  for (uint32_t v = 0; v < before.vertexCount(); ++v)
    old[{before.positions[3 * v], before.positions[3 * v + 1], before.positions[3 * v + 2]}] = v;
  std::vector<uint32_t> toOld(m.vertexCount());
  for (uint32_t v = 0; v < m.vertexCount(); ++v) {
    toOld[v] = old.at({m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]});
    EXPECT_EQ(m.fields[0].values[v], before.fields[0].values[toOld[v]]);
  }
  std::set<std::array<uint32_t, 4>> tets;
  for (uint32_t t = 0; t < before.tetCount(); ++t)
    tets.insert({before.tets[4 * t], before.tets[4 * t + 1], before.tets[4 * t + 2], before.tets[4 * t + 3]});
  for (uint32_t t = 0; t < m.tetCount(); ++t)
    EXPECT_TRUE(tets.count(
        {toOld[m.tets[4 * t]], toOld[m.tets[4 * t + 1]], toOld[m.tets[4 * t + 2]], toOld[m.tets[4 * t + 3]]}))
        << "tet " << t;
  for (uint32_t t = 0; t < m.tetCount(); ++t) EXPECT_GT(tetVolume(m, t), 0.0) << "tet " << t;
}

// A shuffled mesh packs, with a note saying it was renumbered, into a stream whose every level is
// valid and whose last level is the input (the numbering aside: expectSameMesh maps by position).
TEST(Renumber, ShuffledMeshRoundTripsExactly) {
  const TetMesh m = shuffled(harmonic(12), 11);
  PackOptions o;
  o.lossless = true;
  o.renumberMinTets = 0;  // (a mesh this small is left as it is by default)
  PackSummary s;
  pack("renumber-notes", m, o, &s);
  bool noted = false;
  for (const std::string& n : s.notes) noted |= n.find("renumbered") != std::string::npos;
  EXPECT_TRUE(noted);
  roundTrip("renumber-shuffled", m, o);
}

// A scattered mesh with a bad index or coordinate is not renumbered (renumberable()) but refused
// by the validation with the reason, as any mesh is: no crash, no stream.
TEST(Renumber, BrokenScatteredMeshIsRefusedNotRenumbered) {
  const TetMesh good = shuffled(harmonic(12), 5);
  PackOptions o;
  o.renumberMinTets = 0;
  for (int broken = 0; broken < 2; ++broken) {
    TetMesh m = good;
    if (broken == 0)
      m.tets[17] = m.vertexCount() + 3;
    else
      m.positions[10] = std::numeric_limits<float>::infinity();
    PackSummary s;
    const std::string dir = tempDir("renumber-broken-" + std::to_string(broken));
    Result r = packMesh(m, dir, o, s);
    EXPECT_FALSE(r);
    EXPECT_EQ(r.status, broken == 0 ? Status::OutOfRange : Status::NonFinite) << r.message;
    EXPECT_NE(r.message.find(broken == 0 ? "reference a vertex that does not exist" : "NaN or infinite"),
              std::string::npos)
        << r.message;
    EXPECT_FALSE(std::filesystem::exists(std::filesystem::path(dir) / "manifest.json"));
  }
}
