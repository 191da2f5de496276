// Colour by field (wasm/colourmap.h and the colour channel of IncrementalIsosurface): the colour
// maps against their published tables (ends, middles, clamping), and the colour interpolated at
// each surface vertex kept up to date through real vertex splits. The slice plane
// (core/slice.h): exact polygons and areas of planes through a cube mesh, and the slice kept by
// local updates through splits and undos equal to one extracted from scratch.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "colourmap.h"
#include "dataset.h"
#include "io/generators.h"
#include "isosurface.h"
#include "isosurface_incremental.h"
#include "pack/packer.h"
#include "slice.h"
#include "test_helpers.h"

using namespace tetstream;
using namespace tetstream::viewer;

namespace {

// 0..255 as the published tables round them.
std::array<int, 3> rgb255(ColourMap m, float v, float lo = 0, float hi = 1) {
  auto c = mapColour(m, v, lo, hi);
  return {int(std::lround(255 * c[0])), int(std::lround(255 * c[1])), int(std::lround(255 * c[2]))};
}

void expectRgb(ColourMap m, float v, std::array<int, 3> want, float lo = 0, float hi = 1) {
  auto got = rgb255(m, v, lo, hi);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(got[size_t(k)], want[size_t(k)], 1) << colourMapName(m) << " at " << v << " channel " << k;
}

}  // namespace

// Reference colours: matplotlib's viridis/magma/turbo/coolwarm at 0, 0.5 and 1 (as hex in its
// documentation: viridis #440154, #21918c, #fde725; magma #000004, #b73779, #fcfdbf; turbo
// #30123b, #a4fc3c (0.5), #7a0403; coolwarm #3b4cc0, #dddddd (0.5), #b40426).
TEST(ColourMap, EndsAndMiddlesOfEachMap) {
  expectRgb(ColourMap::Viridis, 0, {0x44, 0x01, 0x54});
  expectRgb(ColourMap::Viridis, 0.5f, {0x21, 0x91, 0x8c});
  expectRgb(ColourMap::Viridis, 1, {0xfd, 0xe7, 0x25});
  expectRgb(ColourMap::Magma, 0, {0x00, 0x00, 0x04});
  expectRgb(ColourMap::Magma, 0.5f, {0xb7, 0x37, 0x79});
  expectRgb(ColourMap::Magma, 1, {0xfc, 0xfd, 0xbf});
  expectRgb(ColourMap::Turbo, 0, {0x30, 0x12, 0x3b});
  expectRgb(ColourMap::Turbo, 0.5f, {0xa4, 0xfc, 0x3c});
  expectRgb(ColourMap::Turbo, 1, {0x7a, 0x04, 0x03});
  expectRgb(ColourMap::CoolWarm, 0, {0x3b, 0x4c, 0xc0});
  expectRgb(ColourMap::CoolWarm, 0.5f, {0xdd, 0xdd, 0xdd});
  expectRgb(ColourMap::CoolWarm, 1, {0xb4, 0x04, 0x26});
  expectRgb(ColourMap::Grey, 0, {0, 0, 0});
  expectRgb(ColourMap::Grey, 0.5f, {128, 128, 128});
  expectRgb(ColourMap::Grey, 1, {255, 255, 255});
}

TEST(ColourMap, RangeMapsAndClamps) {
  for (int i = 0; i < kColourMapCount; ++i) {
    const ColourMap m = ColourMap(i);
    // The range [-2, 6]: its ends and middle are the map's ends and middle.
    EXPECT_EQ(rgb255(m, -2, -2, 6), rgb255(m, 0));
    EXPECT_EQ(rgb255(m, 2, -2, 6), rgb255(m, 0.5f));
    EXPECT_EQ(rgb255(m, 6, -2, 6), rgb255(m, 1));
    // Outside: the end colours.
    EXPECT_EQ(rgb255(m, -100, -2, 6), rgb255(m, 0));
    EXPECT_EQ(rgb255(m, 1e30f, -2, 6), rgb255(m, 1));
    EXPECT_EQ(rgb255(m, -INFINITY, -2, 6), rgb255(m, 0));
    // An empty range gives the middle, never a NaN.
    auto c = mapColour(m, 3, 1, 1);
    for (float x : c) EXPECT_TRUE(std::isfinite(x));
    EXPECT_EQ(parseColourMap(colourMapName(m)), m);
  }
  EXPECT_FLOAT_EQ(colourPosition(0.25f, 0, 1), 0.25f);
  EXPECT_FLOAT_EQ(colourPosition(-1, 0, 1), 0.f);
  EXPECT_FLOAT_EQ(colourPosition(2, 0, 1), 1.f);
  EXPECT_EQ(parseColourMap("gray"), ColourMap::Grey);
  EXPECT_EQ(parseColourMap("cool-warm"), ColourMap::CoolWarm);
  EXPECT_FALSE(parseColourMap("jet").has_value());
}

namespace {

// Packs a Harmonic grid with an extra field "x" (the x coordinate) and loads every chunk.
struct StreamedGrid {
  test::ScratchDir dir{"colour-slice"};
  Dataset ds;
  explicit StreamedGrid(uint32_t n) {
    TetMesh m = makeGridMesh(n);
    addHarmonicField(m);
    ScalarField x{"x", {}};
    for (uint32_t v = 0; v < m.vertexCount(); ++v) x.values.push_back(m.positions[3 * size_t(v)]);
    m.fields.push_back(std::move(x));
    PackOptions o;
    o.chunkKb = 1;
    o.zstdLevel = 3;
    PackSummary s;
    EXPECT_TRUE(packMesh(m, dir.path, o, s));
    EXPECT_TRUE(loadPackedDir(dir.path, ds, 1));
    for (uint32_t c = 1; c < ds.manifest.chunks.size(); ++c)
      EXPECT_TRUE(receiveChunk(ds, c, test::loadBytes(dir.path + "/" + ds.manifest.chunks[c].file)));
  }
  std::span<const float> field(const char* name) const {
    int f = ds.pm.mesh.findField(name);
    return ds.pm.mesh.fields[size_t(f)].values;
  }
};

// Every live surface vertex's colour against `expected(position)`.
template <class F>
void expectColours(const IncrementalIsosurface& inc, F expected, float tolerance, const std::string& where) {
  ASSERT_EQ(inc.colours().size(), inc.vertexSlotCount());
  // Check the used vertices (those of live triangles): their slots are live.
  int bad = 0;
  for (uint32_t i : inc.indices()) {
    const float* p = &inc.positions()[3 * size_t(i)];
    const float want = expected(p);
    if (std::abs(inc.colours()[i] - want) > tolerance && ++bad < 5)
      ADD_FAILURE() << where << ": vertex " << i << " colour " << inc.colours()[i] << " expected " << want;
  }
}

}  // namespace

// The colour of a surface vertex is the colour field interpolated along its cut edge with the
// position's weights: a linear colour field (x) gives exactly the vertex's x; the iso field
// itself gives the isovalue. Kept so through splits, undos and recolour().
TEST(ColourField, InterpolatedAtSurfaceVerticesThroughSplits) {
  StreamedGrid g(10);
  Dataset& ds = g.ds;
  const float iso = 0.2f;
  IncrementalIsosurface inc;
  std::vector<uint32_t> changed;
  bool reached = false;
  ASSERT_TRUE(stepTowards(ds, 0, ~0u, changed, &reached));
  inc.rebuild(ds.pm.mesh, g.field("harmonic"), iso, g.field("x"));
  auto isX = [](const float* p) { return p[0]; };
  expectColours(inc, isX, 1e-5f, "base");
  const uint32_t total = ds.splitsReceived();
  for (uint32_t target : {total, total / 3}) {
    const uint32_t stride = target < ds.splitsApplied() ? 13 : 7;
    while (ds.splitsApplied() != target) {
      changed.clear();
      ASSERT_TRUE(stepTowards(ds, target, stride, changed, &reached));
      inc.updateTets(ds.pm.mesh, g.field("harmonic"), changed, g.field("x"));
    }
    expectColours(inc, isX, 1e-5f, "at " + std::to_string(ds.splitsApplied()) + " splits");
  }
  // Another colour field for the same surface: the isovalue's own field.
  inc.recolour(g.field("harmonic"));
  EXPECT_TRUE(inc.fullUploadNeeded());
  expectColours(
      inc, [&](const float*) { return iso; }, 1e-5f, "recoloured by the iso field");
  inc.recolour({});
  expectColours(
      inc, [](const float*) { return 0.f; }, 0.f, "no colour field");
  inc.recolour(g.field("x"));
  expectColours(inc, isX, 1e-5f, "recoloured by x");
  inc.compact();
  expectColours(inc, isX, 1e-5f, "compacted");
  EXPECT_TRUE(inc.validate());
}

// ------------------------------------------------------------------ slice plane

namespace {

// The outline of a slice: its boundary edges (used by one triangle) as corner position pairs.
std::vector<std::array<float, 6>> boundaryEdges(const IncrementalIsosurface& s) {
  std::map<std::pair<uint32_t, uint32_t>, int> count;
  auto idx = s.indices();
  for (size_t t = 0; t < idx.size(); t += 3)
    for (int k = 0; k < 3; ++k) {
      uint32_t a = idx[t + size_t(k)], b = idx[t + size_t((k + 1) % 3)];
      ++count[{std::min(a, b), std::max(a, b)}];
    }
  std::vector<std::array<float, 6>> out;
  auto pos = s.positions();
  for (auto& [e, n] : count)
    if (n == 1) {
      std::array<float, 6> seg;
      for (int k = 0; k < 3; ++k) {
        seg[size_t(k)] = pos[3 * size_t(e.first) + size_t(k)];
        seg[size_t(k) + 3] = pos[3 * size_t(e.second) + size_t(k)];
      }
      out.push_back(seg);
    }
  return out;
}

// Distance from point p to the polygon outline (closed, corners in order).
double distanceToOutline(const float* p, const std::vector<std::array<double, 3>>& poly) {
  double best = 1e30;
  for (size_t i = 0; i < poly.size(); ++i) {
    const auto& a = poly[i];
    const auto& b = poly[(i + 1) % poly.size()];
    double ab[3], ap[3], t = 0, len2 = 0;
    for (int k = 0; k < 3; ++k)
      ab[k] = b[size_t(k)] - a[size_t(k)], ap[k] = p[k] - a[size_t(k)], t += ab[k] * ap[k], len2 += ab[k] * ab[k];
    t = std::clamp(t / len2, 0.0, 1.0);
    double d2 = 0;
    for (int k = 0; k < 3; ++k) d2 += (ap[k] - t * ab[k]) * (ap[k] - t * ab[k]);
    best = std::min(best, std::sqrt(d2));
  }
  return best;
}

// The slice by n·p = offset has area `area`, all its vertices on the plane, its outline on the
// polygon `poly`, and every corner of `poly` among its vertices.
void expectSlice(const TetMesh& mesh, std::array<float, 3> n, float offset, double area,
                 const std::vector<std::array<double, 3>>& poly) {
  SliceTracker slice;
  ASSERT_TRUE(slice.setPlane(n, offset));
  slice.rebuild(mesh, {});
  const IncrementalIsosurface& s = slice.surface();
  EXPECT_NEAR(s.area(), area, 1e-5 * area);
  const auto nn = slice.normal();
  for (uint32_t i : s.indices()) {
    const float* p = &s.positions()[3 * size_t(i)];
    EXPECT_NEAR(nn[0] * p[0] + nn[1] * p[1] + nn[2] * p[2], offset, 1e-5);
  }
  auto edges = boundaryEdges(s);
  EXPECT_FALSE(edges.empty());
  for (const auto& e : edges) {
    EXPECT_LT(distanceToOutline(&e[0], poly), 1e-5);
    EXPECT_LT(distanceToOutline(&e[3], poly), 1e-5);
  }
  for (const auto& c : poly) {
    double best = 1e30;
    for (uint32_t i : s.indices()) {
      const float* p = &s.positions()[3 * size_t(i)];
      best = std::min(best, std::hypot(p[0] - c[0], p[1] - c[1], p[2] - c[2]));
    }
    EXPECT_LT(best, 1e-5) << "corner " << c[0] << " " << c[1] << " " << c[2];
  }
}

}  // namespace

// z = 0.3 through [-1, 1]^3: the 2 x 2 square; x = -0.45 and y = 0.7 likewise.
TEST(Slice, AxisPlaneThroughCubeIsTheSquare) {
  TetMesh m = makeGridMesh(6);
  expectSlice(m, {0, 0, 1}, 0.3f, 4.0, {{-1, -1, 0.3}, {1, -1, 0.3}, {1, 1, 0.3}, {-1, 1, 0.3}});
  expectSlice(m, {2, 0, 0}, -0.45f, 4.0, {{-0.45, -1, -1}, {-0.45, 1, -1}, {-0.45, 1, 1}, {-0.45, -1, 1}});
  expectSlice(m, {0, -1, 0}, -0.7f, 4.0, {{-1, 0.7, -1}, {1, 0.7, -1}, {1, 0.7, 1}, {-1, 0.7, 1}});
}

// Normal (1, 1, 1) through the centre: the regular hexagon with corners at the permutations of
// (1, -1, 0), side sqrt(2), area 3 sqrt(3). On the n = 3 and n = 5 grids the plane passes
// through mesh vertices and along mesh edges (the exact-λ rules); on n = 6 through none.
TEST(Slice, ObliquePlaneThroughCubeIsTheRegularHexagon) {
  const std::vector<std::array<double, 3>> hex = {{1, -1, 0}, {1, 0, -1}, {0, 1, -1},
                                                  {-1, 1, 0}, {-1, 0, 1}, {0, -1, 1}};
  for (uint32_t n : {3u, 5u, 6u}) {
    SCOPED_TRACE("grid " + std::to_string(n));
    expectSlice(makeGridMesh(n), {1, 1, 1}, 0.f, 3 * std::sqrt(3.0), hex);
  }
}

// The slice kept by local updates through real splits and undos equals one made from scratch
// (the same triangles, bit for bit), with the colour field interpolated at its vertices.
TEST(Slice, FollowsSplitsLocallyLikeFromScratch) {
  StreamedGrid g(10);
  Dataset& ds = g.ds;
  std::vector<uint32_t> changed;
  bool reached = false;
  ASSERT_TRUE(stepTowards(ds, 0, ~0u, changed, &reached));
  std::mt19937 rng(7);
  for (auto plane : {std::array<float, 4>{0, 0, 1, 0.3f}, std::array<float, 4>{1, 1, 1, 0.1f},
                     std::array<float, 4>{0.3f, -0.8f, 0.5f, -0.2f}}) {
    SliceTracker slice;
    ASSERT_TRUE(slice.setPlane({plane[0], plane[1], plane[2]}, plane[3]));
    slice.rebuild(ds.pm.mesh, g.field("x"));
    const uint32_t total = ds.splitsReceived();
    for (int round = 0; round < 12; ++round) {
      const uint32_t target = std::uniform_int_distribution<uint32_t>(0, total)(rng);
      while (ds.splitsApplied() != target) {
        changed.clear();
        ASSERT_TRUE(stepTowards(ds, target, 1 + rng() % 17, changed, &reached));
        slice.update(ds.pm.mesh, changed, g.field("x"));
      }
      SliceTracker fresh;
      fresh.setPlane({plane[0], plane[1], plane[2]}, plane[3]);
      fresh.rebuild(ds.pm.mesh, g.field("x"));
      IsoSurface a, b;
      slice.surface().toIsoSurface(a);
      fresh.surface().toIsoSurface(b);
      EXPECT_EQ(a.triangleCount(), b.triangleCount()) << "at " << target;
      EXPECT_NEAR(slice.surface().area(), fresh.surface().area(), 1e-9);
      auto sortedTris = [](const IsoSurface& s) {
        std::vector<std::array<float, 9>> tris;
        for (size_t t = 0; t < s.indices.size(); t += 3) {
          std::array<std::array<float, 3>, 3> c;
          for (int k = 0; k < 3; ++k)
            for (int j = 0; j < 3; ++j)
              c[size_t(k)][size_t(j)] = s.positions[3 * size_t(s.indices[t + size_t(k)]) + size_t(j)];
          std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
          tris.push_back({c[0][0], c[0][1], c[0][2], c[1][0], c[1][1], c[1][2], c[2][0], c[2][1], c[2][2]});
        }
        std::sort(tris.begin(), tris.end());
        return tris;
      };
      EXPECT_TRUE(sortedTris(a) == sortedTris(b)) << "slice differs from scratch at " << target << " splits";
      // The slice's colour is x interpolated: equal to the vertex's x.
      for (uint32_t i : slice.surface().indices())
        EXPECT_NEAR(slice.surface().colours()[i], slice.surface().positions()[3 * size_t(i)], 1e-5);
      EXPECT_TRUE(slice.surface().validate());
    }
  }
}
