// The tetrahedron tables checked by brute force against geometry.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

#include "isosurface.h"
#include "test_helpers.h"
#include "tet_quality.h"
#include "tet_tables.h"

using namespace tetstream;

namespace {
const float kRef[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  // positive orientation

void sub(const float* a, const float* b, float* out) {
  for (int k = 0; k < 3; ++k) out[k] = a[k] - b[k];
}
void cross(const float* u, const float* v, float* out) {
  out[0] = u[1] * v[2] - u[2] * v[1];
  out[1] = u[2] * v[0] - u[0] * v[2];
  out[2] = u[0] * v[1] - u[1] * v[0];
}
float dot(const float* u, const float* v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; }
}  // namespace

TEST(TetTables, EdgesAreTheSixPairs) {
  std::set<std::pair<int, int>> seen;
  for (const auto& e : kTetEdges) {
    EXPECT_LT(e[0], e[1]);
    seen.insert({e[0], e[1]});
  }
  EXPECT_EQ(seen.size(), 6u);
}

TEST(TetTables, FacesAreOppositeAndOutward) {
  ASSERT_GT(tetVolume(kRef[0], kRef[1], kRef[2], kRef[3]), 0);
  for (int f = 0; f < 4; ++f) {
    const uint8_t* v = kTetFaces[f];
    for (int k = 0; k < 3; ++k) EXPECT_NE(v[k], f) << "face " << f << " must not contain its opposite vertex";
    float u[3], w[3], n[3], out[3];
    sub(kRef[v[1]], kRef[v[0]], u);
    sub(kRef[v[2]], kRef[v[0]], w);
    cross(u, w, n);
    sub(kRef[v[0]], kRef[f], out);  // from the opposite vertex to the face
    EXPECT_GT(dot(n, out), 0) << "face " << f << " normal must point outward";
  }
}

// For every sign case: the triangles cover exactly the cut edges, each triangle is proper, and
// its normal points toward the vertices above the isovalue (increasing field).
TEST(TetTables, MarchingCasesMatchBruteForce) {
  for (unsigned mask = 0; mask < 16; ++mask) {
    std::set<int> cut;
    for (int e = 0; e < 6; ++e) {
      bool a = mask >> kTetEdges[e][0] & 1, b = mask >> kTetEdges[e][1] & 1;
      if (a != b) cut.insert(e);
    }
    const MarchingCase& mc = kMarchingTets[mask];
    ASSERT_EQ(mc.triangleCount, cut.size() == 0 ? 0 : cut.size() == 3 ? 1 : 2) << "mask " << mask;
    std::set<int> used;
    float s[4];
    for (int i = 0; i < 4; ++i) s[i] = (mask >> i & 1) ? 1.0f : 0.0f;
    // Field gradient of the linear interpolant on the reference tet: s = s0 + g·p.
    float g[3] = {s[1] - s[0], s[2] - s[0], s[3] - s[0]};
    for (int t = 0; t < mc.triangleCount; ++t) {
      float p[3][3];
      std::set<int> tri;
      for (int k = 0; k < 3; ++k) {
        int e = mc.edges[3 * t + k];
        ASSERT_TRUE(cut.count(e)) << "mask " << mask << " uses an uncut edge";
        tri.insert(e);
        used.insert(e);
        for (int c = 0; c < 3; ++c) p[k][c] = 0.5f * (kRef[kTetEdges[e][0]][c] + kRef[kTetEdges[e][1]][c]);
      }
      EXPECT_EQ(tri.size(), 3u);
      float u[3], w[3], n[3];
      sub(p[1], p[0], u);
      sub(p[2], p[0], w);
      cross(u, w, n);
      EXPECT_GT(dot(n, g), 0) << "mask " << mask << " triangle " << t << " faces the wrong way";
    }
    EXPECT_EQ(used, cut) << "mask " << mask;
  }
}

// Each case, extracted on one tet with values equal to, above and below λ.
TEST(TetTables, SingleTetEveryCaseThroughExtraction) {
  for (unsigned mask = 0; mask < 16; ++mask) {
    TetMesh m = test::oneTet();
    for (int i = 0; i < 4; ++i) m.fields[0].values[i] = (mask >> i & 1) ? 1.0f : -1.0f;
    IsoExtractor x;
    IsoSurface s;
    extractIsosurface(m, m.fields[0].values, 0.0f, x, s);
    EXPECT_EQ(s.triangleCount(), kMarchingTets[mask].triangleCount) << mask;
    if (s.triangleCount()) {
      EXPECT_GT(surfaceArea(s), 0.0);
    }
  }
}

// The closed form of κ(S) (tet_quality.h) against the paper's definition: S = A·W⁻¹,
// κ = ‖S‖_F ‖S⁻¹‖_F, with W mapping the right-angled reference tet onto the equilateral one.
TEST(TetQuality, ConditionNumberMatchesTheMatrixDefinition) {
  auto inverse = [](const double m[3][3], double out[3][3]) {
    double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                 m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        int r1 = (c + 1) % 3, r2 = (c + 2) % 3, c1 = (r + 1) % 3, c2 = (r + 2) % 3;
        out[r][c] = (m[r1][c1] * m[r2][c2] - m[r1][c2] * m[r2][c1]) / det;
      }
  };
  auto frob = [](const double m[3][3]) {
    double s = 0;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) s += m[r][c] * m[r][c];
    return std::sqrt(s);
  };
  const double W[3][3] = {{1, 0.5, 0.5}, {0, std::sqrt(3.0) / 2, std::sqrt(3.0) / 6}, {0, 0, std::sqrt(2.0 / 3.0)}};
  double Winv[3][3];
  inverse(W, Winv);
  uint64_t seed = 12345;
  auto rnd = [&] {
    seed = seed * 6364136223846793005ull + 1442695040888963407ull;
    return double(seed >> 11) / double(1ull << 53) - 0.5;
  };
  for (int trial = 0; trial < 200; ++trial) {
    double p[4][3];
    for (auto& v : p)
      for (double& x : v) x = rnd();
    double A[3][3], S[3][3] = {}, Sinv[3][3];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) A[r][c] = p[c + 1][r] - p[0][r];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 3; ++k) S[r][c] += A[r][k] * Winv[k][c];
    inverse(S, Sinv);
    double expected = frob(S) * frob(Sinv);
    EXPECT_NEAR(tetConditionNumber(p[0], p[1], p[2], p[3]), expected, 1e-9 * expected);
    TetShape shape = tetShape(p[0], p[1], p[2], p[3]);
    EXPECT_NEAR(shape.kappa(), expected, 1e-9 * expected);
    EXPECT_NEAR(shape.det / 6,
                tetVolume(std::array<float, 3>{float(p[0][0]), float(p[0][1]), float(p[0][2])}.data(),
                          std::array<float, 3>{float(p[1][0]), float(p[1][1]), float(p[1][2])}.data(),
                          std::array<float, 3>{float(p[2][0]), float(p[2][1]), float(p[2][2])}.data(),
                          std::array<float, 3>{float(p[3][0]), float(p[3][1]), float(p[3][2])}.data()),
                1e-6);
  }
  const double regular[4][3] = {
      {0, 0, 0}, {1, 0, 0}, {0.5, std::sqrt(3.0) / 2, 0}, {0.5, std::sqrt(3.0) / 6, std::sqrt(2.0 / 3.0)}};
  EXPECT_NEAR(tetConditionNumber(regular[0], regular[1], regular[2], regular[3]), 3.0, 1e-12) << "equilateral: κ = 3";
}
