// Marching tetrahedra on whole meshes: closedness, orientation, convergence, exact values.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>

#include "io/generators.h"
#include "isosurface.h"
#include "test_helpers.h"

using namespace tetstream;

namespace {

struct Topology {
  long vertices = 0, edges = 0, faces = 0, boundaryEdges = 0, nonManifoldEdges = 0;
  long euler() const { return vertices - edges + faces; }
};

Topology topology(const IsoSurface& s) {
  std::map<std::pair<uint32_t, uint32_t>, int> edgeUse;
  for (size_t i = 0; i < s.indices.size(); i += 3)
    for (int k = 0; k < 3; ++k) {
      uint32_t a = s.indices[i + k], b = s.indices[i + (k + 1) % 3];
      edgeUse[{std::min(a, b), std::max(a, b)}]++;
    }
  Topology t;
  t.vertices = s.vertexCount();
  t.faces = s.triangleCount();
  t.edges = long(edgeUse.size());
  for (auto& [e, n] : edgeUse) {
    t.boundaryEdges += n == 1;
    t.nonManifoldEdges += n > 2;
  }
  return t;
}

IsoSurface sphere(uint32_t n, float r) {
  TetMesh m = makeGridMesh(n);
  addDistanceField(m);
  IsoExtractor x;
  IsoSurface s;
  extractIsosurface(m, m.fields[0].values, r, x, s);
  return s;
}

}  // namespace

TEST(Isosurface, SphereIsClosedWithEulerCharacteristicTwo) {
  for (uint32_t n : {9u, 16u, 33u}) {
    IsoSurface s = sphere(n, 0.6f);
    Topology t = topology(s);
    EXPECT_EQ(t.boundaryEdges, 0) << "n=" << n;
    EXPECT_EQ(t.nonManifoldEdges, 0) << "n=" << n;
    EXPECT_EQ(t.euler(), 2) << "n=" << n;
  }
}

TEST(Isosurface, SphereAreaConvergesToFourPiRSquared) {
  const double r = 0.6, exact = 4 * std::numbers::pi * r * r;
  double prevErr = 1e9;
  for (uint32_t n : {9u, 17u, 33u, 65u}) {
    double err = std::abs(surfaceArea(sphere(n, float(r))) - exact) / exact;
    EXPECT_LT(err, prevErr) << "error must shrink as the mesh is refined (n=" << n << ")";
    prevErr = err;
  }
  EXPECT_LT(prevErr, 0.01);
}

TEST(Isosurface, NormalsPointTowardIncreasingField) {
  IsoSurface s = sphere(17, 0.5f);
  ASSERT_GT(s.vertexCount(), 0u);
  for (uint32_t v = 0; v < s.vertexCount(); ++v) {
    const float* p = &s.positions[3 * v];
    const float* n = &s.normals[3 * v];
    EXPECT_GT(p[0] * n[0] + p[1] * n[1] + p[2] * n[2], 0) << "distance grows outward, so normals point out";
    EXPECT_NEAR(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1.0, 1e-5);
  }
}

TEST(Isosurface, VerticesLieOnTheIsovalueByLinearInterpolation) {
  TetMesh m = makeGridMesh(9);
  // A linear field is reproduced exactly by the piecewise-linear interpolant (paper eq. 7).
  ScalarField f{"lin", {}};
  for (uint32_t v = 0; v < m.vertexCount(); ++v)
    f.values.push_back(m.positions[3 * v] + 2 * m.positions[3 * v + 1] + 3 * m.positions[3 * v + 2]);
  m.fields.push_back(f);
  IsoExtractor x;
  IsoSurface s;
  extractIsosurface(m, m.fields[0].values, 0.7f, x, s);
  ASSERT_GT(s.vertexCount(), 0u);
  for (uint32_t v = 0; v < s.vertexCount(); ++v) {
    const float* p = &s.positions[3 * v];
    EXPECT_NEAR(p[0] + 2 * p[1] + 3 * p[2], 0.7, 1e-5);
  }
}

// Vertex values equal to the isovalue: the plane x = 0 passes through a grid layer exactly.
// The surface is the exact 2×2 square, without degenerate triangles or duplicated vertices.
TEST(Isosurface, ValuesExactlyAtTheIsovalueAreWellDefined) {
  TetMesh m = makeGridMesh(9);  // x = -1 + k/4: the layer k = 4 is exactly 0
  ScalarField f{"x", {}};
  for (uint32_t v = 0; v < m.vertexCount(); ++v) f.values.push_back(m.positions[3 * v]);
  m.fields.push_back(f);
  IsoExtractor x;
  IsoSurface s;
  extractIsosurface(m, m.fields[0].values, 0.0f, x, s);
  EXPECT_NEAR(surfaceArea(s), 4.0, 1e-5);
  EXPECT_EQ(s.vertexCount(), 81u) << "one surface vertex per grid vertex on the plane";
  for (size_t i = 0; i < s.indices.size(); i += 3) {
    EXPECT_NE(s.indices[i], s.indices[i + 1]);
    EXPECT_NE(s.indices[i + 1], s.indices[i + 2]);
    EXPECT_NE(s.indices[i], s.indices[i + 2]);
  }
  Topology t = topology(s);
  EXPECT_EQ(t.nonManifoldEdges, 0);
  EXPECT_EQ(t.euler(), 1) << "a disc";
}

TEST(Isosurface, NegativelyOrientedTetsGiveTheSameOrientedSurface) {
  TetMesh m = makeGridMesh(9);
  addDistanceField(m);
  IsoExtractor x;
  IsoSurface a, b;
  extractIsosurface(m, m.fields[0].values, 0.5f, x, a);
  for (uint32_t t = 0; t < m.tetCount(); ++t) std::swap(m.tets[4 * t + 2], m.tets[4 * t + 3]);
  extractIsosurface(m, m.fields[0].values, 0.5f, x, b);
  EXPECT_NEAR(surfaceArea(a), surfaceArea(b), 1e-9);
  ASSERT_EQ(a.vertexCount(), b.vertexCount());
  ASSERT_EQ(a.triangleCount(), b.triangleCount());
  for (uint32_t v = 0; v < b.vertexCount(); ++v) {
    const float* p = &b.positions[3 * v];
    const float* n = &b.normals[3 * v];
    EXPECT_GT(p[0] * n[0] + p[1] * n[1] + p[2] * n[2], 0);
  }
}

TEST(Isosurface, SubsetOfAllTetsEqualsFullExtraction) {
  TetMesh m = makeGridMesh(9);
  addHarmonicField(m);
  std::vector<uint32_t> all(m.tetCount());
  for (uint32_t t = 0; t < m.tetCount(); ++t) all[t] = t;
  IsoExtractor x;
  IsoSurface a, b;
  extractIsosurface(m, m.fields[0].values, 0.1f, x, a);
  extractIsosurface(m, m.fields[0].values, 0.1f, x, b, all);
  EXPECT_EQ(a.indices, b.indices);
  EXPECT_EQ(a.positions, b.positions);
}

TEST(Isosurface, IsovalueOutsideTheRangeGivesNothing) {
  TetMesh m = makeGridMesh(5);
  addHarmonicField(m);
  IsoExtractor x;
  IsoSurface s;
  extractIsosurface(m, m.fields[0].values, 5.0f, x, s);
  EXPECT_EQ(s.triangleCount(), 0u);
  extractIsosurface(m, m.fields[0].values, -5.0f, x, s);
  EXPECT_EQ(s.triangleCount(), 0u);
}
