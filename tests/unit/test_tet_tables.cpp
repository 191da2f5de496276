// The tetrahedron tables checked by brute force against geometry.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "isosurface.h"
#include "tet_tables.h"
#include "test_helpers.h"

using namespace tetstream;

namespace {
const float kRef[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  // positive orientation

void sub(const float* a, const float* b, float* out) { for (int k = 0; k < 3; ++k) out[k] = a[k] - b[k]; }
void cross(const float* u, const float* v, float* out) {
  out[0] = u[1] * v[2] - u[2] * v[1]; out[1] = u[2] * v[0] - u[0] * v[2]; out[2] = u[0] * v[1] - u[1] * v[0];
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
