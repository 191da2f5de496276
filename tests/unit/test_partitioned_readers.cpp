// Partitioned VTK output (core/io/partitioned_reader.cpp, piece_merge.cpp): every listing in
// tests/fixtures/partitioned/ (written by VTK 9.1 and meshio, make_partitioned_fixtures.py) must
// read as the one box it was cut from: the same counts, volume and boundary (a seam would add
// inner faces to the boundary, a doubled ghost cell a duplicate tet), the same field values at
// the same points, and the counts the writers recorded in expected.json. Then damaged and hostile
// listings and pieces, each refused with a message that names the piece.
#include <gtest/gtest.h>
#include <zlib.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "io/generators.h"
#include "io/mesh_io.h"
#include "io/readers.h"
#include "test_helpers.h"
#include "validate.h"

namespace tetstream {
namespace {

namespace fs = std::filesystem;
using test::allNotes;
using test::fixturePath;
using test::hasNote;
using test::loadFile;
using test::saveFile;
using test::ScratchDir;
using test::totalVolume;

std::string partitioned(const std::string& name) { return fixturePath("partitioned/" + name); }

const nlohmann::json& expected() { return test::fixtureJson("partitioned/expected.json"); }

Result read(const std::string& path, TetMesh& m, ReadReport& r) {
  r = ReadReport{};
  return readMesh(path, m, r);
}

// The references: the whole box in one file, as tets and as hexahedra (petsc.vtu's cells; cell
// data becomes other point data over hexahedra than over their tets).
const TetMesh& box(bool hexes = false) {
  static const std::array<TetMesh, 2> m = [] {
    std::array<TetMesh, 2> b;
    ReadReport r;
    EXPECT_TRUE(readMesh(partitioned("box.vtu"), b[0], r));
    EXPECT_TRUE(readMesh(partitioned("box_hex.vtu"), b[1], r));
    return b;
  }();
  return m[hexes];
}

// Copies the fixtures into a scratch folder for a test to damage.
struct Copy {
  ScratchDir dir;
  explicit Copy(const std::string& name) : dir("partitioned-" + name) {
    fs::copy(fixturePath("partitioned"), dir.path, fs::copy_options::recursive);
  }
  std::string path(const std::string& name) const { return dir.path + "/" + name; }
  std::string text(const std::string& name) const { return loadFile(path(name)); }
  void replace(const std::string& name, const std::string& from, const std::string& to) const {
    std::string s = text(name);
    const size_t at = s.find(from);
    ASSERT_NE(at, std::string::npos) << from << " in " << name;
    s.replace(at, from.size(), to);
    ASSERT_TRUE(saveFile(path(name), s));
  }
};

// The reference vertex nearest to p (exact for welded coordinates; ids.pvtu moves points by
// less than 3e-6).
uint32_t nearestBoxVertex(const float* p) {
  const TetMesh& b = box();
  uint32_t best = 0;
  double bestD = 1e300;
  for (uint32_t v = 0; v < b.vertexCount(); ++v) {
    double d = 0;
    for (int c = 0; c < 3; ++c) d += std::pow(double(b.positions[3 * v + c]) - p[c], 2);
    if (d < bestD) bestD = d, best = v;
  }
  return best;
}

float fieldAt(const TetMesh& m, const std::string& name, uint32_t v) {
  const int f = m.findField(name);
  return f < 0 ? NAN : m.fields[size_t(f)].values[v];
}

// ------------------------------------------------------------------ in memory (the fuzzed API)
// A loader over named byte strings, as the fuzz target uses it.
PieceLoader fromMap(const std::map<std::string, std::string>& files) {
  return [&files](const std::string& path, PieceBytes& piece) {
    auto it = files.find(path);
    if (it == files.end()) return fail(Status::IoError, path + ": no such piece");
    piece.bytes = it->second;
    return Result::success();
  };
}

// An ASCII VTU piece of one tet per 4 points, with optional arrays ("name:type:values", cell
// arrays after '|').
std::string asciiPiece(const std::string& points, int tets, const std::vector<std::string>& pointArrays,
                       const std::vector<std::string>& cellArrays, const std::string& pointDataAttrs = "") {
  auto arrays = [](const std::vector<std::string>& list) {
    std::string s;
    for (const std::string& a : list) {
      const size_t c1 = a.find(':'), c2 = a.find(':', c1 + 1);
      s += "<DataArray Name=\"" + a.substr(0, c1) + "\" type=\"" + a.substr(c1 + 1, c2 - c1 - 1) +
           "\" format=\"ascii\">" + a.substr(c2 + 1) + "</DataArray>";
    }
    return s;
  };
  std::string conn, offsets, types;
  for (int t = 0; t < tets; ++t) {
    for (int k = 0; k < 4; ++k) conn += std::to_string(4 * t + k) + " ";
    offsets += std::to_string(4 * t + 4) + " ";
    types += "10 ";
  }
  return "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid><Piece NumberOfPoints=\"" + std::to_string(4 * tets) +
         "\" NumberOfCells=\"" + std::to_string(tets) + "\"><PointData " + pointDataAttrs + ">" + arrays(pointArrays) +
         "</PointData><CellData>" + arrays(cellArrays) +
         "</CellData><Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">" + points +
         "</DataArray></Points><Cells><DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">" + conn +
         "</DataArray><DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">" + offsets +
         "</DataArray><DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">" + types +
         "</DataArray></Cells></Piece></UnstructuredGrid></VTKFile>";
}

const char* kTetA = "0 0 0  1 0 0  0 1 0  0 0 1";
const char* kTetB = "1 0 0  0 1 0  0 0 1  1 1 1";  // shares the face (1,0,0) (0,1,0) (0,0,1)

std::string twoPieceListing(const std::string& extra = "") {
  return "<VTKFile type=\"PUnstructuredGrid\"><PUnstructuredGrid>" + extra +
         "<Piece Source=\"a.vtu\"/><Piece Source=\"b.vtu\"/></PUnstructuredGrid></VTKFile>";
}

// ------------------------------------------------------------------ every listing is the box
struct ListingCase {
  const char* file;
  const char* formatStart;
  const char* weldedBy;  // "coordinates" or the id array's name
};
void PrintTo(const ListingCase& c, std::ostream* os) { *os << c.file; }

class PartitionedListing : public ::testing::TestWithParam<ListingCase> {};

TEST_P(PartitionedListing, ReadsAsTheWholeBox) {
  const ListingCase& c = GetParam();
  ASSERT_FALSE(expected().is_discarded()) << "expected.json does not parse";
  const nlohmann::json& e = expected()[c.file];
  const nlohmann::json& whole = expected()["box.vtu"];
  TetMesh m;
  ReadReport r;
  Result res = read(partitioned(c.file), m, r);
  ASSERT_TRUE(res) << res.message;

  EXPECT_EQ(m.vertexCount(), whole["vertices"].get<uint32_t>()) << allNotes(r);
  EXPECT_EQ(m.tetCount(), whole["tets"].get<uint32_t>()) << allNotes(r);
  EXPECT_NEAR(totalVolume(m), whole["volume"].get<double>(), 1e-5);
  const ValidationReport v = validateMesh(m);
  EXPECT_EQ(v.boundaryFaces, whole["boundaryFaces"].get<uint64_t>()) << "a seam or a doubled cell";
  EXPECT_EQ(v.duplicateTets, 0u);
  EXPECT_EQ(v.nonManifoldFaces, 0u);
  EXPECT_EQ(v.unusedVertices, 0u);

  // What was read, in the writers' own counts.
  EXPECT_EQ(r.format.rfind(c.formatStart, 0), 0u) << r.format;
  const uint64_t pieces = e["pieces"], ghosts = e["ghostCells"], welded = e["interfacePoints"];
  EXPECT_NE(r.format.find(", " + std::to_string(pieces) + " "), std::string::npos) << r.format;
  EXPECT_EQ(r.format.find("ghost cells dropped") != std::string::npos, ghosts > 0) << r.format;
  if (ghosts) {
    EXPECT_NE(r.format.find(vtkio::withThousands(ghosts) + " ghost cells dropped"), std::string::npos) << r.format;
  }
  EXPECT_NE(r.format.find(std::to_string(welded) + " interface points welded by " + c.weldedBy), std::string::npos)
      << r.format;

  // The fields the solver wrote, none of the partition's own arrays, and the values of the box
  // at the same points (the owning piece's values: disagree.pvtu's owner has the true ones).
  std::vector<std::string> names;
  for (const ScalarField& f : m.fields) names.push_back(f.name);
  EXPECT_EQ(names, (std::vector<std::string>{"T", "S", "v_magnitude", "region"}));
  for (uint32_t q = 0; q < m.vertexCount(); ++q) {
    const float* p = &m.positions[3 * size_t(q)];
    const uint32_t b = nearestBoxVertex(p);
    ASSERT_NEAR(p[0], box().positions[3 * b], 3e-6);
    EXPECT_EQ(fieldAt(m, "T", q), fieldAt(box(), "T", b)) << "vertex " << q;
    EXPECT_EQ(fieldAt(m, "S", q), fieldAt(box(), "S", b)) << "vertex " << q;
    EXPECT_NEAR(fieldAt(m, "T", q), p[0] + 2 * p[1] + 3 * p[2], 2e-5);
    // Cell data becomes point data over the joined mesh: as over the box.
    const bool hexes = std::string(c.file) == "petsc.vtu";
    EXPECT_NEAR(fieldAt(m, "region", q), fieldAt(box(hexes), "region", b), 1e-5) << "vertex " << q;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Partitioned, PartitionedListing,
    ::testing::Values(ListingCase{"ghost.pvtu", "parallel VTK (.pvtu), 3 pieces", "coordinates"},
                      ListingCase{"ids.pvtu", "parallel VTK (.pvtu), 4 pieces", "GlobalIds"},
                      ListingCase{"disagree.pvtu", "parallel VTK (.pvtu)", "coordinates"},
                      ListingCase{"meshio.pvtu", "parallel VTK (.pvtu)", "coordinates"},
                      ListingCase{"petsc.vtu", "VTK XML UnstructuredGrid", "coordinates"},
                      ListingCase{"blocks.vtm", "VTK multiblock (.vtm), 3 datasets", "coordinates"},
                      ListingCase{"legacy.pvtk", "parallel legacy VTK (.pvtk), 2 pieces", "coordinates"}),
    [](const ::testing::TestParamInfo<ListingCase>& i) {
      std::string n = i.param.file;
      for (char& ch : n)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return n;
    });

TEST(PartitionedFixtures, EveryListingIsTested) {
  ASSERT_FALSE(expected().is_discarded());
  for (const auto& [name, facts] : expected().items()) EXPECT_TRUE(fs::exists(partitioned(name))) << name;
  EXPECT_EQ(expected().size(), 10u) << "a listing without a case in PartitionedListing or below";
}

// A .vtu of fewer pieces than processes: each reads a run of every piece's cells and the points
// they span, in every encoding the reader takes (VTK's and meshio's writers).
TEST(PartitionedReaders, SharesOfTheCellsOfAVtuMakeTheWhole) {
  for (const char* name :
       {"vtk_ascii.vtu", "vtk_binary.vtu", "vtk_binary_u64.vtu", "vtk_binary_zlib.vtu", "vtk_appended_raw.vtu",
        "vtk_appended_raw_zlib64.vtu", "vtk_appended_base64.vtu", "vtk_appended_base64_zlib.vtu", "vtk_bigendian.vtu",
        "vtk_bigendian_binary.vtu", "meshio_ascii.vtu", "meshio_binary.vtu", "meshio_zlib.vtu", "meshio_u32_cells.vtu",
        "meshio_u64_cells.vtu", "mixed_cells.vtu"})
    for (uint32_t count : {2u, 3u}) test::expectSharesMakeTheWhole(fixturePath(name), count, "cellid");
  test::expectSharesMakeTheWhole(partitioned("petsc.vtu"), 5, "region");  // 3 pieces on 5 processes
}

// Points numbered far from the cells' order (as a solver that numbers points and cells each its
// own way writes them): a run of the cells uses points from all over the piece. Each process then
// reads only the points its cells use, a window of rows at a time, instead of every point their
// ids span; the shares still make the whole.
TEST(PartitionedReaders, SharesReadOnlyThePointsTheirCellsUse) {
  const TetMesh shuffled = test::shuffledPoints(test::harmonicMesh(12));
  const std::string path = test::suiteDir("PartitionedReaders", "shuffled") + "/shuffled.vtu";
  ASSERT_TRUE(writeVtu(path, shuffled));

  for (uint32_t count : {2u, 3u}) {
    test::expectSharesMakeTheWhole(path, count, "");
    test::expectSharesReadOnlyUsedPoints(path, count, "points read for them");
  }
}

// Base64 of `bytes`; with `lineEvery`, a line break after every so many characters (as some
// writers wrap their text).
std::string base64(const std::vector<uint8_t>& bytes, size_t lineEvery = 0) {
  static const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t k = 0; k < bytes.size(); k += 3) {
    const uint32_t b = uint32_t(bytes[k]) << 16 | (k + 1 < bytes.size() ? uint32_t(bytes[k + 1]) << 8 : 0) |
                       (k + 2 < bytes.size() ? bytes[k + 2] : 0);
    out += alphabet[b >> 18 & 63];
    out += alphabet[b >> 12 & 63];
    out += k + 1 < bytes.size() ? alphabet[b >> 6 & 63] : '=';
    out += k + 2 < bytes.size() ? alphabet[b & 63] : '=';
  }
  if (!lineEvery) return out;
  std::string wrapped;
  for (size_t k = 0; k < out.size(); k += lineEvery) wrapped += out.substr(k, lineEvery) + "\n";
  return wrapped;
}

// One DataArray's payload as VTK encodes it with UInt64 headers: the byte count and the data, or
// (zlib) the block count, block size, last block's size and each block's compressed size, then
// the blocks. Base64 text: the header and the blocks encoded apart, as VTK does for zlib data.
template <class T>
std::string encodedArray(const std::vector<T>& values, bool zlib, size_t lineEvery) {
  std::vector<uint8_t> data(values.size() * sizeof(T));
  std::memcpy(data.data(), values.data(), data.size());
  auto words = [](std::initializer_list<uint64_t> w, std::vector<uint8_t>& out) {
    for (uint64_t x : w) {  // (resize and copy: GCC 12 takes inserts here for overflows)
      const size_t at = out.size();
      out.resize(at + 8);
      std::memcpy(out.data() + at, &x, 8);
    }
  };
  std::vector<uint8_t> header;
  if (!zlib) {
    words({data.size()}, header);
    header.resize(8 + data.size());
    if (!data.empty()) std::memcpy(header.data() + 8, data.data(), data.size());
    return base64(header, lineEvery);
  }
  const size_t block = 4096, blocks = (data.size() + block - 1) / block;
  std::vector<uint8_t> packed;
  words({blocks, block, data.size() - (blocks - 1) * block}, header);
  for (size_t b = 0; b < blocks; ++b) {
    const size_t n = std::min(block, data.size() - b * block);
    uLongf size = compressBound(uLong(n));
    std::vector<uint8_t> out(size);
    EXPECT_EQ(compress(out.data(), &size, data.data() + b * block, uLong(n)), Z_OK);
    words({size}, header);
    packed.insert(packed.end(), out.begin(), out.begin() + std::ptrdiff_t(size));
  }
  return base64(header, lineEvery) + base64(packed, lineEvery);
}

// `mesh` as a .vtu of base64 data, as VTK, ParaView and meshio write it: inline or appended,
// plain or zlib-compressed in blocks, its text on one line or wrapped.
void writeBase64Vtu(const TetMesh& mesh, const std::string& path, bool appended, bool zlib, size_t lineEvery = 0) {
  std::vector<int64_t> conn(mesh.tets.begin(), mesh.tets.end()), offsets;
  std::vector<uint8_t> types(mesh.tetCount(), 10);
  for (uint32_t t = 1; t <= mesh.tetCount(); ++t) offsets.push_back(4 * int64_t(t));
  std::string tail;  // appended data
  auto array = [&](const std::string& head, const std::string& text) {
    if (!appended) return "<DataArray " + head + " format=\"binary\">\n" + text + "\n</DataArray>\n";
    const std::string tag =
        "<DataArray " + head + " format=\"appended\" offset=\"" + std::to_string(tail.size()) + "\"/>\n";
    tail += text;
    return tag;
  };
  std::string xml = std::string("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" ") +
                    "byte_order=\"LittleEndian\" header_type=\"UInt64\"" +
                    (zlib ? " compressor=\"vtkZLibDataCompressor\"" : "") + ">\n<UnstructuredGrid>\n<Piece " +
                    "NumberOfPoints=\"" + std::to_string(mesh.vertexCount()) + "\" NumberOfCells=\"" +
                    std::to_string(mesh.tetCount()) + "\">\n<PointData>\n";
  xml += array("type=\"Float32\" Name=\"" + mesh.fields[0].name + "\"",
               encodedArray(mesh.fields[0].values, zlib, lineEvery));
  xml += "</PointData>\n<Points>\n";
  xml += array("type=\"Float32\" NumberOfComponents=\"3\"", encodedArray(mesh.positions, zlib, lineEvery));
  xml += "</Points>\n<Cells>\n";
  xml += array("type=\"Int64\" Name=\"connectivity\"", encodedArray(conn, zlib, lineEvery));
  xml += array("type=\"Int64\" Name=\"offsets\"", encodedArray(offsets, zlib, lineEvery));
  xml += array("type=\"UInt8\" Name=\"types\"", encodedArray(types, zlib, lineEvery));
  xml += "</Cells>\n</Piece>\n</UnstructuredGrid>\n";
  if (appended) xml += "<AppendedData encoding=\"base64\">\n_" + tail + "\n</AppendedData>\n";
  xml += "</VTKFile>\n";
  ASSERT_TRUE(saveFile(path, xml));
}

// Base64 data, inline or appended, plain or compressed: a share reads only the points its cells
// use too, jumping over the text before each window where it holds no line breaks, decoding its
// way through where it does; the shares make the whole either way.
TEST(PartitionedReaders, SharesOfBase64DataReadOnlyThePointsTheirCellsUse) {
  const TetMesh shuffled = test::shuffledPoints(test::harmonicMesh(12));
  const std::string dir = test::suiteDir("PartitionedReaders", "base64");
  for (bool appended : {false, true})
    for (bool zlib : {false, true})
      for (size_t lineEvery : {size_t(0), size_t(76)}) {
        const std::string path = dir + "/shuffled-" + (appended ? "appended" : "inline") + (zlib ? "-zlib" : "") +
                                 (lineEvery ? "-wrapped" : "") + ".vtu";
        SCOPED_TRACE(path);
        writeBase64Vtu(shuffled, path, appended, zlib, lineEvery);
        TetMesh whole;
        ReadReport r;
        ASSERT_TRUE(readMesh(path, whole, r)) << allNotes(r);
        ASSERT_EQ(whole.tetCount(), shuffled.tetCount());
        for (uint32_t count : {2u, 3u}) {
          test::expectSharesMakeTheWhole(path, count, "");
          test::expectSharesReadOnlyUsedPoints(path, count, "points read for them");
        }
      }
}

// A .vti or .vts of fewer pieces than processes: each reads a slab of layers of cells along k
// and their points when every piece has a layer for each process, else along j, else along i;
// else the whole file.
TEST(PartitionedReaders, SlabsOfAStructuredGridMakeTheWhole) {
  for (const char* name : {"formats/grid43.vti", "formats/grid43.vts", "formats/grid43_binary.vts"}) {
    test::expectSharesMakeTheWhole(fixturePath(name), 2, "cid");  // (2 layers of cells along k)
    test::expectSharesMakeTheWhole(fixturePath(name), 3, "cid");  // (2 along k and j, 3 along i)
    TetMesh m;
    ReadReport r;
    ASSERT_TRUE(readMesh(fixturePath(name), m, r, test::shareOf(1, 4)));
    EXPECT_FALSE(r.shared) << name << ": 4 processes, at most 3 layers: read whole";
  }
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(readMesh(fixturePath("formats/grid43.vti"), m, r, test::shareOf(0, 2)));
  EXPECT_TRUE(hasNote(r, "read slab 1 of 2 of the grid along k (6 of 12 cells)")) << allNotes(r);
  ReadReport alongI;
  ASSERT_TRUE(readMesh(fixturePath("formats/grid43.vts"), m, alongI, test::shareOf(2, 3)));
  EXPECT_TRUE(hasNote(alongI, "read slab 3 of 3 of the grid along i (4 of 12 cells)")) << allNotes(alongI);
}

// A grid one cell deep (as layered models write them, wide and thin) is cut along j: each share's
// points carry the whole's values, cell data included away from the cuts.
TEST(PartitionedReaders, SlabsOfAThinGridGoAlongJ) {
  std::string points, cells;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 6; ++j)
      for (int i = 0; i < 3; ++i) points += std::to_string(i + 10 * j + 100 * k) + " ";
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 2; ++i) cells += std::to_string(7 * i + 3 * j) + " ";
  const std::string path = test::tempDir("thin-grid") + "/thin.vti";
  ASSERT_TRUE(saveFile(path, R"(<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian">
<ImageData WholeExtent="0 2 0 5 0 1" Origin="0 0 0" Spacing="1 1 1"><Piece Extent="0 2 0 5 0 1">
<PointData><DataArray type="Float32" Name="f" format="ascii">)" +
                                 points + R"(</DataArray></PointData>
<CellData><DataArray type="Int32" Name="cid" format="ascii">)" +
                                 cells + R"(</DataArray></CellData>
</Piece></ImageData></VTKFile>)"));
  TetMesh whole;
  ReadReport wr;
  ASSERT_TRUE(readMesh(path, whole, wr));
  for (uint32_t count : {2u, 3u, 5u}) {
    test::expectSharesMakeTheWhole(path, count, "cid");
    for (uint32_t k = 0; k < count; ++k) {
      TetMesh part;
      ReadReport r;
      ASSERT_TRUE(readMesh(path, part, r, test::shareOf(k, count)));
      const float from = float(5 * k / count), to = float(5 * (k + 1) / count);
      EXPECT_TRUE(hasNote(r, "along j")) << allNotes(r);
      const int cid = part.findField("cid");
      ASSERT_GE(cid, 0);
      for (uint32_t v = 0; v < part.vertexCount(); ++v) {
        const float* p = &part.positions[3 * v];
        if ((p[1] == from && from > 0) || (p[1] == to && to < 5)) continue;  // on a cut: cells of one side
        const int64_t w = test::findVertex(whole, p[0], p[1], p[2]);
        ASSERT_GE(w, 0);
        EXPECT_EQ(part.fields[size_t(cid)].values[v], whole.fields[size_t(whole.findField("cid"))].values[size_t(w)])
            << "share " << k << " of " << count << " at (" << p[0] << ", " << p[1] << ", " << p[2] << ")";
      }
    }
  }
}

// A listing of fewer files than processes: the processes of a file each read a share of its cells
// (of a legacy piece, the first of them reads it all), and together they hold every tet once.
TEST(PartitionedReaders, MoreProcessesThanFilesShareTheFiles) {
  test::expectSharesMakeTheWhole(partitioned("ghost.pvtu"), 5, "region");
  test::expectSharesMakeTheWhole(partitioned("meshio.pvtu"), 3, "region");
  for (const char* name : {"ids.pvtu", "legacy.pvtk"}) {
    TetMesh whole;
    ReadReport wr;
    ASSERT_TRUE(readMesh(partitioned(name), whole, wr)) << name;
    EXPECT_EQ(test::tetsOfShares(partitioned(name), 7, false), whole.tetCount()) << name;
  }
}

// ------------------------------------------------------------------ the rules, one at a time
// A share of the pieces or partitions (what each process of a distributed pack reads): the shares
// together hold every tet once; a file that cannot be shared says so.
TEST(PartitionedReaders, SharesOfPiecesAndPartitionsHoldEveryTetOnce) {
  for (const std::string& path : {partitioned("ghost.pvtu"), partitioned("ids.pvtu"), partitioned("petsc.vtu"),
                                  fixturePath("hpc/vtkhdf_parts.vtkhdf")}) {
    TetMesh whole;
    ReadReport wr;
    ASSERT_TRUE(readMesh(path, whole, wr)) << path;
    EXPECT_FALSE(wr.shared);
    EXPECT_EQ(test::tetsOfShares(path, 3, true), whole.tetCount()) << path;
  }
  const ReadOptions o = test::shareOf(1, 2);
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(readMesh(partitioned("box.vtu"), m, r, o));
  EXPECT_TRUE(r.shared) << "one piece: a share of its cells";
  EXPECT_TRUE(hasNote(r, "read 162 of the 324 cells (share 2 of 2) and the")) << allNotes(r);
  // One file of several <Piece>s (PETSc's): each share is those pieces, every point as the whole has it.
  test::expectSharesMakeTheWhole(partitioned("petsc.vtu"), 3, "region");
  ReadReport pr;
  ASSERT_TRUE(readMesh(partitioned("petsc.vtu"), m, pr, o));
  EXPECT_TRUE(hasNote(pr, "read pieces 2 to 3 of 3, this process's share of the file")) << allNotes(pr);
  // A share's file is mapped, not read: what cannot be mapped is said as a read would say it.
  ReadReport er;
  EXPECT_FAILS(readMesh(partitioned("missing.vtu"), m, er, o), Status::IoError, "cannot open");
  const std::string folder = (fs::temp_directory_path() / "tetstream-share-folder.vtu").string();
  fs::create_directories(folder);
  EXPECT_FAILS(readMesh(folder, m, er, o), Status::IoError, "not a file");
  fs::remove(folder);
}

TEST(PartitionedReaders, GhostCellsAreDroppedAndTheirFlagsAreNoField) {
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(read(partitioned("ghost.pvtu"), m, r));
  EXPECT_TRUE(hasNote(r, "dropped 392 ghost cells (vtkGhostType DUPLICATECELL")) << allNotes(r);
  EXPECT_LT(m.findField("vtkGhostType"), 0);

  // Without their flags the ghost cells are copies that two pieces hold: kept once, said so.
  Copy c("unflagged");
  for (int k = 0; k < 3; ++k) {
    const std::string piece = "ghost/ghost_" + std::to_string(k) + ".vtu";
    c.replace(piece, "Name=\"vtkGhostType\"", "Name=\"ghostflags\"");
    c.replace(piece, "Name=\"vtkGhostType\"", "Name=\"ghostflags\"");
  }
  ASSERT_TRUE(read(c.path("ghost.pvtu"), m, r));
  EXPECT_EQ(m.tetCount(), 324u);
  EXPECT_EQ(validateMesh(m).boundaryFaces, 180u);
  EXPECT_TRUE(hasNote(r, "dropped 392 cells that another piece also holds")) << allNotes(r);
  EXPECT_NE(r.format.find("392 cells held twice dropped"), std::string::npos) << r.format;
}

TEST(PartitionedReaders, GlobalIdsWeldWhatCoordinatesCannot) {
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(read(partitioned("ids.pvtu"), m, r));
  EXPECT_EQ(m.vertexCount(), 112u);
  EXPECT_TRUE(hasNote(r, "76 of 76 interface points lie up to")) << allNotes(r);
  EXPECT_TRUE(hasNote(r, "by global ids ('GlobalIds')")) << allNotes(r);
  EXPECT_LT(m.findField("GlobalIds"), 0);

  // The same pieces without their ids: the moved points do not meet, and the seams show.
  Copy c("noids");
  for (int k = 0; k < 4; ++k) {
    const std::string piece = "ids/ids_" + std::to_string(k) + ".vtu";
    c.replace(piece, "GlobalIds=\"GlobalIds\"", "");
    c.replace(piece, "Name=\"GlobalIds\"", "Name=\"NodeNumber\"");
  }
  c.replace("ids.pvtu", "Name=\"GlobalIds\"", "Name=\"NodeNumber\"");
  ASSERT_TRUE(read(c.path("ids.pvtu"), m, r));
  EXPECT_GT(m.vertexCount(), 112u);
  EXPECT_GT(validateMesh(m).boundaryFaces, 180u);
  EXPECT_NE(r.format.find("interface points welded by coordinates"), std::string::npos) << r.format;
  EXPECT_TRUE(hasNote(r, "share no point with another piece")) << allNotes(r);

  // GlobalNodeIds (Exodus' name) work the same.
  Copy d("nodeids");
  for (int k = 0; k < 4; ++k) {
    const std::string piece = "ids/ids_" + std::to_string(k) + ".vtu";
    d.replace(piece, "GlobalIds=\"GlobalIds\"", "");
    d.replace(piece, "Name=\"GlobalIds\"", "Name=\"GlobalNodeIds\"");
  }
  d.replace("ids.pvtu", "Name=\"GlobalIds\"", "Name=\"GlobalNodeIds\"");
  ASSERT_TRUE(read(d.path("ids.pvtu"), m, r));
  EXPECT_EQ(m.vertexCount(), 112u);
  EXPECT_NE(r.format.find("welded by GlobalNodeIds"), std::string::npos) << r.format;
}

TEST(PartitionedReaders, GlobalIdsThatAreNotGlobalAreAnError) {
  TetMesh m;
  ReadReport r;
  const uint64_t conflicts = expected()["badids.pvtu"]["conflictingIds"];
  Result res = read(partitioned("badids.pvtu"), m, r);
  EXPECT_EQ(res.status, Status::Corrupt) << res.message;
  EXPECT_NE(res.message.find(std::to_string(conflicts) + " ids name points at different places in different pieces"),
            std::string::npos)
      << res.message;
  EXPECT_NE(res.message.find("piece 0 (badids/badids_0.vtu)"), std::string::npos) << res.message;
  EXPECT_EQ(m.tetCount(), 0u);
}

TEST(PartitionedReaders, DisagreementsAreCountedAndTheOwnerWins) {
  TetMesh m;
  ReadReport r;
  const nlohmann::json& e = expected()["disagree.pvtu"];
  ASSERT_TRUE(read(partitioned("disagree.pvtu"), m, r));
  const std::string of = " of " + std::to_string(e["interfacePoints"].get<int>()) + " interface points";
  EXPECT_TRUE(hasNote(r, "field 'T': " + std::to_string(e["disagreeT"].get<int>()) + of +
                             " disagree between pieces (largest difference 0.5)"))
      << allNotes(r);
  EXPECT_TRUE(hasNote(r, "field 'S': " + std::to_string(e["roundingS"].get<int>()) + of +
                             " differ between pieces by float rounding only"))
      << allNotes(r);
  EXPECT_FALSE(hasNote(r, "averaged")) << allNotes(r);

  // With the changed piece listed first it owns the interface: its values win, not an average.
  Copy c("owner");
  c.replace("disagree.pvtu", "disagree/disagree_0.vtu", "disagree/disagree_X.vtu");
  c.replace("disagree.pvtu", "disagree/disagree_1.vtu", "disagree/disagree_0.vtu");
  c.replace("disagree.pvtu", "disagree/disagree_X.vtu", "disagree/disagree_1.vtu");
  ASSERT_TRUE(read(c.path("disagree.pvtu"), m, r));
  int raised = 0;
  for (uint32_t q = 0; q < m.vertexCount(); ++q) {
    const float d = fieldAt(m, "T", q) - fieldAt(box(), "T", nearestBoxVertex(&m.positions[3 * size_t(q)]));
    EXPECT_TRUE(d == 0 || std::abs(d - 0.5f) < 1e-5f) << d;
    raised += d != 0;
  }
  EXPECT_EQ(raised, e["disagreeT"].get<int>());
}

TEST(PartitionedReaders, MultiblockSkipsWhatIsNoVolumeMesh) {
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(read(partitioned("blocks.vtm"), m, r));
  EXPECT_TRUE(hasNote(r, "skipped 1 block that is not a volume mesh")) << allNotes(r);
  EXPECT_TRUE(hasNote(r, "block walls (blocks/blocks_3.vtp): PolyData")) << allNotes(r);

  // Blocks without a field drop it, with a note naming the block (a .vtm declares nothing).
  Copy c("blockfields");
  c.replace("blocks/blocks_1.vtu", "Name=\"S\"", "Name=\"Q\"");
  ASSERT_TRUE(read(c.path("blocks.vtm"), m, r));
  EXPECT_LT(m.findField("S"), 0);
  EXPECT_TRUE(hasNote(r, "dropped point array 'S': block solid/1/0 (blocks/blocks_1.vtu) lacks it")) << allNotes(r);

  // Only a surface: nothing to read.
  Copy d("onlysurface");
  std::string vtm = d.text("blocks.vtm");
  vtm.replace(vtm.find("<Block name=\"solid\""), vtm.find("</Block>") + 8 - vtm.find("<Block name=\"solid\""), "");
  ASSERT_TRUE(saveFile(d.path("blocks.vtm"), vtm));
  Result res = read(d.path("blocks.vtm"), m, r);
  EXPECT_EQ(res.status, Status::NoTets) << res.message;
}

// ------------------------------------------------------------------ damaged pieces
TEST(PartitionedReaders, DamagedPiecesAreNamed) {
  TetMesh m;
  ReadReport r;
  {
    Copy c("missing");
    fs::remove(c.path("ghost/ghost_1.vtu"));
    EXPECT_FAILS(read(c.path("ghost.pvtu"), m, r), Status::IoError, "ghost.pvtu piece 1 (ghost/ghost_1.vtu): ");
    EXPECT_FAILS(read(c.path("ghost.pvtu"), m, r), Status::IoError, "cannot open");
    EXPECT_EQ(m.tetCount(), 0u);
  }
  {
    Copy c("cut");
    const std::string piece = c.text("ghost/ghost_2.vtu");
    ASSERT_TRUE(saveFile(c.path("ghost/ghost_2.vtu"), piece.substr(0, piece.size() / 2)));
    Result res = read(c.path("ghost.pvtu"), m, r);
    EXPECT_TRUE(res.status == Status::Truncated || res.status == Status::Corrupt) << res.message;
    EXPECT_EQ(res.message.rfind(c.path("ghost.pvtu") + " piece 2 (ghost/ghost_2.vtu): ", 0), 0u) << res.message;
  }
  {
    Copy c("junk");
    ASSERT_TRUE(saveFile(c.path("ghost/ghost_0.vtu"), "not a mesh"));
    EXPECT_FAILS(read(c.path("ghost.pvtu"), m, r), Status::BadMagic, "piece 0 (ghost/ghost_0.vtu): not a VTK XML file");
  }
  {
    Copy c("declared");  // the listing promises an array no piece has
    c.replace("ghost.pvtu", "<PPointData>", "<PPointData><PDataArray type=\"Float32\" Name=\"P\"/>");
    EXPECT_FAILS(read(c.path("ghost.pvtu"), m, r), Status::Corrupt,
                 "piece 0 (ghost/ghost_0.vtu): has no point array 'P', which ");
  }
  {
    Copy c("declaredvector");
    c.replace("ghost.pvtu", "Name=\"v\" NumberOfComponents=\"3\"", "Name=\"v\"");
    EXPECT_FAILS(read(c.path("ghost.pvtu"), m, r), Status::Corrupt, "has no point array 'v', which");
  }
  {
    Copy c("undeclared");  // a piece with an array the listing does not declare: dropped
    c.replace("ghost.pvtu", "<PDataArray type=\"Float64\" Name=\"S\"/>", "");
    ASSERT_TRUE(read(c.path("ghost.pvtu"), m, r));
    EXPECT_LT(m.findField("S"), 0);
    EXPECT_TRUE(hasNote(r, "dropped point array 'S' of piece 0 (ghost/ghost_0.vtu): ")) << allNotes(r);
  }
  {
    Copy c("wrongtype");
    c.replace("ghost.pvtu", "ghost/ghost_2.vtu", "blocks/blocks_3.vtp");
    EXPECT_FAILS(read(c.path("ghost.pvtu"), m, r), Status::Corrupt,
                 "piece 2 (blocks/blocks_3.vtp): is a VTK XML PolyData");
  }
  {
    Copy c("legacycut");
    const std::string piece = c.text("legacy.1.vtk");
    ASSERT_TRUE(saveFile(c.path("legacy.1.vtk"), piece.substr(0, piece.size() - 100)));
    Result res = read(c.path("legacy.pvtk"), m, r);
    EXPECT_FALSE(res);
    EXPECT_NE(res.message.find("legacy.pvtk piece 1 (legacy.1.vtk)"), std::string::npos) << res.message;
  }
  {
    Copy c("legacycount");
    c.replace("legacy.pvtk", "numberOfPieces=\"2\"", "numberOfPieces=\"3\"");
    EXPECT_FAILS(read(c.path("legacy.pvtk"), m, r), Status::Corrupt, "numberOfPieces='3' but 2 <Piece> elements");
  }
}

// ------------------------------------------------------------------ hostile listings
TEST(PartitionedReaders, PiecesStayInTheListingsFolder) {
  TetMesh m;
  ReadReport r;
  Copy c("paths");
  auto withSource = [&](const std::string& source) {
    std::string s = c.text("ghost.pvtu");
    s.replace(s.find("ghost/ghost_1.vtu"), 17, source);
    EXPECT_TRUE(saveFile(c.path("probe.pvtu"), s));
    return read(c.path("probe.pvtu"), m, r);
  };
  EXPECT_FAILS(withSource("../../etc/passwd"), Status::Unsupported, "leaves the listing's folder");
  EXPECT_FAILS(withSource("ghost/../../ghost/ghost_1.vtu"), Status::Unsupported, "leaves the listing's folder");
  EXPECT_FAILS(withSource("..\\..\\etc\\passwd"), Status::Unsupported, "leaves the listing's folder");
  EXPECT_FAILS(withSource("/etc/passwd"), Status::Unsupported, "is an absolute path");
  EXPECT_FAILS(withSource(c.path("ghost/ghost_1.vtu")), Status::Unsupported, "is an absolute path");
  EXPECT_FAILS(withSource("C:/data/ghost_1.vtu"), Status::Unsupported, "is an absolute path");
  EXPECT_FAILS(withSource(""), Status::Corrupt, "piece 1: names no file");
  EXPECT_FAILS(withSource("ghost/.."), Status::Corrupt, "names no file");
  // Recursion: the listing itself, by any spelling, or through a link.
  EXPECT_FAILS(withSource("probe.pvtu"), Status::Corrupt, "names probe.pvtu itself");
  EXPECT_FAILS(withSource("./ghost/../probe.pvtu"), Status::Corrupt, "names probe.pvtu itself");
  fs::create_symlink(c.path("probe.pvtu"), c.path("ghost/link.vtu"));
  EXPECT_FAILS(withSource("ghost/link.vtu"), Status::Corrupt, "is the listing itself");
  // A file listed twice would be read twice.
  EXPECT_FAILS(withSource("ghost/./ghost_0.vtu"), Status::Corrupt, "ghost/ghost_0.vtu is listed twice");
  // Subfolders and dot segments that stay inside are fine.
  ASSERT_TRUE(withSource("ghost/sub/../ghost_1.vtu"));
  EXPECT_EQ(m.tetCount(), 324u);
  // A folder is no piece.
  EXPECT_FAILS(withSource("ghost"), Status::IoError, "not a file");
}

TEST(PartitionedReaders, ThousandsOfPieces) {
  // Every tet of a Kuhn-split 8^3 grid in a piece of its own: 3,072 pieces welded into 729
  // points. (In memory: creating thousands of files costs the file system far more than reading.)
  TetMesh grid = makeGridMesh(9);
  addHarmonicField(grid);
  std::map<std::string, std::string> files;
  std::string listing =
      "<VTKFile type=\"PUnstructuredGrid\"><PUnstructuredGrid><PPointData>"
      "<PDataArray type=\"Float32\" Name=\"h\"/></PPointData>";
  for (uint32_t t = 0; t < grid.tetCount(); ++t) {
    std::string pts, values;
    for (int k = 0; k < 4; ++k) {
      const uint32_t v = grid.tets[4 * t + k];
      char buf[128];
      std::snprintf(buf, sizeof buf, "%.9g %.9g %.9g ", grid.positions[3 * v], grid.positions[3 * v + 1],
                    grid.positions[3 * v + 2]);
      pts += buf;
      std::snprintf(buf, sizeof buf, "%.9g ", grid.fields[0].values[v]);
      values += buf;
    }
    const std::string name = "p/t" + std::to_string(t) + ".vtu";
    files[name] = asciiPiece(pts, 1, {"h:Float32:" + values}, {});
    listing += "<Piece Source=\"" + name + "\"/>";
  }
  listing += "</PUnstructuredGrid></VTKFile>";
  TetMesh m;
  ReadReport r;
  Result res = readListing(listing, "many.pvtu", fromMap(files), m, r);
  ASSERT_TRUE(res) << res.message;
  EXPECT_EQ(m.tetCount(), 3072u);
  EXPECT_EQ(m.vertexCount(), 729u);
  EXPECT_EQ(validateMesh(m).boundaryFaces, 6u * 64 * 2);
  EXPECT_NEAR(totalVolume(m), 8.0, 1e-5);
  EXPECT_NE(r.format.find("3,072 pieces"), std::string::npos) << r.format;
  EXPECT_NE(r.format.find("interface points welded by coordinates"), std::string::npos) << r.format;
  EXPECT_FALSE(hasNote(r, "disagree")) << allNotes(r);

  // Past kMaxPieces the listing is refused before any piece is opened.
  std::string huge = "<VTKFile type=\"PUnstructuredGrid\"><PUnstructuredGrid>";
  for (uint64_t k = 0; k <= vtkio::kMaxPieces; ++k) huge += "<Piece Source=\"x\"/>";
  huge += "</PUnstructuredGrid></VTKFile>";
  int opened = 0;
  PieceLoader count = [&](const std::string&, PieceBytes&) {
    ++opened;
    return fail(Status::IoError, "unexpected");
  };
  EXPECT_FAILS(readListing(huge, "huge.pvtu", count, m, r), Status::TooLarge, "lists more than 1048576 pieces");
  EXPECT_EQ(opened, 0);
}

TEST(PartitionedReaders, InMemoryListingWithALoader) {
  std::map<std::string, std::string> files = {{"a.vtu", asciiPiece(kTetA, 1, {"f:Float32:1 2 3 4"}, {})},
                                              {"b.vtu", asciiPiece(kTetB, 1, {"f:Float32:2 3 4 9"}, {})}};
  TetMesh m;
  ReadReport r;
  Result res = readListing(twoPieceListing(), "two.pvtu", fromMap(files), m, r);
  ASSERT_TRUE(res) << res.message;
  EXPECT_EQ(m.vertexCount(), 5u);
  EXPECT_EQ(m.tetCount(), 2u);
  ASSERT_EQ(m.fields.size(), 1u);
  EXPECT_EQ(m.fields[0].values, (std::vector<float>{1, 2, 3, 4, 9}));
  EXPECT_NE(r.format.find("3 interface points welded by coordinates"), std::string::npos) << r.format;

  // Bytes alone cannot find pieces: readMeshBytes says how to read a listing.
  EXPECT_FAILS(readMeshBytes(twoPieceListing(), "two.pvtu", m, r), Status::Unsupported, "read it by path");
  EXPECT_FAILS(readMeshBytes(twoPieceListing(), "two.vtu", m, r), Status::Unsupported, "read it by path");
  EXPECT_EQ(listingKind(twoPieceListing()), ListingKind::Pvtu);
  EXPECT_EQ(listingKind("<?xml version=\"1.0\"?>\n<!-- x --><File version=\"pvtk-1.0\" dataType=\"x\">"),
            ListingKind::Pvtk);
  EXPECT_EQ(listingKind(files["a.vtu"]), ListingKind::None);
  EXPECT_EQ(listingKind("<VTKFile type=\"vtkMultiBlockDataSet\">"), ListingKind::Vtm);
}

TEST(PartitionedReaders, GhostFlagsAndIdsAreChecked) {
  TetMesh m;
  ReadReport r;
  auto two = [&](const std::string& a, const std::string& b) {
    std::map<std::string, std::string> files = {{"a.vtu", a}, {"b.vtu", b}};
    r = ReadReport{};
    return readListing(twoPieceListing(), "two.pvtu", fromMap(files), m, r);
  };
  const std::string plainB = asciiPiece(kTetB, 1, {}, {});
  EXPECT_FAILS(two(asciiPiece(kTetA, 1, {}, {"vtkGhostType:UInt8:300"}), plainB), Status::Corrupt,
               "piece 0 (a.vtu): DataArray 'vtkGhostType': value 0 is 300, not a ghost flag");
  EXPECT_FAILS(two(asciiPiece(kTetA, 1, {}, {"vtkGhostType:Float32:0.5"}), plainB), Status::Corrupt,
               "not a ghost flag");
  EXPECT_FAILS(two(asciiPiece(kTetA, 1, {"GlobalIds:Int64:0 1 -2 3"}, {}), plainB), Status::Corrupt,
               "DataArray 'GlobalIds': value 2 is -2, not a global id");
  EXPECT_FAILS(two(asciiPiece(kTetA, 1, {"vtkGhostType:UInt8:0 0 0 0 0 0 0 0"}, {}), plainB), Status::Corrupt,
               "has more than the expected 4 values");

  // Ids in one piece only: welded by coordinates, said so; the ids are no field either way.
  ASSERT_TRUE(two(asciiPiece(kTetA, 1, {"GlobalIds:Int64:0 1 2 3"}, {}), plainB));
  EXPECT_EQ(m.vertexCount(), 5u);
  EXPECT_TRUE(m.fields.empty());
  EXPECT_TRUE(hasNote(r, "global ids are in some pieces only")) << allNotes(r);

  // Ids named by the PointData's GlobalIds attribute, whatever the array is called.
  ASSERT_TRUE(two(asciiPiece(kTetA, 1, {"node:Int64:10 11 12 13"}, {}, "GlobalIds=\"node\""),
                  asciiPiece("1 0 0  0 1 0  0 0 1  1 1 1.5", 1, {"node:Int64:11 12 13 14"}, {}, "GlobalIds=\"node\"")));
  EXPECT_EQ(m.vertexCount(), 5u);
  EXPECT_TRUE(m.fields.empty());
  EXPECT_NE(r.format.find("welded by node"), std::string::npos) << r.format;

  // Hidden cells go, hidden points stay for their cells; old-style ghost levels are ghosts too.
  ASSERT_TRUE(two(asciiPiece(std::string(kTetA) + " " + kTetB, 2, {"vtkGhostType:UInt8:0 0 0 0 2 2 2 2"},
                             {"vtkGhostType:UInt8:0 32"}),
                  asciiPiece(kTetB, 1, {}, {"vtkGhostLevels:UInt8:1"})));
  EXPECT_EQ(m.tetCount(), 1u);
  EXPECT_NE(r.format.find("1 ghost cell dropped, 1 hidden cell dropped"), std::string::npos) << r.format;
  EXPECT_TRUE(hasNote(r, "kept 4 hidden points")) << allNotes(r);
  EXPECT_TRUE(m.fields.empty());
}

TEST(PartitionedReaders, MultiPieceVtuAndLegacyGhosts) {
  // One .vtu of two <Piece>s, the second a ghost copy of the first's tet plus its own.
  const std::string a = asciiPiece(kTetA, 1, {}, {}),
                    b = asciiPiece(std::string(kTetA) + " " + kTetB, 2, {}, {"vtkGhostType:UInt8:1 0"});
  auto pieceOf = [](const std::string& doc) {
    const size_t s = doc.find("<Piece "), e = doc.find("</Piece>") + 8;
    return doc.substr(s, e - s);
  };
  const std::string doc = "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid>" + pieceOf(a) + pieceOf(b) +
                          "</UnstructuredGrid></VTKFile>";
  TetMesh m;
  ReadReport r;
  ASSERT_TRUE(readMeshBytes(doc, "two.vtu", m, r));
  EXPECT_EQ(m.tetCount(), 2u);
  EXPECT_EQ(m.vertexCount(), 5u);
  EXPECT_NE(r.format.find(", 2 pieces, 1 ghost cell dropped, 3 interface points welded by coordinates"),
            std::string::npos)
      << r.format;

  // A legacy file on its own with ghost flags and global ids: ghosts dropped, no such fields.
  const std::string legacy =
      "# vtk DataFile Version 4.2\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 5 float\n0 0 0 1 0 0 0 1 0 0 0 1 1 1 "
      "1\nCELLS 2 10\n4 0 1 2 3\n4 1 2 3 4\nCELL_TYPES 2\n10\n10\nCELL_DATA 2\nFIELD FieldData 1\nvtkGhostType 1 2 "
      "unsigned_char\n0 1\nPOINT_DATA 5\nGLOBAL_IDS ids vtkIdType\n0 1 2 3 4\nSCALARS T float\nLOOKUP_TABLE "
      "default\n1 2 3 4 5\n";
  ASSERT_TRUE(readMeshBytes(legacy, "one.vtk", m, r));
  EXPECT_EQ(m.tetCount(), 1u);
  ASSERT_EQ(m.fields.size(), 1u);
  EXPECT_EQ(m.fields[0].name, "T");
  EXPECT_NE(r.format.find("1 ghost cell dropped"), std::string::npos) << r.format;
}

TEST(PartitionedReaders, ListingsThatAreNotListings) {
  TetMesh m;
  ReadReport r;
  const std::map<std::string, std::string> none;
  EXPECT_FAILS(readListing("", "x.pvtu", fromMap(none), m, r), Status::Truncated, "malformed XML");
  EXPECT_FAILS(readListing("<VTKFile type=\"UnstructuredGrid\"/>", "x.pvtu", fromMap(none), m, r), Status::BadMagic,
               "not a listing of pieces");
  EXPECT_FAILS(readListing("<VTKFile type=\"PUnstructuredGrid\"/>", "x.pvtu", fromMap(none), m, r), Status::Corrupt,
               "has no <PUnstructuredGrid>");
  EXPECT_FAILS(
      readListing("<VTKFile type=\"PUnstructuredGrid\"><PUnstructuredGrid/></VTKFile>", "x.pvtu", fromMap(none), m, r),
      Status::NoTets, "lists no pieces");
  EXPECT_FAILS(readListing("<File version=\"pvtk-1.0\" dataType=\"vtkPolyData\"><Piece fileName=\"a.vtk\"/></File>",
                           "x.pvtk", fromMap(none), m, r),
               Status::Unsupported, "vtkPolyData");
  std::string deep = "<VTKFile type=\"vtkMultiBlockDataSet\"><vtkMultiBlockDataSet>";
  for (int k = 0; k < 200; ++k) deep += "<Block>";
  for (int k = 0; k < 200; ++k) deep += "</Block>";
  deep += "</vtkMultiBlockDataSet></VTKFile>";
  EXPECT_FAILS(readListing(deep, "x.vtm", fromMap(none), m, r), Status::Corrupt, "blocks nested deeper than 64");
  // A .vtm naming a listing: skipped, so there is nothing to read.
  const std::map<std::string, std::string> inner = {{"in.pvtu", twoPieceListing()}};
  EXPECT_FAILS(readListing("<VTKFile type=\"vtkMultiBlockDataSet\"><vtkMultiBlockDataSet><DataSet file=\"in.pvtu\"/>"
                           "</vtkMultiBlockDataSet></VTKFile>",
                           "x.vtm", fromMap(inner), m, r),
               Status::NoTets, "no block is a volume mesh");
  EXPECT_TRUE(hasNote(r, "block 0 (in.pvtu): PUnstructuredGrid")) << allNotes(r);
}

TEST(PartitionedReaders, RecognisedByContent) {
  Copy c("sniff");
  fs::copy_file(c.path("ghost.pvtu"), c.path("ghost.xml"));
  fs::copy_file(c.path("ghost.pvtu"), c.path("listing.vtu"));
  fs::copy_file(c.path("legacy.pvtk"), c.path("legacy.txt"));
  fs::copy_file(c.path("box.vtu"), c.path("box.pvtu"));  // a mesh under a listing's name
  for (const char* name : {"ghost.xml", "listing.vtu", "legacy.txt", "box.pvtu"}) {
    TetMesh m;
    ReadReport r;
    Result res = read(c.path(name), m, r);
    ASSERT_TRUE(res) << name << ": " << res.message;
    EXPECT_EQ(m.tetCount(), 324u) << name;
  }
}

}  // namespace
}  // namespace tetstream
