// The viewer's model natively (no GL, no ImGui, no Emscripten): loading states, hostile input,
// isovalue and field changes, streaming splits under a time budget with the surface and hull
// kept up to date locally, the level of detail moving back and forth, the download rate, and
// the camera framing the dataset.
#include <gtest/gtest.h>
#include <zstd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <numeric>
#include <random>

#include "adjacency.h"
#include "camera.h"
#include "frame_policy.h"
#include "geometry_sync.h"
#include "io/generators.h"
#include "pack/chunk_encode.h"
#include "pack/packer.h"
#include "page_state.h"
#include "test_helpers.h"
#include "update_pacing.h"
#include "viewer_memory.h"
#include "viewer_state.h"

using namespace tetstream;
using namespace tetstream::viewer;

namespace {

// The domain boundary of a mesh, built from scratch: the reference the incremental HullTracker
// is checked against. Triangles are unshared so each carries its flat normal.
struct BoundaryMesh {
  std::vector<float> positions;     // 3 per corner, 9 per triangle
  std::vector<float> normals;       // 3 per corner, outward unit normal of the triangle
  std::vector<float> featureLines;  // 6 per segment: boundary edges whose faces meet at a crease
  uint32_t triangleCount() const { return uint32_t(positions.size() / 9); }
  uint32_t lineCount() const { return uint32_t(featureLines.size() / 6); }
};

// Boundary triangles of a mesh and their crease edges (dihedral angle above ~30 degrees, or an
// edge not shared by exactly two boundary triangles).
void buildBoundary(const TetMesh& mesh, BoundaryMesh& out) {
  out = {};
  if (mesh.tetCount() == 0) return;
  const std::vector<uint32_t> tris = test::boundaryTriangles(mesh);

  const float* p = mesh.positions.data();
  const size_t nt = tris.size() / 3;
  std::vector<float> faceNormals(3 * nt);
  out.positions.reserve(9 * nt);
  out.normals.reserve(9 * nt);
  for (size_t t = 0; t < nt; ++t) {
    float n[3];
    triangleNormal(p, &tris[3 * t], n);
    for (int k = 0; k < 3; ++k) {
      const float* q = p + 3 * size_t(tris[3 * t + k]);
      out.positions.insert(out.positions.end(), q, q + 3);
      out.normals.insert(out.normals.end(), n, n + 3);
    }
    std::copy(n, n + 3, &faceNormals[3 * t]);
  }

  // Crease edges: group the triangles' edges by their sorted vertex pair. An edge with two
  // triangles is drawn when their normals differ by more than ~30 degrees (box corners, sharp
  // features); an edge with any other count is an open or non-manifold rim and always drawn.
  struct EdgeUse {
    uint64_t key;
    uint32_t tri;
  };
  std::vector<EdgeUse> edges;
  edges.reserve(3 * nt);
  for (size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) edges.push_back({edgeKey(tris[3 * t + k], tris[3 * t + (k + 1) % 3]), uint32_t(t)});
  std::sort(edges.begin(), edges.end(), [](const EdgeUse& x, const EdgeUse& y) { return x.key < y.key; });
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j].key == edges[i].key) ++j;
    bool draw = j - i != 2;
    if (!draw) {
      const float* n0 = &faceNormals[3 * size_t(edges[i].tri)];
      const float* n1 = &faceNormals[3 * size_t(edges[i + 1].tri)];
      draw = n0[0] * n1[0] + n0[1] * n1[1] + n0[2] * n1[2] < kCreaseCos;
    }
    if (draw) {
      uint32_t a = uint32_t(edges[i].key >> 32), b = uint32_t(edges[i].key);
      out.featureLines.insert(out.featureLines.end(), p + 3 * size_t(a), p + 3 * size_t(a) + 3);
      out.featureLines.insert(out.featureLines.end(), p + 3 * size_t(b), p + 3 * size_t(b) + 3);
    }
    i = j;
  }
}

struct Packed {
  std::string manifest;
  std::vector<std::vector<uint8_t>> chunks;
};

Packed pack(int n, double baseFraction, uint32_t chunkKb, const char* name,
            uint32_t leafVertices = PackOptions{}.leafVertices) {
  test::ScratchDir dir(name);
  TetMesh m = makeGridMesh(n);
  addHarmonicField(m);
  addDistanceField(m);
  PackSummary s;
  PackOptions o;
  o.baseFraction = baseFraction;
  o.chunkKb = chunkKb;
  o.leafVertices = leafVertices;
  o.zstdLevel = 3;
  Result r = packMesh(m, dir.path, o, s);
  EXPECT_TRUE(r) << r.message;
  Packed out;
  out.manifest = test::loadFile(dir.path + "/manifest.json");
  for (const ChunkInfo& c : s.manifest.chunks) out.chunks.push_back(test::loadBytes(dir.path + "/" + c.file));
  return out;
}

// Harmonic 24³ with a distance field in one base chunk (no splits).
const Packed& packedBase() {
  static Packed p = pack(24, 1.0, 256, "viewer-state-base");
  return p;
}

// Harmonic 12³: a 5% base and many small split chunks.
const Packed& packedStream() {
  static Packed p = pack(12, 0.05, 1, "viewer-state-stream");
  return p;
}

nlohmann::json stats(const ViewerState& s) { return nlohmann::json::parse(statsJson(s)); }

// A clock that advances one unit per reading: advance() then does a bounded number of batches.
double g_ticks = 0;
double fakeNow() { return g_ticks += 1; }

// Runs advance() until the level reaches its target; returns the number of calls.
int settle(ViewerState& s, double ticksPerCall = 3) {
  int calls = 0;
  while (advance(s, g_ticks + ticksPerCall, fakeNow)) ++calls;
  return calls;
}

// The surface and hull of the current level equal a from-scratch extraction.
void expectMatchesFromScratch(const ViewerState& s, const char* where) {
  SCOPED_TRACE(where);
  const TetMesh& mesh = s.dataset.pm.mesh;
  int f = mesh.findField(s.dataset.manifest.fields[size_t(s.field)].name);
  ASSERT_GE(f, 0);
  IsoExtractor x;
  IsoSurface ref;
  extractIsosurface(mesh, mesh.fields[size_t(f)].values, s.isovalue, x, ref);
  EXPECT_EQ(s.surface.triangleCount(), ref.triangleCount());
  EXPECT_EQ(s.surface.vertexCount(), ref.vertexCount());
  EXPECT_NEAR(s.surface.area(), surfaceArea(ref), 1e-9 * std::max(1.0, surfaceArea(ref)));
  EXPECT_TRUE(s.surface.validate());

  // Hull: the same outward-wound triangles (compared with the smallest id first) and creases.
  const std::vector<uint32_t> tris = test::boundaryTriangles(mesh);
  auto canonical = [](std::span<const uint32_t> t) {
    std::vector<std::array<uint32_t, 3>> out;
    for (size_t i = 0; i + 2 < t.size(); i += 3) {
      std::array<uint32_t, 3> a = {t[i], t[i + 1], t[i + 2]};
      std::rotate(a.begin(), std::min_element(a.begin(), a.end()), a.end());
      out.push_back(a);
    }
    std::sort(out.begin(), out.end());
    return out;
  };
  EXPECT_EQ(canonical(s.hull.faces()), canonical(tris));
  BoundaryMesh b;
  buildBoundary(mesh, b);
  EXPECT_EQ(s.hull.lineCount(), b.lineCount());
  EXPECT_EQ(s.hull.trianglePositions().size(), 9 * size_t(s.hull.triangleCount()));
}

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
  const Packed& p = packedBase();
  ViewerState s;
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  EXPECT_EQ(s.state, LoadState::Loading);
  EXPECT_EQ(s.chunksTotal, 1u);
  EXPECT_FALSE(addChunk(s, 1, p.chunks[0]).ok()) << "out of order";
  EXPECT_EQ(s.state, LoadState::Error);
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  EXPECT_FALSE(addChunk(s, 0, std::span<const uint8_t>(p.chunks[0]).first(p.chunks[0].size() / 2)).ok());
  EXPECT_EQ(s.state, LoadState::Error);
  EXPECT_EQ(s.dataset.pm.mesh.tetCount(), 0u);
  EXPECT_NE(s.error.find("chunk 0"), std::string::npos) << s.error;
  EXPECT_FALSE(addChunk(s, 0, p.chunks[0]).ok()) << "nothing is accepted once in error";
}

TEST(ViewerState, LoadsExtractsAndFollowsTheControls) {
  const Packed& p = packedBase();
  ViewerState s;
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  auto mj = nlohmann::json::parse(p.manifest);
  float mid = 0.5f * (mj["fields"][0]["min"].get<float>() + mj["fields"][0]["max"].get<float>());
  EXPECT_NEAR(s.isovalue, mid, 1e-6f) << "starts in the middle of the range";
  ASSERT_TRUE(addChunk(s, 0, p.chunks[0]).ok());
  EXPECT_EQ(s.state, LoadState::Complete) << "a base-only dataset is complete at once";
  EXPECT_GT(s.surface.triangleCount(), 0u);
  EXPECT_TRUE(s.dirty.surface);
  EXPECT_TRUE(s.surface.fullUploadNeeded());
  EXPECT_GT(s.hull.triangleCount(), 0u);
  EXPECT_EQ(s.hull.lineCount(), 12u * 23) << "the cube's 12 edges, 23 segments each";
  EXPECT_FALSE(advance(s, g_ticks + 10, fakeNow)) << "nothing to refine";
  expectMatchesFromScratch(s, "base");

  uint32_t tris = s.surface.triangleCount();
  setIsovalue(s, s.isovalue + 0.2f);
  EXPECT_NE(s.surface.triangleCount(), tris);
  EXPECT_TRUE(setField(s, "distance"));
  EXPECT_EQ(s.field, 1);
  EXPECT_FALSE(setField(s, "nope"));
  EXPECT_EQ(s.field, 1);
  setIsovalue(s, 0.8f);
  EXPECT_NEAR(s.surface.area(), 4 * std::numbers::pi * 0.64, 0.02 * s.surface.area()) << "sphere of radius 0.8";
  expectMatchesFromScratch(s, "distance field");

  EXPECT_FALSE(addChunk(s, 1, p.chunks[0]).ok()) << "a chunk past the end is refused";
  EXPECT_GT(s.surface.triangleCount(), 0u) << "and the surface stays";
  failLoad(s, "network down");
  auto j = stats(s);
  EXPECT_EQ(j["state"], "error");
  EXPECT_EQ(j["error"], "network down");
  EXPECT_EQ(j["field"], "distance");
  EXPECT_EQ(j["fields"].size(), 2u);
  EXPECT_EQ(j["triangles"].get<uint32_t>(), s.surface.triangleCount());
}

TEST(ViewerState, StreamsSplitsUnderABudgetWithLocalUpdates) {
  const Packed& p = packedStream();
  ASSERT_GE(p.chunks.size(), 4u) << "the test needs several split chunks";
  ViewerState s;
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  ASSERT_TRUE(setField(s, "harmonic"));
  setIsovalue(s, 0.1f);
  ASSERT_TRUE(addChunk(s, 0, p.chunks[0]).ok());
  EXPECT_EQ(s.state, LoadState::Streaming);
  const uint32_t baseVertices = s.dataset.pm.vertexCount();
  expectMatchesFromScratch(s, "base");
  s.surface.clearChanges();
  s.hull.clearChanges();

  // Verification only: nothing is applied until the frame loop advances.
  ASSERT_TRUE(addChunk(s, 1, p.chunks[1]).ok());
  EXPECT_EQ(s.dataset.pm.vertexCount(), baseVertices);
  EXPECT_EQ(s.level.targetSplits, s.dataset.splitsReceived()) << "live: the target follows new data";

  // One bounded slice: some splits, not all, and only local changes for the renderer.
  ASSERT_TRUE(advance(s, g_ticks + 2, fakeNow));
  EXPECT_GT(s.telemetry.refineSteps, 0u);
  EXPECT_LE(s.telemetry.refineSteps, 2 * kStepBatch);
  EXPECT_EQ(s.dataset.splitsApplied(), s.telemetry.refineSteps);
  // The slice is counted in the histogram of slice durations (2 ticks: the first bin).
  EXPECT_EQ(s.telemetry.refineMs, 2);
  EXPECT_EQ(s.telemetry.sliceCounts[0], 1u);
  EXPECT_EQ(std::accumulate(s.telemetry.sliceCounts.begin(), s.telemetry.sliceCounts.end(), 0u), 1u);
  EXPECT_FALSE(s.surface.fullUploadNeeded()) << "splits never re-extract the whole surface";
  EXPECT_FALSE(s.hull.fullUploadNeeded());
  expectMatchesFromScratch(s, "inside chunk 1");

  for (uint32_t c = 2; c < p.chunks.size(); ++c) {
    ASSERT_TRUE(addChunk(s, c, p.chunks[c]).ok()) << c;
    advance(s, g_ticks + 4, fakeNow);
    if (c + 1 < p.chunks.size()) {
      EXPECT_EQ(s.state, LoadState::Streaming);
    }
  }
  settle(s);
  EXPECT_EQ(s.state, LoadState::Complete);
  EXPECT_EQ(s.dataset.pm.vertexCount(), s.dataset.manifest.vertices);
  EXPECT_FALSE(s.surface.fullUploadNeeded());
  expectMatchesFromScratch(s, "complete");
  auto j = stats(s);
  EXPECT_EQ(j["level"].get<double>(), 1.0);
  EXPECT_EQ(j["fieldError"].get<double>(), 0.0);
  EXPECT_EQ(j["splitsApplied"], j["splitsTotal"]);
  EXPECT_EQ(j["chunksApplied"].get<uint32_t>(), s.chunksTotal);
  // A slow clock (20 ms a reading): every later slice lands in the bins over 30 ms.
  setLevel(s, 0);
  // The bins from 30 ms up: the edge 30 is kSliceEdgesMs[4], so bins 5 (30-60) and 6 (60 and over).
  ASSERT_EQ(kSliceEdgesMs[4], 30.0);
  auto over30 = [&] { return s.telemetry.sliceCounts[5] + s.telemetry.sliceCounts[6]; };
  const uint32_t before = over30();
  int slow = 0;
  while (advance(s, g_ticks + 1, [] { return g_ticks += 20; })) ++slow;
  EXPECT_GT(slow, 0);
  EXPECT_EQ(over30(), before + uint32_t(slow));
  EXPECT_EQ(j["sliceEdgesMs"].size() + 1, j["sliceCounts"].size());
}

TEST(ViewerState, LevelMovesBackAndForthAndStaysWhereTheUserPutsIt) {
  const Packed& p = packedStream();
  ViewerState s;
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  ASSERT_TRUE(addChunk(s, 0, p.chunks[0]).ok());
  const uint32_t base = s.dataset.pm.baseVertices;
  ASSERT_TRUE(addChunk(s, 1, p.chunks[1]).ok());
  ASSERT_TRUE(addChunk(s, 2, p.chunks[2]).ok());
  settle(s);
  const uint32_t received = s.dataset.splitsReceived();
  EXPECT_EQ(s.dataset.splitsApplied(), received);

  // Back to the base: coarser, the surface following through undos.
  setLevelFraction(s, 0);
  EXPECT_FALSE(s.level.live);
  settle(s);
  EXPECT_EQ(s.dataset.pm.vertexCount(), base);
  EXPECT_EQ(stats(s)["fieldError"].get<double>(), s.dataset.manifest.chunks[0].fieldError);
  EXPECT_EQ(stats(s)["fieldRms"].get<double>(), s.dataset.manifest.chunks[0].fieldRms);  // measured by the packer
  EXPECT_EQ(stats(s)["fieldMax"].get<double>(), s.dataset.manifest.chunks[0].fieldMax);
  EXPECT_GE(s.dataset.manifest.chunks[0].fieldMax, s.dataset.manifest.chunks[0].fieldRms);
  expectMatchesFromScratch(s, "back at the base");

  // New data does not move a level the user put back.
  ASSERT_TRUE(addChunk(s, 3, p.chunks[3]).ok());
  settle(s);
  EXPECT_EQ(s.dataset.pm.vertexCount(), base);
  EXPECT_EQ(s.state, LoadState::Streaming);

  // Random levels, each equal to a from-scratch extraction.
  std::mt19937 rng(7);
  for (int k = 0; k < 6; ++k) {
    uint32_t target = std::uniform_int_distribution<uint32_t>(0, s.dataset.splitsReceived())(rng);
    setLevel(s, target);
    settle(s, 2);
    EXPECT_EQ(s.dataset.splitsApplied(), target);
    expectMatchesFromScratch(s, ("level " + std::to_string(target)).c_str());
  }

  // Forward to the newest level: live again, so the next chunk is followed.
  setLevelFraction(s, 1.0);
  EXPECT_TRUE(s.level.live);
  EXPECT_EQ(s.level.targetSplits, s.dataset.splitsReceived());
  EXPECT_GT(s.dataset.splitsReceived(), received);
  for (uint32_t c = 4; c < p.chunks.size(); ++c) ASSERT_TRUE(addChunk(s, c, p.chunks[c]).ok());
  settle(s);
  EXPECT_EQ(s.state, LoadState::Complete);
  expectMatchesFromScratch(s, "complete after moving around");

  // A fraction is of the full mesh's vertices.
  setLevelFraction(s, 0.5);
  settle(s);
  EXPECT_EQ(s.dataset.pm.vertexCount(), uint32_t(std::round(0.5 * s.dataset.manifest.vertices)));
  EXPECT_EQ(s.state, LoadState::Streaming) << "complete means every split applied";
}

TEST(ViewerState, ErrorsKeepTheLevelUsable) {
  const Packed& p = packedStream();
  ViewerState s;
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  ASSERT_TRUE(addChunk(s, 0, p.chunks[0]).ok());
  ASSERT_TRUE(addChunk(s, 1, p.chunks[1]).ok());
  failLoad(s, "Could not download part 3: HTTP 404 (not found).");
  EXPECT_FALSE(addChunk(s, 2, p.chunks[2]).ok());
  settle(s);
  EXPECT_EQ(s.state, LoadState::Error);
  EXPECT_EQ(s.dataset.splitsApplied(), s.dataset.splitsReceived()) << "what did arrive is still applied";
  setLevelFraction(s, 0);
  settle(s);
  EXPECT_EQ(s.dataset.pm.vertexCount(), s.dataset.pm.baseVertices) << "and the level slider still works";
  expectMatchesFromScratch(s, "after an error");
}

TEST(ViewerState, AHostileChunkWithAValidHashEndsInErrorAtTheLastGoodLevel) {
  const Packed& p = packedStream();
  ViewerState s;
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  ASSERT_TRUE(addChunk(s, 0, p.chunks[0]).ok());
  ASSERT_TRUE(addChunk(s, 1, p.chunks[1]).ok());
  settle(s);
  const uint32_t goodVertices = s.dataset.pm.vertexCount();
  // Chunk 2 with its last record cut short, compressed and hashed as if it were right.
  ChunkInfo& info = s.dataset.manifest.chunks[2];
  std::vector<uint8_t> bad = test::forgeTruncatedChunk(p.chunks[2], info);
  ASSERT_FALSE(bad.empty());
  ASSERT_TRUE(addChunk(s, 2, bad).ok()) << "the hash matches: only applying finds the damage";
  settle(s);
  EXPECT_EQ(s.state, LoadState::Error);
  EXPECT_NE(s.error.find("Part 3 of"), std::string::npos) << s.error;
  EXPECT_EQ(s.dataset.chunksReceived, 2u);
  EXPECT_EQ(s.dataset.pm.vertexCount(), goodVertices);
  expectMatchesFromScratch(s, "after the dropped chunk");
  EXPECT_FALSE(addChunk(s, 3, p.chunks[3]).ok());
}

// The network belongs to the page (web/rate.js measures the rate, tests/node/rate.test.mjs):
// the viewer shows its snapshot and asks it to pause.
TEST(ViewerState, PauseAndDownloadFiguresComeFromThePage) {
  const Packed& p = packedStream();
  ViewerState s;
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  EXPECT_TRUE(downloading(s));
  setNetwork(s, {.receivedBytes = 300, .totalBytes = 1000, .bytesPerSecond = 100000, .secondsLeft = 2.5});
  EXPECT_EQ(stats(s)["rateBytesPerSec"], 100000);
  EXPECT_EQ(stats(s)["secondsLeft"], 2.5);
  requestPauseToggle(s);
  EXPECT_TRUE(s.pauseToggleRequested);
  EXPECT_TRUE(downloading(s)) << "the page decides";
  setNetwork(s, {.receivedBytes = 300, .totalBytes = 1000, .paused = true});
  EXPECT_FALSE(downloading(s));
  EXPECT_EQ(stats(s)["paused"], true);
  EXPECT_TRUE(stats(s)["secondsLeft"].is_null());
}

// Malloc'd copy of a chunk, as the page hands it over (offerChunk takes ownership).
uint8_t* mallocCopy(std::span<const uint8_t> bytes) {
  auto* out = static_cast<uint8_t*>(std::malloc(std::max<size_t>(1, bytes.size())));
  std::copy(bytes.begin(), bytes.end(), out);
  return out;
}

ChunkCheck offer(ViewerState& s, uint32_t index, std::span<const uint8_t> bytes) {
  return offerChunk(s, index, mallocCopy(bytes), bytes.size());
}

TEST(ViewerState, OfferedChunksAreCheckedOnceAndAddedInOrder) {
  const Packed& p = packedStream();
  ASSERT_GE(p.chunks.size(), 4u);
  ViewerState s;
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  std::vector<uint8_t> flipped = p.chunks[2];
  flipped[flipped.size() / 2] ^= 0x10;
  EXPECT_EQ(offer(s, 2, flipped), ChunkCheck::WrongHash);
  EXPECT_EQ(offer(s, 2, p.chunks[1]), ChunkCheck::WrongSize);
  EXPECT_EQ(offer(s, 9999, p.chunks[1]), ChunkCheck::NoSuchChunk);
  EXPECT_EQ(offer(s, 2, p.chunks[2]), ChunkCheck::Ok);
  EXPECT_EQ(offer(s, 1, p.chunks[1]), ChunkCheck::Ok);
  EXPECT_EQ(s.dataset.chunksReceived, 0u) << "waiting for the base";
  EXPECT_EQ(s.state, LoadState::Loading);
  EXPECT_EQ(offer(s, 0, p.chunks[0]), ChunkCheck::Ok);
  EXPECT_EQ(s.dataset.chunksReceived, 3u) << "the base and the two kept after it";
  EXPECT_TRUE(s.pendingChunks.empty());
  EXPECT_EQ(offer(s, 1, p.chunks[1]), ChunkCheck::NoSuchChunk) << "already added";
  for (uint32_t c = 3; c < p.chunks.size(); ++c) EXPECT_EQ(offer(s, c, p.chunks[c]), ChunkCheck::Ok);
  settle(s);
  EXPECT_EQ(s.state, LoadState::Complete);
  expectMatchesFromScratch(s, "offered out of order");
}

// Harmonic 24³ streamed from a 1% base: the memory estimate against the measured use.
const Packed& packedMemory() {
  static Packed p = pack(24, 0.01, 16, "viewer-state-memory");
  return p;
}

// Streams every chunk it is allowed to and applies all splits.
void streamAll(ViewerState& s, const Packed& p) {
  for (uint32_t c = 0; c < p.chunks.size() && s.state != LoadState::Error; ++c) {
    if (!addChunk(s, c, p.chunks[c]).ok()) break;
    settle(s);
  }
  settle(s);
}

TEST(ViewerState, MemoryEstimateFollowsTheMeasuredUse) {
  const Packed& p = packedMemory();
  ViewerState s;
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  const Manifest& m = s.dataset.manifest;
  ASSERT_GE(m.chunks.size(), 6u);
  setIsovalue(s, 0.1f);
  // The mesh arrays are reserved for the last level at the base, so every level holds at most
  // what the last one needs; at the last one the estimate covers the use without wasting half.
  const uint64_t full = estimateLevelBytes(m, uint32_t(m.chunks.size()));
  uint64_t previous = 0;
  for (uint32_t c = 0; c < p.chunks.size(); ++c) {
    ASSERT_TRUE(addChunk(s, c, p.chunks[c]).ok()) << c;
    settle(s);
    const uint64_t estimate = estimateLevelBytes(m, c + 1);
    EXPECT_GE(estimate, previous) << "levels only grow";
    previous = estimate;
    EXPECT_LE(memoryInUse(s), full) << "chunk " << c;
  }
  while (growTree(s, g_ticks + 2, fakeNow)) {
  }
  EXPECT_EQ(s.surface.treeCoverage(), m.tets) << "the estimate covers the interval tree too";
  EXPECT_GE(double(full), 1.0 * double(memoryInUse(s)));
  EXPECT_LE(double(full), 1.5 * double(memoryInUse(s)));
  EXPECT_EQ(s.state, LoadState::Complete);
  EXPECT_EQ(s.memory.neededBytes, estimateLevelBytes(m, s.chunksTotal));
  std::printf("Harmonic 24: %u tets, estimate %.1f MB, measured %.1f MB (%.1f bytes per tet)\n", m.tets,
              double(s.memory.neededBytes) / (1 << 20), double(memoryInUse(s)) / (1 << 20),
              double(memoryInUse(s)) / m.tets);
  auto j = stats(s);
  EXPECT_EQ(j["memory"]["dataBytes"].get<uint64_t>(), memoryInUse(s));
  EXPECT_EQ(j["memory"]["limitBytes"], nullptr);
  EXPECT_EQ(j["chunksAllowed"].get<uint32_t>(), s.chunksTotal);
}

// (A dataset of regions is fetched as far as it fits instead: test_fetch_plan.cpp.)
TEST(ViewerState, ADatasetTooBigStopsAtTheLastLevelThatFits) {
  static const Packed p = pack(24, 0.01, 16, "viewer-state-memory-sequence", /*leafVertices=*/0);
  Manifest m;
  ASSERT_TRUE(parseManifest(p.manifest, m).ok());
  const uint32_t fit = uint32_t(m.chunks.size()) / 2;
  ViewerState s;
  s.memory.baseBytes = 1 << 20;
  s.memory.limitBytes = s.memory.baseBytes + (estimateLevelBytes(m, fit) + estimateLevelBytes(m, fit + 1)) / 2;
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  EXPECT_EQ(s.memory.chunksAllowed, fit);
  EXPECT_TRUE(downloading(s));
  streamAll(s, p);
  EXPECT_EQ(s.state, LoadState::Error);
  EXPECT_TRUE(s.memory.limited);
  EXPECT_EQ(s.dataset.chunksReceived, fit);
  EXPECT_EQ(s.dataset.splitsApplied(), s.dataset.splitsReceived()) << "everything that fits is applied";
  EXPECT_NE(s.error.find("Streaming stopped after part " + std::to_string(fit) + " of"), std::string::npos) << s.error;
  EXPECT_NE(s.error.find("this page may use"), std::string::npos) << s.error;
  EXPECT_FALSE(downloading(s));
  EXPECT_LE(memoryInUse(s), estimateLevelBytes(m, fit)) << "what is held fits the estimate that was allowed";
  expectMatchesFromScratch(s, "stopped for memory");
  setLevelFraction(s, 0);
  settle(s);
  EXPECT_EQ(s.dataset.pm.vertexCount(), s.dataset.pm.baseVertices) << "the level slider still works";

  // Not even the base fits: refused before anything is fetched.
  ViewerState tiny;
  tiny.memory.limitBytes = estimateLevelBytes(m, 1) / 2;
  EXPECT_FALSE(openManifest(tiny, p.manifest).ok());
  EXPECT_EQ(tiny.state, LoadState::Error);
  EXPECT_NE(tiny.error.find("even at its coarsest level"), std::string::npos) << tiny.error;
}

bool g_refuseHeap = false;
uint64_t g_heapAsked = 0;  // the last request
int g_refusals = 0;        // refuse this many more requests, then give
bool fakeReserveHeap(uint64_t bytes) {
  g_heapAsked = bytes;
  if (g_refusals > 0) return --g_refusals, false;
  return !g_refuseHeap;
}

TEST(ViewerState, TheBrowserRefusingMemoryStopsWithAMessage) {
  const Packed& p = packedMemory();
  ViewerState s;
  s.memory.reserveHeap = fakeReserveHeap;
  g_refuseHeap = false;
  g_heapAsked = 0;
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  ASSERT_TRUE(addChunk(s, 0, p.chunks[0]).ok());
  EXPECT_EQ(g_heapAsked, estimateLevelBytes(s.dataset.manifest, s.chunksTotal)) << "with the base: for the last level";
  ASSERT_TRUE(addChunk(s, 1, p.chunks[1]).ok());
  settle(s);
  EXPECT_EQ(g_heapAsked, estimateLevelBytes(s.dataset.manifest, 2)) << "asked for the next level before taking it";
  const uint32_t vertices = s.dataset.pm.vertexCount();
  g_refuseHeap = true;
  EXPECT_FALSE(addChunk(s, 2, p.chunks[2]).ok());
  EXPECT_EQ(s.state, LoadState::Error);
  EXPECT_TRUE(s.memory.limited);
  EXPECT_NE(s.error.find("did not give the viewer"), std::string::npos) << s.error;
  settle(s);
  EXPECT_EQ(s.dataset.pm.vertexCount(), vertices);
  expectMatchesFromScratch(s, "memory refused");

  // Not enough at the base for the last level's arrays at once: they grow level by level.
  ViewerState t;
  t.memory.reserveHeap = fakeReserveHeap;
  g_refuseHeap = false;
  g_refusals = 1;
  ASSERT_TRUE(openManifest(t, p.manifest).ok());
  streamAll(t, p);
  EXPECT_EQ(g_refusals, 0);
  EXPECT_EQ(t.state, LoadState::Complete) << t.error;
  EXPECT_EQ(t.dataset.pm.vertexCount(), t.dataset.manifest.vertices);
}

TEST(ViewerState, TheIntervalTreeWaitsUntilTheLevelSettles) {
  const Packed& p = packedStream();
  ViewerState s;
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  ASSERT_TRUE(addChunk(s, 0, p.chunks[0]).ok());
  ASSERT_TRUE(addChunk(s, 1, p.chunks[1]).ok());
  EXPECT_FALSE(treePending(s)) << "chunks still to come: no tree";
  settle(s);
  EXPECT_FALSE(treePending(s));
  EXPECT_EQ(s.surface.treeCoverage(), 0u);
  setIsovalue(s, 0.2f);
  expectMatchesFromScratch(s, "isovalue without a tree");
  for (uint32_t c = 2; c < p.chunks.size(); ++c) ASSERT_TRUE(addChunk(s, c, p.chunks[c]).ok());
  EXPECT_FALSE(treePending(s)) << "splits still to apply";
  settle(s);
  ASSERT_EQ(s.state, LoadState::Complete);
  EXPECT_TRUE(treePending(s));
  while (growTree(s, g_ticks + 2, fakeNow)) {
  }
  EXPECT_EQ(s.surface.treeCoverage(), s.dataset.pm.mesh.tetCount());
  EXPECT_FALSE(treePending(s));
  EXPECT_EQ(stats(s)["treeTets"].get<uint32_t>(), s.dataset.pm.mesh.tetCount());
  setIsovalue(s, 0.05f);
  expectMatchesFromScratch(s, "isovalue through the tree");
  setLevelFraction(s, 0.5);  // undoing splits keeps the tree on the tets that remain
  settle(s);
  EXPECT_LE(s.surface.treeCoverage(), s.dataset.pm.mesh.tetCount());
  setIsovalue(s, 0.1f);
  expectMatchesFromScratch(s, "after moving the level");
}

TEST(ViewerState, ChunksAreCheckedWithoutSideEffects) {
  const Packed& p = packedStream();
  ViewerState s;
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  EXPECT_EQ(checkChunk(s, 0, p.chunks[0]), ChunkCheck::Ok);
  EXPECT_EQ(checkChunk(s, 1, p.chunks[0]), ChunkCheck::WrongSize) << "another chunk";
  std::vector<uint8_t> flipped = p.chunks[1];
  flipped[flipped.size() / 2] ^= 0x10;
  EXPECT_EQ(checkChunk(s, 1, flipped), ChunkCheck::WrongHash);
  EXPECT_EQ(checkChunk(s, 1, std::span<const uint8_t>(p.chunks[1]).first(p.chunks[1].size() - 1)),
            ChunkCheck::WrongSize);
  EXPECT_EQ(checkChunk(s, 9999, p.chunks[1]), ChunkCheck::NoSuchChunk);
  EXPECT_EQ(s.state, LoadState::Loading) << "checking changes nothing";
  EXPECT_EQ(s.dataset.chunksReceived, 0u);
  setNetwork(s, {.notice = "connection lost, retrying part 2 in 4 s"});
  EXPECT_EQ(stats(s)["notice"], "connection lost, retrying part 2 in 4 s");
}

// A software GL draws the scene smaller while the level refines or the user interacts (never a
// screenshot), at most kReducedPixels, and at full size otherwise.
TEST(ViewerState, SceneIsReducedOnASoftwareGlWhileBusy) {
  EXPECT_FLOAT_EQ(sceneScale(true, true, false, 1280, 800), 0.5f);
  EXPECT_EQ(sceneScale(false, true, false, 1280, 800), 1.f) << "a GPU draws full size";
  EXPECT_EQ(sceneScale(true, false, false, 1280, 800), 1.f) << "the still frame";
  EXPECT_EQ(sceneScale(true, true, true, 1280, 800), 1.f) << "a screenshot";
  EXPECT_EQ(sceneScale(true, true, false, 640, 400), 1.f) << "small enough already";
  EXPECT_EQ(sceneScale(true, true, false, 0, 0), 1.f);
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

// Colour by field and the slice plane through the model: the colour field is independent of the
// isovalue's, the slice turned on mid-stream follows the splits locally (no full upload) and ends
// equal to one made from scratch, and both show in the stats.
TEST(ViewerState, ColourFieldAndSliceFollowTheStream) {
  const Packed& p = packedStream();
  ViewerState s;
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  ASSERT_TRUE(setField(s, "harmonic"));
  setIsovalue(s, 0.1f);
  ASSERT_TRUE(setColourField(s, "distance"));
  EXPECT_FALSE(setColourField(s, "nonsense"));
  const Range d = s.dataset.manifest.fields[size_t(s.dataset.manifest.findField("distance"))].range;
  EXPECT_EQ(s.colour.min, d.min);
  EXPECT_EQ(s.colour.max, d.max);
  setColourRange(s, 0.9f, 0.2f);
  EXPECT_EQ(s.colour.min, 0.2f);
  EXPECT_EQ(s.colour.max, 0.9f);
  ASSERT_TRUE(addChunk(s, 0, p.chunks[0]).ok());
  setSliceEnabled(s, true);
  ASSERT_TRUE(setSlicePlane(s, {0, 0, 2}, 0.3f));
  EXPECT_GT(s.slice.surface().triangleCount(), 0u);
  s.slice.surface().clearChanges();
  for (uint32_t c = 1; c < p.chunks.size(); ++c) {
    ASSERT_TRUE(addChunk(s, c, p.chunks[c]).ok()) << c;
    advance(s, g_ticks + 4, fakeNow);
    EXPECT_FALSE(s.slice.surface().fullUploadNeeded()) << "splits never re-extract the slice";
  }
  settle(s);
  EXPECT_EQ(s.state, LoadState::Complete);
  expectMatchesFromScratch(s, "complete");
  // The surface's colours: the distance field interpolated (|p| at a vertex, up to the
  // interpolation along an edge, which lies inside the sphere through its ends).
  for (uint32_t i : s.surface.indices()) {
    const float* q = &s.surface.positions()[3 * size_t(i)];
    EXPECT_LE(std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]), s.surface.colours()[i] + 1e-4f);
  }
  SliceTracker fresh;
  fresh.setPlane({0, 0, 1}, 0.3f);
  fresh.rebuild(s.dataset.pm.mesh, {});
  EXPECT_EQ(s.slice.surface().triangleCount(), fresh.surface().triangleCount());
  EXPECT_NEAR(s.slice.surface().area(), 4.0, 1e-3);  // the 16-bit grid moves vertices a little
  EXPECT_NEAR(s.slice.surface().area(), fresh.surface().area(), 1e-9);
  auto j = stats(s);
  EXPECT_EQ(j["colourField"], "distance");
  EXPECT_EQ(j["colourMap"], "viridis");
  EXPECT_EQ(j["slice"]["on"], true);
  EXPECT_EQ(j["slice"]["normal"][2].get<double>(), 1.0);
  EXPECT_EQ(j["slice"]["triangles"].get<uint32_t>(), s.slice.surface().triangleCount());
  setSliceEnabled(s, false);
  EXPECT_EQ(s.slice.surface().triangleCount(), 0u);
  EXPECT_TRUE(setColourField(s, -1));
  for (uint32_t i : s.surface.indices()) EXPECT_EQ(s.surface.colours()[i], 0.f);
}

// "fit": the colour range becomes the colour field's range over the shown triangles' vertices,
// computed here from the triangles themselves; with the slice on it covers the slice too.
TEST(ViewerState, FitColourRangeCoversWhatIsShown) {
  const Packed& p = packedStream();
  ViewerState s;
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  EXPECT_FALSE(fitColourRange(s)) << "no colour field yet";
  ASSERT_TRUE(setField(s, "harmonic"));
  setIsovalue(s, 0.1f);
  ASSERT_TRUE(setColourField(s, "distance"));
  for (uint32_t c = 0; c < p.chunks.size(); ++c) ASSERT_TRUE(addChunk(s, c, p.chunks[c]).ok()) << c;
  settle(s);
  auto rangeOf = [](const IncrementalIsosurface& x, float& lo, float& hi) {
    for (uint32_t t = 0; t < x.triangleCount(); ++t)
      for (int k = 0; k < 3; ++k) {
        float c = x.colours()[x.indices()[3 * size_t(t) + k]];
        lo = std::min(lo, c);
        hi = std::max(hi, c);
      }
  };
  float lo = 1e30f, hi = -1e30f;
  rangeOf(s.surface, lo, hi);
  ASSERT_TRUE(fitColourRange(s));
  EXPECT_EQ(s.colour.min, lo);
  EXPECT_EQ(s.colour.max, hi);
  const Range d = s.dataset.manifest.fields[size_t(s.dataset.manifest.findField("distance"))].range;
  EXPECT_GT(s.colour.min, d.min) << "the surface spans part of the field's range";
  setSliceEnabled(s, true);
  ASSERT_TRUE(setSlicePlane(s, {0, 0, 1}, 0.3f));
  rangeOf(s.slice.surface(), lo, hi);
  ASSERT_TRUE(fitColourRange(s));
  EXPECT_EQ(s.colour.min, lo);
  EXPECT_EQ(s.colour.max, hi);
}

namespace {

// The mirror holds the tracker's live surface: the same triangles in the same slots, and at
// every vertex a triangle uses the same position, normal and colour.
void expectMirrors(const IncrementalIsosurface& s, const SurfaceMirror& m, const char* where) {
  SCOPED_TRACE(where);
  ASSERT_EQ(m.triangleCount(), s.triangleCount());
  ASSERT_EQ(m.vertexSlotCount(), s.vertexSlotCount());
  EXPECT_EQ(m.vertexCount(), s.vertexCount());
  EXPECT_EQ(m.area(), s.area());
  ASSERT_TRUE(std::equal(s.indices().begin(), s.indices().end(), m.indices().begin()));
  for (uint32_t v : s.indices()) {
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(m.positions()[3 * v + k], s.positions()[3 * v + k]);
      ASSERT_EQ(m.normals()[3 * v + k], s.normals()[3 * v + k]);
    }
    ASSERT_EQ(m.colours()[v], s.colours()[v]);
  }
}

void expectMirrors(const HullTracker& h, const HullMirror& m) {
  ASSERT_EQ(m.triangleCount(), h.triangleCount());
  ASSERT_EQ(m.lineCount(), h.lineCount());
  EXPECT_TRUE(std::ranges::equal(m.trianglePositions(), h.trianglePositions()));
  EXPECT_TRUE(std::ranges::equal(m.triangleNormals(), h.triangleNormals()));
  EXPECT_TRUE(std::ranges::equal(m.lineVertices(), h.lineVertices()));
}

// One delta from the model's trackers into the mirrors, as the worker and the page do it.
void sync(ViewerState& s, SurfaceMirror& surface, SurfaceMirror& slice, HullMirror& hull, size_t* bytes = nullptr) {
  std::vector<uint8_t> delta;
  writeDelta(&s.surface, &s.slice.surface(), &s.hull, delta);
  s.surface.clearChanges();
  s.slice.surface().clearChanges();
  s.hull.clearChanges();
  DeltaApplied applied;
  std::string error;
  ASSERT_TRUE(applyDelta(delta, surface, slice, hull, applied, error)) << error;
  EXPECT_TRUE(applied.surface && applied.slice && applied.hull);
  if (bytes) *bytes = delta.size();
}

}  // namespace

// The page draws mirrors of the worker's surface, slice and hull, kept by deltas: after every
// slice of splits, undo, new isovalue and colour, the mirrors hold what the model holds, and a
// delta while splits stream is a small part of a full copy.
TEST(GeometrySync, MirrorsFollowTheModelThroughSplitsUndoAndNewValues) {
  const Packed& p = packedStream();
  ViewerState s;
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  ASSERT_TRUE(setField(s, "harmonic"));
  setIsovalue(s, 0.1f);
  ASSERT_TRUE(setColourField(s, "distance"));
  ASSERT_TRUE(addChunk(s, 0, p.chunks[0]).ok());
  setSliceEnabled(s, true);
  ASSERT_TRUE(setSlicePlane(s, {0, 0, 1}, 0.3f));
  SurfaceMirror surface, slice;
  HullMirror hull;
  size_t fullBytes = 0, partialBytes = 0;
  sync(s, surface, slice, hull, &fullBytes);
  expectMirrors(s.surface, surface, "base");
  EXPECT_TRUE(surface.fullUploadNeeded());
  surface.clearChanges();
  for (uint32_t c = 1; c < p.chunks.size(); ++c) {
    ASSERT_TRUE(addChunk(s, c, p.chunks[c]).ok()) << c;
    advance(s, g_ticks + 2, fakeNow);
    size_t bytes = 0;
    sync(s, surface, slice, hull, &bytes);
    partialBytes = std::max(partialBytes, bytes);
    EXPECT_FALSE(surface.fullUploadNeeded());
    expectMirrors(s.surface, surface, "streaming");
    expectMirrors(s.slice.surface(), slice, "slice streaming");
    expectMirrors(s.hull, hull);
    surface.clearChanges();
    slice.clearChanges();
    hull.clearChanges();
  }
  settle(s);
  sync(s, surface, slice, hull);
  expectMirrors(s.surface, surface, "complete");
  EXPECT_LT(partialBytes, fullBytes) << "a slice of splits sends what it changed";

  setLevel(s, s.dataset.splitsReceived() / 3);  // undo
  while (advance(s, g_ticks + 2, fakeNow)) {
    sync(s, surface, slice, hull);
    expectMirrors(s.surface, surface, "undoing");
    expectMirrors(s.hull, hull);
  }
  sync(s, surface, slice, hull);
  setIsovalue(s, 0.6f);
  ASSERT_TRUE(setColourField(s, -1));
  setSliceEnabled(s, false);
  sync(s, surface, slice, hull);
  expectMirrors(s.surface, surface, "new isovalue");
  expectMirrors(s.slice.surface(), slice, "slice off");
  EXPECT_EQ(slice.triangleCount(), 0u);
  expectMirrors(s.hull, hull);
}

// A damaged delta (cut short anywhere, or a corner past the vertices) is refused with a reason
// and changes nothing.
TEST(GeometrySync, ADamagedDeltaChangesNothing) {
  const Packed& p = packedBase();
  ViewerState s;
  ASSERT_TRUE(openManifest(s, p.manifest).ok());
  ASSERT_TRUE(addChunk(s, 0, p.chunks[0]).ok());
  std::vector<uint8_t> delta;
  writeDelta(&s.surface, nullptr, &s.hull, delta);
  SurfaceMirror surface, slice;
  HullMirror hull;
  DeltaApplied applied;
  std::string error;
  for (size_t cut : {size_t(0), size_t(1), size_t(9), delta.size() / 2, delta.size() - 1}) {
    ASSERT_FALSE(applyDelta(std::span(delta).first(cut), surface, slice, hull, applied, error)) << cut;
    EXPECT_NE(error.find("malformed"), std::string::npos);
    EXPECT_EQ(surface.triangleCount(), 0u);
    EXPECT_EQ(hull.triangleCount(), 0u);
  }
  std::vector<uint8_t> bad = delta;
  bad.push_back(0);
  EXPECT_FALSE(applyDelta(bad, surface, slice, hull, applied, error));
  // The first triangle's first corner (after the part mask, the header and the vertex arrays).
  const uint32_t slots = s.surface.vertexSlotCount();
  const size_t corner = 1 + 4 + 4 + 4 + 8 + 1 + size_t(slots) * 28;
  bad = delta;
  std::memcpy(&bad[corner], &slots, 4);
  EXPECT_FALSE(applyDelta(bad, surface, slice, hull, applied, error));
  EXPECT_NE(error.find("past the vertices"), std::string::npos);
  EXPECT_EQ(surface.triangleCount(), 0u);
  ASSERT_TRUE(applyDelta(delta, surface, slice, hull, applied, error)) << error;
  expectMirrors(s.surface, surface, "whole");
}

// The page holds the view and the worker's reports; the worker's model follows the commands.
// One round: the page's choices reach the model as they are (the page's rules, not the
// model's, decide the values), the report comes back with the geometry, and until the worker
// has applied the latest view the page does not repeat its "complete" or "exact".
TEST(PageState, TheWorkersModelFollowsThePageAndReportsBack) {
  const Packed& p = packedStream();
  PageState page;
  ASSERT_TRUE(openPage(page, p.manifest));
  ViewerState model;  // the worker's
  ASSERT_TRUE(openManifest(model, p.manifest).ok());

  // The worker's side of one exchange: apply the command, refine, report with a delta.
  uint32_t seen = 0;
  auto exchange = [&](bool settle) {
    const std::string text = takeCommand(page);
    if (!text.empty()) {
      const auto c = nlohmann::json::parse(text);
      applyView(model, c["view"]);
      if (c.contains("level")) setLevelFraction(model, c["level"]["fraction"].get<double>());
      seen = c["version"].get<uint32_t>();
    }
    while (settle && advance(model, g_ticks + 3, fakeNow)) {
    }
    std::vector<uint8_t> delta;
    writeDelta(&model.surface, &model.slice.surface(), &model.hull, delta);
    model.surface.clearChanges();
    model.slice.surface().clearChanges();
    model.hull.clearChanges();
    std::string error;
    ASSERT_TRUE(takeReport(page, statsJson(model), seen, delta, error)) << error;
  };

  ASSERT_TRUE(setField(page, "distance"));
  ASSERT_TRUE(setColourField(page, "harmonic"));
  setSliceEnabled(page, true);
  ASSERT_TRUE(setSlicePlane(page, {0, 0, 3}, 0.25f));
  setIsovalue(page, 0.7f);
  EXPECT_EQ(page.settings.sliceNormal[2], 1.f) << "normalised on the page";
  for (size_t c = 0; c < p.chunks.size(); ++c) ASSERT_TRUE(addChunk(model, uint32_t(c), p.chunks[c]).ok());
  exchange(true);
  EXPECT_TRUE(takeCommand(page).empty()) << "nothing changed since";
  EXPECT_EQ(shownState(page), LoadState::Complete);
  EXPECT_EQ(model.dataset.manifest.fields[size_t(model.field)].name, "distance");
  EXPECT_EQ(model.isovalue, 0.7f);
  EXPECT_TRUE(model.sliceOn);
  EXPECT_EQ(model.slice.offset(), 0.25f);
  // The page's view and the model's are the same object (the level aside, which the model keeps).
  nlohmann::json a = viewObject(page), b = viewObject(model);
  a.erase("fetch");
  EXPECT_EQ(a, b);
  EXPECT_EQ(page.surface.triangleCount(), model.surface.triangleCount());
  EXPECT_EQ(page.slice.triangleCount(), model.slice.surface().triangleCount());
  EXPECT_GT(page.surface.triangleCount(), 0u);

  // A new isovalue: until the worker answers, the old surface is not "complete".
  setIsovalue(page, 0.4f);
  EXPECT_EQ(shownState(page), LoadState::Streaming);
  exchange(false);  // the command goes out, the report comes back
  EXPECT_EQ(shownState(page), LoadState::Complete);
  EXPECT_EQ(page.surface.triangleCount(), model.surface.triangleCount());

  // A level asked for is shown on the slider at once and kept until the worker has it.
  setLevelFraction(page, 0.5);
  const uint32_t asked = shownTargetSplits(page);
  EXPECT_LT(asked, page.model.splitsReceived);
  EXPECT_EQ(shownState(page), LoadState::Streaming);
  exchange(true);
  EXPECT_EQ(page.levelRequest, -1.0);
  EXPECT_EQ(shownTargetSplits(page), asked);
  EXPECT_EQ(page.model.splitsApplied, asked);
  EXPECT_EQ(page.surface.triangleCount(), model.surface.triangleCount());

  // A report that is not JSON changes nothing and says so.
  std::string error;
  EXPECT_FALSE(takeReport(page, "not json", seen, {}, error));
  EXPECT_FALSE(error.empty());
  EXPECT_EQ(page.surface.triangleCount(), model.surface.triangleCount());
}

// While the worker refines, the page gets an update at most every 33 ms (update_pacing.h): with
// slices of 12 ms, after every third slice and after the last; the slices between go in one
// delta, so the page's mirrors equal the model after every update. A command applied or a new
// plan goes out after the next slice, whenever the last update went.
TEST(PageState, UpdatesWhileRefiningCarryTheSlicesBetweenThem) {
  const Packed& p = packedStream();
  ViewerState model;
  ASSERT_TRUE(openManifest(model, p.manifest).ok());
  for (size_t c = 0; c < p.chunks.size(); ++c) ASSERT_TRUE(addChunk(model, uint32_t(c), p.chunks[c]).ok());
  SurfaceMirror surface, slice;
  HullMirror hull;
  UpdatePacing pacing;
  sync(model, surface, slice, hull);  // the base
  pacing.sent(0, model.fetch.version);
  double ms = 0;
  int slices = 0, updates = 0;
  for (bool more = true; more;) {
    advance(model, g_ticks + 2, fakeNow);  // one batch of splits
    ms += 12;
    ++slices;
    more = refining(model);
    if (!pacing.due(ms, more, model.fetch.version)) continue;
    pacing.sent(ms, model.fetch.version);
    sync(model, surface, slice, hull);
    ++updates;
    expectMirrors(model.surface, surface, "after an update");
  }
  EXPECT_GT(slices, 6);
  EXPECT_EQ(updates, (slices + 2) / 3) << slices << " slices";
  EXPECT_EQ(model.state, LoadState::Complete);
  expectMirrors(model.hull, hull);

  const uint32_t plan = model.fetch.version;
  EXPECT_FALSE(pacing.due(ms + 12, true, plan));
  pacing.commandApplied();
  EXPECT_TRUE(pacing.due(ms + 12, true, plan)) << "a command applied";
  pacing.sent(ms + 12, plan);
  EXPECT_FALSE(pacing.due(ms + 24, true, plan));
  EXPECT_TRUE(pacing.due(ms + 24, true, plan + 1)) << "a new plan";
  EXPECT_TRUE(pacing.due(ms + 24, false, plan)) << "the refinement stopped";
}
