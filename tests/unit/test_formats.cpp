// The readers beyond VTU/VTK (Gmsh, TetGen, Medit, VTK structured, PLOT3D) and the cell pipeline
// they share (cells.cpp): every file in tests/fixtures/formats was written by another tool
// (make_format_fixtures.py) and is checked against what that tool was given (expected.json):
// counts, volume, boundary area (a split that does not conform leaves inner faces on the
// boundary and adds area), field values, the point values of converted cell data. Then the
// hexahedron split's conformity under random vertex numberings, degenerate input, hostile bytes.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "adjacency.h"
#include "io/mesh_io.h"
#include "io/readers.h"
#include "test_helpers.h"
#include "validate.h"

namespace tetstream {
namespace {

using test::allNotes;
using test::fixturePath;
using test::hasNote;
using test::loadFile;

std::string formatsPath(const std::string& name) { return fixturePath("formats/" + name); }

const nlohmann::json& expected() {
  static const nlohmann::json j = nlohmann::json::parse(loadFile(formatsPath("expected.json")), nullptr, false);
  return j;
}

double totalVolume(const TetMesh& m) {
  double v = 0;
  for (uint32_t t = 0; t < m.tetCount(); ++t) v += std::abs(tetVolume(m, t));
  return v;
}

double boundaryArea(const TetMesh& m) {
  FaceAdjacency adj;
  buildFaceAdjacency(m.tets, m.vertexCount(), adj);
  std::vector<uint32_t> tris;
  extractBoundary(m.tets, adj, tris);
  double area = 0;
  for (size_t i = 0; i < tris.size(); i += 3) {
    const float* a = &m.positions[3 * size_t(tris[i])];
    const float* b = &m.positions[3 * size_t(tris[i + 1])];
    const float* c = &m.positions[3 * size_t(tris[i + 2])];
    double u[3], v[3];
    for (int k = 0; k < 3; ++k) {
      u[k] = double(b[k]) - a[k];
      v[k] = double(c[k]) - a[k];
    }
    double x = u[1] * v[2] - u[2] * v[1], y = u[2] * v[0] - u[0] * v[2], z = u[0] * v[1] - u[1] * v[0];
    area += 0.5 * std::sqrt(x * x + y * y + z * z);
  }
  return area;
}

// A conforming, valid mesh: every inner face shared by exactly two tets, a closed manifold
// boundary, one orientation, no flat or duplicate tets, no unused vertices.
void expectValid(const TetMesh& m, const std::string& what) {
  ValidationReport v = validateMesh(m);
  EXPECT_FALSE(v.fatal()) << what;
  EXPECT_EQ(v.invertedTets, 0u) << what;
  EXPECT_EQ(v.zeroVolumeTets, 0u) << what;
  EXPECT_EQ(v.duplicateTets, 0u) << what;
  EXPECT_EQ(v.unusedVertices, 0u) << what;
  EXPECT_EQ(v.nonManifoldFaces, 0u) << what;
  EXPECT_EQ(v.nonManifoldBoundaryEdges, 0u) << what;
}

int64_t findVertex(const TetMesh& m, double x, double y, double z) {
  for (uint32_t v = 0; v < m.vertexCount(); ++v)
    if (m.positions[3 * v] == float(x) && m.positions[3 * v + 1] == float(y) && m.positions[3 * v + 2] == float(z))
      return v;
  return -1;
}

// ------------------------------------------------------------------ every fixture vs expected.json
class FormatFixture : public testing::TestWithParam<std::string> {};

TEST_P(FormatFixture, CountsVolumeConformityAndFields) {
  const std::string file = GetParam();
  const nlohmann::json& e = expected()[file];
  TetMesh m;
  ReadReport r;
  Result res = readMesh(formatsPath(file), m, r);
  ASSERT_TRUE(res) << statusName(res.status) << ": " << res.message;
  if (e.contains("vertices")) {
    EXPECT_EQ(m.vertexCount(), e["vertices"].get<uint32_t>()) << file << allNotes(r);
  }
  EXPECT_EQ(m.tetCount(), e["tets"].get<uint32_t>()) << file << allNotes(r);
  EXPECT_NEAR(totalVolume(m), e["volume"].get<double>(), 1e-9 * e["volume"].get<double>()) << file;
  if (e.contains("area")) {
    EXPECT_NEAR(boundaryArea(m), e["area"].get<double>(), 1e-6) << file;
  }
  expectValid(m, file);
  if (e.contains("inputPoints") && e["inputPoints"].get<uint32_t>() > m.vertexCount()) {
    EXPECT_TRUE(hasNote(r, "that no tetrahedron uses")) << file << allNotes(r);
  }

  // The writers' analytic point data: f = x + 2y + 3z, |v| = |p|.
  for (const char* name : {"f", "attr0", "sol0"}) {
    int f = m.findField(name);
    if (f < 0) continue;
    for (uint32_t v = 0; v < m.vertexCount(); ++v) {
      double x = m.positions[3 * v], y = m.positions[3 * v + 1], z = m.positions[3 * v + 2];
      ASSERT_NEAR(m.fields[size_t(f)].values[v], x + 2 * y + 3 * z, 1e-5) << file << " " << name << " vertex " << v;
    }
  }
  for (const char* name : {"v_magnitude", "sol1_magnitude"}) {
    int f = m.findField(name);
    if (f < 0) continue;
    for (uint32_t v = 0; v < m.vertexCount(); ++v) {
      double x = m.positions[3 * v], y = m.positions[3 * v + 1], z = m.positions[3 * v + 2];
      ASSERT_NEAR(m.fields[size_t(f)].values[v], std::sqrt(x * x + y * y + z * z), 1e-5) << file << " vertex " << v;
    }
  }
  // Cell data turned into point data: the values the fixture script computed.
  for (const char* name : {"col", "c", "cid"}) {
    if (!e.contains(name)) continue;
    int f = m.findField(name);
    ASSERT_GE(f, 0) << file << " has no field " << name << allNotes(r);
    for (const auto& row : e[name]) {
      int64_t v = findVertex(m, row[0], row[1], row[2]);
      ASSERT_GE(v, 0) << file << " vertex at " << row;
      EXPECT_NEAR(m.fields[size_t(f)].values[size_t(v)], row[3].get<double>(), 1e-5) << file << " " << name << " at "
                                                                                      << row;
    }
    EXPECT_TRUE(hasNote(r, std::string("converted cell data '") + name)) << file << allNotes(r);
  }
}

std::vector<std::string> expectedFiles() {
  std::vector<std::string> files;
  for (const auto& [name, value] : expected().items()) files.push_back(name);
  return files;
}

std::string fileCaseName(const testing::TestParamInfo<std::string>& info) {
  std::string n = info.param;
  for (char& c : n)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return n;
}

INSTANTIATE_TEST_SUITE_P(Formats, FormatFixture, testing::ValuesIn(expectedFiles()), fileCaseName);

TEST(FormatFixtureList, EveryMainFileIsInExpected) {
  ASSERT_FALSE(expected().is_discarded()) << "expected.json does not parse";
  size_t mains = 0;
  for (const auto& entry : std::filesystem::directory_iterator(fixturePath("formats"))) {
    const std::string name = entry.path().filename().string();
    const std::string ext = entry.path().extension().string();
    // Companion files (Q, .sol, .ele) are checked through their main file.
    if (ext == ".q" || ext == ".sol" || ext == ".ele" || ext == ".json") continue;
    ++mains;
    EXPECT_TRUE(expected().contains(name)) << name << " is in tests/fixtures/formats but not in expected.json";
  }
  EXPECT_EQ(mains, expected().size());
}

// ------------------------------------------------------------------ per format: what the notes and format say
struct Said {
  const char* file;
  std::vector<std::string> format, notes;
};

TEST(FormatNotes, EachConversionIsSaid) {
  const std::vector<Said> cases = {
      {"grid_22_ascii.msh", {"Gmsh MSH 2.2 ASCII"}, {"converted cell data 'c'", "'v' to its magnitude"}},
      {"grid_22_binary.msh", {"Gmsh MSH 2.2 binary"}, {"converted cell data 'c'"}},
      {"grid_22_binary_bigendian.msh", {"Gmsh MSH 2.2 binary (other byte order)"}, {"converted cell data 'c'"}},
      {"grid_41_binary.msh", {"Gmsh MSH 4.1 binary"}, {"converted cell data 'c'"}},
      {"gmsh_box_p2_22_binary.msh",
       {"Gmsh MSH 2.2 binary"},
       {"Gmsh 10-node tetrahedron (type 11) cells to their 4 corner vertices", "Gmsh 6-node triangle (type 9)"}},
      {"gmsh_hexbox_41_binary.msh", {"Gmsh MSH 4.1 binary"}, {"split 8 hexahedra into 48 tetrahedra"}},
      {"mixed.vtu", {"VTK XML UnstructuredGrid"}, {"split 2 hexahedra, 4 wedges, 12 pyramids into 48 tetrahedra"}},
      {"mixed_quadratic.vtu",
       {"VTK XML UnstructuredGrid"},
       {"reduced 2 VTK_TRIQUADRATIC_HEXAHEDRON (29) cells to their 8 corner vertices",
        "reduced 4 VTK_BIQUADRATIC_QUADRATIC_WEDGE (32) cells to their 6 corner vertices",
        "reduced 12 VTK_QUADRATIC_PYRAMID (27) cells to their 5 corner vertices",
        "reduced 12 VTK_QUADRATIC_TETRA (24) cells to their 4 corner vertices",
        "split 2 hexahedra, 4 wedges, 12 pyramids into 48 tetrahedra", "only higher-order nodes"}},
      {"mixed_quadratic_41_binary.msh",
       {"Gmsh MSH 4.1 binary"},
       {"Gmsh 14-node pyramid (type 14) cells to their 5 corner vertices",
        "Gmsh 18-node prism (type 13) cells to their 6 corner vertices"}},
      {"grid.mesh", {"Medit .mesh (ASCII) + .sol"}, {"SolAtVertices", "'sol1' to its magnitude 'sol1_magnitude'"}},
      {"mixed.mesh", {"Medit .mesh (ASCII)"}, {"split 2 hexahedra, 4 wedges, 12 pyramids"}},
      {"grid.node",
       {"TetGen .node/.ele (0-based, 4-node tetrahedra)"},
       {"point attributes became fields attr0..attr1", "ignored the points' boundary markers"}},
      {"tetgen_cube.node", {"TetGen .node/.ele (1-based, 4-node tetrahedra)"}, {}},
      {"tetgen_cube_p2.node", {"(1-based, 10-node tetrahedra)"}, {"TetGen 10-node tetrahedron cells to their 4 corner"}},
      {"grid43.vti", {"VTK XML ImageData (ascii, UInt32 header, 4x3x3)"}, {"split 12 hexahedra into 72 tetrahedra (grid cells"}},
      {"grid43.vts", {"VTK XML StructuredGrid (appended base64, zlib"}, {"converted cell data 'cid'"}},
      {"grid43_points.vtk", {"legacy VTK 5.1 (BINARY, STRUCTURED_POINTS 4x3x3)"}, {"converted cell data 'cid'"}},
      {"grid43_sgrid.vtk", {"(ASCII, STRUCTURED_GRID 4x3x3)"}, {}},
      {"grid43_rgrid.vtk", {"(ASCII, RECTILINEAR_GRID 4x3x3)"}, {}},
      {"p3d_be.xyz",
       {"PLOT3D grid (C binary, big-endian, float, single-grid header, no IBLANK, 1 block 4x3x3) + Q solution "
        "(C binary, big-endian, float, single-grid header)"},
       {"using the Q solution file", "ignored 100 zero bytes at the end of", "gamma = 1.4", "free-stream Mach 2.5"}},
      {"p3d_fortran_iblank.x",
       {"Fortran records, little-endian, double, multi-grid header, IBLANK"},
       {"IBLANK: 1 points are blanked (0); 1 cells touching them are left out"}},
      {"p3d_two_blocks.g",
       {"2 blocks 4x3x3, 3x3x3"},
       {"read 2 grid blocks", "merged 9 duplicate vertices"}},
  };
  for (const Said& c : cases) {
    TetMesh m;
    ReadReport r;
    Result res = readMesh(formatsPath(c.file), m, r);
    ASSERT_TRUE(res) << c.file << ": " << res.message;
    for (const std::string& f : c.format) EXPECT_NE(r.format.find(f), std::string::npos) << c.file << ": " << r.format;
    for (const std::string& n : c.notes) EXPECT_TRUE(hasNote(r, n)) << c.file << " lacks '" << n << "'" << allNotes(r);
  }
}

TEST(FormatValues, TetgenAttributesAndPlot3dSolution) {
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(readMesh(formatsPath("grid.node"), m, r));
  int g = m.findField("attr1");
  ASSERT_GE(g, 0) << allNotes(r);
  for (uint32_t v = 0; v < m.vertexCount(); ++v)
    EXPECT_NEAR(m.fields[size_t(g)].values[v], m.positions[3 * v] * m.positions[3 * v + 1] - m.positions[3 * v + 2],
                1e-6);
  // The same mesh read through the .ele file name.
  TetMesh viaEle;
  ASSERT_TRUE(readMesh(formatsPath("grid.ele"), viaEle, r));
  EXPECT_EQ(viaEle.tets, m.tets);

  // PLOT3D Q: density 1 + 0.1x, momentum (0.5x, 0.25y, -0.5z), energy 3 + 0.2y (make_format_fixtures.py).
  for (const char* file : {"p3d_be.xyz", "p3d_fortran_iblank.x", "p3d_two_blocks.g"}) {
    ASSERT_TRUE(readMesh(formatsPath(file), m, r)) << file;
    const int rho = m.findField("density"), mom = m.findField("momentum_magnitude"), en = m.findField("energy"),
              p = m.findField("pressure");
    ASSERT_TRUE(rho == 0 && mom == 1 && en == 2 && p == 3) << file << allNotes(r);
    for (uint32_t v = 0; v < m.vertexCount(); ++v) {
      const double x = m.positions[3 * v], y = m.positions[3 * v + 1], z = m.positions[3 * v + 2];
      const double d = 1 + 0.1 * x, mx = 0.5 * x, my = 0.25 * y, mz = -0.5 * z, e = 3 + 0.2 * y;
      const double m2 = mx * mx + my * my + mz * mz;
      EXPECT_NEAR(m.fields[0].values[v], d, 1e-5) << file;
      EXPECT_NEAR(m.fields[1].values[v], std::sqrt(m2), 1e-5) << file;
      EXPECT_NEAR(m.fields[2].values[v], e, 1e-5) << file;
      EXPECT_NEAR(m.fields[3].values[v], 0.4 * (e - 0.5 * m2 / d), 1e-5) << file;
    }
  }

  // --q names the solution explicitly; a wrong one is refused with the grid's dimensions.
  ReadOptions opt;
  opt.solution = formatsPath("p3d_be.q");
  ASSERT_TRUE(readMesh(formatsPath("p3d_be.xyz"), m, r, opt));
  EXPECT_EQ(m.fields.size(), 4u);
  opt.solution = formatsPath("p3d_two_blocks.q");
  Result bad = readMesh(formatsPath("p3d_be.xyz"), m, r, opt);
  EXPECT_EQ(bad.status, Status::Corrupt);
  EXPECT_NE(bad.message.find("not a PLOT3D Q file for this grid"), std::string::npos) << bad.message;
  EXPECT_NE(bad.message.find("4x3x3"), std::string::npos) << bad.message;
  opt.solution = formatsPath("p3d_be.q");
  EXPECT_EQ(readMesh(formatsPath("mixed.vtu"), m, r, opt).status, Status::BadArgument);
  // A grid without a Q file: geometry only, and a note on how to name one.
  ReadReport r2;
  ASSERT_TRUE(readMeshBytes(loadFile(formatsPath("p3d_be.xyz")), "p3d_be.xyz", m, r2));
  EXPECT_TRUE(m.fields.empty());
  EXPECT_TRUE(hasNote(r2, "no Q solution file")) << allNotes(r2);
}

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
        std::vector<int> c = {vid(i, j, k),         vid(i + 1, j, k),         vid(i + 1, j + 1, k),
                              vid(i, j + 1, k),     vid(i, j, k + 1),         vid(i + 1, j, k + 1),
                              vid(i + 1, j + 1, k + 1), vid(i, j + 1, k + 1)};
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
          for (auto f : std::vector<std::array<int, 4>>{{0, 1, 2, 3}, {4, 7, 6, 5}, {0, 4, 5, 1}, {1, 5, 6, 2},
                                                         {2, 6, 7, 3}, {3, 7, 4, 0}})
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
  return "# vtk DataFile Version 4.2\nd\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS " + std::to_string(npts) + " float\n" +
         points + "\nCELLS " + std::to_string(ncells) + " " + std::to_string(ints) + "\n" + cells + "\nCELL_TYPES " +
         std::to_string(ncells) + "\n" + types + "\n" + tail;
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
  EXPECT_TRUE(hasNote(r, "found 2 vertices at the same coordinates as another; not merged, since merging would make "
                         "1 more face or boundary edge non-manifold")) << allNotes(r);
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
    cells3 += "\n4 " + std::to_string(b) + " " + std::to_string(b + 1) + " " + std::to_string(b + 2) + " " + std::to_string(b + 3);
  }
  ASSERT_TRUE(readMeshBytes(legacy(pts3, 14 + 4 * apartTets, cells3, 4 + apartTets, 5 * (4 + apartTets),
                                   "10 10 10 10 10 10 10 10 10 10"),
                            "f.vtk", m, r));
  EXPECT_TRUE(hasNote(r, "not merged, since merging would make 1 more face or boundary edge non-manifold")) << allNotes(r);
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
      for (int i = 0; i < 3; ++i) p += std::to_string(i) + " " + (i == 2 ? "0.5" : std::to_string(j)) + " " + std::to_string(k) + "\n";
  std::string text = "# vtk DataFile Version 3.0\ns\nASCII\nDATASET STRUCTURED_GRID\nDIMENSIONS 3 2 2\nPOINTS 12 float\n" + p;
  TetMesh m;
  ReadReport r;
  Result res = readMeshBytes(text, "s.vtk", m, r);
  ASSERT_TRUE(res) << res.message;
  EXPECT_TRUE(hasNote(r, "merged 2 duplicate vertices")) << allNotes(r);
  EXPECT_TRUE(hasNote(r, "with a repeated vertex (no volume) from 1 degenerate cell")) << allNotes(r);
  EXPECT_NEAR(totalVolume(m), 1.0 + 0.5, 1e-9);  // a unit cube plus a wedge of volume 1/2
  expectValid(m, "collapsed column");
}

// ------------------------------------------------------------------ hostile bytes
Result readBytes(const std::string& bytes, const std::string& name) {
  TetMesh m;
  ReadReport r;
  Result res = readMeshBytes(bytes, name, m, r);
  if (!res) {
    EXPECT_EQ(m.tetCount(), 0u) << "out must be empty on failure";
  }
  return res;
}

Result readTetgenText(const std::string& node, const std::string& ele) {
  TetMesh m;
  ReadReport r;
  return readTetgen(node, "t.node", ele, "t.ele", m, r);
}

TEST(FormatBadInput, Gmsh) {
  const std::string head = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
  const std::string nodes = "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n";
  EXPECT_TRUE(readBytes(head + nodes + "$Elements\n1\n1 4 0 1 2 3 4\n$EndElements\n", "a.msh"));
  EXPECT_FAILS(readBytes("hello", "a.msh"), Status::BadMagic, "expected '$MeshFormat'");
  EXPECT_FAILS(readBytes("$MeshFormat\n4.0 0 8\n$EndMeshFormat\n", "a.msh"), Status::UnsupportedVersion, "4.0");
  EXPECT_FAILS(readBytes(head + "$Nodes\n4000000000\n1 0 0 0\n", "a.msh"), Status::Truncated, "4000000000 nodes");
  EXPECT_FAILS(readBytes(head + nodes + "$Elements\n1\n1 4 0 1 2 3 9\n$EndElements\n", "a.msh"), Status::OutOfRange,
               "element 1 (4-node tetrahedron) uses node 9");
  EXPECT_FAILS(readBytes(head + nodes + "$Elements\n1\n1 4 0 1 2 3 4\n", "a.msh"), Status::Truncated,
               "($Elements): file ends before $EndElements");
  EXPECT_FAILS(readBytes(head + "$Nodes\n2\n1 0 0 0\n1 1 0 0\n$EndNodes\n", "a.msh"), Status::Corrupt,
               "node tag 1 appears twice");
  EXPECT_FAILS(readBytes(head + nodes + "$Elements\n1\n1 4 0 1 2 x 4\n$EndElements\n", "a.msh"), Status::Corrupt,
               "line 13 ($Elements)");
  EXPECT_FAILS(readBytes(head + nodes + "$Elements\n1\n1 2 0 1 2 3\n$EndElements\n", "a.msh"), Status::NoTets,
               "Gmsh 3-node triangle");
  // Binary: the endianness word, and element types we could not skip.
  std::string bin = loadFile(formatsPath("grid_22_binary.msh"));
  std::string b = bin;
  b[b.find("\n", b.find("2.2 1 8")) + 1] = 7;
  EXPECT_FAILS(readBytes(b, "b.msh"), Status::Corrupt, "endianness check");
  b = bin;
  size_t el = b.find("$Elements\n48\n") + 13;
  b[el] = 99;  // the first block's element type
  EXPECT_FAILS(readBytes(b, "b.msh"), Status::Unsupported, "element type 99");
  // Data for a node that does not exist.
  EXPECT_FAILS(readBytes(head + nodes + "$Elements\n1\n1 4 0 1 2 3 4\n$EndElements\n$NodeData\n1\n\"f\"\n0\n3\n0\n1\n1\n"
                                        "7 1.5\n$EndNodeData\n",
                         "a.msh"),
               Status::OutOfRange, "'f' gives a value for node 7");
}

TEST(FormatBadInput, TetgenAndMedit) {
  const std::string node = "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n";
  EXPECT_TRUE(readTetgenText(node, "1 4 0\n0 0 1 2 3\n"));
  EXPECT_FAILS(readTetgenText(node, "1 4 0\n0 0 1 2 9\n"), Status::OutOfRange,
               "t.ele line 2: tetrahedron 0 uses point 9, but the points are numbered 0..3");
  EXPECT_FAILS(readTetgenText("4 2 0 0\n", "1 4 0\n"), Status::Unsupported, "dimension 2");
  EXPECT_FAILS(readTetgenText("90000000 3 0 0\n0 0 0 0\n", "1 4 0\n"), Status::Truncated, "90000000 points");
  EXPECT_FAILS(readTetgenText("4 3 0 0\n0 0 0 0\n1 1 0 0\n5 0 1 0\n3 0 0 1\n", "1 4 0\n0 0 1 2 3\n"), Status::Corrupt,
               "t.node line 4: point numbered 5, expected 2");
  EXPECT_FAILS(readTetgenText(node, "1 5 0\n"), Status::Corrupt, "expected #tetrahedra 4|10");
  EXPECT_FAILS(readTetgenText(node, "2 4 0\n0 0 1 2 3\n"), Status::Truncated, "file ends before tetrahedron 1");
  // readMesh finds the other file, or says which one is missing.
  test::ScratchDir scratch("tetgen");
  ASSERT_TRUE(test::saveFile(scratch.path + "/m.node", node));
  TetMesh m;
  ReadReport r;
  EXPECT_FAILS(readMesh(scratch.path + "/m.node", m, r), Status::IoError, "the .ele file of TetGen mesh");

  const std::string mh = "MeshVersionFormatted 2\nDimension 3\nVertices\n4\n0 0 0 1\n1 0 0 1\n0 1 0 1\n0 0 1 1\n";
  EXPECT_TRUE(readBytes(mh + "Tetrahedra\n1\n1 2 3 4 0\nEnd\n", "a.mesh"));
  EXPECT_FAILS(readBytes(mh + "Tetrahedra\n1\n1 2 3 5 0\nEnd\n", "a.mesh"), Status::OutOfRange,
               "a.mesh line 11: Tetrahedra 1 uses vertex 5, but there are 4 vertices");
  EXPECT_FAILS(readBytes(mh + "Tetrahedra\n900000000\n1 2 3 4 0\n", "a.mesh"), Status::Truncated, "900000000 entries");
  EXPECT_FAILS(readBytes("Hello 3\n", "a.mesh"), Status::BadMagic, "expected 'MeshVersionFormatted'");
  EXPECT_FAILS(readBytes(mh + "Triangles\n1\n1 2 3 0\nEnd\n", "a.mesh"), Status::NoTets, "Medit Triangles");
  TetMesh mm;
  ReadReport mr;
  EXPECT_TRUE(readBytes(mh + "Tetrahedra\n1\n1 2 3 4 0\nFancyKeyword 2\n1 2\nEnd\n", "a.mesh"));
  EXPECT_FAILS(readMedit(mh + "Tetrahedra\n1\n1 2 3 4 0\nEnd\n", "a.mesh", "SolAtVertices\n3\n1 1\n1 2 3\n", "a.sol", mm, mr),
               Status::Corrupt, "SolAtVertices has 3 entries, the mesh has 4 vertices");
}

TEST(FormatBadInput, StructuredAndPlot3d) {
  EXPECT_FAILS(readBytes("# vtk DataFile Version 3.0\nx\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 1000 1000 1000\n",
                         "a.vtk"),
               Status::Truncated, "DIMENSIONS declares 1000000000 points");
  EXPECT_FAILS(readBytes("# vtk DataFile Version 3.0\nx\nASCII\nDATASET STRUCTURED_GRID\nDIMENSIONS 2 2 2\nPOINTS 7 "
                         "float\n0 0 0 1 0 0 0 1 0 1 1 0 0 0 1 1 0 1 0 1 1\n",
                         "a.vtk"),
               Status::Corrupt, "POINTS has 7 points, DIMENSIONS 8");
  EXPECT_FAILS(readBytes("# vtk DataFile Version 3.0\nx\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\nCELL_DATA "
                         "2\nSCALARS c float\nLOOKUP_TABLE default\n1 2\n",
                         "a.vtk"),
               Status::Corrupt, "CELL_DATA 2 but there are 1 cells");
  std::string vti = loadFile(formatsPath("grid43.vti"));
  std::string big = vti;
  for (size_t at; (at = big.find("Extent=\"0 3 0 2 0 2\"")) != std::string::npos;)
    big.replace(at, 20, "Extent=\"0 300 0 2000 0 2000\"");
  EXPECT_FAILS(readBytes(big, "a.vti"), Status::Truncated, "Extent declares");
  // An image with no values: refused before a grid is built for its extent.
  std::string empty = vti;
  empty.erase(empty.find("    <PointData"), empty.find("  </Piece>") - empty.find("    <PointData"));
  EXPECT_FAILS(readBytes(empty, "a.vti"), Status::MissingField, "no numeric PointData or CellData arrays");

  EXPECT_FAILS(readBytes(std::string(100, 'x'), "a.xyz"), Status::Corrupt, "no layout");
  EXPECT_FAILS(readBytes("abc", "a.xyz"), Status::Truncated, "too short for a PLOT3D grid header");
  // A Q file given as the grid.
  EXPECT_FAILS(readBytes(loadFile(formatsPath("p3d_be.q")), "p3d_be.xyz"), Status::Corrupt, "reads as a PLOT3D Q (solution) file");
  TetMesh m;
  ReadReport r;
  const std::string grid = loadFile(formatsPath("p3d_be.xyz")), q = loadFile(formatsPath("p3d_be.q"));
  EXPECT_FAILS(readPlot3d(grid, "g.xyz", q.substr(0, q.size() - 200), "g.q", m, r), Status::Corrupt, "g.q: not a PLOT3D Q");
}

// Cuts every fixture (the main file, and the companion of two-file formats) at many lengths:
// no crash, failures name the file, a prefix that reads gives a subset of the full mesh.
TEST(FormatBadInput, TruncatedAndDamagedFixturesNeverCrash) {
  struct Pair {
    std::string main, second;
  };
  std::vector<Pair> files;
  for (const std::string& f : expectedFiles()) {
    std::string ext = std::filesystem::path(f).extension().string();
    std::string stem = std::filesystem::path(f).stem().string();
    std::string second = ext == ".node" ? stem + ".ele" : ext == ".mesh" && stem == "grid" ? "grid.sol" : "";
    if (f.starts_with("p3d_")) second = stem + ".q";
    files.push_back({f, second});
  }
  std::mt19937 rng(7);
  for (const Pair& p : files) {
    const std::string a = loadFile(formatsPath(p.main)), b = p.second.empty() ? "" : loadFile(formatsPath(p.second));
    // The readers themselves (not the readMesh wrapper, which catches exceptions): an exception
    // here is a reader sizing something by a count it did not check.
    auto read = [&](std::string_view x, std::string_view y, TetMesh& m, ReadReport& r) -> Result {
      const std::string ext = std::filesystem::path(p.main).extension().string();
      try {
        if (ext == ".node") return readTetgen(x, p.main, y, p.second, m, r);
        if (ext == ".mesh") return readMedit(x, p.main, y, p.second, m, r);
        if (p.main.starts_with("p3d_")) return readPlot3d(x, p.main, y, p.second, m, r);
        if (ext == ".msh") return readGmsh(x, p.main, m, r);
        return readMeshBytes(x, p.main, m, r);
      } catch (const std::exception& e) {
        ADD_FAILURE() << p.main << " (" << x.size() << " bytes, second " << y.size() << "): " << e.what();
        return fail(Status::Corrupt, "exception");
      }
    };
    TetMesh full;
    ReadReport fr;
    ASSERT_TRUE(read(a, b, full, fr)) << p.main;
    for (int which = 0; which < (b.empty() ? 1 : 2); ++which) {
      const std::string& cut = which == 0 ? a : b;
      for (size_t len = 0; len < cut.size(); len += (len < 300 || len + 100 > cut.size()) ? 1 : 13) {
        TetMesh m;
        ReadReport r;
        std::string_view part = std::string_view(cut).substr(0, len);
        Result res = which == 0 ? read(part, b, m, r) : read(a, part, m, r);
        if (!res) {
          ASSERT_FALSE(res.message.empty());
          ASSERT_EQ(m.tetCount(), 0u);
          continue;
        }
        ASSERT_LE(m.tetCount(), full.tetCount()) << p.main << " cut at " << len;
        ASSERT_LE(m.vertexCount(), full.vertexCount()) << p.main << " cut at " << len;
      }
    }
    for (int trial = 0; trial < 60; ++trial) {
      std::string x = a;
      for (int k = 0; k < 1 + int(rng() % 4); ++k) x[rng() % x.size()] = char(rng());
      TetMesh m;
      ReadReport r;
      Result res = read(x, b, m, r);
      if (!res) {
        ASSERT_FALSE(res.message.empty());
      }
    }
  }
}

}  // namespace
}  // namespace tetstream
