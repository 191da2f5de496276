// The viewer's model natively (no GL, no ImGui, no Emscripten): loading states, hostile input,
// isovalue and field changes, the hull, and the camera framing the dataset.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>

#include <nlohmann/json.hpp>

#include "camera.h"
#include "pack/generators.h"
#include "pack/packer.h"
#include "test_helpers.h"
#include "viewer_state.h"

using namespace tetstream;
using namespace tetstream::viewer;

namespace {

struct Packed {
  std::string manifest;
  std::vector<uint8_t> chunk;
};

// Harmonic 24³ with a distance field, packed once for the whole suite.
const Packed& packed() {
  static test::ScratchDir dir("viewer-state");
  static Packed p = [] {
    TetMesh m = makeGridMesh(24);
    addHarmonicField(m);
    addDistanceField(m);
    PackSummary s;
    PackOptions o;
    o.baseFraction = 1.0;  // one base chunk: streaming splits is covered elsewhere
    o.zstdLevel = 3;
    Result r = packMesh(m, dir.path, o, s);
    EXPECT_TRUE(r) << r.message;
    Packed out;
    out.manifest = test::loadFile(dir.path + "/manifest.json");
    out.chunk = test::loadBytes(dir.path + "/" + s.manifest.chunks[0].file);
    return out;
  }();
  return p;
}

nlohmann::json stats(const ViewerState& s) { return nlohmann::json::parse(statsJson(s)); }

}  // namespace

TEST(ViewerState, StartsIdle) {
  ViewerState s;
  EXPECT_EQ(stats(s)["state"], "idle");
}

TEST(ViewerState, HostileManifestsEndInErrorWithAMessage) {
  for (const char* bad : {"", "{", "[]", "{\"format\":\"tetstream\"}", "\xff\xfe"}) {
    ViewerState s;
    EXPECT_FALSE(openManifest(s, bad).ok()) << bad;
    EXPECT_EQ(s.state, LoadState::Error);
    EXPECT_FALSE(s.error.empty());
    EXPECT_EQ(stats(s)["state"], "error");
  }
}

TEST(ViewerState, BadChunksNeverReplaceTheShownLevel) {
  const Packed& p = packed();
  ViewerState s;
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  EXPECT_EQ(s.state, LoadState::Loading);
  EXPECT_EQ(s.chunksTotal, 1u);
  EXPECT_FALSE(addChunk(s, 1, p.chunk).ok()) << "out of order";
  EXPECT_EQ(s.state, LoadState::Error);
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  EXPECT_FALSE(addChunk(s, 0, std::span<const uint8_t>(p.chunk).first(p.chunk.size() / 2)).ok());
  EXPECT_EQ(s.state, LoadState::Error);
  EXPECT_EQ(s.dataset.pm.mesh.tetCount(), 0u);
  EXPECT_NE(s.error.find("chunk 0"), std::string::npos) << s.error;
}

TEST(ViewerState, LoadsExtractsAndFollowsTheControls) {
  const Packed& p = packed();
  ViewerState s;
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  auto mj = nlohmann::json::parse(p.manifest);
  float mid = 0.5f * (mj["fields"][0]["min"].get<float>() + mj["fields"][0]["max"].get<float>());
  EXPECT_NEAR(s.isovalue, mid, 1e-6f) << "starts in the middle of the range";
  ASSERT_TRUE(addChunk(s, 0, p.chunk).ok());
  EXPECT_EQ(s.state, LoadState::Complete);
  EXPECT_GT(s.surface.triangleCount(), 0u);
  EXPECT_TRUE(s.surfaceDirty);

  updateBoundary(s);
  EXPECT_FALSE(s.boundaryStale);
  EXPECT_GT(s.boundary.triangleCount(), 0u);
  EXPECT_EQ(s.boundary.lineCount(), 12u * 23) << "the cube's 12 edges, 23 segments each";

  uint32_t tris = s.surface.triangleCount();
  setIsovalue(s, s.isovalue + 0.2f);
  EXPECT_NE(s.surface.triangleCount(), tris);
  EXPECT_TRUE(setField(s, "distance"));
  EXPECT_EQ(s.field, 1);
  EXPECT_FALSE(setField(s, "nope"));
  EXPECT_EQ(s.field, 1);
  setIsovalue(s, 0.8f);
  EXPECT_NEAR(s.surfaceArea, 4 * std::numbers::pi * 0.64, 0.02 * s.surfaceArea) << "sphere of radius 0.8";

  EXPECT_FALSE(addChunk(s, 1, p.chunk).ok()) << "a chunk past the end is refused";
  EXPECT_GT(s.surface.triangleCount(), 0u) << "and the surface stays";
  failLoad(s, "network down");
  auto j = stats(s);
  EXPECT_EQ(j["state"], "error");
  EXPECT_EQ(j["error"], "network down");
  EXPECT_EQ(j["field"], "distance");
  EXPECT_EQ(j["fields"].size(), 2u);
  EXPECT_EQ(j["triangles"].get<uint32_t>(), s.surface.triangleCount());
}

TEST(ViewerState, CameraFramesTheBoundingBox) {
  OrbitCamera c;
  float lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
  c.setBounds(lo, hi, 1.6f);
  glm::mat4 vp = c.projection(1.6f) * c.view();
  for (int k = 0; k < 8; ++k) {
    glm::vec4 p = vp * glm::vec4(k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1, 1);
    p /= p.w;
    EXPECT_LE(std::abs(p.x), 1);
    EXPECT_LE(std::abs(p.y), 1);
    EXPECT_GT(p.z, -1);
    EXPECT_LT(p.z, 1);
  }
}
