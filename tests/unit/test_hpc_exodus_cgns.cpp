// The Exodus II and CGNS readers (exodus_reader.cpp, cgns_reader.cpp) against files other tools
// wrote (tests/fixtures/make_hpc_fixtures_exodus_cgns.py: VTK's vtkExodusIIWriter, meshio,
// CGNS's tecplot_to_cgns, plot3d_to_cgns, convert_location, adf2hdf/hdf2adf, and the CGNS
// library itself), checked against what those tools were given (expected_exodus_cgns.json):
// counts, volume, boundary area (a seam between blocks or zones leaves inner faces on the
// boundary and adds area), field values, the point values of converted cell data, time steps;
// then damaged copies (truncated, bytes changed) must give a Result naming the file.
#include <cgnslib.h>
#include <exodusII.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <netcdf.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

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
using test::saveFile;
using test::ScratchDir;
using test::totalVolume;

std::string hpcPath(const std::string& name) { return fixturePath("hpc/" + name); }

const nlohmann::json& expected() { return test::fixtureJson("hpc/expected_exodus_cgns.json"); }

const std::vector<float>& field(const TetMesh& m, const std::string& name) {
  static const std::vector<float> none;
  const int f = m.findField(name);
  EXPECT_GE(f, 0) << "no field " << name;
  return f >= 0 ? m.fields[size_t(f)].values : none;
}

// Every vertex's value of `name` against fn(x, y, z).
template <class F>
void expectFieldIs(const TetMesh& m, const std::string& name, F&& fn, double tolerance, const std::string& what) {
  const std::vector<float>& values = field(m, name);
  ASSERT_EQ(values.size(), m.vertexCount()) << what << " " << name;
  for (uint32_t v = 0; v < m.vertexCount(); ++v) {
    const double x = m.positions[3 * v], y = m.positions[3 * v + 1], z = m.positions[3 * v + 2];
    ASSERT_NEAR(values[v], fn(x, y, z), tolerance)
        << what << " " << name << " at (" << x << ", " << y << ", " << z << ")";
  }
}

// Rows (x, y, z, value) of expected_exodus_cgns.json: the point values the cell data must become.
void expectRows(const TetMesh& m, const std::string& name, const nlohmann::json& rows, const std::string& what) {
  const std::vector<float>& values = field(m, name);
  ASSERT_FALSE(rows.empty()) << what;
  for (const auto& row : rows) {
    const int64_t v = findVertex(m, row[0], row[1], row[2]);
    ASSERT_GE(v, 0) << what << " vertex at " << row;
    EXPECT_NEAR(values[size_t(v)], row[3].get<double>(), 1e-5) << what << " " << name << " at " << row;
  }
}

Result read(const std::string& file, TetMesh& m, ReadReport& r, ReadOptions o = {}) {
  r = {};
  return readMesh(hpcPath(file), m, r, o);
}

ReadOptions atStep(uint64_t k) {
  ReadOptions o;
  o.step = k;
  return o;
}

// ------------------------------------------------------------------ every readable fixture
class ExodusCgnsFixture : public testing::TestWithParam<std::string> {};

TEST_P(ExodusCgnsFixture, CountsVolumeAndNoSeam) {
  const std::string file = GetParam();
  const nlohmann::json& e = expected()[file];
  TetMesh m;
  ReadReport r;
  Result res = read(file, m, r);
  ASSERT_TRUE(res) << statusName(res.status) << ": " << res.message;
  EXPECT_EQ(m.vertexCount(), e["vertices"].get<uint32_t>()) << file << allNotes(r);
  EXPECT_EQ(m.tetCount(), e["tets"].get<uint32_t>()) << file << allNotes(r);
  EXPECT_NEAR(totalVolume(m), e["volume"].get<double>(), 1e-6 * e["volume"].get<double>()) << file;
  EXPECT_NEAR(boundaryArea(m), e["area"].get<double>(), 1e-5) << file;
  expectValid(m, file);
  if (e.contains("container")) {
    EXPECT_NE(r.format.find("CGNS (" + e["container"].get<std::string>() + ")"), std::string::npos) << r.format;
    EXPECT_NE(r.format.find(", " + std::to_string(e["zones"].get<int>()) + " "), std::string::npos) << r.format;
  }
}

std::vector<std::string> readableFixtures() {
  std::vector<std::string> files;
  for (const auto& [name, value] : expected().items())
    if (value.contains("tets")) files.push_back(name);
  return files;
}

std::string fileCaseName(const testing::TestParamInfo<std::string>& info) {
  std::string n = info.param;
  for (char& c : n)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return n;
}

INSTANTIATE_TEST_SUITE_P(ExodusCgnsFiles, ExodusCgnsFixture, testing::ValuesIn(readableFixtures()), fileCaseName);

TEST(ExodusCgnsFixtureList, EveryFileIsInExpected) {
  ASSERT_FALSE(expected().is_discarded()) << "expected_exodus_cgns.json does not parse";
  size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(fixturePath("hpc"))) {
    const std::string name = entry.path().filename().string();
    if (!name.starts_with("exo_") && !name.starts_with("cgns_")) continue;
    ++files;
    EXPECT_TRUE(expected().contains(name)) << name << " is in tests/fixtures/hpc but not in expected_exodus_cgns.json";
  }
  EXPECT_EQ(files, expected().size());
  EXPECT_GE(readableFixtures().size(), 7u);
}

// ------------------------------------------------------------------ Exodus II
TEST(ExodusBlocks, BlocksStepsAndWhatWasSkipped) {
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(read("exo_blocks.exo", m, r));
  EXPECT_NE(r.format.find("Exodus II (netCDF 64-bit offset), 6 element blocks (5 of volume cells)"), std::string::npos)
      << r.format;
  EXPECT_NE(r.format.find("step 2 of 3"), std::string::npos) << r.format;
  ASSERT_EQ(r.steps.size(), 3u);
  EXPECT_EQ(r.steps[1].time, 0.5);
  EXPECT_EQ(r.stepRead, 2u);  // the last by default, with a note
  EXPECT_TRUE(hasNote(r, "has 3 time steps")) << allNotes(r);
  EXPECT_TRUE(hasNote(r, "reduced 96 Exodus TETRA (10 nodes) cells to their 4 corner vertices")) << allNotes(r);
  EXPECT_TRUE(hasNote(r, "skipped 64 cells of unsupported type Exodus TRIANGLE")) << allNotes(r);
  ASSERT_EQ(r.skippedCells.size(), 1u);
  EXPECT_EQ(r.skippedCells[0].vtkType, 5);
  EXPECT_EQ(r.skippedCells[0].count, 64u);
  EXPECT_TRUE(hasNote(r, "193 only higher-order nodes or nodes of skipped cells")) << allNotes(r);
  EXPECT_TRUE(hasNote(r, "added 'velocity_magnitude'")) << allNotes(r);
}

TEST(ExodusBlocks, NodalAndElementVariablesOfEachStep) {
  const nlohmann::json& e = expected()["exo_blocks.exo"];
  for (uint64_t step = 0; step < 3; ++step) {
    TetMesh m;
    ReadReport r;
    ASSERT_TRUE(read("exo_blocks.exo", m, r, atStep(step)));
    const double t = e["times"][step].get<double>();
    EXPECT_EQ(r.stepRead, step);
    const std::string what = "step " + std::to_string(step);
    expectFieldIs(
        m, "temperature", [&](double x, double y, double z) { return x + 2 * y + 3 * z + 10 * t; }, 1e-5, what);
    // Components stay fields under their own names; the vector also gives its magnitude.
    expectFieldIs(
        m, "velocityX", [&](double, double y, double) { return y * (1 + t); }, 1e-6, what);
    expectFieldIs(
        m, "velocityY", [&](double x, double, double) { return -x * (1 + t); }, 1e-6, what);
    expectFieldIs(
        m, "velocityZ", [&](double, double, double z) { return z * (1 + t); }, 1e-6, what);
    expectFieldIs(
        m, "velocity_magnitude",
        [&](double x, double y, double z) { return std::sqrt(x * x + y * y + z * z) * (1 + t); }, 1e-5, what);
    expectRows(m, "pressure", e["pressure_step" + std::to_string(step)], what);
    EXPECT_TRUE(hasNote(r, "converted cell data 'pressure'")) << allNotes(r);
  }
}

TEST(ExodusBlocks, TimePicksTheNearestStep) {
  TetMesh m;
  ReadReport r;
  ReadOptions o;
  o.time = 0.4;
  ASSERT_TRUE(read("exo_blocks.exo", m, r, o));
  EXPECT_EQ(r.stepRead, 1u);
  EXPECT_TRUE(hasNote(r, "no step at t = 0.4; read the nearest, step 1 (t = 0.5)")) << allNotes(r);
  expectFieldIs(
      m, "temperature", [](double x, double y, double z) { return x + 2 * y + 3 * z + 5; }, 1e-5, "t=0.4");

  EXPECT_FAILS(read("exo_blocks.exo", m, r, atStep(3)), Status::BadArgument, "--step 3 does not exist");
  EXPECT_EQ(m.vertexCount(), 0u);
}

TEST(ExodusMeshio, NetcdfFourFileWithItsNodalVariable) {
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(read("exo_meshio.exo", m, r));
  EXPECT_NE(r.format.find("Exodus II (netCDF-4), 5 element blocks (4 of volume cells)"), std::string::npos) << r.format;
  expectFieldIs(
      m, "f", [](double x, double y, double z) { return x + 2 * y + 3 * z; }, 1e-6, "meshio");
  EXPECT_TRUE(hasNote(r, "through netCDF")) << allNotes(r);
  EXPECT_TRUE(hasNote(r, "skipped 2 cells of unsupported type Exodus TRI3")) << allNotes(r);
  // One step (t = 0): listed, and --step 0 is that state.
  ASSERT_EQ(r.steps.size(), 1u);
  EXPECT_TRUE(read("exo_meshio.exo", m, r, atStep(0)));
}

TEST(ExodusErrors, UnsupportedElementTypeIsNamedWithItsCount) {
  TetMesh m;
  ReadReport r;
  EXPECT_FAILS(read("exo_unsupported.exo", m, r), Status::NoTets, "found 32 Exodus CONVEX");
  EXPECT_EQ(m.vertexCount(), 0u);
}

TEST(ExodusErrors, MissingVariableIsNamed) {
  TetMesh m;
  ReadReport r;
  const Result res = read("exo_missing_var.exo", m, r);
  EXPECT_EQ(res.status, Status::Corrupt) << res.message;
  EXPECT_NE(res.message.find("exo_missing_var.exo: nodal variable 'g' at step 0"), std::string::npos) << res.message;
  EXPECT_EQ(m.tetCount(), 0u);
}

TEST(ExodusErrors, NotAContainerAndBytesInMemory) {
  ScratchDir dir("exodus-errors");
  const std::string junk = dir.path + "/junk.exo";
  ASSERT_TRUE(saveFile(junk, std::string(200, 'x')));
  TetMesh m;
  ReadReport r;
  EXPECT_FAILS(readMesh(junk, m, r), Status::BadMagic, "junk.exo: not an Exodus II file");
  ASSERT_TRUE(saveFile(junk, ""));
  EXPECT_FAILS(readMesh(junk, m, r), Status::BadMagic, "the file is empty");
  // The library reads files, not memory.
  const std::string bytes = loadFile(hpcPath("exo_blocks.exo"));
  EXPECT_FAILS(readMeshBytes(bytes, "run.exo", m, r), Status::Unsupported, "read it by path");
  EXPECT_FAILS(readMeshBytes(bytes, "run.bin", m, r), Status::Unsupported, "netCDF 64-bit offset container");
}

// A copy of `file` cut at several lengths and with bytes changed must read cleanly or fail with
// a Result naming the copy (never crash, never hang). Cut copies must fail.
void damagedCopies(const std::string& file, const std::string& ext, bool& anyFailed) {
  ScratchDir dir("hpc-damaged-" + ext);
  const std::string bytes = loadFile(hpcPath(file));
  ASSERT_GT(bytes.size(), 1000u);
  const std::string copy = dir.path + "/damaged." + ext;
  for (size_t cut : {size_t(0), size_t(3), size_t(100), bytes.size() / 10, bytes.size() / 3, bytes.size() / 2,
                     bytes.size() - bytes.size() / 10}) {
    ASSERT_TRUE(saveFile(copy, bytes.substr(0, cut)));
    TetMesh m;
    ReadReport r;
    const Result res = readMesh(copy, m, r);
    EXPECT_FALSE(res) << file << " cut at " << cut << " of " << bytes.size() << " read without complaint";
    EXPECT_NE(res.message.find(copy), std::string::npos) << res.message;
    anyFailed |= !res;
  }
  uint32_t state = 12345;
  for (int trial = 0; trial < 12; ++trial) {
    std::string changed = bytes;
    for (int k = 0; k < 1 + trial * 3; ++k) {
      state = state * 1664525u + 1013904223u;
      // Half the changes in the first 4 KB, where headers and B-tree roots are.
      const size_t at = (k % 2 ? state % std::min<size_t>(4096, bytes.size()) : state % bytes.size());
      changed[at] = char(state >> 24);
    }
    ASSERT_TRUE(saveFile(copy, changed));
    // Read whole, and as one process's share of three (a window of each zone, or a slab).
    for (const ReadOptions& o : {ReadOptions{}, test::shareOf(1, 3)}) {
      TetMesh m;
      ReadReport r;
      const Result res = readMesh(copy, m, r, o);
      if (!res) {
        EXPECT_NE(res.message.find(copy), std::string::npos) << res.message;
      }
    }
  }
}

TEST(ExodusErrors, TruncatedOrChangedCopiesGiveResults) {
  bool failed = false;
  damagedCopies("exo_blocks.exo", "exo", failed);  // netCDF classic
  damagedCopies("exo_meshio.exo", "e", failed);    // netCDF-4 (HDF5)
  EXPECT_TRUE(failed);
}

// Attributes the Exodus library copies into fixed fields without a bound (an element type name
// into 33 bytes, api_version into one float) are checked through netCDF before it reads them.
TEST(ExodusErrors, AttributesTooLongForTheLibraryAreRefused) {
  ScratchDir dir("exodus-attributes");
  const std::string copy = dir.path + "/long.exo";
  auto edit = [&](auto&& change) {
    ASSERT_TRUE(saveFile(copy, loadFile(hpcPath("exo_blocks.exo"))));
    int nc = -1, var = -1;
    ASSERT_EQ(nc_open(copy.c_str(), NC_WRITE, &nc), NC_NOERR);
    ASSERT_EQ(nc_redef(nc), NC_NOERR);
    ASSERT_EQ(nc_inq_varid(nc, "connect2", &var), NC_NOERR);
    change(nc, var);
    ASSERT_EQ(nc_close(nc), NC_NOERR);
  };
  TetMesh m;
  ReadReport r;
  edit([](int nc, int var) {
    const std::string name = "WEDGE" + std::string(195, 'X');
    ASSERT_EQ(nc_put_att_text(nc, var, "elem_type", name.size(), name.data()), NC_NOERR);
  });
  EXPECT_FAILS(readMesh(copy, m, r), Status::Corrupt, "element block 2 (connect2) has an element type name of 200");
  edit([](int nc, int) {
    const float versions[4] = {7, 7, 7, 7};
    ASSERT_EQ(nc_put_att_float(nc, NC_GLOBAL, "api_version", NC_FLOAT, 4, versions), NC_NOERR);
  });
  EXPECT_FAILS(readMesh(copy, m, r), Status::Corrupt, "the global attribute api_version holds 4 values");
}

// Exodus numbers nodes and elements 1.. inside the file; users know them by the number maps' ids,
// which the messages give too (exo_blocks.exo: node k has id 999 + 2k, element k 4998 + 3k).
TEST(ExodusErrors, MessagesNameNodesAndElementsByTheirIds) {
  ScratchDir dir("exodus-ids");
  const std::string copy = dir.path + "/ids.exo";
  auto edit = [&](const char* var, std::vector<size_t> index, double value) {
    ASSERT_TRUE(saveFile(copy, loadFile(hpcPath("exo_blocks.exo"))));
    int nc = -1, id = -1;
    ASSERT_EQ(nc_open(copy.c_str(), NC_WRITE, &nc), NC_NOERR);
    ASSERT_EQ(nc_inq_varid(nc, var, &id), NC_NOERR);
    ASSERT_EQ(nc_put_var1_double(nc, id, index.data(), &value), NC_NOERR);
    ASSERT_EQ(nc_close(nc), NC_NOERR);
  };
  TetMesh m;
  ReadReport r;
  edit("connect2", {1, 1}, 9999);  // block 20 (WEDGE): element 2's second node
  EXPECT_FAILS(readMesh(copy, m, r), Status::OutOfRange,
               "element block 20 (wedge) element 2 (id 5100) uses node 9999, but the nodes are numbered 1..450");
  edit("coordy", {4}, std::nan(""));
  EXPECT_FAILS(readMesh(copy, m, r), Status::NonFinite, "node 5 (id 1009) has a non-finite coordinate");
}

// damaged_hdf5_wild_free.exo: a netCDF-4 file with bytes changed on which HDF5 1.10.8 frees a
// wild pointer while netCDF opens it (AddressSanitizer stops there; plain builds may go on or
// crash). The open is tried in a child process first: either way the read is a Result.
TEST(ExodusErrors, FileThatMakesHdf5FreeAWildPointerIsAResult) {
  TetMesh m;
  ReadReport r;
  const std::string file = hpcPath("damaged_hdf5_wild_free.exo");
  const Result res = readMesh(file, m, r);
  EXPECT_EQ(res.status, Status::Corrupt) << res.message;
  EXPECT_NE(res.message.find(file + ": "), std::string::npos) << res.message;
}

TEST(ExodusCgnsProbe, ACrashStaysInTheChildProcess) {
  EXPECT_EQ(vtkio::runInChildProcess([] { return 7; }), 7);
  EXPECT_EQ(vtkio::runInChildProcess([] {
              std::raise(SIGSEGV);
              return 0;
            }),
            -1);
  EXPECT_EQ(vtkio::runInChildProcess([] {
              std::abort();
              return 0;
            }),
            -1);
}

// A 2D mesh (num_dim 2: a block of quadrilaterals, as 2D solvers write) has no volume cells.
TEST(ExodusErrors, TwoDimensionalMeshIsSaidSo) {
  ScratchDir dir("exodus-2d");
  const std::string file = dir.path + "/plate.exo";
  int cpu = 8, io = 8;
  const int id = ex_create(file.c_str(), EX_CLOBBER, &cpu, &io);
  ASSERT_GE(id, 0);
  const double x[4] = {0, 1, 1, 0}, y[4] = {0, 0, 1, 1};
  const int conn[4] = {1, 2, 3, 4};
  ASSERT_EQ(ex_put_init(id, "plate", 2, 4, 1, 1, 0, 0), 0);
  ASSERT_EQ(ex_put_coord(id, x, y, nullptr), 0);
  ASSERT_EQ(ex_put_block(id, EX_ELEM_BLOCK, 1, "QUAD4", 1, 4, 0, 0, 0), 0);
  ASSERT_EQ(ex_put_conn(id, EX_ELEM_BLOCK, 1, conn, nullptr, nullptr), 0);
  ASSERT_EQ(ex_close(id), 0);
  TetMesh m;
  ReadReport r;
  EXPECT_FAILS(readMesh(file, m, r), Status::NoTets, "plate.exo: a 2D Exodus II mesh (num_dim 2): no volume cells");
}

TEST(ExodusNetcdfHeader, CountsAreCheckedAgainstTheFile) {
  const std::string bytes = loadFile(hpcPath("exo_blocks.exo"));
  ASSERT_TRUE(bytes.starts_with(std::string("CDF\x02", 4)));
  const auto whole = vtkio::checkNetcdfClassicHeader(bytes, bytes.size(), "a.exo");
  EXPECT_TRUE(whole.result) << whole.result.message;
  EXPECT_FALSE(whole.needMore);
  // A header longer than what was given asks for more; a file that ends inside it is truncated.
  EXPECT_TRUE(vtkio::checkNetcdfClassicHeader(bytes.substr(0, 64), bytes.size(), "a.exo").needMore);
  EXPECT_EQ(vtkio::checkNetcdfClassicHeader(bytes.substr(0, 64), 64, "a.exo").result.status, Status::Truncated);
  // The data cut short: the variables' extents are past the end.
  const std::string cut = bytes.substr(0, bytes.size() - 100);
  const auto shortFile = vtkio::checkNetcdfClassicHeader(cut, cut.size(), "a.exo");
  EXPECT_EQ(shortFile.result.status, Status::Truncated) << shortFile.result.message;
  EXPECT_NE(shortFile.result.message.find("a.exo: "), std::string::npos);
  // A dimension count no file of this size can hold (bytes 8..15: NC_DIMENSION, count).
  std::string huge = bytes;
  huge[12] = '\x7f';
  const auto counted = vtkio::checkNetcdfClassicHeader(huge, huge.size(), "a.exo");
  EXPECT_EQ(counted.result.status, Status::Truncated) << counted.result.message;
  EXPECT_NE(counted.result.message.find("dimensions"), std::string::npos) << counted.result.message;
}

// ------------------------------------------------------------------ CGNS
class CgnsContainers : public testing::TestWithParam<const char*> {};

TEST_P(CgnsContainers, UnstructuredZonesTetraAndMixed) {
  const std::string file = std::string("cgns_unstructured") + GetParam();
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(read(file, m, r));
  EXPECT_NE(r.format.find("2 unstructured zones"), std::string::npos) << r.format;
  expectFieldIs(
      m, "T", [](double x, double y, double z) { return x + 2 * y + 3 * z; }, 1e-5, file);
  // CellCenter values (named T_cell beside the Vertex T) become volume-weighted point data.
  expectRows(m, "T_cell", expected()[file]["T_cell"], file);
  EXPECT_TRUE(hasNote(r, "merged 9 duplicate vertices")) << allNotes(r);
  EXPECT_TRUE(hasNote(r, "split 4 hexahedra, 4 wedges, 12 pyramids into 60 tetrahedra")) << allNotes(r);
  // tecplot_to_cgns (CGNS 3.4.0) writes a wrong ElementStartOffset; the type codes are read.
  EXPECT_TRUE(hasNote(r, "ElementStartOffset disagrees with the element types")) << allNotes(r);
}

TEST_P(CgnsContainers, StructuredZonesVertexAndCellCenter) {
  const std::string file = std::string("cgns_structured") + GetParam();
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(read(file, m, r));
  EXPECT_NE(r.format.find("2 structured zones"), std::string::npos) << r.format;
  expectFieldIs(
      m, "Density", [](double x, double, double) { return 1 + 0.1 * x; }, 1e-5, file);
  expectFieldIs(
      m, "MomentumY", [](double, double y, double) { return 0.25 * y; }, 1e-6, file);
  expectFieldIs(
      m, "Momentum_magnitude",
      [](double x, double y, double z) { return std::sqrt(0.25 * x * x + 0.0625 * y * y + 0.25 * z * z); }, 1e-5, file);
  expectRows(m, "Density_cell", expected()[file]["Density_cell"], file);
  EXPECT_TRUE(hasNote(r, "merged 12 duplicate vertices")) << allNotes(r);
  // One state: no steps to choose from.
  EXPECT_TRUE(r.steps.empty());
  EXPECT_FAILS(read(file, m, r, atStep(0)), Status::BadArgument, "holds no time steps");
}

INSTANTIATE_TEST_SUITE_P(CgnsAdfAndHdf5, CgnsContainers, testing::Values(".cgns", ".adf.cgns"),
                         [](const testing::TestParamInfo<const char*>& i) {
                           return std::string(i.param) == ".cgns" ? "Hdf5" : "Adf";
                         });

TEST(CgnsSteps, EachStepReadsTheSolutionItsPointerNames) {
  for (uint64_t step = 0; step < 3; ++step) {
    TetMesh m;
    ReadReport r;
    ASSERT_TRUE(read("cgns_steps.cgns", m, r, atStep(step)));
    const double t = 0.5 * double(step);
    expectFieldIs(
        m, "T", [&](double x, double y, double z) { return x + 2 * y + 3 * z + 10 * t; }, 1e-5,
        "step " + std::to_string(step));
    ASSERT_EQ(r.steps.size(), 3u);
    EXPECT_EQ(r.steps[step].time, t);
    EXPECT_TRUE(hasNote(r, "read base 'Volume'; not read: 'Surface' (2D cells)")) << allNotes(r);
    EXPECT_TRUE(hasNote(r, "skipped 8 cells of unsupported type CGNS TRI_3")) << allNotes(r);
  }
  TetMesh m;
  ReadReport r;
  ReadOptions o;
  o.time = 0.6;
  ASSERT_TRUE(read("cgns_steps.cgns", m, r, o));
  EXPECT_EQ(r.stepRead, 1u);
  EXPECT_NE(r.format.find("step 1 of 3"), std::string::npos) << r.format;
  ASSERT_TRUE(read("cgns_steps.cgns", m, r));
  EXPECT_EQ(r.stepRead, 2u);
}

TEST(CgnsErrors, PolyhedraAreRefusedByName) {
  TetMesh m;
  ReadReport r;
  EXPECT_FAILS(read("cgns_polyhedra.cgns", m, r), Status::Unsupported, "section 'Cells': 1 NFACE_n cells");
}

TEST(CgnsErrors, TruncatedOrChangedCopiesGiveResults) {
  bool failed = false;
  damagedCopies("cgns_structured.adf.cgns", "cgns", failed);    // ADF
  damagedCopies("cgns_unstructured.cgns", "hdf.cgns", failed);  // HDF5
  EXPECT_TRUE(failed);
}

TEST(CgnsErrors, BytesInMemoryAreReadByPath) {
  TetMesh m;
  ReadReport r;
  const std::string bytes = loadFile(hpcPath("cgns_structured.adf.cgns"));
  EXPECT_FAILS(readMeshBytes(bytes, "flow.cgns", m, r), Status::Unsupported, "read it by path");
  EXPECT_FAILS(readMeshBytes(bytes, "flow", m, r), Status::Unsupported, "ADF container");
}

// ------------------------------------------------------------------ recognised by content
TEST(ExodusSniff, ContentDecidesWhenTheExtensionDoesNot) {
  ScratchDir dir("hpc-sniff");
  struct Case {
    const char* from;
    const char* to;
    const char* format;
  };
  // ".g" is a Genesis (Exodus) mesh or a PLOT3D grid; ".e-s0001" a restart file; ".dat" anything.
  for (const Case& c : {Case{"exo_blocks.exo", "mesh.g", "Exodus II (netCDF 64-bit offset)"},
                        Case{"exo_meshio.exo", "run.e-s0001", "Exodus II (netCDF-4)"},
                        Case{"cgns_structured.adf.cgns", "flow.dat", "CGNS (ADF)"},
                        Case{"cgns_unstructured.cgns", "flow.bin", "CGNS (HDF5)"}}) {
    const std::string to = dir.path + "/" + c.to;
    ASSERT_TRUE(saveFile(to, loadFile(hpcPath(c.from))));
    TetMesh m;
    ReadReport r;
    Result res = readMesh(to, m, r);
    ASSERT_TRUE(res) << c.to << ": " << res.message;
    EXPECT_NE(r.format.find(c.format), std::string::npos) << c.to << ": " << r.format;
  }
  // A damaged netCDF header is checked before netCDF reads it, also when only content tells.
  std::string damaged = loadFile(hpcPath("exo_blocks.exo"));
  damaged[12] = '\x7f';  // the dimension count
  ASSERT_TRUE(saveFile(dir.path + "/damaged.dat", damaged));
  TetMesh m;
  ReadReport r;
  EXPECT_FAILS(readMesh(dir.path + "/damaged.dat", m, r), Status::Truncated, "damaged.dat: the netCDF header lists");
  // A PLOT3D grid under .g stays PLOT3D.
  ASSERT_TRUE(readMesh(fixturePath("formats/p3d_two_blocks.g"), m, r));
  EXPECT_NE(r.format.find("PLOT3D"), std::string::npos) << r.format;
}

TEST(CgnsSniff, OtherHdf5FilesAreNeitherFormat) {
  ScratchDir dir("hpc-sniff-hdf5");
  const std::string file = dir.path + "/data.h5";
  {  // An HDF5 file with a VTKHDF root group, as VTK writes them.
    const hid_t f = H5Fcreate(file.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    const hid_t g = H5Gcreate2(f, "VTKHDF", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Gclose(g);
    H5Fclose(f);
  }
  const std::string head = loadFile(file).substr(0, 4096);
  EXPECT_EQ(vtkio::containerSignature(head), vtkio::Container::Hdf5);
  EXPECT_EQ(vtkio::hpcFormatByContent(file, head), vtkio::HpcFormat::None);
  const std::string cgns = hpcPath("cgns_steps.cgns"), exo = hpcPath("exo_meshio.exo");
  EXPECT_EQ(vtkio::hpcFormatByContent(cgns, loadFile(cgns).substr(0, 4096)), vtkio::HpcFormat::Cgns);
  EXPECT_EQ(vtkio::hpcFormatByContent(exo, loadFile(exo).substr(0, 4096)), vtkio::HpcFormat::Exodus);
}

TEST(ExodusComponents, TriplesNeedOneSpellingInOrder) {
  using vtkio::componentTriples;
  const auto t = componentTriples(
      {"T", "vel_x", "vel_y", "vel_z", "MomentumX", "MomentumY", "MomentumZ", "ax", "by", "cz", "u_X", "u_y", "u_Z"});
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[0].stem, "vel");
  EXPECT_EQ(t[0].first, 1u);
  EXPECT_EQ(t[1].stem, "Momentum");
  EXPECT_EQ(t[1].first, 4u);
  EXPECT_TRUE(componentTriples({"x", "y", "z"}).empty());  // no stem
}

// For a process of several (core/dist), the file's elements in shares: each share reads its rows
// of the blocks and the nodes they span (the library's partial reads), and together they hold
// every tet of the whole once, with the whole's nodal values at every point.
TEST(ExodusShares, TheSharesOfAFileHoldEveryTetOnceWithItsValues) {
  for (uint32_t count : {2u, 3u, 5u}) {
    test::expectSharesMakeTheWhole(hpcPath("exo_blocks.exo"), count, "pressure");
    test::expectSharesMakeTheWhole(hpcPath("exo_meshio.exo"), count);
    test::expectSharesReadOnlyUsedPoints(hpcPath("exo_blocks.exo"), count, "nodes they use");
  }
}

// Writes `mesh` through the Exodus library: one block of TETRA elements, the fields as nodal
// variables at one time step, the points in the mesh's order.
void writeExodusTets(const TetMesh& mesh, const std::string& path) {
  int cpu = 8, io = 8;
  const int id = ex_create(path.c_str(), EX_CLOBBER, &cpu, &io);
  ASSERT_GE(id, 0);
  const int V = int(mesh.vertexCount()), T = int(mesh.tetCount()), F = int(mesh.fields.size());
  ASSERT_EQ(ex_put_init(id, "tets", 3, V, T, 1, 0, 0), 0);
  std::vector<double> axis[3];
  for (int k = 0; k < 3; ++k)
    for (int v = 0; v < V; ++v) axis[k].push_back(mesh.positions[3 * size_t(v) + size_t(k)]);
  ASSERT_EQ(ex_put_coord(id, axis[0].data(), axis[1].data(), axis[2].data()), 0);
  ASSERT_EQ(ex_put_block(id, EX_ELEM_BLOCK, 1, "TETRA", T, 4, 0, 0, 0), 0);
  std::vector<int> conn(mesh.tets.begin(), mesh.tets.end());
  for (int& v : conn) ++v;
  ASSERT_EQ(ex_put_conn(id, EX_ELEM_BLOCK, 1, conn.data(), nullptr, nullptr), 0);
  std::vector<std::string> names;
  std::vector<char*> pointers;
  for (const ScalarField& f : mesh.fields) names.push_back(f.name);
  for (std::string& n : names) pointers.push_back(n.data());
  ASSERT_EQ(ex_put_variable_param(id, EX_NODAL, F), 0);
  ASSERT_EQ(ex_put_variable_names(id, EX_NODAL, F, pointers.data()), 0);
  const double time = 0;
  ASSERT_EQ(ex_put_time(id, 1, &time), 0);
  for (int f = 0; f < F; ++f) {
    const std::vector<double> values(mesh.fields[size_t(f)].values.begin(), mesh.fields[size_t(f)].values.end());
    ASSERT_EQ(ex_put_var(id, 1, EX_NODAL, f + 1, 1, V, values.data()), 0);
  }
  ASSERT_EQ(ex_close(id), 0);
}

// Nodes numbered far from the elements' order: a share of the elements reads only the nodes they
// use (io/row_pick.h), a window of rows at a time, coordinates and nodal variables alike.
TEST(ExodusShares, SharesOfShuffledNodesReadOnlyTheNodesTheirElementsUse) {
  const std::string path = test::suiteDir("ExodusShares", "shuffled") + "/shuffled.exo";
  writeExodusTets(test::shuffledPoints(test::harmonicMesh(10)), path);
  for (uint32_t count : {2u, 3u}) {
    test::expectSharesMakeTheWhole(path, count);
    test::expectSharesReadOnlyUsedPoints(path, count, "nodes they use");
  }
}

// Writes `mesh` through the CGNS library as a base of `zones` unstructured zones of TETRA_4
// elements, each a run of the tets with its own copy of the vertices they use (in the order the
// tets first use them, or with `meshOrder` in the mesh's), and the fields as Vertex solutions: the
// layout of a solver that writes one zone per rank.
void writeCgnsZones(const TetMesh& mesh, int zones, const std::string& path, bool meshOrder = false) {
  int fn = -1, base = 0;
  ASSERT_EQ(cg_open(path.c_str(), CG_MODE_WRITE, &fn), CG_OK) << cg_get_error();
  ASSERT_EQ(cg_base_write(fn, "Base", 3, 3, &base), CG_OK);
  const uint32_t T = mesh.tetCount();
  for (int z = 0; z < zones; ++z) {
    const uint32_t from = uint32_t(uint64_t(T) * uint32_t(z) / uint32_t(zones)),
                   to = uint32_t(uint64_t(T) * uint32_t(z + 1) / uint32_t(zones));
    std::map<uint32_t, cgsize_t> local;  // mesh vertex -> 1-based zone vertex
    if (meshOrder)
      for (uint32_t t = from; t < to; ++t)
        for (int k = 0; k < 4; ++k) local.emplace(mesh.tets[4 * size_t(t) + size_t(k)], 0);
    cgsize_t next = 0;
    for (auto& [v, id] : local) id = ++next;
    std::vector<cgsize_t> conn;
    for (uint32_t t = from; t < to; ++t)
      for (int k = 0; k < 4; ++k) {
        const uint32_t v = mesh.tets[4 * size_t(t) + size_t(k)];
        auto [it, added] = local.emplace(v, cgsize_t(local.size() + 1));
        conn.push_back(it->second);
      }
    std::vector<uint32_t> order(local.size());
    for (const auto& [v, id] : local) order[size_t(id - 1)] = v;
    cgsize_t size[3] = {cgsize_t(order.size()), cgsize_t(to - from), 0};
    int zone = 0, coord = 0, section = 0, sol = 0, field = 0;
    ASSERT_EQ(cg_zone_write(fn, base, ("rank" + std::to_string(z)).c_str(), size, CGNS_ENUMV(Unstructured), &zone),
              CG_OK);
    for (int a = 0; a < 3; ++a) {
      std::vector<double> x;
      for (uint32_t v : order) x.push_back(mesh.positions[3 * size_t(v) + size_t(a)]);
      const char* name[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
      ASSERT_EQ(cg_coord_write(fn, base, zone, CGNS_ENUMV(RealDouble), name[a], x.data(), &coord), CG_OK);
    }
    ASSERT_EQ(
        cg_section_write(fn, base, zone, "Tets", CGNS_ENUMV(TETRA_4), 1, cgsize_t(to - from), 0, conn.data(), &section),
        CG_OK);
    ASSERT_EQ(cg_sol_write(fn, base, zone, "Solution", CGNS_ENUMV(Vertex), &sol), CG_OK);
    for (const ScalarField& f : mesh.fields) {
      std::vector<double> values;
      for (uint32_t v : order) values.push_back(f.values[v]);
      ASSERT_EQ(cg_field_write(fn, base, zone, sol, CGNS_ENUMV(RealDouble), f.name.c_str(), values.data(), &field),
                CG_OK);
    }
  }
  ASSERT_EQ(cg_close(fn), CG_OK);
}

// A CGNS base of fewer unstructured zones than processes (one zone per rank of a smaller run):
// each process reads its window of every zone, the elements and the vertices they use.
TEST(CgnsShares, FewerUnstructuredZonesThanProcessesAreReadInWindows) {
  ScratchDir dir("cgns-zones");
  const std::string path = dir.path + "/zones.cgns";
  writeCgnsZones(test::harmonicMesh(6), 3, path);
  for (uint32_t count : {3u, 4u, 7u}) test::expectSharesMakeTheWhole(path, count);
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(readMesh(path, m, r, test::shareOf(1, 4)));
  EXPECT_TRUE(hasNote(r, "(a share of each of the 3 unstructured zones) and the")) << allNotes(r);
}

// Vertices numbered far from the elements' order: a share of a zone's elements reads only the
// vertices they use (io/row_pick.h), coordinates and solutions alike.
TEST(CgnsShares, SharesOfShuffledVerticesReadOnlyTheVerticesTheirElementsUse) {
  ScratchDir dir("cgns-shuffled");
  const std::string path = dir.path + "/shuffled.cgns";
  writeCgnsZones(test::shuffledPoints(test::harmonicMesh(8)), 1, path, /*meshOrder=*/true);
  for (uint32_t count : {2u, 3u}) {
    test::expectSharesMakeTheWhole(path, count);
    test::expectSharesReadOnlyUsedPoints(path, count, "vertices they use");
  }
}

// Writes `mesh` through the CGNS library as one unstructured zone with one MIXED section: its
// tets (TETRA_4), and between them elements that are not read, a triangle (TRI_3) after every 7th
// tet and a bar (BAR_2) after every 11th, with each element's ElementStartOffset, or with
// `wrongOffsets` offsets that disagree with the types inside (as CGNS 3.4.0's tools write them).
void writeCgnsMixed(const TetMesh& mesh, const std::string& path, bool wrongOffsets) {
  std::vector<cgsize_t> conn, offsets{0};
  auto add = [&](CGNS_ENUMT(ElementType_t) type, std::initializer_list<uint32_t> nodes) {
    conn.push_back(cgsize_t(type));
    for (uint32_t v : nodes) conn.push_back(cgsize_t(v + 1));
    offsets.push_back(cgsize_t(conn.size()));
  };
  for (uint32_t t = 0; t < mesh.tetCount(); ++t) {
    const uint32_t* v = &mesh.tets[4 * size_t(t)];
    add(CGNS_ENUMV(TETRA_4), {v[0], v[1], v[2], v[3]});
    if (t % 7 == 0) add(CGNS_ENUMV(TRI_3), {v[0], v[1], v[2]});
    if (t % 11 == 0) add(CGNS_ENUMV(BAR_2), {v[0], v[3]});
  }
  const cgsize_t elements = cgsize_t(offsets.size() - 1);
  if (wrongOffsets)
    for (size_t k = 1; k + 1 < offsets.size(); ++k) offsets[k] += 1;
  int fn = -1, base = 0, zone = 0, coord = 0, section = 0, sol = 0, field = 0;
  ASSERT_EQ(cg_open(path.c_str(), CG_MODE_WRITE, &fn), CG_OK) << cg_get_error();
  ASSERT_EQ(cg_base_write(fn, "Base", 3, 3, &base), CG_OK);
  cgsize_t size[3] = {cgsize_t(mesh.vertexCount()), elements, 0};
  ASSERT_EQ(cg_zone_write(fn, base, "mixed", size, CGNS_ENUMV(Unstructured), &zone), CG_OK);
  for (int a = 0; a < 3; ++a) {
    std::vector<double> x;
    for (uint32_t v = 0; v < mesh.vertexCount(); ++v) x.push_back(mesh.positions[3 * size_t(v) + size_t(a)]);
    const char* name[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
    ASSERT_EQ(cg_coord_write(fn, base, zone, CGNS_ENUMV(RealDouble), name[a], x.data(), &coord), CG_OK);
  }
  ASSERT_EQ(cg_poly_section_write(fn, base, zone, "Cells", CGNS_ENUMV(MIXED), 1, elements, 0, conn.data(),
                                  offsets.data(), &section),
            CG_OK)
      << cg_get_error();
  ASSERT_EQ(cg_sol_write(fn, base, zone, "Solution", CGNS_ENUMV(Vertex), &sol), CG_OK);
  std::vector<double> values(mesh.fields[0].values.begin(), mesh.fields[0].values.end());
  ASSERT_EQ(
      cg_field_write(fn, base, zone, sol, CGNS_ENUMV(RealDouble), mesh.fields[0].name.c_str(), values.data(), &field),
      CG_OK);
  ASSERT_EQ(cg_close(fn), CG_OK);
}

// Sets the code of element `element` (0-based) of the MIXED section writeCgnsMixed wrote to
// `code`, through HDF5 (the CGNS library refuses to write a code no element type has). The
// element is found by the codes before it (the offsets may be wrong).
void setMixedCode(const std::string& path, size_t element, int code) {
  hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  hid_t conn = H5Dopen2(file, "/Base/mixed/Cells/ElementConnectivity/ data", H5P_DEFAULT);
  ASSERT_GE(conn, 0);
  std::vector<int64_t> c(size_t(H5Sget_simple_extent_npoints(H5Dget_space(conn))));
  H5Dread(conn, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, c.data());
  size_t at = 0;
  for (size_t e = 0; e < element; ++e) {
    int npe = 0;
    ASSERT_EQ(cg_npe(CGNS_ENUMT(ElementType_t)(c[at]), &npe), CG_OK);
    at += 1 + size_t(npe);
  }
  c[at] = code;
  H5Dwrite(conn, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, c.data());
  H5Dclose(conn);
  H5Fclose(file);
}

// A MIXED section read by several processes: each reads the offsets of its own elements and the
// connectivity they name, and only the vertices their corners use. Offsets that disagree with the
// element types (CGNS 3.4.0's tools) are not trusted: the types are walked from the first element.
// Either way the shares hold every tet of the whole once; so for the fixture whose MIXED zone
// has such offsets, in ADF and HDF5.
TEST(CgnsShares, MixedSectionsAreReadInWindows) {
  ScratchDir dir("cgns-mixed");
  const TetMesh mesh = test::shuffledPoints(test::harmonicMesh(7));
  for (bool wrong : {false, true}) {
    SCOPED_TRACE(wrong ? "offsets that disagree" : "offsets");
    const std::string path = dir.path + (wrong ? "/wrong.cgns" : "/mixed.cgns");
    writeCgnsMixed(mesh, path, wrong);
    TetMesh whole;
    ReadReport r;
    ASSERT_TRUE(readMesh(path, whole, r)) << allNotes(r);
    EXPECT_EQ(whole.tetCount(), mesh.tetCount());
    for (uint32_t count : {2u, 3u, 5u}) {
      test::expectSharesMakeTheWhole(path, count);
      test::expectSharesReadOnlyUsedPoints(path, count, "vertices they use");
    }
    ASSERT_TRUE(readMesh(path, whole, r = ReadReport{}, test::shareOf(1, 3)));
    EXPECT_EQ(hasNote(r, "found by their types, from the first element"), wrong) << allNotes(r);
  }
  for (const char* name : {"cgns_unstructured.cgns", "cgns_unstructured.adf.cgns"})
    for (uint32_t count : {3u, 4u}) test::expectSharesMakeTheWhole(hpcPath(name), count);
  // A code no element type has, in the last share's elements: that share and the whole refuse
  // the file, naming the element; the first share never reaches it.
  const std::string bad = dir.path + "/bad.cgns";
  for (bool wrong : {false, true}) {
    writeCgnsMixed(mesh, bad, wrong);
    setMixedCode(bad, 1000, 99);
    TetMesh m;
    ReadReport r;
    EXPECT_FAILS(readMesh(bad, m, r), Status::Corrupt, "element 1001 has element type code 99");
    EXPECT_FAILS(readMesh(bad, m, r, test::shareOf(1, 2)), Status::Corrupt, "element 1001 has element type code 99");
    EXPECT_TRUE(readMesh(bad, m, r, test::shareOf(0, 2)));
  }
}

// Writes a base of two zones that meet at x = 1: an unstructured zone of the tets of a grid on
// [-1, 1]³ and a structured zone of 5³ points on [1, 3] × [-1, 1]², point field f = x + 2y + 3z
// in both (a hybrid mesh: a structured block beside an unstructured one).
void writeCgnsHybrid(const std::string& path) {
  const TetMesh grid = test::harmonicMesh(5);
  auto f = [](double x, double y, double z) { return x + 2 * y + 3 * z; };
  int fn = -1, base = 0, zone = 0, coord = 0, section = 0, sol = 0, field = 0;
  ASSERT_EQ(cg_open(path.c_str(), CG_MODE_WRITE, &fn), CG_OK) << cg_get_error();
  ASSERT_EQ(cg_base_write(fn, "Base", 3, 3, &base), CG_OK);
  const char* names[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
  cgsize_t size[9] = {cgsize_t(grid.vertexCount()), cgsize_t(grid.tetCount()), 0};
  ASSERT_EQ(cg_zone_write(fn, base, "tets", size, CGNS_ENUMV(Unstructured), &zone), CG_OK);
  std::vector<double> values;
  for (int a = 0; a < 3; ++a) {
    std::vector<double> x;
    for (uint32_t v = 0; v < grid.vertexCount(); ++v) x.push_back(grid.positions[3 * size_t(v) + size_t(a)]);
    ASSERT_EQ(cg_coord_write(fn, base, zone, CGNS_ENUMV(RealDouble), names[a], x.data(), &coord), CG_OK);
  }
  for (uint32_t v = 0; v < grid.vertexCount(); ++v)
    values.push_back(f(grid.positions[3 * v], grid.positions[3 * v + 1], grid.positions[3 * v + 2]));
  std::vector<cgsize_t> conn;
  for (uint32_t id : grid.tets) conn.push_back(cgsize_t(id + 1));
  ASSERT_EQ(cg_section_write(fn, base, zone, "Tets", CGNS_ENUMV(TETRA_4), 1, cgsize_t(grid.tetCount()), 0, conn.data(),
                             &section),
            CG_OK);
  ASSERT_EQ(cg_sol_write(fn, base, zone, "Solution", CGNS_ENUMV(Vertex), &sol), CG_OK);
  ASSERT_EQ(cg_field_write(fn, base, zone, sol, CGNS_ENUMV(RealDouble), "f", values.data(), &field), CG_OK);

  const cgsize_t n = 5;
  cgsize_t block[9] = {n, n, n, n - 1, n - 1, n - 1, 0, 0, 0};
  ASSERT_EQ(cg_zone_write(fn, base, "block", block, CGNS_ENUMV(Structured), &zone), CG_OK);
  std::vector<double> xyz[3];
  values.clear();
  for (cgsize_t k = 0; k < n; ++k)
    for (cgsize_t j = 0; j < n; ++j)
      for (cgsize_t i = 0; i < n; ++i) {
        const double p[3] = {1 + 0.5 * double(i), -1 + 0.5 * double(j), -1 + 0.5 * double(k)};
        for (int a = 0; a < 3; ++a) xyz[a].push_back(p[a]);
        values.push_back(f(p[0], p[1], p[2]));
      }
  for (int a = 0; a < 3; ++a)
    ASSERT_EQ(cg_coord_write(fn, base, zone, CGNS_ENUMV(RealDouble), names[a], xyz[a].data(), &coord), CG_OK);
  ASSERT_EQ(cg_sol_write(fn, base, zone, "Solution", CGNS_ENUMV(Vertex), &sol), CG_OK);
  ASSERT_EQ(cg_field_write(fn, base, zone, sol, CGNS_ENUMV(RealDouble), "f", values.data(), &field), CG_OK);
  ASSERT_EQ(cg_close(fn), CG_OK);
}

// A base of fewer zones than processes, structured and unstructured together: each process reads
// a slab of the structured zone and a window of the unstructured one.
TEST(CgnsShares, HybridBasesAreReadInSlabsAndWindows) {
  ScratchDir dir("cgns-hybrid");
  const std::string path = dir.path + "/hybrid.cgns";
  writeCgnsHybrid(path);
  for (uint32_t count : {3u, 4u}) test::expectSharesMakeTheWhole(path, count);
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(readMesh(path, m, r, test::shareOf(1, 3)));
  EXPECT_TRUE(hasNote(r,
                      "read slab 2 of 3 of the 1 structured zone (1 of 4 layers of cells) and elements 129 to 256 of "
                      "384 of the unstructured zone and the"))
      << allNotes(r);
  ASSERT_TRUE(readMesh(path, m, r = ReadReport{}, test::shareOf(1, 5)));
  EXPECT_FALSE(r.shared) << "a block of 4 layers cannot give 5 processes one each";
}

// A CGNS base of as many zones as processes or more: each reads its zones whole. A base of one
// unstructured zone: each reads its elements and the vertices they use, with its rows of the
// solutions (a time series here: the step's solution). Fewer structured zones than processes:
// each reads its slab of k-layers of every zone, with those layers of the solutions.
TEST(CgnsShares, EachProcessReadsItsZonesOrItsElements) {
  for (const char* name : {"cgns_unstructured.cgns", "cgns_structured.cgns", "cgns_structured.adf.cgns"})
    test::expectSharesMakeTheWhole(hpcPath(name), 2);
  for (const char* name : {"cgns_structured.cgns", "cgns_structured.adf.cgns"})
    test::expectSharesMakeTheWhole(hpcPath(name), 3);  // (each zone is 3 cells deep along k)
  for (uint32_t count : {2u, 3u}) test::expectSharesMakeTheWhole(hpcPath("cgns_steps.cgns"), count);
  TetMesh m;
  ReadReport r;
  ReadOptions o;
  o.shareIndex = 1;
  o.shareCount = 5;  // more processes than zones and than layers of cells: read whole
  ASSERT_TRUE(readMesh(hpcPath("cgns_structured.cgns"), m, r, o));
  EXPECT_FALSE(r.shared);
}

}  // namespace
}  // namespace tetstream
