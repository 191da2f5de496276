// Mesh readers for VTK files (core/io/mesh_io.h): every fixture written by VTK or meshio reads
// with the right counts and analytic field values, and hostile bytes (truncations, flips, lies in
// headers) give a Result. The writers are tested in test_writers.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>

#include "io/mesh_io.h"
#include "io/readers.h"
#include "test_helpers.h"

namespace tetstream {
namespace {

using test::allNotes;
using test::fixturePath;
using test::hasNote;
using test::loadFile;

// ------------------------------------------------------------------ fixtures (make_fixtures.py)
struct FixtureCase {
  const char* file;
  uint32_t vertices;
  uint32_t tets;
  std::vector<std::string> fields;     // in reading order
  std::vector<std::string> formatHas;  // substrings of ReadReport::format
  std::vector<std::string> fileHas;    // substrings of the file itself: proves what the writer did
};

// gtest prints parameters in test listings (and so in ctest's test names): name the file only.
void PrintTo(const FixtureCase& c, std::ostream* os) { *os << c.file; }

// VTK fixtures also carry cell data 'cellid', which becomes point data (cells.cpp).
const std::vector<std::string> kVtkFields = {"f", "v_magnitude", "label", "cellid"};
const std::vector<std::string> kMeshioFields = {"f", "v_magnitude"};

// clang-format off
const std::vector<FixtureCase>& fixtureCases() {
  static const std::vector<FixtureCase> cases = {
    {"vtk_ascii.vtu", 27, 48, kVtkFields, {"(ascii, UInt32 header)"}, {"format=\"ascii\"", "type=\"Int64\" Name=\"connectivity\""}},
    {"vtk_binary.vtu", 27, 48, kVtkFields, {"(inline base64, UInt32 header)"}, {"type=\"Int32\" Name=\"connectivity\"", "InformationKey"}},
    {"vtk_binary_u64.vtu", 27, 48, kVtkFields, {"(inline base64, UInt64 header)"}, {"header_type=\"UInt64\"", "type=\"Float64\" Name=\"Points\""}},
    {"vtk_binary_zlib.vtu", 27, 48, kVtkFields, {"(inline base64, zlib, UInt32 header)"}, {"vtkZLibDataCompressor"}},
    {"vtk_appended_raw.vtu", 27, 48, kVtkFields, {"(appended raw, UInt32 header)"}, {"encoding=\"raw\"", "type=\"Int32\" Name=\"offsets\""}},
    {"vtk_appended_raw_zlib64.vtu", 27, 48, kVtkFields, {"(appended raw, zlib, UInt64 header)"}, {"type=\"Float64\" Name=\"Points\""}},
    {"vtk_appended_base64.vtu", 27, 48, kVtkFields, {"(appended base64, UInt32 header)"}, {"encoding=\"base64\""}},
    {"vtk_appended_base64_zlib.vtu", 27, 48, kVtkFields, {"(appended base64, zlib, UInt64 header)"}, {"encoding=\"base64\""}},
    {"vtk_bigendian.vtu", 27, 48, kVtkFields, {"(appended raw, zlib, UInt32 header, BigEndian)"}, {"byte_order=\"BigEndian\""}},
    {"vtk_bigendian_binary.vtu", 27, 48, kVtkFields, {"(inline base64, UInt64 header, BigEndian)"}, {"byte_order=\"BigEndian\""}},
    {"vtk_legacy_ascii.vtk", 27, 48, kVtkFields, {"legacy VTK 5.1 (ASCII, OFFSETS/CONNECTIVITY cells)"}, {"LOOKUP_TABLE", "METADATA"}},
    {"vtk_legacy_binary.vtk", 27, 48, kVtkFields, {"legacy VTK 5.1 (BINARY, OFFSETS/CONNECTIVITY cells)"}, {"VECTORS v float"}},
    {"vtk_legacy42_ascii.vtk", 27, 48, kVtkFields, {"legacy VTK 4.2 (ASCII, classic CELLS)"}, {"CELLS 48 240"}},
    {"vtk_legacy42_binary.vtk", 27, 48, kVtkFields, {"legacy VTK 4.2 (BINARY, classic CELLS)"}, {"POINTS 27 double"}},
    {"meshio_ascii.vtu", 27, 48, kMeshioFields, {"(ascii, UInt32 header)"}, {"meshio"}},
    {"meshio_binary.vtu", 27, 48, kMeshioFields, {"(inline base64, UInt32 header)"}, {"meshio"}},
    {"meshio_zlib.vtu", 27, 48, kMeshioFields, {"(inline base64, zlib, UInt32 header)"}, {"meshio"}},
    {"meshio_u64_cells.vtu", 27, 48, kMeshioFields, {"(inline base64, zlib, UInt64 header)"}, {"type=\"UInt64\" Name=\"connectivity\""}},
    {"meshio_u32_cells.vtu", 27, 48, kMeshioFields, {"(inline base64, UInt32 header)"}, {"type=\"UInt32\" Name=\"connectivity\"", "type=\"Float32\" Name=\"Points\""}},
    {"meshio_ascii.vtk", 27, 48, kMeshioFields, {"legacy VTK 5.1 (ASCII, OFFSETS/CONNECTIVITY cells)"}, {"FIELD FieldData 2"}},
    {"meshio_binary.vtk", 27, 48, kMeshioFields, {"legacy VTK 5.1 (BINARY, OFFSETS/CONNECTIVITY cells)"}, {"meshio"}},
    {"meshio_legacy42.vtk", 27, 48, kMeshioFields, {"legacy VTK 4.2 (BINARY, classic CELLS)"}, {"meshio"}},
    {"mixed_quadratic.vtu", 31, 49, kVtkFields, {"(appended raw, UInt32 header)"}, {}},
    {"mixed_cells.vtu", 39, 60, kMeshioFields, {"(inline base64, zlib, UInt32 header)"}, {}},
    {"mixed_cells.vtk", 39, 60, kVtkFields, {"legacy VTK 5.1 (BINARY, OFFSETS/CONNECTIVITY cells)"}, {"FIELD FieldData 3"}},
  };
  return cases;
}
// clang-format on

std::string caseName(const testing::TestParamInfo<FixtureCase>& info) {
  std::string n = info.param.file;
  for (char& c : n)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return n;
}

// The analytic fields of make_fixtures.py at vertex v.
void expectAnalyticFields(const TetMesh& m, const std::string& file) {
  int f = m.findField("f"), vm = m.findField("v_magnitude"), label = m.findField("label");
  ASSERT_GE(f, 0) << file;
  ASSERT_GE(vm, 0) << file;
  for (uint32_t v = 0; v < m.vertexCount(); ++v) {
    double x = m.positions[3 * v], y = m.positions[3 * v + 1], z = m.positions[3 * v + 2];
    ASSERT_NEAR(m.fields[f].values[v], x + 2 * y + 3 * z, 1e-6) << file << " vertex " << v;
    ASSERT_NEAR(m.fields[vm].values[v], std::sqrt(x * x + y * y + z * z), 1e-6) << file << " vertex " << v;
    if (label >= 0) {
      ASSERT_EQ(m.fields[label].values[v], float(v)) << file;
    }
  }
  // cellid (cell data = cell index) became point data: at each vertex the volume-weighted mean
  // of the ids of the cells around it. The first 48 cells are the grid's equal-volume tets.
  int cellid = m.findField("cellid");
  if (cellid < 0) return;
  std::vector<double> sum(m.vertexCount()), count(m.vertexCount());
  for (uint32_t t = 0; t < 48; ++t)
    for (int k = 0; k < 4; ++k) {
      sum[m.tets[4 * t + k]] += t;
      count[m.tets[4 * t + k]] += 1;
    }
  for (uint32_t v = 0; v < 27; ++v)
    ASSERT_NEAR(m.fields[cellid].values[v], sum[v] / count[v], 1e-4) << file << " vertex " << v;
}

class ReaderFixture : public testing::TestWithParam<FixtureCase> {};

TEST_P(ReaderFixture, ReadsCountsFieldsAndValues) {
  const FixtureCase& c = GetParam();
  std::string bytes = loadFile(fixturePath(c.file));
  ASSERT_FALSE(bytes.empty()) << c.file;
  for (const std::string& s : c.fileHas)
    EXPECT_NE(bytes.find(s), std::string::npos) << c.file << " should contain " << s;

  TetMesh m;
  ReadReport report;
  Result r = readMesh(fixturePath(c.file), m, report);
  ASSERT_TRUE(r) << statusName(r.status) << ": " << r.message;
  EXPECT_EQ(m.vertexCount(), c.vertices) << c.file;
  EXPECT_EQ(m.tetCount(), c.tets) << c.file;
  std::vector<std::string> names;
  for (const ScalarField& f : m.fields) names.push_back(f.name);
  EXPECT_EQ(names, c.fields) << c.file << allNotes(report);
  for (const std::string& s : c.formatHas) EXPECT_NE(report.format.find(s), std::string::npos) << report.format;
  EXPECT_EQ(m.name, std::string(c.file).substr(0, std::strlen(c.file) - 4));
  EXPECT_TRUE(hasNote(report, "'v' to its magnitude 'v_magnitude'")) << allNotes(report);
  expectAnalyticFields(m, c.file);

  // The grid's 48 tets are positively oriented in every fixture (ids kept in file order).
  for (uint32_t t = 0; t < 48; ++t) EXPECT_GT(tetVolume(m, t), 0) << c.file << " tet " << t;
}

INSTANTIATE_TEST_SUITE_P(ReaderFixtures, ReaderFixture, testing::ValuesIn(fixtureCases()), caseName);

TEST(ReaderFixtureList, EveryFixtureFileIsChecked) {
  std::vector<std::string> files = test::fixtureFiles();
  EXPECT_EQ(files.size(), fixtureCases().size());
  for (const std::string& f : files) {
    bool listed = false;
    for (const FixtureCase& c : fixtureCases()) listed |= f == c.file;
    EXPECT_TRUE(listed) << f << " is in tests/fixtures but not in fixtureCases()";
  }
}

TEST(ReaderFixtureList, SameMeshFromEveryWriter) {
  TetMesh ref;
  ReadReport rr;
  ASSERT_TRUE(readMesh(fixturePath("vtk_ascii.vtu"), ref, rr));
  for (const FixtureCase& c : fixtureCases()) {
    TetMesh m;
    ReadReport r;
    ASSERT_TRUE(readMesh(fixturePath(c.file), m, r)) << c.file;
    EXPECT_TRUE(std::equal(ref.positions.begin(), ref.positions.end(), m.positions.begin())) << c.file;
    EXPECT_TRUE(std::equal(ref.tets.begin(), ref.tets.end(), m.tets.begin())) << c.file;
  }
}

TEST(ReaderCells, QuadraticTetReducedToCorners) {
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(readMesh(fixturePath("mixed_quadratic.vtu"), m, r));
  ASSERT_EQ(m.tetCount(), 49u);
  EXPECT_EQ(std::vector<uint32_t>(m.tets.end() - 4, m.tets.end()), (std::vector<uint32_t>{27, 28, 29, 30}));
  EXPECT_EQ(m.vertexCount(), 31u) << "the 6 mid-edge nodes are dropped";
  EXPECT_TRUE(hasNote(r, "reduced 1 VTK_QUADRATIC_TETRA (24) cells to their 4 corner vertices")) << allNotes(r);
  EXPECT_TRUE(hasNote(r, "dropped 6 vertices that no tetrahedron uses (6 only higher-order nodes")) << allNotes(r);
  EXPECT_TRUE(r.skippedCells.empty());
}

TEST(ReaderCells, HexahedraSplitAndOtherCellsReportedByNameAndCount) {
  for (const char* file : {"mixed_cells.vtu", "mixed_cells.vtk"}) {
    TetMesh m;
    ReadReport r;
    ASSERT_TRUE(readMesh(fixturePath(file), m, r)) << file;
    EXPECT_EQ(m.tetCount(), 60u);
    EXPECT_EQ(m.vertexCount(), 39u);
    EXPECT_TRUE(hasNote(r, "split 2 hexahedra into 12 tetrahedra")) << file << allNotes(r);
    EXPECT_TRUE(hasNote(r, "skipped 3 cells of unsupported type VTK_TRIANGLE (5)")) << file << allNotes(r);
    ASSERT_EQ(r.skippedCells.size(), 1u);
    EXPECT_EQ(r.skippedCells[0].vtkType, 5);
    EXPECT_EQ(r.skippedCells[0].typeName, "VTK_TRIANGLE");
    EXPECT_EQ(r.skippedCells[0].count, 3u);
    // The two unit hexahedra [2,4]x[0,1]x[0,1] share a face: 12 tets of volume 2 in all.
    double volume = 0;
    for (uint32_t t = 48; t < 60; ++t) {
      EXPECT_GT(tetVolume(m, t), 0) << file << " tet " << t;
      volume += tetVolume(m, t);
    }
    EXPECT_NEAR(volume, 2.0, 1e-12) << file;
  }
}

TEST(ReaderNotes, CellDataBecomesPointDataWithANote) {
  for (const char* file : {"vtk_appended_raw.vtu", "vtk_legacy_binary.vtk"}) {
    TetMesh m;
    ReadReport r;
    ASSERT_TRUE(readMesh(fixturePath(file), m, r));
    EXPECT_TRUE(hasNote(r, "converted cell data 'cellid' to point data (at each vertex, the volume-weighted average"))
        << file << allNotes(r);
    EXPECT_GE(m.findField("cellid"), 0) << file;
  }
}

// ------------------------------------------------------------------ hostile input
// A tiny ASCII .vtu with the given arrays.
std::string asciiVtu(int np, int nc, const std::string& points, const std::string& conn, const std::string& offsets,
                     const std::string& types, const std::string& extraPiece = "", const std::string& rootAttrs = "") {
  return "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\"" + rootAttrs +
         "><UnstructuredGrid><Piece NumberOfPoints=\"" + std::to_string(np) + "\" NumberOfCells=\"" +
         std::to_string(nc) + "\">" + extraPiece +
         "<Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">" + points +
         "</DataArray></Points><Cells>"
         "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">" +
         conn +
         "</DataArray>"
         "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">" +
         offsets +
         "</DataArray>"
         "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">" +
         types +
         "</DataArray>"
         "</Cells></Piece></UnstructuredGrid></VTKFile>\n";
}

const std::string kTetPoints = "0 0 0 1 0 0 0 1 0 0 0 1";

std::string asciiVtk(const std::string& points, const std::string& cells, const std::string& types,
                     const std::string& tail = "") {
  return "# vtk DataFile Version 4.2\nhand written\nASCII\nDATASET UNSTRUCTURED_GRID\n" + points + cells + types + tail;
}

Result readBytes(const std::string& bytes, const std::string& name, TetMesh& m, ReadReport& r) {
  return readMeshBytes(bytes, name, m, r);
}

Result readBytes(const std::string& bytes, const std::string& name) {
  TetMesh m;
  ReadReport r;
  Result res = readMeshBytes(bytes, name, m, r);
  if (!res) {
    EXPECT_EQ(m.tetCount(), 0u) << "out must be empty on failure";
  }
  return res;
}

TEST(ReaderBadInput, HandWrittenFilesAreValid) {
  // The helpers themselves produce readable files; each bad-input test changes one thing.
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(readBytes(asciiVtu(4, 1, kTetPoints, "0 1 2 3", "4", "10"), "t.vtu", m, r));
  EXPECT_EQ(m.tetCount(), 1u);
  Result lr = readBytes(
      asciiVtk("POINTS 4 float\n" + kTetPoints + "\n", "CELLS 1 5\n4 0 1 2 3\n", "CELL_TYPES 1\n10\n"), "t.vtk", m, r);
  ASSERT_TRUE(lr) << lr.message;
  EXPECT_EQ(m.tetCount(), 1u);
}

TEST(ReaderBadInput, IndexOutOfRangeNamesTheCell) {
  EXPECT_FAILS(readBytes(asciiVtu(4, 2, kTetPoints, "0 1 2 3 0 1 2 999", "4 8", "10 10"), "t.vtu"), Status::OutOfRange,
               "cell 1 (VTK_TETRA) references vertex 999, but there are 4 points");
  EXPECT_FAILS(readBytes(asciiVtu(4, 1, kTetPoints, "0 1 -2 3", "4", "10"), "t.vtu"), Status::OutOfRange, "cell 0");
  EXPECT_FAILS(
      readBytes(asciiVtk("POINTS 4 float\n" + kTetPoints + "\n", "CELLS 1 5\n4 0 1 2 999\n", "CELL_TYPES 1\n10\n"),
                "t.vtk"),
      Status::OutOfRange, "cell 0 (VTK_TETRA) references vertex 999");
}

TEST(ReaderBadInput, NonFiniteCoordinateNamesTheVertex) {
  EXPECT_FAILS(readBytes(asciiVtu(4, 1, "0 0 0 1 0 0 0 nan 0 0 0 1", "0 1 2 3", "4", "10"), "t.vtu"), Status::NonFinite,
               "point 2");
  EXPECT_FAILS(readBytes(asciiVtu(4, 1, "0 0 0 1 0 0 0 1 0 0 0 -inf", "0 1 2 3", "4", "10"), "t.vtu"),
               Status::NonFinite, "point 3");
  EXPECT_FAILS(readBytes(asciiVtu(4, 1, "0 0 0 1e39 0 0 0 1 0 0 0 1", "0 1 2 3", "4", "10"), "t.vtu"),
               Status::NonFinite, "point 1");
  EXPECT_FAILS(
      readBytes(asciiVtk("POINTS 4 float\n0 0 0 1 0 0 0 1 0 nan 0 1\n", "CELLS 1 5\n4 0 1 2 3\n", "CELL_TYPES 1\n10\n"),
                "t.vtk"),
      Status::NonFinite, "point 3");
}

TEST(ReaderBadInput, NoTetsListsWhatWasFound) {
  EXPECT_FAILS(readBytes(asciiVtu(4, 2, kTetPoints, "0 1 2 1 2 3", "3 6", "5 5"), "t.vtu"), Status::NoTets,
               "found 2 VTK_TRIANGLE");
  EXPECT_FAILS(readBytes(asciiVtu(0, 0, "", "", "", ""), "t.vtu"), Status::NoTets, "no tetrahedra");
  EXPECT_FAILS(
      readBytes(asciiVtk("POINTS 4 float\n" + kTetPoints + "\n", "CELLS 1 4\n3 0 1 2\n", "CELL_TYPES 1\n5\n"), "t.vtk"),
      Status::NoTets, "found 1 VTK_TRIANGLE");
  EXPECT_FAILS(readBytes(asciiVtk("POINTS 4 float\n" + kTetPoints + "\n", "", ""), "t.vtk"), Status::NoTets,
               "no CELLS section (4 points");
}

TEST(ReaderBadInput, WrongExtensionAndMissingFile) {
  TetMesh m;
  ReadReport r;
  // Unknown extensions are recognized by content; other content is refused with the list.
  test::ScratchDir scratch("ext");
  ASSERT_TRUE(test::saveFile(scratch.path + "/mesh.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n"));
  ASSERT_TRUE(test::saveFile(scratch.path + "/mesh", "solid x\nendsolid\n"));
  EXPECT_FAILS(readMesh(scratch.path + "/mesh.obj", m, r), Status::Unsupported, "supported: .vtu");
  EXPECT_FAILS(readMesh(scratch.path + "/mesh", m, r), Status::Unsupported, ".vtk (legacy");
  EXPECT_FAILS(readMesh("/tmp/no-such-mesh.obj", m, r), Status::IoError, "cannot open");
  // A VTK XML file under another name is still read (sniffed).
  ASSERT_TRUE(test::saveFile(scratch.path + "/grid.xml", loadFile(fixturePath("vtk_ascii.vtu"))));
  EXPECT_TRUE(readMesh(scratch.path + "/grid.xml", m, r));
  EXPECT_EQ(m.tetCount(), 48u);
  EXPECT_FAILS(readMesh("/nonexistent/dir/mesh.vtu", m, r), Status::IoError, "/nonexistent/dir/mesh.vtu: cannot open");
  EXPECT_TRUE(readMesh(fixturePath("vtk_ascii.vtu"), m, r));
}

TEST(ReaderBadInput, WrongMagic) {
  std::string vtu = loadFile(fixturePath("vtk_appended_raw.vtu"));
  std::string vtk = loadFile(fixturePath("vtk_legacy_binary.vtk"));
  EXPECT_FAILS(readBytes(vtk, "legacy.vtu"), Status::BadMagic, "it is a legacy VTK file");
  EXPECT_FAILS(readBytes(vtu, "xml.vtk"), Status::BadMagic, "looks like VTK XML");
  std::string v2 = vtk;
  v2[2] = 'V';
  v2[4] = 'x';
  EXPECT_FAILS(readBytes(v2, "a.vtk"), Status::BadMagic, "expected '# vtk DataFile Version x.x'");
  std::string x2 = vtu;
  x2.replace(x2.find("<VTKFile"), 8, "<VTKFilx");
  EXPECT_FALSE(readBytes(x2, "a.vtu"));  // start/end tag mismatch
  std::string x3 = "<?xml version=\"1.0\"?><Mesh></Mesh>";
  EXPECT_FAILS(readBytes(x3, "a.vtu"), Status::BadMagic, "root element is <Mesh>");
  EXPECT_FAILS(readBytes(std::string("\x89PNG\r\n\x1a\n....", 12), "a.vtu"), Status::BadMagic,
               "does not start with '<'");
  EXPECT_FAILS(readBytes("", "a.vtu"), Status::Truncated, "empty");
  EXPECT_FAILS(readBytes("", "a.vtk"), Status::Truncated, "empty file");
  EXPECT_FAILS(readBytes("# vtk Data", "a.vtk"), Status::Truncated,
               "file ends inside the '# vtk DataFile Version' line");
  EXPECT_FAILS(readBytes("# vtk DataFile Version 7.0\nx\nASCII\n", "a.vtk"), Status::UnsupportedVersion, "7.0");
}

TEST(ReaderBadInput, UnsupportedButValidFiles) {
  std::string poly = "<VTKFile type=\"PolyData\" version=\"1.0\"><PolyData/></VTKFile>";
  EXPECT_FAILS(readBytes(poly, "a.vtu"), Status::Unsupported, "VTKFile type 'PolyData'");
  std::string lz4 = asciiVtu(4, 1, kTetPoints, "0 1 2 3", "4", "10", "", " compressor=\"vtkLZ4DataCompressor\"");
  EXPECT_FAILS(readBytes(lz4, "a.vtu"), Status::Unsupported, "compressor 'vtkLZ4DataCompressor'");
  EXPECT_FAILS(
      readBytes("# vtk DataFile Version 3.0\nx\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 1\n", "a.vtk"),
      Status::NoTets, "DIMENSIONS 2 2 1 is not a 3D grid");
  EXPECT_FAILS(readBytes("# vtk DataFile Version 3.0\nx\nBINARY\nDATASET POLYDATA\n", "a.vtk"), Status::Unsupported,
               "POLYDATA");
  std::string strType = asciiVtu(4, 1, kTetPoints, "0 1 2 3", "4", "10");
  strType.replace(strType.find("type=\"Int64\" Name=\"connectivity\""), 12, "type=\"Bit\"  ");
  EXPECT_FAILS(readBytes(strType, "a.vtu"), Status::Unsupported, "type 'Bit'");
}

TEST(ReaderBadInput, GarbageOffsetsAndCounts) {
  EXPECT_FAILS(readBytes(asciiVtu(4, 2, kTetPoints, "0 1 2 3 0 1 2 3", "4 -3", "10 10"), "t.vtu"), Status::Corrupt,
               "last offset -3");
  EXPECT_FAILS(readBytes(asciiVtu(4, 3, kTetPoints, "0 1 2 3 0 1 2 3", "8 4 8", "12 10 10"), "t.vtu"), Status::Corrupt,
               "cell 1 has offsets 8..4");
  EXPECT_FAILS(readBytes(asciiVtu(4, 1, kTetPoints, "0 1 2 3 0", "5", "10"), "t.vtu"), Status::Corrupt,
               "VTK_TETRA with 5 points, expected 4");
  EXPECT_FAILS(readBytes(asciiVtu(4, 1, kTetPoints, "0 1 2 3", "4", "10 10"), "t.vtu"), Status::Corrupt,
               "more than the expected 1 values");
  EXPECT_FAILS(readBytes(asciiVtu(4, 1, kTetPoints, "0 1 2", "4", "10"), "t.vtu"), Status::Corrupt,
               "'connectivity': has 3 of 4 values");
  EXPECT_FAILS(readBytes(asciiVtu(4, 1, kTetPoints, "0 1 x 3", "4", "10"), "t.vtu"), Status::Corrupt,
               "value 2 'x' is not an integer");
  EXPECT_FAILS(readBytes(asciiVtu(4, 1, "0 0 0 1 0 0 0 1 0 0 0", "0 1 2 3", "4", "10"), "t.vtu"), Status::Corrupt,
               "has 11 of 12 values");
  // Counts far beyond the data must fail before anything is sized by them.
  EXPECT_FALSE(readBytes(asciiVtu(2000000000, 1, kTetPoints, "0 1 2 3", "4", "10"), "t.vtu"));
  std::string huge = asciiVtu(4, 1, kTetPoints, "0 1 2 3", "4", "10");
  huge.replace(huge.find("NumberOfPoints=\"4\""), 18, "NumberOfPoints=\"18446744073709551615\"");
  EXPECT_FAILS(readBytes(huge, "t.vtu"), Status::TooLarge, "32 bits");
  std::string neg = asciiVtu(4, 1, kTetPoints, "0 1 2 3", "4", "10");
  neg.replace(neg.find("NumberOfCells=\"1\""), 17, "NumberOfCells=\"-1\"");
  EXPECT_FAILS(readBytes(neg, "t.vtu"), Status::Corrupt, "NumberOfCells='-1'");

  std::string pts = "POINTS 4 float\n" + kTetPoints + "\n";
  EXPECT_FAILS(readBytes(asciiVtk("POINTS 4000000000 float\n1 2 3\n", "", ""), "t.vtk"), Status::Truncated,
               "declares 12000000000 values");
  EXPECT_FAILS(readBytes(asciiVtk("POINTS 99999999999 float\n1 2 3\n", "", ""), "t.vtk"), Status::TooLarge, "32 bits");
  EXPECT_FAILS(readBytes(asciiVtk(pts, "CELLS 1 5000000000\n4 0 1 2 3\n", "CELL_TYPES 1\n10\n"), "t.vtk"),
               Status::Truncated, "CELLS");
  EXPECT_FAILS(readBytes(asciiVtk(pts, "CELLS 2 5\n4 0 1 2 3\n", "CELL_TYPES 2\n10 10\n"), "t.vtk"), Status::Corrupt,
               "CELLS: cell 1 starts after");
  EXPECT_FAILS(readBytes(asciiVtk(pts, "CELLS 1 5\n-4 0 1 2 3\n", "CELL_TYPES 1\n10\n"), "t.vtk"), Status::Corrupt,
               "cell 0 declares -4");
  EXPECT_FAILS(readBytes(asciiVtk(pts, "CELLS 1 5\n4 0 1 2 3\n", "CELL_TYPES 2\n10 10\n"), "t.vtk"), Status::Corrupt,
               "CELL_TYPES lists 2 cells, CELLS has 1");
  EXPECT_FAILS(readBytes(asciiVtk(pts, "CELLS 3 4\nOFFSETS vtktypeint64\n0 4 -1\nCONNECTIVITY vtktypeint64\n0 1 2 3\n",
                                  "CELL_TYPES 2\n10 10\n"),
                         "t.vtk"),
               Status::Corrupt, "cell 1 has offsets 4..-1");
  EXPECT_FAILS(readBytes(asciiVtk(pts, "CELLS 1 5\n4 0 1 2 3\n", "CELL_TYPES 1\n10\n", "POINT_DATA 5\n"), "t.vtk"),
               Status::Corrupt, "POINT_DATA 5 but there are 4 points");
  EXPECT_FAILS(
      readBytes(asciiVtk(pts, "CELLS 1 5\n4 0 1 2 3\n", "CELL_TYPES 1\n10\n", "POINT_DATA 4\nSCALARS s float\n1 2 3\n"),
                "t.vtk"),
      Status::Truncated, "SCALARS 's': file ends after 3 of 4 values");
  EXPECT_FAILS(readBytes(asciiVtk(pts, "CELLS 1 5\n4 0 1 2 3\n", "CELL_TYPES 1\n10\n",
                                  "POINT_DATA 4\nSCALARS s float\n1 2 zz 3\n"),
                         "t.vtk"),
               Status::Corrupt, "line 13: SCALARS 's': value 2 'zz' is not a number");
  EXPECT_FAILS(readBytes(asciiVtk(pts, "CELLS 1 5\n4 0 1 2 3\n", "CELL_TYPES 1\n10\n", "WHATEVER 4\n"), "t.vtk"),
               Status::Corrupt, "line 11: unknown keyword 'WHATEVER'");
  EXPECT_FAILS(
      readBytes(asciiVtk(pts, "CELLS 1 5\n4 0 1 2 3\n", "CELL_TYPES 1\n10\n", "POINT_DATA 4\nSCALARS s quaternion\n"),
                "t.vtk"),
      Status::Corrupt, "unknown data type 'quaternion'");
}

TEST(ReaderBadInput, LegacyAttributesAndStringArrays) {
  std::string pts = "POINTS 4 float\n" + kTetPoints + "\n";
  std::string ok =
      asciiVtk(pts, "CELLS 1 5\n4 0 1 2 3\n", "CELL_TYPES 1\n10\n",
               "CELL_DATA 1\nSCALARS c int 1\nLOOKUP_TABLE default\n7\n"
               "POINT_DATA 4\nSCALARS s double 2\n1 0 0 1 3 4 0 0\nNORMALS n float\n0 0 1 0 0 1 0 0 1 0 0 1\n"
               "TEXTURE_COORDINATES uv 2 float\n0 0 1 0 0 1 1 1\n"
               "FIELD fd 2\nname%20with%20space 1 4 float\n5 6 7 8\nids 1 4 string\na\nb\nc\nd\n"
               "VECTORS later float\n0 0 0 0 0 0 0 0 0 0 0 0\n");
  TetMesh m;
  ReadReport r;
  Result res = readBytes(ok, "t.vtk", m, r);
  ASSERT_TRUE(res) << res.message;
  ASSERT_EQ(m.fields.size(), 4u) << allNotes(r);
  EXPECT_EQ(m.fields[0].name, "s_magnitude");
  EXPECT_EQ(m.fields[0].values, (std::vector<float>{1, 1, 5, 0}));
  EXPECT_EQ(m.fields[1].name, "n_magnitude");
  EXPECT_EQ(m.fields[2].name, "name with space");
  EXPECT_EQ(m.fields[3].name, "c");
  EXPECT_EQ(m.fields[3].values, (std::vector<float>{7, 7, 7, 7}));
  EXPECT_TRUE(hasNote(r, "converted cell data 'c'")) << allNotes(r);
  EXPECT_TRUE(hasNote(r, "skipped TEXTURE_COORDINATES 'uv'")) << allNotes(r);
  EXPECT_TRUE(hasNote(r, "string array")) << allNotes(r);
}

// Cuts every fixture at many lengths: a .vtu prefix always fails (its end is marked); a legacy
// prefix may end on a section boundary and then reads a complete mesh with fewer fields.
TEST(ReaderBadInput, TruncatedFixturesNeverCrash) {
  for (const std::string& file : test::fixtureFiles()) {
    const std::string bytes = loadFile(fixturePath(file));
    const bool xml = file.ends_with(".vtu");
    TetMesh full;
    ReadReport fr;
    ASSERT_TRUE(readMeshBytes(bytes, file, full, fr)) << file;
    const size_t end = xml ? bytes.rfind("</VTKFile>") + 10 : bytes.size();
    size_t failures = 0, tried = 0;
    for (size_t len = 0; len < end; len += (len < 400 || len + 200 > end) ? 1 : 7) {
      TetMesh m;
      ReadReport r;
      Result res = readMeshBytes(std::string_view(bytes).substr(0, len), file, m, r);
      ++tried;
      if (!res) {
        ++failures;
        ASSERT_EQ(res.message.rfind(file, 0), 0u) << "message should start with the file: " << res.message;
        ASSERT_EQ(m.tetCount(), 0u);
        continue;
      }
      ASSERT_FALSE(xml) << file << " cut at " << len << " of " << bytes.size() << " read as ok";
      // e.g. the last cell type "10" cut to "1" (VTK_VERTEX): fewer tets, all of them right.
      ASSERT_EQ(m.vertexCount(), full.vertexCount()) << file << " cut at " << len;
      ASSERT_LE(m.tets.size(), full.tets.size()) << file << " cut at " << len;
      ASSERT_TRUE(std::equal(m.tets.begin(), m.tets.end(), full.tets.begin())) << file << " cut at " << len;
      ASSERT_LE(m.fields.size(), full.fields.size()) << file << " cut at " << len;
    }
    EXPECT_GT(double(failures), 0.8 * double(tried)) << file;
  }
}

// Seeded random byte damage: any outcome but a crash (run under TETSTREAM_SANITIZE for more).
TEST(ReaderBadInput, RandomByteDamageNeverCrashes) {
  std::mt19937 rng(12345);
  for (const std::string& file : test::fixtureFiles()) {
    const std::string bytes = loadFile(fixturePath(file));
    for (int trial = 0; trial < 150; ++trial) {
      std::string b = bytes;
      int flips = 1 + int(rng() % 4);
      for (int k = 0; k < flips; ++k) {
        size_t at = rng() % b.size();
        switch (rng() % 3) {
          case 0: b[at] = char(rng()); break;
          case 1: b[at] ^= char(1 << (rng() % 8)); break;
          default: b[at] = "0123456789-e. <>\"_\n"[rng() % 19];
        }
      }
      TetMesh m;
      ReadReport r;
      Result res = readMeshBytes(b, file, m, r);
      if (!res) {
        ASSERT_FALSE(res.message.empty()) << file;
      }
    }
  }
}

// ASCII integers as every text reader takes them: the quick path for plain digits and the full
// one for the rest agree on what they accept, the value, and where pos ends.
TEST(ReaderText, ParseNextInt) {
  using tetstream::vtkio::parseNextInt;
  struct Case {
    const char* text;
    int result;
    int64_t value;
    size_t pos;  // after the call
  };
  const Case cases[] = {
      {"  42 7", 1, 42, 4},
      {"\t\n-12\n", 1, -12, 5},
      {"+7", 1, 7, 2},
      {"007 ", 1, 7, 3},
      {"-0", 1, 0, 2},
      {"4.0 1", 1, 4, 3},
      {"4e0", 1, 4, 3},
      {"4.5", -1, 0, 0},
      {"12abc", -1, 0, 0},
      {" -", -1, 0, 1},
      {"   ", 0, 0, 3},
      {"", 0, 0, 0},
      {"123456789012345678", 1, 123456789012345678, 18},
      {"1234567890123456789", 1, 1234567890123456789, 19},  // 19 digits: past the quick path
      {"-9223372036854775808", 1, INT64_MIN, 20},
      {"99999999999999999999", -1, 0, 0},  // beyond int64
  };
  for (const Case& c : cases) {
    size_t pos = 0;
    int64_t v = 0;
    EXPECT_EQ(parseNextInt(c.text, pos, v), c.result) << '"' << c.text << '"';
    if (c.result == 1) {
      EXPECT_EQ(v, c.value) << '"' << c.text << '"';
    }
    EXPECT_EQ(pos, c.pos) << '"' << c.text << '"';
  }
  // A run of numbers read one after another.
  std::string_view text = "1 -2\t3\n\n 40 5";
  size_t pos = 0;
  int64_t v = 0, sum = 0;
  int n = 0;
  while (parseNextInt(text, pos, v) == 1) sum += v, ++n;
  EXPECT_EQ(n, 5);
  EXPECT_EQ(sum, 47);
}

// Base64 broken into lines (as some writers wrap it), the breaks falling inside 4-character
// groups and inside the compressed blocks' header words: the same mesh as the one-line text.
TEST(ReaderVtu, WrappedBase64ReadsAlike) {
  for (const char* file : {"vtk_binary_zlib.vtu", "meshio_zlib.vtu", "vtk_binary_u64.vtu"}) {
    const std::string text = loadFile(fixturePath(file));
    std::string wrapped;
    size_t arrays = 0;
    for (size_t at = 0;;) {
      const size_t tag = text.find("format=\"binary\"", at);
      if (tag == std::string::npos) {
        wrapped += text.substr(at);
        break;
      }
      const size_t begin = text.find('>', tag) + 1, end = text.find('<', begin);
      wrapped += text.substr(at, begin - at);
      for (size_t k = begin; k < end; ++k) {
        wrapped += text[k];
        if ((k - begin) % 7 == 6) wrapped += (k % 2 ? "\n    " : "\r\n\t");
      }
      at = end;
      ++arrays;
    }
    ASSERT_GT(arrays, 2u) << file;
    TetMesh a, b;
    ReadReport ra, rb;
    ASSERT_TRUE(readBytes(text, file, a, ra)) << file;
    ASSERT_TRUE(readBytes(wrapped, file, b, rb)) << file;
    EXPECT_EQ(a.positions, b.positions) << file;
    EXPECT_EQ(a.tets, b.tets) << file;
    ASSERT_EQ(a.fields.size(), b.fields.size()) << file;
    for (size_t f = 0; f < a.fields.size(); ++f) EXPECT_EQ(a.fields[f].values, b.fields[f].values) << file;
  }
}

TEST(ReaderBadInput, BadBase64AndZlib) {
  std::string b64 = loadFile(fixturePath("vtk_binary.vtu"));
  size_t at = b64.find("format=\"binary\"");
  at = b64.find('>', at) + 20;  // inside the first array's base64 text
  std::string bad = b64;
  bad[at] = '*';
  EXPECT_FAILS(readBytes(bad, "a.vtu"), Status::Corrupt, "invalid base64 character 0x2a");
  bad = b64;
  bad[at] = '=';
  EXPECT_FALSE(readBytes(bad, "a.vtu"));

  // Corrupt the first zlib stream in raw appended data (its 0x78 header byte).
  std::string z = loadFile(fixturePath("vtk_appended_raw_zlib64.vtu"));
  size_t data = z.find('_', z.find("<AppendedData")) + 1;
  size_t zhead = z.find('\x78', data);
  ASSERT_NE(zhead, std::string::npos);
  z[zhead] = 0;
  EXPECT_FAILS(readBytes(z, "z.vtu"), Status::DecompressFailed, "zlib block 0 of");

  // Inline zlib: break the deflate stream of the first block, leave the header intact.
  std::string iz = loadFile(fixturePath("meshio_zlib.vtu"));
  size_t t = iz.find("format=\"binary\"");
  t = iz.find('>', t) + 1;
  // meshio base64-encodes the 16-byte header on its own ("...==") and then the deflate data,
  // which starts with the zlib header 0x78 0x9c ("eJ").
  size_t deflate = iz.find_first_not_of('=', iz.find('=', t));
  ASSERT_EQ(iz.substr(deflate, 2), "eJ");
  iz.replace(deflate, 4, "AAAA");
  EXPECT_FAILS(readBytes(iz, "z.vtu"), Status::DecompressFailed, "corrupt zlib data");
}

// Binary payload headers that lie about sizes: handcrafted appended-raw files.
std::string appendedVtu(const std::string& header, const std::string& payload, const std::string& pointsOffset = "0") {
  return "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" " + header +
         "><UnstructuredGrid><Piece NumberOfPoints=\"4\" NumberOfCells=\"1\">"
         "<Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"appended\" offset=\"" +
         pointsOffset +
         "\"/></Points>"
         "<Cells><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1 2 3</DataArray>"
         "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">4</DataArray>"
         "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">10</DataArray></Cells>"
         "</Piece></UnstructuredGrid><AppendedData encoding=\"raw\">_" +
         payload + "</AppendedData></VTKFile>";
}

std::string u32(uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); }
std::string u64(uint64_t v) { return std::string(reinterpret_cast<const char*>(&v), 8); }

TEST(ReaderBadInput, LyingPayloadHeaders) {
  float p[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::string pts(reinterpret_cast<const char*>(p), 48);
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(readBytes(appendedVtu("", u32(48) + pts), "a.vtu", m, r));
  EXPECT_EQ(m.positions[9 + 2], 1.f);

  EXPECT_FAILS(readBytes(appendedVtu("", u32(4000000000u) + pts), "a.vtu"), Status::Truncated,
               "header says 4000000000 bytes, expected 48");
  EXPECT_FAILS(readBytes(appendedVtu("", u32(40) + pts), "a.vtu"), Status::Corrupt,
               "header says 40 bytes, expected 48");
  EXPECT_FAILS(readBytes(appendedVtu("", u32(48) + pts.substr(0, 30)), "a.vtu"), Status::Truncated, "needs 48 bytes");
  EXPECT_FAILS(readBytes(appendedVtu("", u32(48) + pts, "9999"), "a.vtu"), Status::Truncated, "offset 9999 is beyond");
  EXPECT_FAILS(readBytes(appendedVtu("", u32(48) + pts, "-5"), "a.vtu"), Status::Corrupt, "offset '-5'");
  EXPECT_FAILS(readBytes(appendedVtu("", u32(48) + pts, "abc"), "a.vtu"), Status::Corrupt, "offset 'abc'");
  EXPECT_FAILS(readBytes(appendedVtu("header_type=\"UInt64\"", u64(~0ull) + pts), "a.vtu"), Status::Truncated,
               "header says 18446744073709551615");
  EXPECT_FAILS(readBytes(appendedVtu("header_type=\"UInt16\"", u32(48) + pts), "a.vtu"), Status::Unsupported,
               "header_type 'UInt16'");

  // zlib: absurd block counts, sizes and ratios.
  const std::string z = "compressor=\"vtkZLibDataCompressor\"";
  EXPECT_FAILS(readBytes(appendedVtu(z, u32(0x40000000) + u32(48) + u32(0)), "a.vtu"), Status::Truncated,
               "declares 1073741824 blocks");
  EXPECT_FAILS(readBytes(appendedVtu(z, u32(1) + u32(48) + u32(0) + u32(0x7fffffff) + "xx"), "a.vtu"),
               Status::Truncated, "compressed block 0 of 1 needs 2147483647 bytes");
  EXPECT_FAILS(readBytes(appendedVtu(z, u32(1) + u32(480) + u32(0) + u32(2) + "xx"), "a.vtu"), Status::Corrupt,
               "compressed data holds 480 bytes, expected 48");
  EXPECT_FAILS(readBytes(appendedVtu(z, u32(1) + u32(64) + u32(48) + u32(2) + "xx"), "a.vtu"), Status::DecompressFailed,
               "zlib block 0");
  EXPECT_FAILS(readBytes(appendedVtu(z, u32(2) + u32(32) + u32(40) + u32(2) + u32(2) + "xxxx"), "a.vtu"),
               Status::Corrupt, "last block size 40 exceeds the block size 32");
  // A ratio no zlib stream reaches: 48 bytes from... make the expected size large via more points.
  std::string big = appendedVtu(z, u32(1) + u32(4800000) + u32(0) + u32(1) + "x");
  big.replace(big.find("NumberOfPoints=\"4\""), 18, "NumberOfPoints=\"400000\"");
  EXPECT_FAILS(readBytes(big, "a.vtu"), Status::Corrupt, "beyond what zlib can produce");

  // Missing end of file after the payload.
  std::string cut = appendedVtu("", u32(48) + pts);
  cut.resize(cut.size() - 10);
  EXPECT_FAILS(readBytes(cut, "a.vtu"), Status::Truncated, "ends before </VTKFile>");
}

TEST(ReaderBadInput, MultiplePiecesAreConcatenated) {
  // Two pieces, each one tet; the second repeats three points of the first (their shared face),
  // as a partitioned solver writes them: the copies are merged and the face is shared.
  auto piece = [](const std::string& points, const std::string& f) {
    return "<Piece NumberOfPoints=\"4\" NumberOfCells=\"1\"><PointData><DataArray type=\"Float32\" Name=\"f\" "
           "format=\"ascii\">" +
           f +
           "</DataArray></PointData><Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">" +
           points +
           "</DataArray></Points><Cells><DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">0 1 2 3"
           "</DataArray><DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">4</DataArray>"
           "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">10</DataArray></Cells></Piece>";
  };
  const std::string a = piece(kTetPoints, "1 2 3 4"), b = piece("1 1 1 0 0 1 0 1 0 1 0 0", "5 4 3 2");
  std::string doc = "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid>" + a + b + "</UnstructuredGrid></VTKFile>";
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(readBytes(doc, "p.vtu", m, r));
  EXPECT_EQ(m.vertexCount(), 5u);
  EXPECT_EQ(m.tets, (std::vector<uint32_t>{0, 1, 2, 3, 4, 3, 2, 1}));
  ASSERT_EQ(m.fields.size(), 1u);
  EXPECT_EQ(m.fields[0].values, (std::vector<float>{1, 2, 3, 4, 5}));
  EXPECT_TRUE(hasNote(r, "concatenated 2 pieces"));
  EXPECT_TRUE(hasNote(r, "merged 3 duplicate vertices (exactly the same coordinates) into the first copy"))
      << allNotes(r);

  // A field missing from the second piece is dropped, with a note.
  std::string b2 = b;
  b2.replace(b2.find("Name=\"f\""), 8, "Name=\"g\"");
  doc = "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid>" + a + b2 + "</UnstructuredGrid></VTKFile>";
  ASSERT_TRUE(readBytes(doc, "p.vtu", m, r));
  EXPECT_TRUE(m.fields.empty());
  EXPECT_TRUE(hasNote(r, "dropped point array 'f': Piece 1 lacks it")) << allNotes(r);
}

}  // namespace
}  // namespace tetstream
