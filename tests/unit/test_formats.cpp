// The readers beyond VTU/VTK (Gmsh, TetGen, Medit, VTK structured, PLOT3D) and the cell pipeline
// they share (cells.cpp): every file in tests/fixtures/formats was written by another tool
// (make_format_fixtures.py) and is checked against what that tool was given (expected.json):
// counts, volume, boundary area (a split that does not conform leaves inner faces on the
// boundary and adds area), field values, the point values of converted cell data; then hostile
// bytes. The cell pipeline on its own (conformity, degenerate cells) is in test_cells.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>

#include "adjacency.h"
#include "io/mesh_io.h"
#include "io/readers.h"
#include "test_helpers.h"

namespace tetstream {
namespace {

using test::allNotes;
using test::boundaryArea;
using test::expectValid;
using test::findVertex;
using test::fixturePath;
using test::hasNote;
using test::loadFile;
using test::totalVolume;

std::string formatsPath(const std::string& name) { return fixturePath("formats/" + name); }

const nlohmann::json& expected() { return test::fixtureJson("formats/expected.json"); }

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
      EXPECT_NEAR(m.fields[size_t(f)].values[size_t(v)], row[3].get<double>(), 1e-5)
          << file << " " << name << " at " << row;
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
      {"tetgen_cube_p2.node",
       {"(1-based, 10-node tetrahedra)"},
       {"TetGen 10-node tetrahedron cells to their 4 corner"}},
      {"grid43.vti",
       {"VTK XML ImageData (ascii, UInt32 header, 4x3x3)"},
       {"split 12 hexahedra into 72 tetrahedra (each quad face cut through its corner lowest"}},
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
      {"p3d_two_blocks.g", {"2 blocks 4x3x3, 3x3x3"}, {"read 2 grid blocks", "merged 9 duplicate vertices"}},
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
  EXPECT_FAILS(readBytes(head + nodes +
                             "$Elements\n1\n1 4 0 1 2 3 4\n$EndElements\n$NodeData\n1\n\"f\"\n0\n3\n0\n1\n1\n"
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
  EXPECT_FAILS(
      readMedit(mh + "Tetrahedra\n1\n1 2 3 4 0\nEnd\n", "a.mesh", "SolAtVertices\n3\n1 1\n1 2 3\n", "a.sol", mm, mr),
      Status::Corrupt, "SolAtVertices has 3 entries, the mesh has 4 vertices");
}

TEST(FormatBadInput, StructuredAndPlot3d) {
  EXPECT_FAILS(
      readBytes("# vtk DataFile Version 3.0\nx\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 1000 1000 1000\n",
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
  EXPECT_FAILS(readBytes(loadFile(formatsPath("p3d_be.q")), "p3d_be.xyz"), Status::Corrupt,
               "reads as a PLOT3D Q (solution) file");
  TetMesh m;
  ReadReport r;
  const std::string grid = loadFile(formatsPath("p3d_be.xyz")), q = loadFile(formatsPath("p3d_be.q"));
  EXPECT_FAILS(readPlot3d(grid, "g.xyz", q.substr(0, q.size() - 200), "g.q", m, r), Status::Corrupt,
               "g.q: not a PLOT3D Q");
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
