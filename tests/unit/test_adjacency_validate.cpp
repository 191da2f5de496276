// Face adjacency, boundary extraction and validation findings on tiny hand-made meshes.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "adjacency.h"
#include "io/generators.h"
#include "test_helpers.h"
#include "tet_tables.h"
#include "validate.h"

using namespace tetstream;

TEST(Adjacency, TwoTetsShareOneFace) {
  TetMesh m = test::twoTets();
  FaceAdjacency adj;
  buildFaceAdjacency(m.tets, m.vertexCount(), adj);
  int paired = 0;
  for (uint32_t h = 0; h < 8; ++h) {
    if (adj.opposite[h] == kNoNeighbor) continue;
    ++paired;
    EXPECT_EQ(adj.opposite[adj.opposite[h]], h) << "adjacency must be symmetric";
    EXPECT_NE(h / 4, adj.opposite[h] / 4);
  }
  EXPECT_EQ(paired, 2);
  std::vector<uint32_t> boundary;
  extractBoundary(m.tets, adj, boundary);
  EXPECT_EQ(boundary.size(), 6u * 3);
  EXPECT_EQ(countNonManifoldBoundaryEdges(boundary), 0u);
}

TEST(Adjacency, GridBoundaryIsClosedAndOutward) {
  const uint32_t n = 6;
  TetMesh m = makeGridMesh(n);
  FaceAdjacency adj;
  buildFaceAdjacency(m.tets, m.vertexCount(), adj);
  EXPECT_EQ(adj.nonManifoldFaces, 0u);
  std::vector<uint32_t> b;
  extractBoundary(m.tets, adj, b);
  EXPECT_EQ(b.size() / 3, size_t(6 * 2 * (n - 1) * (n - 1)));
  EXPECT_EQ(countNonManifoldBoundaryEdges(b), 0u);
  // Outward: the normal points away from the cube's centre.
  for (size_t i = 0; i < b.size(); i += 3) {
    const float* p0 = &m.positions[3 * b[i]];
    const float* p1 = &m.positions[3 * b[i + 1]];
    const float* p2 = &m.positions[3 * b[i + 2]];
    float u[3], v[3], c[3];
    for (int k = 0; k < 3; ++k) {
      u[k] = p1[k] - p0[k];
      v[k] = p2[k] - p0[k];
      c[k] = (p0[k] + p1[k] + p2[k]) / 3;
    }
    float nx = u[1] * v[2] - u[2] * v[1], ny = u[2] * v[0] - u[0] * v[2], nz = u[0] * v[1] - u[1] * v[0];
    EXPECT_GT(nx * c[0] + ny * c[1] + nz * c[2], 0);
  }
}

// Above 100,000 tets the faces are paired on two threads, each for half of the vertices.
TEST(Adjacency, LargeMeshPairsEveryFaceOnce) {
  const uint32_t n = 32;  // 178,746 tets
  TetMesh m = makeGridMesh(n);
  FaceAdjacency adj;
  buildFaceAdjacency(m.tets, m.vertexCount(), adj);
  EXPECT_EQ(adj.nonManifoldFaces, 0u);
  size_t boundary = 0;
  auto faceOf = [&](uint32_t h) {
    std::array<uint32_t, 3> f;
    for (int k = 0; k < 3; ++k) f[size_t(k)] = m.tets[4 * (h / 4) + kTetFaces[h % 4][k]];
    std::sort(f.begin(), f.end());
    return f;
  };
  for (uint32_t h = 0; h < adj.opposite.size(); ++h) {
    const uint32_t o = adj.opposite[h];
    if (o == kNoNeighbor) {
      ++boundary;
      continue;
    }
    ASSERT_EQ(adj.opposite[o], h);
    ASSERT_EQ(faceOf(o), faceOf(h));
  }
  EXPECT_EQ(boundary, size_t(12 * (n - 1) * (n - 1)));
  // A copy of an interior tet from each half of the numbering: four faces with three tets each.
  std::vector<uint32_t> interior;
  for (uint32_t t = 0; t < m.tetCount(); ++t)
    if (adj.opposite[4 * t] != kNoNeighbor && adj.opposite[4 * t + 1] != kNoNeighbor &&
        adj.opposite[4 * t + 2] != kNoNeighbor && adj.opposite[4 * t + 3] != kNoNeighbor)
      interior.push_back(t);
  for (uint32_t t : {interior[interior.size() / 8], interior[interior.size() * 7 / 8]})
    m.tets.insert(m.tets.end(), m.tets.begin() + 4 * t, m.tets.begin() + 4 * t + 4);
  buildFaceAdjacency(m.tets, m.vertexCount(), adj);
  EXPECT_EQ(adj.nonManifoldFaces, 8u);
}

TEST(Adjacency, ThreeTetsOnOneFaceAreNonManifold) {
  TetMesh m = test::twoTets();
  m.positions.insert(m.positions.end(), {2, 2, 2});
  m.tets.insert(m.tets.end(), {5, 1, 3, 2});
  FaceAdjacency adj;
  buildFaceAdjacency(m.tets, m.vertexCount(), adj);
  EXPECT_EQ(adj.nonManifoldFaces, 1u);
}

TEST(Validate, CleanGridHasNoFindings) {
  TetMesh m = makeGridMesh(5);
  addHarmonicField(m);
  ValidationReport r = validateMesh(m);
  EXPECT_TRUE(r.findings.empty()) << r.findings.front();
  EXPECT_FALSE(r.fatal());
  EXPECT_EQ(r.positiveTets, m.tetCount());
}

// Each kind of flaw counted once, on a small grid and on one large enough for the second thread
// (validate.cpp: the shapes and duplicates beside the faces from 10,000 tets).
TEST(Validate, ReportsEachKindOfFlaw) {
  for (uint32_t n : {4u, 20u}) {  // 162 and 41,154 tets
    TetMesh m = makeGridMesh(n);
    addHarmonicField(m);
    const uint32_t middle = 4 * (m.tetCount() / 2);
    std::swap(m.tets[middle + 2], m.tets[middle + 3]);                    // one inverted tet
    m.tets.insert(m.tets.end(), m.tets.begin() + 4, m.tets.begin() + 8);  // a duplicate
    m.positions.insert(m.positions.end(), {5, 5, 5});                     // an unused vertex
    m.fields[0].values.push_back(std::numeric_limits<float>::quiet_NaN());
    // A flat tet: four coplanar vertices of the grid's bottom face.
    m.tets.insert(m.tets.end(), {0, 1, n, n + 1});
    ValidationReport r = validateMesh(m);
    EXPECT_EQ(r.invertedTets, 1u) << n;
    EXPECT_EQ(r.duplicateTets, 1u) << n;
    EXPECT_EQ(r.unusedVertices, 1u) << n;
    EXPECT_EQ(r.nonFiniteFieldValues, 1u) << n;
    EXPECT_EQ(r.zeroVolumeTets, 1u) << n;
    EXPECT_EQ(r.positiveTets + r.negativeTets + r.zeroVolumeTets, m.tetCount()) << n;
    EXPECT_FALSE(r.fatal()) << n;
    EXPECT_GE(r.findings.size(), 5u) << n;
  }
}

TEST(Validate, CountsNonManifoldBoundaryEdges) {
  // Two tets meeting in an edge only: four boundary triangles share it.
  TetMesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1};
  m.tets = {0, 1, 2, 3, 0, 1, 4, 5};
  EXPECT_EQ(validateMesh(m).nonManifoldBoundaryEdges, 1u);
  // Triangles alone: an open one has three edges with one triangle each; a closed
  // tetrahedron's surface none.
  const std::vector<uint32_t> open = {7, 3, 9};
  EXPECT_EQ(countNonManifoldBoundaryEdges(open), 3u);
  const std::vector<uint32_t> closed = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2};
  EXPECT_EQ(countNonManifoldBoundaryEdges(closed), 0u);
  EXPECT_EQ(countNonManifoldBoundaryEdges(std::vector<uint32_t>{}), 0u);
}

TEST(Validate, FatalFlaws) {
  TetMesh a = test::oneTet();
  a.tets[3] = 99;
  EXPECT_EQ(validateMesh(a).outOfRangeIndices, 1u);
  EXPECT_TRUE(validateMesh(a).fatal());

  TetMesh b = test::oneTet();
  b.positions[4] = std::numeric_limits<float>::infinity();
  EXPECT_EQ(validateMesh(b).nonFinitePositions, 1u);
  EXPECT_TRUE(validateMesh(b).fatal());

  TetMesh c = test::oneTet();
  c.tets[3] = c.tets[0];
  EXPECT_EQ(validateMesh(c).repeatedVertexTets, 1u);

  TetMesh d = test::oneTet();
  d.tets.clear();
  EXPECT_TRUE(validateMesh(d).noTets);
  EXPECT_TRUE(validateMesh(d).fatal());
}
