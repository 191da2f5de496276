// The XDMF and VTKHDF readers against files other writers made (tests/fixtures/hpc, written by
// make_hpc_fixtures_xdmf.py: meshio for XDMF, h5py to the VTKHDF specification and checked by
// VTK's vtkHDFReader): counts, volume, boundary area, the writers' analytic point data, cell data
// at the points, time steps; then damaged and hostile inputs, each of which must come back as a
// Result that names the file and the item.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "io/mesh_io.h"
#include "io/readers.h"
#include "io/xdmf_mixed.h"
#include "io/xml_path.h"
#include "test_helpers.h"

namespace tetstream {
namespace {

namespace fs = std::filesystem;
using test::allNotes;
using test::boundaryArea;
using test::expectValid;
using test::findVertex;
using test::fixturePath;
using test::hasNote;
using test::loadFile;
using test::saveFile;
using test::ScratchDir;
using test::totalVolume;

std::string hpcPath(const std::string& name) { return fixturePath("hpc/" + name); }

const nlohmann::json& expected() { return test::fixtureJson("hpc/xdmf_vtkhdf_expected.json"); }

// f = x + 2y + 3z + offset at every vertex.
void expectLinearField(const TetMesh& m, const char* name, double offset, const std::string& what) {
  const int f = m.findField(name);
  ASSERT_GE(f, 0) << what << " has no field " << name;
  for (uint32_t v = 0; v < m.vertexCount(); ++v) {
    const double x = m.positions[3 * v], y = m.positions[3 * v + 1], z = m.positions[3 * v + 2];
    ASSERT_NEAR(m.fields[size_t(f)].values[v], x + 2 * y + 3 * z + offset, 1e-5) << what << " vertex " << v;
  }
}

// Cell data turned into point data: the values the fixture script computed, [x, y, z, value].
void expectPointValues(const TetMesh& m, const char* name, const nlohmann::json& rows, const std::string& what) {
  const int f = m.findField(name);
  ASSERT_GE(f, 0) << what << " has no field " << name;
  ASSERT_FALSE(rows.empty());
  for (const auto& row : rows) {
    const int64_t v = findVertex(m, row[0], row[1], row[2]);
    ASSERT_GE(v, 0) << what << " vertex at " << row;
    EXPECT_NEAR(m.fields[size_t(f)].values[size_t(v)], row[3].get<double>(), 1e-5)
        << what << " " << name << " at " << row;
  }
}

Result read(const std::string& path, TetMesh& m, ReadReport& r, ReadOptions o = {}) { return readMesh(path, m, r, o); }

// ------------------------------------------------------------------ every fixture vs the writer
class HpcFixture : public testing::TestWithParam<std::string> {};
class XdmfFixture : public HpcFixture {};
class VtkHdfFixture : public HpcFixture {};

void checkFixture(const std::string& file) {
  const nlohmann::json& e = expected()[file];
  ASSERT_FALSE(e.is_null()) << file << " is not in xdmf_vtkhdf_expected.json";
  TetMesh m;
  ReadReport r;
  Result res = read(hpcPath(file), m, r);
  ASSERT_TRUE(res) << statusName(res.status) << ": " << res.message;
  EXPECT_EQ(m.vertexCount(), e["vertices"].get<uint32_t>()) << file << allNotes(r);
  EXPECT_EQ(m.tetCount(), e["tets"].get<uint32_t>()) << file << allNotes(r);
  const double volume = e["volume"].is_array() ? e["volume"].back().get<double>() : e["volume"].get<double>();
  EXPECT_NEAR(totalVolume(m), volume, 1e-6 * volume) << file;
  if (e.contains("area")) {
    EXPECT_NEAR(boundaryArea(m), e["area"].get<double>(), 1e-6) << file;
  }
  expectValid(m, file);
  if (e.contains("topology")) {
    EXPECT_NE(r.format.find(e["topology"].get<std::string>()), std::string::npos) << r.format;
  }
  // The last step of a time series is read by default: f carries 10 t.
  const double t = e.contains("times") ? e["times"].back().get<double>() : 0.0;
  expectLinearField(m, "f", 10 * t, file);
  if (const int v = m.findField("v_magnitude"); v >= 0)
    for (uint32_t i = 0; i < m.vertexCount(); ++i) {
      const double x = m.positions[3 * i], y = m.positions[3 * i + 1], z = m.positions[3 * i + 2];
      ASSERT_NEAR(m.fields[size_t(v)].values[i], (1 + t) * std::sqrt(x * x + y * y + z * z), 1e-5) << file;
    }
  for (const char* name : {"c", "col"})
    if (e.contains(name)) expectPointValues(m, name, e[name], file);
}

TEST_P(XdmfFixture, CountsVolumeConformityAndFields) { checkFixture(GetParam()); }
TEST_P(VtkHdfFixture, CountsVolumeConformityAndFields) { checkFixture(GetParam()); }

std::string caseName(const testing::TestParamInfo<std::string>& info) {
  std::string n = info.param;
  for (char& c : n)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return n;
}

INSTANTIATE_TEST_SUITE_P(Xdmf, XdmfFixture,
                         testing::Values("xdmf_grid.xdmf", "xdmf_binary.xdmf", "xdmf_mixed.xdmf",
                                         "xdmf_mixed_quadratic.xdmf", "xdmf_series.xdmf", "xdmf_inline.xmf"),
                         caseName);
INSTANTIATE_TEST_SUITE_P(VtkHdf, VtkHdfFixture,
                         testing::Values("vtkhdf_parts.vtkhdf", "vtkhdf_mixed.hdf", "vtkhdf_series.vtkhdf"), caseName);

TEST(XdmfFixtureList, EveryFileIsChecked) {
  ASSERT_FALSE(expected().is_discarded()) << "xdmf_vtkhdf_expected.json does not parse";
  EXPECT_EQ(expected().size(), 9u);
}

// ------------------------------------------------------------------ what was read, in words
TEST(XdmfReader, FormatAndNotesSayWhatWasRead) {
  struct Case {
    const char* file;
    std::vector<std::string> format, notes;
  };
  const std::vector<Case> cases = {
      {"xdmf_grid.xdmf", {"XDMF 3 (HDF5 heavy data), Tetrahedron"}, {"converted cell data 'c'"}},
      {"xdmf_binary.xdmf", {"XDMF 3 (binary data), Tetrahedron"}, {}},
      {"xdmf_mixed.xdmf", {"XDMF 3 (HDF5 heavy data), Mixed"}, {"split 2 hexahedra, 4 wedges, 12 pyramids"}},
      {"xdmf_mixed_quadratic.xdmf",
       {"Mixed"},
       {"reduced 12 VTK_QUADRATIC_TETRA (24) cells to their 4 corner vertices",
        "reduced 2 VTK_TRIQUADRATIC_HEXAHEDRON (29) cells to their 8 corner vertices",
        "reduced 4 VTK_BIQUADRATIC_QUADRATIC_WEDGE (32) cells to their 6 corner vertices"}},
      {"xdmf_series.xdmf",
       {"XDMF 3 (HDF5 heavy data), Tetrahedron, step 3 of 4 (t = 0.75)"},
       {"has 4 time steps (t = 0 .. 0.75); read the last, step 3", "read the time series 'TimeSeries_meshio'"}},
      {"xdmf_inline.xmf",
       {"XDMF 2 (XML data), Tetrahedron, 2 grids"},
       {"Grid 'bottom': 2 Triangle cells", "skipped 2 cells of unsupported type XDMF Triangle",
        "merged 9 duplicate vertices"}},
      {"vtkhdf_parts.vtkhdf", {"VTKHDF 1.0 UnstructuredGrid, 3 partitions"}, {"merged 24 duplicate vertices"}},
      {"vtkhdf_series.vtkhdf", {"VTKHDF 2.0 UnstructuredGrid, 2 partitions, step 2 of 3 (t = 1)"}, {}},
  };
  for (const Case& c : cases) {
    TetMesh m;
    ReadReport r;
    Result res = read(hpcPath(c.file), m, r);
    ASSERT_TRUE(res) << c.file << ": " << res.message;
    for (const std::string& f : c.format) EXPECT_NE(r.format.find(f), std::string::npos) << c.file << ": " << r.format;
    for (const std::string& n : c.notes) EXPECT_TRUE(hasNote(r, n)) << c.file << " lacks '" << n << "'" << allNotes(r);
  }
  // Skipped cells are named by their XDMF type.
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(read(hpcPath("xdmf_inline.xmf"), m, r));
  ASSERT_EQ(r.skippedCells.size(), 1u);
  EXPECT_EQ(r.skippedCells[0].typeName, "XDMF Triangle");
  EXPECT_EQ(r.skippedCells[0].count, 2u);
}

// ------------------------------------------------------------------ time steps
// One grid read by several processes (core/dist): each reads its rows of the cells and of the
// points they use (io/row_pick.h). Together the shares hold every tet of the whole once, on the
// same points with the same point values, from HDF5 (hyperslabs), from raw binary files and
// through a time series whose steps include their mesh.
TEST(XdmfShares, TheSharesOfAGridHoldEveryTetOnceWithItsValues) {
  for (const char* name : {"xdmf_grid.xdmf", "xdmf_binary.xdmf", "xdmf_series.xdmf"}) {
    test::expectSharesMakeTheWhole(hpcPath(name), 3, "c");
    test::expectSharesReadOnlyUsedPoints(hpcPath(name), 3, "points they use");
  }
}

// A spatial collection of grids (one per rank of the run that wrote it): on as many processes as
// volume grids each reads its own grids whole; on more, each reads its rows of every grid. The
// grid of triangles beside them is skipped either way.
TEST(XdmfShares, TheGridsOfACollectionAreSharedByGridOrByRows) {
  for (uint32_t count : {2u, 3u}) test::expectSharesMakeTheWhole(hpcPath("xdmf_inline.xmf"), count, "c");
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(readMesh(hpcPath("xdmf_inline.xmf"), m, r, test::shareOf(1, 2)));
  EXPECT_TRUE(hasNote(r, "read grid 2 of the 2 volume grids, this process's share of the file")) << allNotes(r);
  ASSERT_TRUE(readMesh(hpcPath("xdmf_inline.xmf"), m, r = ReadReport{}, test::shareOf(1, 3)));
  EXPECT_TRUE(hasNote(r, "this process's share of the grid")) << allNotes(r);
}

// Writes `mesh` as one XDMF grid of Mixed cells in HDF5, ids from BaseOffset 1: its tets
// (code 6), and between them cells tetstream does not read, a triangle (code 4) after every 7th
// tet and a polyline of two nodes (code 2 and its node count) after every 11th, as a mesh with
// its facets and edges in one topology is written. Point field "f" and cell data "c".
void writeMixedXdmf(const TetMesh& mesh, const std::string& dir) {
  std::vector<int64_t> topo;
  std::vector<double> cellValues;
  for (uint32_t t = 0; t < mesh.tetCount(); ++t) {
    const uint32_t* v = &mesh.tets[4 * size_t(t)];
    topo.insert(topo.end(), {6, v[0] + 1, v[1] + 1, v[2] + 1, v[3] + 1});
    cellValues.push_back(t);
    if (t % 7 == 0) topo.insert(topo.end(), {4, v[0] + 1, v[1] + 1, v[2] + 1}), cellValues.push_back(-1);
    if (t % 11 == 0) topo.insert(topo.end(), {2, 2, v[0] + 1, v[3] + 1}), cellValues.push_back(-2);
  }
  std::vector<double> xyz(mesh.positions.begin(), mesh.positions.end()),
      f(mesh.fields[0].values.begin(), mesh.fields[0].values.end());
  hid_t file = H5Fcreate((dir + "/mixed.h5").c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  auto write = [&](const char* name, hid_t type, const void* data, std::vector<hsize_t> dims) {
    hid_t space = H5Screate_simple(int(dims.size()), dims.data(), nullptr);
    hid_t d = H5Dcreate2(file, name, type == H5T_NATIVE_INT64 ? H5T_STD_I64LE : H5T_IEEE_F64LE, space, H5P_DEFAULT,
                         H5P_DEFAULT, H5P_DEFAULT);
    H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
    H5Dclose(d);
    H5Sclose(space);
  };
  write("topo", H5T_NATIVE_INT64, topo.data(), {topo.size()});
  write("xyz", H5T_NATIVE_DOUBLE, xyz.data(), {mesh.vertexCount(), 3});
  write("f", H5T_NATIVE_DOUBLE, f.data(), {mesh.vertexCount()});
  write("c", H5T_NATIVE_DOUBLE, cellValues.data(), {cellValues.size()});
  H5Fclose(file);
  const std::string n = std::to_string(mesh.vertexCount());
  saveFile(
      dir + "/mixed.xdmf", R"(<Xdmf Version="3.0"><Domain><Grid Name="mesh">
<Topology TopologyType="Mixed" NumberOfElements=")" +
                               std::to_string(cellValues.size()) + R"(" BaseOffset="1">
 <DataItem Dimensions=")" + std::to_string(topo.size()) +
                               R"(" NumberType="Int" Precision="8" Format="HDF">mixed.h5:/topo</DataItem></Topology>
<Geometry GeometryType="XYZ"><DataItem Dimensions=")" +
                               n + R"( 3" Precision="8" Format="HDF">mixed.h5:/xyz</DataItem></Geometry>
<Attribute Name="f" Center="Node"><DataItem Dimensions=")" +
                               n + R"(" Precision="8" Format="HDF">mixed.h5:/f</DataItem></Attribute>
<Attribute Name="c" Center="Cell"><DataItem Dimensions=")" +
                               std::to_string(cellValues.size()) +
                               R"(" Precision="8" Format="HDF">mixed.h5:/c</DataItem></Attribute>
</Grid></Domain></Xdmf>)");
}

// One grid of Mixed cells read by several processes: each walks the topology's codes to its
// share of the cells (counting them first when the topology does not say how many) and reads
// only the points they use; together the shares hold every tet of the whole once. Node ids lose
// the BaseOffset, type codes do not.
TEST(XdmfShares, MixedCellsAreSharedByWalkingTheirCodes) {
  ScratchDir dir("xdmf-mixed-shares");
  const TetMesh mesh = test::shuffledPoints(test::harmonicMesh(6));
  writeMixedXdmf(mesh, dir.path);
  const std::string path = dir.path + "/mixed.xdmf";
  TetMesh whole;
  ReadReport r;
  ASSERT_TRUE(readMesh(path, whole, r)) << allNotes(r);
  EXPECT_EQ(whole.tetCount(), mesh.tetCount());
  EXPECT_TRUE(
      hasNote(r, "skipped " + std::to_string((mesh.tetCount() + 6) / 7) + " cells of unsupported type XDMF Triangle"))
      << allNotes(r);
  for (uint32_t count : {2u, 3u, 5u}) {
    test::expectSharesMakeTheWhole(path, count, "c");
    test::expectSharesReadOnlyUsedPoints(path, count, "points they use");
  }
  // Without NumberOfElements the cells are counted by a first walk.
  std::string xml = loadFile(path);
  const size_t at = xml.find(" NumberOfElements=");
  ASSERT_NE(at, std::string::npos);
  xml.erase(at, xml.find('"', xml.find('"', at) + 1) + 1 - at);
  const std::string uncounted = dir.path + "/uncounted.xdmf";
  ASSERT_TRUE(saveFile(uncounted, xml));
  for (uint32_t count : {2u, 3u}) {
    test::expectSharesMakeTheWhole(uncounted, count, "c");
    test::expectSharesReadOnlyUsedPoints(uncounted, count, "points they use");
  }
  for (const char* name : {"xdmf_mixed.xdmf", "xdmf_mixed_quadratic.xdmf"})  // ("col": cell data)
    for (uint32_t count : {2u, 3u}) test::expectSharesMakeTheWhole(hpcPath(name), count, "col");
}

// The walk a window of values at a time finds the cells the walk of all of them does, wherever
// the windows cut the cells; a topology cut short inside a cell, or one with a cell code nobody
// defines, is refused by the walk that reaches it.
TEST(XdmfMixed, WalkingInWindowsFindsTheSameCells) {
  // A tet, a polyhedron of two faces (a triangle and a quad), a polyline of 3, a pyramid, a tet.
  const std::vector<int64_t> topo = {6, 0, 1, 2, 3, 0x10, 2, 3, 0, 1, 2, 4, 0, 1, 2, 3,
                                     2, 3, 4, 5, 6, 7,    1, 2, 3, 4, 5, 6, 1, 2, 3, 4};
  xdmf::MixedCells all;
  size_t used = 0;
  xdmf::MixedWalker whole("t", 0, 0, UINT64_MAX);
  ASSERT_TRUE(whole.walk(topo, true, all, used));
  EXPECT_EQ(used, topo.size());
  EXPECT_EQ(whole.cells(), 5u);
  EXPECT_EQ(all.types, (std::vector<int64_t>{10, 0, 0, 14, 10}));
  for (uint64_t from = 0; from <= 5; ++from)
    for (uint64_t to = from; to <= 5; ++to)
      for (size_t window = 1; window <= 8; ++window) {
        SCOPED_TRACE("cells " + std::to_string(from) + " to " + std::to_string(to) + ", windows of " +
                     std::to_string(window));
        xdmf::MixedWalker w("t", 0, from, to);
        xdmf::MixedCells part;
        size_t at = 0, n = window;
        while (!w.done() && at < topo.size()) {
          const size_t take = std::min(n, topo.size() - at);
          ASSERT_TRUE(w.walk(std::span(topo).subspan(at, take), at + take == topo.size(), part, used));
          at += used;
          n = used ? window : 2 * n;
        }
        EXPECT_EQ(w.cells(), to);
        EXPECT_EQ(part.types, std::vector<int64_t>(all.types.begin() + std::ptrdiff_t(from),
                                                   all.types.begin() + std::ptrdiff_t(to)));
        const auto first = all.connectivity.begin();
        EXPECT_EQ(part.connectivity, std::vector<int64_t>(first + all.offsets[from], first + all.offsets[to]));
      }
  xdmf::MixedCells out;
  xdmf::MixedWalker cut("t", 0, 0, UINT64_MAX);
  Result r = cut.walk(std::span(topo).first(topo.size() - 1), true, out, used);
  EXPECT_EQ(r.status, Status::Truncated);
  EXPECT_NE(r.message.find("cell 4 needs 4 more values for its nodes, 3 remain"), std::string::npos) << r.message;
  xdmf::MixedWalker unknown("t", 0, 3, 4);
  r = unknown.walk(std::vector<int64_t>{6, 0, 1, 2, 3, 99, 0}, false, out, used);
  EXPECT_EQ(r.status, Status::Corrupt);
  EXPECT_NE(r.message.find("cell 1 has the unknown cell type code 99"), std::string::npos) << r.message;
}

TEST(XdmfTimeSeries, StepsAreListedAndPicked) {
  const std::string file = hpcPath("xdmf_series.xdmf");
  const nlohmann::json& e = expected()["xdmf_series.xdmf"];
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(read(file, m, r));
  ASSERT_EQ(r.steps.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(r.steps[i].index, i);
    EXPECT_EQ(r.steps[i].time, e["times"][i].get<double>());
  }
  EXPECT_EQ(r.stepRead, 3u);

  ReadOptions byStep;
  byStep.step = 1;
  ReadReport r1;
  ASSERT_TRUE(read(file, m, r1, byStep));
  EXPECT_EQ(r1.stepRead, 1u);
  expectLinearField(m, "f", 2.5, "step 1");
  expectPointValues(m, "c", e["c_step1"], "step 1");
  EXPECT_NE(r1.format.find("step 1 of 4 (t = 0.25)"), std::string::npos) << r1.format;

  ReadOptions byTime;
  byTime.time = 0.6;  // nearest: 0.5, step 2
  ReadReport r2;
  ASSERT_TRUE(read(file, m, r2, byTime));
  EXPECT_EQ(r2.stepRead, 2u);
  expectLinearField(m, "f", 5.0, "t = 0.5");
  EXPECT_TRUE(hasNote(r2, "read the nearest, step 2")) << allNotes(r2);

  ReadOptions past;
  past.step = 4;
  ReadReport r3;
  EXPECT_FAILS(read(file, m, r3, past), Status::BadArgument, "steps 0 .. 3");
  EXPECT_EQ(m.tetCount(), 0u);
}

TEST(XdmfTimeSeries, OnlyTheChosenStepIsRead) {
  // Step 0's point data names a dataset that is not there: the other steps still read, and
  // reading step 0 names the dataset.
  ScratchDir dir("xdmf-steps");
  std::string xml = loadFile(hpcPath("xdmf_series.xdmf"));
  const size_t at = xml.find("xdmf_series.h5:/data2<");
  ASSERT_NE(at, std::string::npos);
  xml.replace(at, 21, "xdmf_series.h5:/gone");
  fs::copy_file(hpcPath("xdmf_series.h5"), dir.path + "/xdmf_series.h5");
  const std::string file = dir.path + "/series.xdmf";
  ASSERT_TRUE(saveFile(file, xml));
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(read(file, m, r)) << "the last step must not need step 0's data";
  ReadOptions first;
  first.step = 0;
  ReadReport r0;
  EXPECT_FAILS(read(file, m, r0, first), Status::Corrupt, "xdmf_series.h5: dataset '/gone' does not exist");
  EXPECT_FAILS(read(file, m, r0, first), Status::Corrupt, "Attribute 'f'");
}

TEST(VtkHdfTimeSeries, StepsAreListedAndPicked) {
  const std::string file = hpcPath("vtkhdf_series.vtkhdf");
  const nlohmann::json& e = expected()["vtkhdf_series.vtkhdf"];
  for (uint64_t s = 0; s < 3; ++s) {
    ReadOptions o;
    o.step = s;
    TetMesh m;
    ReadReport r;
    Result res = read(file, m, r, o);
    ASSERT_TRUE(res) << res.message;
    ASSERT_EQ(r.steps.size(), 3u);
    EXPECT_EQ(r.steps[s].time, e["times"][s].get<double>());
    EXPECT_EQ(r.stepRead, s);
    // Step s is the grid scaled by 1 + s, f = x + 2y + 3z + 10 t at its own points.
    EXPECT_NEAR(totalVolume(m), e["volume"][s].get<double>(), 1e-6) << "step " << s;
    expectLinearField(m, "f", 10 * e["times"][s].get<double>(), "step " + std::to_string(s));
    const Range c = computeRange(m.fields[size_t(m.findField("c"))].values);
    EXPECT_GE(c.min, 10.0 * double(s) - 1e-6);
    EXPECT_LE(c.max, 10.0 * double(s) + 1 + 1e-6);
    expectValid(m, "step " + std::to_string(s));
  }
  ReadOptions byTime;
  byTime.time = 0.4;
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(read(file, m, r, byTime));
  EXPECT_EQ(r.stepRead, 1u);
}

TEST(VtkHdfReader, PartitionsMergeWithoutSeams) {
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(read(hpcPath("vtkhdf_parts.vtkhdf"), m, r));
  // 3 partitions with their own copies of shared points: merged, the boundary is the cube's.
  EXPECT_EQ(m.vertexCount(), 27u);
  EXPECT_NEAR(boundaryArea(m), 6.0, 1e-9);
  EXPECT_TRUE(hasNote(r, "concatenated 3 partitions")) << allNotes(r);
  EXPECT_TRUE(r.steps.empty());
  ReadOptions o;
  o.step = 0;
  EXPECT_FAILS(read(hpcPath("vtkhdf_parts.vtkhdf"), m, r, o), Status::BadArgument, "holds no time steps");
}

// ------------------------------------------------------------------ recognised by content
TEST(VtkHdfReader, AnHdf5FileIsRecognisedByItsContent) {
  ScratchDir dir("vtkhdf-sniff");
  fs::copy_file(hpcPath("vtkhdf_parts.vtkhdf"), dir.path + "/result.h5");
  fs::copy_file(hpcPath("vtkhdf_parts.vtkhdf"), dir.path + "/result.dat");
  for (const char* name : {"/result.h5", "/result.dat"}) {
    TetMesh m;
    ReadReport r;
    Result res = read(dir.path + name, m, r);
    ASSERT_TRUE(res) << name << ": " << res.message;
    EXPECT_EQ(m.tetCount(), 48u);
    EXPECT_NE(r.format.find("VTKHDF"), std::string::npos) << r.format;
  }
  // XDMF's heavy data is HDF5 without /VTKHDF: the message says where to go instead.
  TetMesh m;
  ReadReport r;
  EXPECT_FAILS(read(hpcPath("xdmf_grid.h5"), m, r), Status::BadMagic, "read the .xdmf");
}

TEST(XdmfReader, FromBytesReadsXmlDataAndRefusesHeavyData) {
  TetMesh m;
  ReadReport r;
  Result res = readMeshBytes(loadFile(hpcPath("xdmf_inline.xmf")), "inline.xmf", m, r);
  ASSERT_TRUE(res) << res.message;
  EXPECT_EQ(m.tetCount(), 48u);
  EXPECT_EQ(m.vertexCount(), 27u);
  ReadReport r2;
  EXPECT_FAILS(readMeshBytes(loadFile(hpcPath("xdmf_grid.xdmf")), "grid.xdmf", m, r2), Status::Unsupported,
               "read the XDMF file by path");
  ReadReport r3;
  EXPECT_FAILS(readMeshBytes(loadFile(hpcPath("vtkhdf_parts.vtkhdf")), "parts.vtkhdf", m, r3), Status::Unsupported,
               "read it by path");
  // XML whose root is <Xdmf> is XDMF under any extension.
  ReadReport r4;
  ASSERT_TRUE(readMeshBytes(loadFile(hpcPath("xdmf_inline.xmf")), "inline.xml", m, r4));
  EXPECT_NE(r4.format.find("XDMF 2"), std::string::npos) << r4.format;
}

// ------------------------------------------------------------------ damaged files
// The grid fixture copied into a scratch folder, its XML changed by `edit`.
struct GridCopy {
  ScratchDir dir;
  std::string xdmf;
  explicit GridCopy(const std::string& name, const std::string& from = "", const std::string& to = "",
                    bool copyH5 = true)
      : dir(name) {
    std::string xml = loadFile(hpcPath("xdmf_grid.xdmf"));
    if (!from.empty()) {
      const size_t at = xml.find(from);
      EXPECT_NE(at, std::string::npos) << from;
      if (at != std::string::npos) xml.replace(at, from.size(), to);
    }
    xdmf = dir.path + "/grid.xdmf";
    saveFile(xdmf, xml);
    if (copyH5) fs::copy_file(hpcPath("xdmf_grid.h5"), dir.path + "/xdmf_grid.h5");
  }
};

TEST(XdmfDamaged, MissingTruncatedOrGarbledHeavyData) {
  TetMesh m;
  ReadReport r;
  {
    GridCopy g("xdmf-missing-h5", "", "", false);
    EXPECT_FAILS(read(g.xdmf, m, r), Status::IoError, "xdmf_grid.h5: cannot open");
    EXPECT_FAILS(read(g.xdmf, m, r), Status::IoError, "grid.xdmf Grid 'Grid' Geometry");
  }
  {
    GridCopy g("xdmf-truncated-h5");
    const std::string h5 = loadFile(hpcPath("xdmf_grid.h5"));
    ASSERT_TRUE(saveFile(g.dir.path + "/xdmf_grid.h5", h5.substr(0, h5.size() / 2)));
    EXPECT_FAILS(read(g.xdmf, m, r), Status::Truncated, "xdmf_grid.h5");
    EXPECT_FAILS(read(g.xdmf, m, r), Status::Truncated, "shorter than it says");
  }
  {
    GridCopy g("xdmf-empty-h5");
    ASSERT_TRUE(saveFile(g.dir.path + "/xdmf_grid.h5", ""));
    EXPECT_FAILS(read(g.xdmf, m, r), Status::Truncated, "xdmf_grid.h5: not an HDF5 file (empty)");
  }
  {
    // Every byte after the superblock garbled: whatever the library makes of it, a Result.
    GridCopy g("xdmf-garbled-h5");
    std::string h5 = loadFile(hpcPath("xdmf_grid.h5"));
    for (size_t i = 96; i < h5.size(); i += 7) h5[i] = char(h5[i] ^ 0x5a);
    ASSERT_TRUE(saveFile(g.dir.path + "/xdmf_grid.h5", h5));
    Result res = read(g.xdmf, m, r);
    EXPECT_FALSE(res);
    EXPECT_NE(res.message.find("grid.xdmf"), std::string::npos) << res.message;
    EXPECT_EQ(m.tetCount(), 0u);
  }
}

TEST(XdmfDamaged, MissingDatasetAndDimensionsThatDisagree) {
  TetMesh m;
  ReadReport r;
  {
    GridCopy g("xdmf-no-dataset", "xdmf_grid.h5:/data1<", "xdmf_grid.h5:/Mesh/topology<");
    EXPECT_FAILS(read(g.xdmf, m, r), Status::Corrupt, "dataset '/Mesh/topology' does not exist");
    EXPECT_FAILS(read(g.xdmf, m, r), Status::Corrupt, "Topology");
  }
  {
    GridCopy g("xdmf-dims", "Dimensions=\"27 3\"", "Dimensions=\"28 3\"");
    EXPECT_FAILS(read(g.xdmf, m, r), Status::Corrupt,
                 "Dimensions '28 3' declare 84 values, the dataset holds 81 (27 3)");
  }
  {
    GridCopy g("xdmf-elements", "NumberOfElements=\"48\"", "NumberOfElements=\"47\"");
    EXPECT_FAILS(read(g.xdmf, m, r), Status::Corrupt, "NumberOfElements=47 but the DataItem holds 48 Tetrahedron");
  }
  {
    // An attribute whose data is not there names the attribute.
    GridCopy g("xdmf-attribute", "xdmf_grid.h5:/data2<", "xdmf_grid.h5:/nothing<");
    EXPECT_FAILS(read(g.xdmf, m, r), Status::Corrupt, "Attribute 'f'");
    EXPECT_FAILS(read(g.xdmf, m, r), Status::Corrupt, "'/nothing' does not exist");
  }
  {
    // A point attribute with the values of the cells.
    GridCopy g("xdmf-attribute-size", "Dimensions=\"27\"", "Dimensions=\"48\"");
    Result res = read(g.xdmf, m, r);
    EXPECT_FALSE(res) << "an attribute sized for the cells on the points";
  }
}

TEST(XdmfDamaged, UnsupportedTopologyIsNamedWithItsCount) {
  TetMesh m;
  ReadReport r;
  {
    GridCopy g("xdmf-hex64", "TopologyType=\"Tetrahedron\"", "TopologyType=\"Hexahedron_64\"");
    EXPECT_FAILS(read(g.xdmf, m, r), Status::NoTets, "48 XDMF Hexahedron_64");
  }
  {
    GridCopy g("xdmf-polygon", "TopologyType=\"Tetrahedron\"", "TopologyType=\"Quadrilateral\"");
    EXPECT_FAILS(read(g.xdmf, m, r), Status::NoTets, "XDMF Quadrilateral");
  }
  {
    GridCopy g("xdmf-unknown", "TopologyType=\"Tetrahedron\"", "TopologyType=\"Octahedron\"");
    EXPECT_FAILS(read(g.xdmf, m, r), Status::Unsupported, "TopologyType 'Octahedron'");
  }
  {
    GridCopy g("xdmf-structured", "TopologyType=\"Tetrahedron\"", "TopologyType=\"3DCoRectMesh\"");
    EXPECT_FAILS(read(g.xdmf, m, r), Status::Unsupported, "structured grid");
  }
  {
    GridCopy g("xdmf-xy", "GeometryType=\"XYZ\"", "GeometryType=\"XY\"");
    EXPECT_FAILS(read(g.xdmf, m, r), Status::Unsupported, "GeometryType XY is a 2D mesh");
  }
}

TEST(XdmfDamaged, HeavyDataOutsideTheFolderIsRefused) {
  TetMesh m;
  ReadReport r;
  {
    GridCopy g("xdmf-absolute", "xdmf_grid.h5:/data0", "/etc/passwd:/x");
    EXPECT_FAILS(read(g.xdmf, m, r), Status::Unsupported, "the data file '/etc/passwd' is an absolute path");
  }
  {
    GridCopy g("xdmf-up", "xdmf_grid.h5:/data0", "../xdmf_grid.h5:/data0");
    EXPECT_FAILS(read(g.xdmf, m, r), Status::Unsupported, "outside the XDMF file's folder");
  }
  {
    // Below the folder is fine.
    GridCopy g("xdmf-below");
    std::string xml = loadFile(g.xdmf);
    for (size_t at; (at = xml.find(">xdmf_grid.h5:")) != std::string::npos;) xml.replace(at, 1, ">sub/");
    ASSERT_TRUE(saveFile(g.xdmf, xml));
    fs::create_directories(g.dir.path + "/sub");
    fs::rename(g.dir.path + "/xdmf_grid.h5", g.dir.path + "/sub/xdmf_grid.h5");
    Result res = read(g.xdmf, m, r);
    EXPECT_TRUE(res) << res.message;
    EXPECT_EQ(m.tetCount(), 48u);
  }
}

// ------------------------------------------------------------------ hand-written XML
// A grid of two tets sharing the face (1, 2, 3), with XML data; `attributes` go into its grid.
std::string twoTets(const std::string& attributes, const std::string& topologyAttrs = "",
                    const std::string& topologyData = "0 1 2 3 4 1 3 2") {
  return R"(<?xml version="1.0"?>
<Xdmf Version="3.0"><Domain><Grid Name="g">
<Topology TopologyType="Tetrahedron" )" +
         topologyAttrs + R"(><DataItem Dimensions="2 4" DataType="Int" Format="XML">)" + topologyData +
         R"(</DataItem></Topology>
<Geometry GeometryType="XYZ"><DataItem Dimensions="5 3" Format="XML">0 0 0 1 0 0 0 1 0 0 0 1 1 1 1</DataItem></Geometry>
)" + attributes +
         "</Grid></Domain></Xdmf>";
}

Result readText(const std::string& xml, TetMesh& m, ReadReport& r, const std::string& name = "t.xdmf") {
  r = ReadReport{};
  return readMeshBytes(xml, name, m, r);
}

TEST(XdmfHostile, HugeDimensionsCyclesAndUnknownPaths) {
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(readText(twoTets(""), m, r)) << "the base case reads";
  EXPECT_FAILS(
      readText(
          twoTets(
              R"(<Attribute Name="f"><DataItem Dimensions="1000000000000" Format="XML">1 2 3</DataItem></Attribute>)"),
          m, r),
      Status::Truncated, "Attribute 'f'");
  EXPECT_FAILS(
      readText(
          twoTets(
              R"(<Attribute Name="f"><DataItem Dimensions="99999999999999999999" Format="XML">1</DataItem></Attribute>)"),
          m, r),
      Status::Corrupt, "Dimensions='99999999999999999999'");
  EXPECT_FAILS(
      readText(
          twoTets(
              R"(<Attribute Name="f"><DataItem Dimensions="1099511627775 1099511627775" Format="XML">1</DataItem></Attribute>)"),
          m, r),
      Status::TooLarge, "overflow");
  // A DataItem that refers to itself.
  EXPECT_FAILS(
      readText(
          twoTets(
              R"(<Attribute Name="f"><DataItem Name="me" Reference="XML">/Xdmf/Domain/Grid/Attribute/DataItem[@Name="me"]</DataItem></Attribute>)"),
          m, r),
      Status::Corrupt, "references nest more than 8 deep");
  // A grid that includes the grids, itself among them.
  const std::string selfInclude = R"x(<Xdmf Version="3.0" xmlns:xi="http://www.w3.org/2001/XInclude"><Domain>
<Grid Name="c" GridType="Collection"><xi:include xpointer="xpointer(//Grid)"/></Grid></Domain></Xdmf>)x";
  Result res = readText(selfInclude, m, r);
  EXPECT_FALSE(res);
  EXPECT_NE(res.message.find("t.xdmf"), std::string::npos) << res.message;
  // JOINs of JOINs, each level by reference to the next: refused by depth, not read 16^6 times.
  std::string nested;
  for (int level = 0; level < 6; ++level) {
    nested += "<DataItem Name=\"j" + std::to_string(level) + R"x(" ItemType="Function" Function="JOIN($0)">)x";
    nested += level < 5 ? "<DataItem Reference=\"/Xdmf/Domain/DataItem[@Name='j" + std::to_string(level + 1) + "']\"/>"
                        : std::string(R"(<DataItem Dimensions="5" Format="XML">1 2 3 4 5</DataItem>)");
    nested += "</DataItem>";
  }
  std::string join =
      twoTets(R"(<Attribute Name="f"><DataItem Reference="/Xdmf/Domain/DataItem[@Name='j0']"/></Attribute>)");
  join.insert(join.find("<Grid"), nested);
  EXPECT_FAILS(readText(join, m, r), Status::Corrupt, "DataItems nest more than 4 deep");
  // XPath outside the subset, another file, unknown formats.
  EXPECT_FAILS(
      readText(
          twoTets(
              R"(<Attribute Name="f"><DataItem Reference="XML">//DataItem[position() &lt; 3]</DataItem></Attribute>)"),
          m, r),
      Status::Unsupported, "predicate [position() < 3]");
  EXPECT_FAILS(
      readText(
          twoTets(
              R"x(<Attribute Name="f"><xi:include href="other.xmf" xpointer="xpointer(//DataItem)"/></Attribute>)x"),
          m, r),
      Status::Unsupported, "includes another file");
  EXPECT_FAILS(
      readText(
          twoTets(R"(<Attribute Name="f"><DataItem Dimensions="5" Format="NetCDF">x.nc:/f</DataItem></Attribute>)"), m,
          r),
      Status::Unsupported, "Format=\"NetCDF\"");
  EXPECT_FAILS(
      readText(
          twoTets(R"(<Attribute Name="f"><DataItem Dimensions="5" Format="XML">1 2 3 4 five</DataItem></Attribute>)"),
          m, r),
      Status::Corrupt, "value 4 'five' is not a number");
  EXPECT_FAILS(readText(twoTets("", "", "0 1 2 3 4 1 3 9"), m, r), Status::OutOfRange, "references vertex 9");
  EXPECT_FAILS(readText("<Xdmf><Domain><Grid", m, r), Status::Truncated, "malformed XML");
  EXPECT_FAILS(readText("<VTKFile/>", m, r, "t.xmf"), Status::BadMagic, "expected <Xdmf>");
  EXPECT_FAILS(readText(R"(<Xdmf Version="7.0"><Domain/></Xdmf>)", m, r), Status::UnsupportedVersion, "Version='7.0'");
}

TEST(XdmfReader, MixedCodesHyperSlabAndJoin) {
  // Mixed: a tet (code 6), a triangle (4), a polyline (2, with its node count) and a pyramid (7)
  // on the tet's face (1, 2, 3). Cell data stays aligned with the cells around the skipped ones.
  // x comes from a HyperSlab of a longer item, v from a JOIN of three.
  const std::string xml = R"x(<Xdmf Version="3.0"><Domain><Grid Name="m">
<Topology TopologyType="Mixed" NumberOfElements="4"><DataItem Dimensions="19" DataType="Int" Format="XML">
6 0 1 2 3   4 1 2 3   2 2 0 1   7 1 4 5 2 3</DataItem></Topology>
<Geometry GeometryType="X_Y_Z">
 <DataItem ItemType="HyperSlab" Dimensions="6"><DataItem Dimensions="3 1" Format="XML">0 1 6</DataItem>
   <DataItem Dimensions="8" Format="XML">0 1 0 0 2 2 9 9</DataItem></DataItem>
 <DataItem Dimensions="6" Format="XML">0 0 1 0 0 1</DataItem>
 <DataItem Dimensions="6" Format="XML">0 0 0 1 0 0</DataItem>
</Geometry>
<Attribute Name="v" AttributeType="Vector" Center="Node"><DataItem ItemType="Function" Function="JOIN($0, $1, $2)" Dimensions="6 3">
 <DataItem Dimensions="6" Format="XML">3 3 3 3 3 3</DataItem><DataItem Dimensions="6" Format="XML">4 4 4 4 4 4</DataItem>
 <DataItem Dimensions="6" Format="XML">0 0 0 0 0 0</DataItem></DataItem></Attribute>
<Attribute Name="c" Center="Cell"><DataItem Dimensions="4" Format="XML">10 20 30 40</DataItem></Attribute>
</Grid></Domain></Xdmf>)x";
  TetMesh m;
  ReadReport r;
  Result res = readText(xml, m, r);
  ASSERT_TRUE(res) << res.message;
  EXPECT_EQ(m.tetCount(), 3u) << allNotes(r);  // the tet, the pyramid as 2
  EXPECT_TRUE(hasNote(r, "skipped 1 cells of unsupported type XDMF Triangle")) << allNotes(r);
  EXPECT_TRUE(hasNote(r, "skipped 1 cells of unsupported type XDMF Polyline")) << allNotes(r);
  const int v = m.findField("v_magnitude");
  ASSERT_GE(v, 0);
  for (float x : m.fields[size_t(v)].values) EXPECT_FLOAT_EQ(x, 5.0f);
  // Vertex 0 is only in the tet (c = 10); vertex 5 only in the pyramid (c = 40).
  const int c = m.findField("c");
  ASSERT_GE(c, 0);
  EXPECT_FLOAT_EQ(m.fields[size_t(c)].values[size_t(findVertex(m, 0, 0, 0))], 10.0f);
  EXPECT_FLOAT_EQ(m.fields[size_t(c)].values[size_t(findVertex(m, 2, 1, 0))], 40.0f);
  EXPECT_NEAR(totalVolume(m), 1.0 / 6 + 1.5 / 3, 1e-6);  // the tet, and the pyramid of base 1.5, height 1
  const std::string badCode =
      R"(<Xdmf><Domain><Grid><Topology TopologyType="Mixed"><DataItem Dimensions="5" Format="XML">99 0 1 2 3</DataItem></Topology>
<Geometry><DataItem Dimensions="4 3" Format="XML">0 0 0 1 0 0 0 1 0 0 0 1</DataItem></Geometry></Grid></Domain></Xdmf>)";
  EXPECT_FAILS(readText(badCode, m, r), Status::Corrupt, "unknown cell type code 99");
  const std::string shortCell =
      R"(<Xdmf><Domain><Grid><Topology TopologyType="Mixed"><DataItem Dimensions="4" Format="XML">6 0 1 2</DataItem></Topology>
<Geometry><DataItem Dimensions="4 3" Format="XML">0 0 0 1 0 0 0 1 0 0 0 1</DataItem></Geometry></Grid></Domain></Xdmf>)";
  EXPECT_FAILS(readText(shortCell, m, r), Status::Truncated, "needs 4 more values for its nodes, 3 remain");
}

TEST(XdmfReader, DolfinxStyleFunctionsShareTheMesh) {
  // DOLFINx writes the mesh once and one temporal collection per function, each step including
  // the mesh's Topology and Geometry by an xpointer; both functions are read at the chosen step.
  auto step = [](const char* fn, int t, double value) {
    const std::string v = std::to_string(value);
    return std::string(R"(<Grid Name=")") + fn + R"x(" GridType="Uniform">
<xi:include xpointer="xpointer(/Xdmf/Domain/Grid[@GridType='Uniform'][1]/*[self::Topology or self::Geometry])"/>
<Time Value=")x" +
           std::to_string(t) + R"("/><Attribute Name=")" + fn +
           R"(" AttributeType="Scalar" Center="Node"><DataItem Dimensions="5 1" Format="XML">)" + v + " " + v + " " +
           v + " " + v + " " + v + "</DataItem></Attribute></Grid>";
  };
  const std::string xml = R"(<Xdmf Version="3.0" xmlns:xi="http://www.w3.org/2001/XInclude"><Domain>
<Grid Name="mesh" GridType="Uniform">
<Topology TopologyType="Tetrahedron" NumberOfElements="2" NodesPerElement="4"><DataItem Dimensions="2 4" NumberType="Int" Format="XML">0 1 2 3 4 1 3 2</DataItem></Topology>
<Geometry GeometryType="XYZ"><DataItem Dimensions="5 3" Format="XML">0 0 0 1 0 0 0 1 0 0 0 1 1 1 1</DataItem></Geometry></Grid>
<Grid Name="u" GridType="Collection" CollectionType="Temporal">)" +
                          step("u", 0, 1.0) + step("u", 1, 2.0) + R"(</Grid>
<Grid Name="p" GridType="Collection" CollectionType="Temporal">)" +
                          step("p", 0, 10.0) + step("p", 1, 20.0) + "</Grid></Domain></Xdmf>";
  TetMesh m;
  ReadReport r;
  Result res = readText(xml, m, r);
  ASSERT_TRUE(res) << res.message;
  ASSERT_EQ(r.steps.size(), 2u);
  const int u = m.findField("u"), p = m.findField("p");
  ASSERT_GE(u, 0) << allNotes(r);
  ASSERT_GE(p, 0) << allNotes(r);
  EXPECT_FLOAT_EQ(m.fields[size_t(u)].values[0], 2.0f);
  EXPECT_FLOAT_EQ(m.fields[size_t(p)].values[0], 20.0f);
  EXPECT_TRUE(hasNote(r, "read the time series 'u' with 1 more")) << allNotes(r);
}

TEST(XdmfReader, BinaryDataWithEndianAndSeek) {
  // Points as big-endian doubles after 16 bytes of something else, ids as little-endian Int32.
  ScratchDir dir("xdmf-binary");
  const double p[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
  std::string points(16, 'x');
  for (double v : p) {
    uint64_t bits;
    std::memcpy(&bits, &v, 8);
    for (int b = 7; b >= 0; --b) points += char(bits >> (8 * b));
  }
  std::string ids;
  for (int32_t v : {0, 1, 2, 3, 4, 1, 3, 2})
    for (int b = 0; b < 4; ++b) ids += char(uint32_t(v) >> (8 * b));
  ASSERT_TRUE(saveFile(dir.path + "/points.bin", points));
  ASSERT_TRUE(saveFile(dir.path + "/ids.bin", ids));
  auto xdmf = [&](const char* seek) {
    return std::string(R"(<Xdmf Version="2.0"><Domain><Grid Name="g">
<Topology TopologyType="Tetrahedron"><DataItem Dimensions="2 4" NumberType="Int" Precision="4" Endian="Little" Format="Binary">ids.bin</DataItem></Topology>
<Geometry GeometryType="XYZ"><DataItem Dimensions="5 3" Precision="8" Endian="Big" Seek=")") +
           seek + R"(" Format="Binary">points.bin</DataItem></Geometry></Grid></Domain></Xdmf>)";
  };
  ASSERT_TRUE(saveFile(dir.path + "/b.xmf", xdmf("16")));
  TetMesh m;
  ReadReport r;
  Result res = read(dir.path + "/b.xmf", m, r);
  ASSERT_TRUE(res) << res.message;
  EXPECT_EQ(m.tetCount(), 2u);
  ASSERT_EQ(m.positions.size(), 15u);
  for (int i = 0; i < 15; ++i) EXPECT_EQ(m.positions[size_t(i)], float(p[i]));
  EXPECT_NE(r.format.find("XDMF 2 (binary data)"), std::string::npos) << r.format;
  ASSERT_TRUE(saveFile(dir.path + "/b.xmf", xdmf("40")));
  EXPECT_FAILS(read(dir.path + "/b.xmf", m, r), Status::Truncated,
               "(points.bin): needs 120 bytes from byte 40, the file has 136");
}

TEST(XdmfReader, GridsOnTheSamePoints) {
  // DOLFINx's write_mesh + write_meshtags: the cell tags are a second grid of (some of) the
  // mesh's cells on the mesh's Geometry, the facet tags a grid of triangles. Neither adds cells.
  const std::string tags = R"x(<Xdmf Version="3.0" xmlns:xi="http://www.w3.org/2001/XInclude"><Domain>
<Grid Name="mesh" GridType="Uniform">
<Topology TopologyType="Tetrahedron" NumberOfElements="2" NodesPerElement="4"><DataItem Dimensions="2 4" NumberType="Int" Format="XML">0 1 2 3 4 1 3 2</DataItem></Topology>
<Geometry GeometryType="XYZ"><DataItem Dimensions="5 3" Format="XML">0 0 0 1 0 0 0 1 0 0 0 1 1 1 1</DataItem></Geometry>
<Attribute Name="f" Center="Node"><DataItem Dimensions="5" Format="XML">0 1 2 3 4</DataItem></Attribute></Grid>
<Grid Name="cell_tags" GridType="Uniform"><xi:include xpointer="xpointer(/Xdmf/Domain/Grid/Geometry)"/>
<Topology TopologyType="Tetrahedron" NumberOfElements="2" NodesPerElement="4"><DataItem Dimensions="2 4" NumberType="Int" Format="XML">3 2 1 0 2 3 1 4</DataItem></Topology>
<Attribute Name="cell_tags" Center="Cell"><DataItem Dimensions="2" Format="XML">7 8</DataItem></Attribute></Grid>
<Grid Name="facet_tags" GridType="Uniform"><xi:include xpointer="xpointer(/Xdmf/Domain/Grid/Geometry)"/>
<Topology TopologyType="Triangle" NumberOfElements="1" NodesPerElement="3"><DataItem Dimensions="1 3" NumberType="Int" Format="XML">0 1 2</DataItem></Topology>
<Attribute Name="facet_tags" Center="Cell"><DataItem Dimensions="1" Format="XML">3</DataItem></Attribute></Grid>
</Domain></Xdmf>)x";
  TetMesh m;
  ReadReport r;
  Result res = readText(tags, m, r);
  ASSERT_TRUE(res) << res.message;
  EXPECT_EQ(m.tetCount(), 2u) << allNotes(r);
  EXPECT_EQ(m.vertexCount(), 5u);
  EXPECT_GE(m.findField("f"), 0);
  EXPECT_TRUE(hasNote(r, "Grid 'cell_tags': 2 cells repeat cells of an earlier grid")) << allNotes(r);
  EXPECT_TRUE(hasNote(r, "Grid 'facet_tags': 1 Triangle cells")) << allNotes(r);
  expectValid(m, "mesh with tags");
  // On two processes the tags grid is not another process's share: every process reads both grids
  // (and keeps its share of the tets), so the repeated cells are still recognised.
  r = ReadReport{};
  ASSERT_TRUE(readXdmf(tags, "t.xdmf", std::nullopt, test::shareOf(1, 2), m, r));
  EXPECT_FALSE(r.shared);
  EXPECT_EQ(m.tetCount(), 2u) << allNotes(r);

  // Two blocks of different cells on one shared Geometry: both are read, on the same points.
  const std::string blocks = R"x(<Xdmf Version="2.0"><Domain>
<Geometry Name="points" GeometryType="XYZ"><DataItem Dimensions="5 3" Format="XML">0 0 0 1 0 0 0 1 0 0 0 1 1 1 1</DataItem></Geometry>
<Grid Name="a"><Topology TopologyType="Tetrahedron"><DataItem Dimensions="1 4" Format="XML" NumberType="Int">0 1 2 3</DataItem></Topology>
<Geometry Reference="/Xdmf/Domain/Geometry[1]"/><Attribute Name="mat" Center="Cell"><DataItem Dimensions="1" Format="XML">1</DataItem></Attribute></Grid>
<Grid Name="b"><Topology TopologyType="Tetrahedron"><DataItem Dimensions="1 4" Format="XML" NumberType="Int">4 1 3 2</DataItem></Topology>
<Geometry Reference="/Xdmf/Domain/Geometry[1]"/><Attribute Name="mat" Center="Cell"><DataItem Dimensions="1" Format="XML">2</DataItem></Attribute></Grid>
</Domain></Xdmf>)x";
  res = readText(blocks, m, r);
  ASSERT_TRUE(res) << res.message;
  EXPECT_EQ(m.tetCount(), 2u) << allNotes(r);
  EXPECT_EQ(m.vertexCount(), 5u);
  const int mat = m.findField("mat");
  ASSERT_GE(mat, 0) << allNotes(r);
  EXPECT_FLOAT_EQ(m.fields[size_t(mat)].values[size_t(findVertex(m, 0, 0, 0))], 1.0f);
  EXPECT_FLOAT_EQ(m.fields[size_t(mat)].values[size_t(findVertex(m, 1, 1, 1))], 2.0f);
  EXPECT_FALSE(hasNote(r, "merged")) << "the points are read once" << allNotes(r);
}

TEST(XdmfReader, LegacyDolfinFunctionThroughItsDofs) {
  // write_checkpoint's layout for two P1 tets (CG1) and for DG0: cell_dofs, vector, x_cell_dofs,
  // cells. The dofs are numbered apart from the vertices: dof of vertex v is 4 - v.
  auto function = [](const char* family, int degree, const std::string& cellDofs, const std::string& vector,
                     const std::string& starts, int nDofs, int nValues) {
    return std::string(R"(<Attribute ItemType="FiniteElementFunction" ElementFamily=")") + family +
           R"(" ElementDegree=")" + std::to_string(degree) + R"(" Name="u" Center="Other" AttributeType="Scalar">
<DataItem Dimensions=")" +
           std::to_string(nDofs) + R"( 1" NumberType="UInt" Format="XML">)" + cellDofs + R"(</DataItem>
<DataItem Dimensions=")" +
           std::to_string(nValues) + R"( 1" Format="XML">)" + vector + R"(</DataItem>
<DataItem Dimensions="3 1" NumberType="UInt" Format="XML">)" +
           starts + R"(</DataItem>
<DataItem Dimensions="2 1" NumberType="UInt" Format="XML">0 1</DataItem></Attribute>)";
  };
  TetMesh m;
  ReadReport r;
  // vertex v has value 100 + v; its dof is 4 - v, so vector[d] = 100 + 4 - d.
  Result res = readText(twoTets(function("CG", 1, "4 3 2 1 0 3 1 2", "104 103 102 101 100", "0 4 8", 8, 5)), m, r);
  ASSERT_TRUE(res) << res.message;
  const int u = m.findField("u");
  ASSERT_GE(u, 0) << allNotes(r);
  for (uint32_t v = 0; v < 5; ++v) EXPECT_FLOAT_EQ(m.fields[size_t(u)].values[v], 100.0f + float(v));
  EXPECT_TRUE(hasNote(r, "read finite element function 'u' (CG1) at the vertices")) << allNotes(r);

  // DG0: one value per cell, cell data at the points (vertex 0 only in cell 0, 4 only in cell 1).
  res = readText(twoTets(function("DG", 0, "1 0", "7 5", "0 1 2", 2, 2)), m, r);
  ASSERT_TRUE(res) << res.message;
  EXPECT_FLOAT_EQ(m.fields[size_t(m.findField("u"))].values[0], 5.0f);
  EXPECT_FLOAT_EQ(m.fields[size_t(m.findField("u"))].values[4], 7.0f);

  // A dof past the vector names the cell.
  EXPECT_FAILS(readText(twoTets(function("CG", 1, "4 3 2 1 0 3 1 9", "104 103 102 101 100", "0 4 8", 8, 5)), m, r),
               Status::OutOfRange, "cell_dofs of cell 1 names dof 9");
  EXPECT_FAILS(readText(twoTets(function("N1curl", 1, "4 3 2 1 0 3 1 2", "1 1 1 1 1", "0 4 8", 8, 5)), m, r),
               Status::Unsupported, "family 'N1curl'");
}

TEST(XdmfXmlPath, TheSubsetWritersUse) {
  pugi::xml_document doc;
  ASSERT_TRUE(doc.load_string(R"(<Xdmf><Domain>
<Grid Name="mesh" GridType="Uniform"><Topology/><Geometry/><Attribute/></Grid>
<Grid Name="f" GridType="Collection"><Grid Name="f0"><Topology Name="inner"/></Grid></Grid>
<DataItem Name="a"/><DataItem Name='b'/></Domain></Xdmf>)"));
  std::vector<pugi::xml_node> out;
  std::string error;
  ASSERT_TRUE(
      xmlpath::select(doc, "/Xdmf/Domain/Grid[@GridType='Uniform'][1]/*[self::Topology or self::Geometry]", out, error))
      << error;
  ASSERT_EQ(out.size(), 2u);
  EXPECT_STREQ(out[0].name(), "Topology");
  EXPECT_STREQ(out[1].name(), "Geometry");
  ASSERT_TRUE(xmlpath::select(doc, "//Grid[@Name=\"mesh\"]/*[self::Topology or self::Geometry]", out, error));
  EXPECT_EQ(out.size(), 2u);
  ASSERT_TRUE(xmlpath::select(doc, "//Topology", out, error));
  ASSERT_EQ(out.size(), 2u);  // in document order
  EXPECT_STREQ(out[1].attribute("Name").value(), "inner");
  ASSERT_TRUE(xmlpath::select(doc, "/Xdmf/Domain/DataItem[last()]", out, error));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_STREQ(out[0].attribute("Name").value(), "b");
  ASSERT_TRUE(xmlpath::select(doc, "/Xdmf/Domain/Grid[@Missing]", out, error));
  EXPECT_TRUE(out.empty());
  for (const char* bad : {"Xdmf/Domain", "/Xdmf/Domain/Grid[count(*) > 1]", "/Xdmf/ancestor::Grid", "/Xdmf[",
                          "/Xdmf/Domain/Grid[@Name=mesh]", "/Xdmf/Domain/Grid[0]"})
    EXPECT_FALSE(xmlpath::select(doc, bad, out, error)) << bad;
}

// ------------------------------------------------------------------ VTKHDF made hostile with HDF5 itself
// A minimal VTKHDF file written through the HDF5 C API: one partition, `types` and `conn`.
struct VtkHdfWriter {
  hid_t file;
  hid_t root;
  explicit VtkHdfWriter(const std::string& path, const char* type = "UnstructuredGrid") {
    file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    root = H5Gcreate2(file, "VTKHDF", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    hid_t str = H5Tcopy(H5T_C_S1);
    H5Tset_size(str, std::strlen(type));
    hid_t space = H5Screate(H5S_SCALAR);
    hid_t a = H5Acreate2(root, "Type", str, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, str, type);
    H5Aclose(a);
    H5Sclose(space);
    H5Tclose(str);
  }
  void ints(const char* name, const std::vector<int64_t>& v) {
    const hsize_t n = v.size();
    hid_t space = H5Screate_simple(1, &n, nullptr);
    hid_t d = H5Dcreate2(root, name, H5T_STD_I64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dwrite(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
    H5Dclose(d);
    H5Sclose(space);
  }
  // Points in the file, or (`externalFile`) kept in a raw file elsewhere (HDF5 external storage).
  void points(const std::vector<double>& p, const char* externalFile = nullptr) {
    const hsize_t dims[2] = {p.size() / 3, 3};
    hid_t space = H5Screate_simple(2, dims, nullptr);
    hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    if (externalFile) H5Pset_external(dcpl, externalFile, 0, hsize_t(p.size() * 8));
    hid_t d = H5Dcreate2(root, "Points", H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    if (!externalFile) H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, p.data());
    H5Pclose(dcpl);
    H5Dclose(d);
    H5Sclose(space);
  }
  ~VtkHdfWriter() {
    H5Gclose(root);
    H5Fclose(file);
  }
};

enum class PointsAt { Here, ExternalStorage, ExternalLink };

void writeTwoTets(const std::string& path, std::vector<int64_t> counts, std::vector<int64_t> conn,
                  const char* type = "UnstructuredGrid", PointsAt at = PointsAt::Here) {
  VtkHdfWriter w(path, type);
  w.ints("NumberOfPoints", {counts[0]});
  w.ints("NumberOfCells", {counts[1]});
  w.ints("NumberOfConnectivityIds", {counts[2]});
  if (at == PointsAt::ExternalLink)
    H5Lcreate_external("other.h5", "/VTKHDF/Points", w.root, "Points", H5P_DEFAULT, H5P_DEFAULT);
  else
    w.points({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1},
             at == PointsAt::ExternalStorage ? "/etc/hostname" : nullptr);
  w.ints("Types", {10, 10});
  w.ints("Offsets", {0, 4, 8});
  w.ints("Connectivity", conn);
}

TEST(VtkHdfDamaged, CountsIdsAndTypesAreChecked) {
  ScratchDir dir("vtkhdf-hostile");
  const std::string ok = dir.path + "/ok.vtkhdf";
  writeTwoTets(ok, {5, 2, 8}, {0, 1, 2, 3, 4, 1, 3, 2});
  TetMesh m;
  ReadReport r;
  Result res = read(ok, m, r);
  ASSERT_TRUE(res) << res.message;
  EXPECT_EQ(m.tetCount(), 2u);

  const std::string many = dir.path + "/many.vtkhdf";
  writeTwoTets(many, {5000000000, 2, 8}, {0, 1, 2, 3, 4, 1, 3, 2});
  EXPECT_FAILS(read(many, m, r), Status::TooLarge, "5000000000 points");

  const std::string rows = dir.path + "/rows.vtkhdf";
  writeTwoTets(rows, {50, 2, 8}, {0, 1, 2, 3, 4, 1, 3, 2});
  EXPECT_FAILS(read(rows, m, r), Status::Truncated, "dataset '/VTKHDF/Points' has 5 rows; rows 0..50 are needed");

  const std::string id = dir.path + "/id.vtkhdf";
  writeTwoTets(id, {5, 2, 8}, {0, 1, 2, 3, 4, 1, 3, 7});
  EXPECT_FAILS(read(id, m, r), Status::OutOfRange, "references vertex 7");

  const std::string negative = dir.path + "/negative.vtkhdf";
  writeTwoTets(negative, {5, -2, 8}, {0, 1, 2, 3, 4, 1, 3, 2});
  EXPECT_FAILS(read(negative, m, r), Status::Corrupt, "NumberOfCells': partition 0 has -2");

  const std::string image = dir.path + "/image.vtkhdf";
  writeTwoTets(image, {5, 2, 8}, {0, 1, 2, 3, 4, 1, 3, 2}, "ImageData");
  EXPECT_FAILS(read(image, m, r), Status::Unsupported, "VTKHDF Type 'ImageData' is not read");

  // Data in other files is not followed: an external link, raw external storage.
  const std::string link = dir.path + "/link.vtkhdf";
  writeTwoTets(link, {5, 2, 8}, {0, 1, 2, 3, 4, 1, 3, 2}, "UnstructuredGrid", PointsAt::ExternalLink);
  EXPECT_FAILS(read(link, m, r), Status::Unsupported, "'/VTKHDF/Points' is a link into another file");
  const std::string external = dir.path + "/external.vtkhdf";
  writeTwoTets(external, {5, 2, 8}, {0, 1, 2, 3, 4, 1, 3, 2}, "UnstructuredGrid", PointsAt::ExternalStorage);
  EXPECT_FAILS(read(external, m, r), Status::Unsupported, "keeps its data in other files");

  // Cut in half: the library refuses it, and the message says so and names the file.
  const std::string whole = loadFile(hpcPath("vtkhdf_parts.vtkhdf"));
  const std::string cut = dir.path + "/cut.vtkhdf";
  ASSERT_TRUE(saveFile(cut, whole.substr(0, whole.size() / 2)));
  EXPECT_FAILS(read(cut, m, r), Status::Truncated, "cut.vtkhdf");
}

}  // namespace
}  // namespace tetstream
