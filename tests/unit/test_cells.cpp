// The cell pipeline every reader shares (core/io/cells.cpp): hexahedra, wedges and pyramids
// split into tets that conform across cells under any vertex numbering, structured grids split
// as the generator splits them, and degenerate cells, repeated and duplicate vertices handled.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <sstream>

#include "io/mesh_io.h"
#include "io/readers.h"
#include "test_helpers.h"
#include "validate.h"

namespace tetstream {
namespace {

using test::allNotes;
using test::boundaryArea;
using test::expectValid;
using test::fixturePath;
using test::hasNote;
using test::totalVolume;

std::string formatsPath(const std::string& name) { return fixturePath("formats/" + name); }

// ------------------------------------------------------------------ conformity under any numbering
// A legacy VTK ASCII file of an n x n x n block of unit cubes, each a hexahedron, two wedges or
// six pyramids around a centre point (by `pattern`), with the vertex ids shuffled.
std::string blockMesh(int n, int pattern, uint32_t seed, uint64_t& cells) {
  std::vector<std::array<double, 3>> pts;
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) pts.push_back({double(i), double(j), double(k)});
  auto vid = [&](int i, int j, int k) { return i + (n + 1) * (j + (n + 1) * k); };
  std::vector<std::pair<int, std::vector<int>>> out;
  std::mt19937 rng(seed);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        std::vector<int> c = {vid(i, j, k),     vid(i + 1, j, k),     vid(i + 1, j + 1, k),     vid(i, j + 1, k),
                              vid(i, j, k + 1), vid(i + 1, j, k + 1), vid(i + 1, j + 1, k + 1), vid(i, j + 1, k + 1)};
        // Mixed: a random kind per cube, except that wedges come in whole z columns (their
        // triangle faces only meet other wedges' triangles, as in a real prism layer).
        int kind = pattern;
        if (pattern == 3) {
          kind = (std::mt19937(seed * 7 + uint32_t(i * 5 + j))() % 3) == 1 ? 1 : int(rng() % 2) * 2;
        }
        if (kind == 0) {
          out.push_back({12, c});
        } else if (kind == 1) {
          // Two wedges split along a diagonal of the z faces; cubes stacked in z share their
          // triangles, so the diagonal is chosen per (i, j) column.
          if ((std::mt19937(seed * 1000 + uint32_t(i * 31 + j))() % 2) != 0) {
            out.push_back({13, {c[0], c[1], c[2], c[4], c[5], c[6]}});
            out.push_back({13, {c[0], c[2], c[3], c[4], c[6], c[7]}});
          } else {
            out.push_back({13, {c[0], c[1], c[3], c[4], c[5], c[7]}});
            out.push_back({13, {c[1], c[2], c[3], c[5], c[6], c[7]}});
          }
        } else {
          int centre = int(pts.size());
          pts.push_back({i + 0.5, j + 0.5, k + 0.5});
          for (auto f : std::vector<std::array<int, 4>>{
                   {0, 1, 2, 3}, {4, 7, 6, 5}, {0, 4, 5, 1}, {1, 5, 6, 2}, {2, 6, 7, 3}, {3, 7, 4, 0}})
            out.push_back({14, {c[f[0]], c[f[1]], c[f[2]], c[f[3]], centre}});
        }
      }
  // Shuffle the numbering: the split may only depend on ids, and must conform for any ids.
  std::vector<int> perm(pts.size());
  for (size_t i = 0; i < perm.size(); ++i) perm[i] = int(i);
  std::shuffle(perm.begin(), perm.end(), rng);
  std::vector<std::array<double, 3>> shuffled(pts.size());
  for (size_t i = 0; i < pts.size(); ++i) shuffled[size_t(perm[i])] = pts[i];
  std::ostringstream s;
  s << "# vtk DataFile Version 4.2\nblock\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS " << pts.size() << " double\n";
  for (const auto& p : shuffled) s << p[0] << " " << p[1] << " " << p[2] << "\n";
  size_t ints = 0;
  for (const auto& c : out) ints += 1 + c.second.size();
  s << "CELLS " << out.size() << " " << ints << "\n";
  for (const auto& c : out) {
    s << c.second.size();
    for (int id : c.second) s << " " << perm[size_t(id)];
    s << "\n";
  }
  s << "CELL_TYPES " << out.size() << "\n";
  for (const auto& c : out) s << c.first << "\n";
  cells = out.size();
  return s.str();
}

TEST(SplitConformity, HexWedgePyramidBlocksUnderShuffledIds) {
  const int n = 3;
  for (int pattern = 0; pattern < 4; ++pattern)
    for (uint32_t seed = 1; seed <= 6; ++seed) {
      uint64_t cells;
      const std::string text = blockMesh(n, pattern, seed, cells);
      TetMesh m;
      ReadReport r;
      Result res = readMeshBytes(text, "block.vtk", m, r);
      ASSERT_TRUE(res) << res.message;
      const std::string what = "pattern " + std::to_string(pattern) + " seed " + std::to_string(seed);
      EXPECT_NEAR(totalVolume(m), n * n * n, 1e-9) << what;
      EXPECT_NEAR(boundaryArea(m), 6.0 * n * n, 1e-9) << what << ": a non-conforming face adds boundary area";
      expectValid(m, what);
      const uint32_t perCube[3] = {6, 6, 12};  // a hexahedron; 2 wedges of 3; 6 pyramids of 2
      if (pattern < 3) {
        EXPECT_EQ(m.tetCount(), perCube[pattern] * n * n * n) << what;
      }
      // Every inner face is shared by exactly two tets: tets * 4 = 2 * inner + boundary faces.
      FaceAdjacency adj;
      buildFaceAdjacency(m.tets, m.vertexCount(), adj);
      uint64_t unmatched = 0;
      for (uint32_t o : adj.opposite) unmatched += o == kNoNeighbor;
      EXPECT_EQ(unmatched, validateMesh(m).boundaryFaces) << what;
    }
}

TEST(SplitConformity, StructuredGridIsKuhnAndMatchesTheGenerator) {
  // A 4x3x3 ImageData of VTK's: the same 6 tets per cell around the main diagonal in every cell.
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(readMesh(formatsPath("grid43.vti"), m, r));
  for (uint32_t t = 0; t < m.tetCount(); ++t) {
    // Every tet has an edge from its cell's lowest corner to its highest (the main diagonal).
    const uint32_t* v = &m.tets[4 * t];
    float lo[3] = {1e9, 1e9, 1e9}, hi[3] = {-1e9, -1e9, -1e9};
    for (int k = 0; k < 4; ++k)
      for (int c = 0; c < 3; ++c) {
        lo[c] = std::min(lo[c], m.positions[3 * v[k] + c]);
        hi[c] = std::max(hi[c], m.positions[3 * v[k] + c]);
      }
    bool hasLo = false, hasHi = false;
    for (int k = 0; k < 4; ++k) {
      const float* p = &m.positions[3 * v[k]];
      hasLo |= p[0] == lo[0] && p[1] == lo[1] && p[2] == lo[2];
      hasHi |= p[0] == hi[0] && p[1] == hi[1] && p[2] == hi[2];
    }
    EXPECT_TRUE(hasLo && hasHi) << "tet " << t;
  }
}

// ------------------------------------------------------------------ degenerate input
std::string legacy(const std::string& points, int npts, const std::string& cells, int ncells, int ints,
                   const std::string& types, const std::string& tail = "") {
  return "# vtk DataFile Version 4.2\nd\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS " + std::to_string(npts) +
         " float\n" + points + "\nCELLS " + std::to_string(ncells) + " " + std::to_string(ints) + "\n" + cells +
         "\nCELL_TYPES " + std::to_string(ncells) + "\n" + types + "\n" + tail;
}

TEST(Degenerate, CollapsedHexahedronKeepsItsVolume) {
  // A pyramid written as a hexahedron with its top face collapsed to one point (ids 4 4 4 4).
  const std::string pts = "0 0 0 1 0 0 1 1 0 0 1 0 0.5 0.5 1";
  TetMesh m;
  ReadReport r;
  Result res = readMeshBytes(legacy(pts, 5, "8 0 1 2 3 4 4 4 4", 1, 9, "12"), "c.vtk", m, r);
  ASSERT_TRUE(res) << res.message;
  EXPECT_NEAR(totalVolume(m), 1.0 / 3.0, 1e-9);
  EXPECT_EQ(m.tetCount(), 2u);
  EXPECT_TRUE(hasNote(r, "with a repeated vertex (no volume) from 1 degenerate cell")) << allNotes(r);
  expectValid(m, "collapsed hex");
}

TEST(Degenerate, DuplicateVerticesMergedOrKeptApart) {
  // Two tets sharing a face through duplicated points: merged, the face becomes inner.
  const std::string pts = "0 0 0 1 0 0 0 1 0 0 0 1 1 0 0 0 1 0 0 0 1 1 1 1";
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(readMeshBytes(legacy(pts, 8, "4 0 1 2 3\n4 7 4 6 5", 2, 10, "10 10",
                                   "POINT_DATA 8\nSCALARS s float\nLOOKUP_TABLE default\n0 1 2 3 5 6 7 9\n"),
                            "d.vtk", m, r));
  EXPECT_EQ(m.vertexCount(), 5u);
  EXPECT_EQ(validateMesh(m).boundaryFaces, 6u);
  EXPECT_TRUE(hasNote(r, "merged 3 duplicate vertices")) << allNotes(r);
  EXPECT_TRUE(hasNote(r, "3 of them had other field values, averaged")) << allNotes(r);
  EXPECT_EQ(m.fields[0].values, (std::vector<float>{0, 3, 4, 5, 9}));

  // Two tets touching only along an edge through duplicated points: merging would make that
  // edge non-manifold, so the copies are kept apart and said so.
  const std::string pts2 = "0 0 0 1 0 0 0 1 0 0 0 1 0 0 0 1 0 0 0 -1 0 0 0 -1";
  ASSERT_TRUE(readMeshBytes(legacy(pts2, 8, "4 0 1 2 3\n4 4 5 6 7", 2, 10, "10 10"), "e.vtk", m, r));
  EXPECT_EQ(m.vertexCount(), 8u);
  EXPECT_TRUE(hasNote(r,
                      "found 2 vertices at the same coordinates as another; not merged, since merging would make "
                      "1 more face or boundary edge non-manifold"))
      << allNotes(r);
  EXPECT_EQ(validateMesh(m).nonManifoldBoundaryEdges, 0u);

  // The same, with more tets elsewhere, two of them already sharing only an edge. With few cells
  // near the merged vertices the count looks only there (the cases above count the whole mesh),
  // and what lies elsewhere is the same either way.
  std::string pts3 = pts2 + " 10 0 0 11 0 0 10 1 0 10 0 1 10 -1 0 10 0 -1";
  std::string cells3 = "4 0 1 2 3\n4 4 5 6 7\n4 8 9 10 11\n4 8 9 12 13";
  const int apartTets = 6;  // alone, far away: 2 of 10 cells are near a merged vertex
  for (int k = 0; k < apartTets; ++k) {
    const std::string x = std::to_string(20 + 2 * k), x1 = std::to_string(21 + 2 * k);
    pts3 += " " + x + " 0 0 " + x1 + " 0 0 " + x + " 1 0 " + x + " 0 1";
    const int b = 14 + 4 * k;
    cells3 += "\n4 " + std::to_string(b) + " " + std::to_string(b + 1) + " " + std::to_string(b + 2) + " " +
              std::to_string(b + 3);
  }
  ASSERT_TRUE(readMeshBytes(
      legacy(pts3, 14 + 4 * apartTets, cells3, 4 + apartTets, 5 * (4 + apartTets), "10 10 10 10 10 10 10 10 10 10"),
      "f.vtk", m, r));
  EXPECT_TRUE(hasNote(r, "not merged, since merging would make 1 more face or boundary edge non-manifold"))
      << allNotes(r);
  EXPECT_EQ(m.tetCount(), 10u);
  EXPECT_EQ(validateMesh(m).nonManifoldBoundaryEdges, 1u);
}

TEST(Degenerate, RepeatedVertexTetsDroppedAndUnusedVerticesDropped) {
  const std::string pts = "0 0 0 1 0 0 0 1 0 0 0 1 5 5 5";
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(readMeshBytes(legacy(pts, 5, "4 0 1 2 3\n4 0 1 1 3", 2, 10, "10 10"), "r.vtk", m, r));
  EXPECT_EQ(m.tetCount(), 1u);
  EXPECT_EQ(m.vertexCount(), 4u);
  EXPECT_TRUE(hasNote(r, "dropped 1 tetrahedron with a repeated vertex")) << allNotes(r);
  EXPECT_TRUE(hasNote(r, "dropped 1 vertex that no tetrahedron uses (1 in no cell)")) << allNotes(r);
  // Nothing but degenerate cells: refused, saying why.
  Result res = readMeshBytes(legacy(pts, 5, "4 0 1 1 3", 1, 5, "10"), "r.vtk", m, r);
  EXPECT_EQ(res.status, Status::NoTets);
  EXPECT_NE(res.message.find("every cell is degenerate"), std::string::npos) << res.message;
}

TEST(Degenerate, StructuredGridWithACollapsedEdge) {
  // A 3x2x2 structured grid whose last column of cells collapses to a line (at x = 2, the points
  // of y = 0 and y = 1 coincide), like the collapsed cells of Blunt Fin's grid.
  std::string p;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i)
        p += std::to_string(i) + " " + (i == 2 ? "0.5" : std::to_string(j)) + " " + std::to_string(k) + "\n";
  std::string text =
      "# vtk DataFile Version 3.0\ns\nASCII\nDATASET STRUCTURED_GRID\nDIMENSIONS 3 2 2\nPOINTS 12 float\n" + p;
  TetMesh m;
  ReadReport r;
  Result res = readMeshBytes(text, "s.vtk", m, r);
  ASSERT_TRUE(res) << res.message;
  EXPECT_TRUE(hasNote(r, "merged 2 duplicate vertices")) << allNotes(r);
  EXPECT_TRUE(hasNote(r, "with a repeated vertex (no volume) from 1 degenerate cell")) << allNotes(r);
  EXPECT_NEAR(totalVolume(m), 1.0 + 0.5, 1e-9);  // a unit cube plus a wedge of volume 1/2
  expectValid(m, "collapsed column");
}

}  // namespace
}  // namespace tetstream
