// Mesh writers (core/io/mesh_io.h: .vtu; core/io/ply_writer.h): our .vtu round-trips exactly
// through our reader and reads in meshio and VTK; the isosurface's .ply is binary with normals.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "io/generators.h"
#include "io/mesh_io.h"
#include "io/ply_writer.h"
#include "quantize.h"
#include "test_helpers.h"

namespace tetstream {
namespace {

using test::fixturePath;
using test::loadFile;

TetMesh oddMesh() {
  TetMesh m = makeGridMesh(4);
  ScalarField a{"a & <b> \"c\"", {}}, b{"plain", {}};
  for (uint32_t v = 0; v < m.vertexCount(); ++v) {
    a.values.push_back(float(v) * 0.25f - 3.f);
    b.values.push_back(std::sin(float(v)));
  }
  m.fields = {a, b};
  return m;
}

void expectSameMesh(const TetMesh& a, const TetMesh& b) {
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.tets, b.tets);
  ASSERT_EQ(a.fields.size(), b.fields.size());
  for (size_t i = 0; i < a.fields.size(); ++i) {
    EXPECT_EQ(a.fields[i].name, b.fields[i].name);
    EXPECT_EQ(a.fields[i].values, b.fields[i].values);
  }
}

TEST(VtuWriter, RoundTripIsExact) {
  test::ScratchDir scratch("vtu-roundtrip");
  const std::string& dir = scratch.path;
  TetMesh fromFixture;
  ReadReport fr;
  ASSERT_TRUE(readMesh(fixturePath("mixed_quadratic.vtu"), fromFixture, fr));
  for (const TetMesh& src : {oddMesh(), fromFixture}) {
    std::string path = dir + "/out.vtu";
    ASSERT_TRUE(writeMesh(path, src));
    TetMesh back;
    ReadReport r;
    Result res = readMesh(path, back, r);
    ASSERT_TRUE(res) << res.message;
    expectSameMesh(src, back);
    EXPECT_NE(r.format.find("appended raw, UInt64 header"), std::string::npos) << r.format;
  }
}

TEST(VtuWriter, RejectsInconsistentMeshAndOtherExtensions) {
  test::ScratchDir scratch("vtu-bad");
  const std::string& dir = scratch.path;
  TetMesh m = makeGridMesh(2);
  m.fields.push_back({"short", {1, 2}});
  Result r = writeMesh(dir + "/a.vtu", m);
  EXPECT_EQ(r.status, Status::BadArgument);
  EXPECT_NE(r.message.find("'short'"), std::string::npos) << r.message;
  EXPECT_EQ(writeMesh(dir + "/a.obj", makeGridMesh(2)).status, Status::Unsupported);
  EXPECT_EQ(writeMesh(dir + "/no/such/dir/a.vtu", makeGridMesh(2)).status, Status::IoError);
}

// The mesh as the pieces of a parallel run: read back (pieces welded at their shared points) it
// is the same mesh; every piece is a .vtu of its own.
TEST(VtuWriter, PiecesOfAParallelRunReadBackAsTheMesh) {
  test::ScratchDir scratch("pvtu-pieces");
  TetMesh m = makeGridMesh(9);
  addHarmonicField(m);
  ASSERT_TRUE(writeMesh(scratch.path + "/h.pvtu", m, 3));
  TetMesh back;
  ReadReport r;
  ASSERT_TRUE(readMesh(scratch.path + "/h.pvtu", back, r));
  EXPECT_NE(r.format.find("3 pieces"), std::string::npos) << r.format;
  Manifest q;
  q.bounds = computeBounds(m.positions);
  q.fields.push_back({"harmonic", computeRange(m.fields[0].values)});
  test::expectSameMesh(m, back, makeQuantizer(q), true);
  for (int k = 0; k < 3; ++k) {
    TetMesh piece;
    ReadReport pr;
    ASSERT_TRUE(readMesh(scratch.path + "/h/h_" + std::to_string(k) + ".vtu", piece, pr));
    EXPECT_GT(piece.tetCount(), m.tetCount() / 4);
    EXPECT_LT(piece.tetCount(), m.tetCount() / 2);
  }
  EXPECT_EQ(writeMesh(scratch.path + "/a.obj", m, 3).status, Status::Unsupported);
}

// Independent readers (meshio, VTK) see what we wrote.
TEST(VtuWriter, MeshioAndVtkReadOurFile) {
  if (!test::haveMeshioPython()) GTEST_SKIP() << "/usr/bin/python3 with meshio not available";
  test::ScratchDir scratch("vtu-meshio");
  const std::string& dir = scratch.path;
  TetMesh m = oddMesh();
  ASSERT_TRUE(writeMesh(dir + "/m.vtu", m));
  double sum = 0;
  for (float f : m.fields[1].values) sum += f;
  std::string out;
  int rc = test::runCommand(
      "/usr/bin/python3 -c \"import meshio, sys; m = meshio.read(sys.argv[1]); "
      "print(len(m.points), sum(len(c.data) for c in m.cells if c.type == 'tetra'), "
      "len(m.point_data), float(m.point_data['plain'].sum()))\" " +
          dir + "/m.vtu 2>&1",
      out);
  ASSERT_EQ(rc, 0) << out;
  unsigned nv = 0, nt = 0, nf = 0;
  double s = 0;
  ASSERT_EQ(std::sscanf(out.c_str(), "%u %u %u %lf", &nv, &nt, &nf, &s), 4) << out;
  EXPECT_EQ(nv, m.vertexCount());
  EXPECT_EQ(nt, m.tetCount());
  EXPECT_EQ(nf, 2u);
  EXPECT_NEAR(s, sum, 1e-3);

  rc = test::runCommand(
      "/usr/bin/python3 -c \"import vtk, sys; r = vtk.vtkXMLUnstructuredGridReader(); r.SetFileName(sys.argv[1]); "
      "r.Update(); g = r.GetOutput(); print(g.GetNumberOfPoints(), g.GetNumberOfCells(), "
      "g.GetPointData().GetNumberOfArrays())\" " +
          dir + "/m.vtu 2>&1",
      out);
  if (rc != 0) GTEST_SKIP() << "python3 vtk not usable: " << out;
  ASSERT_EQ(std::sscanf(out.c_str(), "%u %u %u", &nv, &nt, &nf), 3) << out;
  EXPECT_EQ(nv, m.vertexCount());
  EXPECT_EQ(nt, m.tetCount());
  EXPECT_EQ(nf, 2u);
}

// The paper-scale mesh (64^3 grid, 1.5M tets) writes and reads back exactly. The times are
// recorded as test properties, not asserted: a busy machine must not fail the suite.
TEST(VtuWriter, LargeMeshRoundTrip) {
  test::ScratchDir scratch("vtu-large");
  const std::string& dir = scratch.path;
  TetMesh m = makeGridMesh(64);
  addHarmonicField(m);
  ASSERT_EQ(m.tetCount(), 1500282u);
  auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(writeMesh(dir + "/big.vtu", m));
  auto t1 = std::chrono::steady_clock::now();
  TetMesh back;
  ReadReport r;
  ASSERT_TRUE(readMesh(dir + "/big.vtu", back, r));
  auto t2 = std::chrono::steady_clock::now();
  expectSameMesh(m, back);
  auto ms = [](auto a, auto b) { return std::chrono::duration<double, std::milli>(b - a).count(); };
  RecordProperty("write_ms", int(ms(t0, t1)));
  RecordProperty("read_ms", int(ms(t1, t2)));
  std::printf("[   info   ] 1.5M tets: write %.0f ms, read %.0f ms\n", ms(t0, t1), ms(t1, t2));
}

TEST(PlyWriter, WritesBinaryPlyWithNormals) {
  test::ScratchDir scratch("ply");
  const std::string& dir = scratch.path;
  std::vector<float> pos = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::vector<float> nrm = {0, 0, 1, 0, 0, 1, 0, 0, 1, 1, 0, 0};
  std::vector<uint32_t> tri = {0, 1, 2, 0, 2, 3};
  ASSERT_TRUE(writePly(dir + "/s.ply", pos, nrm, tri));
  std::string b = loadFile(dir + "/s.ply");
  size_t end = b.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  std::string header = b.substr(0, end);
  EXPECT_EQ(header.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  EXPECT_NE(header.find("element vertex 4\n"), std::string::npos);
  EXPECT_NE(header.find("property float nz\n"), std::string::npos);
  EXPECT_NE(header.find("element face 2\nproperty list uchar uint vertex_indices\n"), std::string::npos);
  const char* body = b.data() + end + 11;
  ASSERT_EQ(b.size() - (end + 11), 4 * 24 + 2 * 13u);
  float v3[6];
  std::memcpy(v3, body + 3 * 24, 24);
  EXPECT_EQ(v3[2], 1.f);
  EXPECT_EQ(v3[3], 1.f);
  const char* face1 = body + 4 * 24 + 13;
  EXPECT_EQ(uint8_t(face1[0]), 3);
  uint32_t ids[3];
  std::memcpy(ids, face1 + 1, 12);
  EXPECT_EQ(ids[2], 3u);

  ASSERT_TRUE(writePly(dir + "/n.ply", pos, {}, tri));  // normals are optional
  EXPECT_EQ(loadFile(dir + "/n.ply").find("property float nx"), std::string::npos);
  EXPECT_EQ(writePly(dir + "/bad.ply", pos, nrm, std::vector<uint32_t>{0, 1, 9}).status, Status::BadArgument);
  EXPECT_EQ(writePly(dir + "/bad.ply", pos, std::vector<float>{0, 0, 1}, tri).status, Status::BadArgument);
  EXPECT_EQ(writePly(dir + "/no/dir/x.ply", pos, nrm, tri).status, Status::IoError);

  if (!test::haveMeshioPython()) return;
  std::string out;
  int rc = test::runCommand(
      "/usr/bin/python3 -c \"import meshio, sys; m = meshio.read(sys.argv[1]); "
      "print(len(m.points), len(m.cells[0].data))\" " +
          dir + "/s.ply 2>&1",
      out);
  ASSERT_EQ(rc, 0) << out;
  EXPECT_EQ(out, "4 2\n");
}

}  // namespace
}  // namespace tetstream
