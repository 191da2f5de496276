#include "viewer_state.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>

#include <nlohmann/json.hpp>

#include "adjacency.h"
#include "hash.h"
#include "tet_tables.h"
#include "viewer_memory.h"

namespace tetstream::viewer {
namespace {

double nowMs() {
  using namespace std::chrono;
  return duration<double, std::milli>(steady_clock::now().time_since_epoch()).count();
}

float middleOf(const Range& r) { return r.min + 0.5f * (r.max - r.min); }

// Boundary edges whose two triangles' normals differ by more than ~30 degrees are creases.
constexpr float kCreaseCos = 0.866f;

uint64_t edgeKey(uint32_t a, uint32_t b) { return a < b ? uint64_t(a) << 32 | b : uint64_t(b) << 32 | a; }

uint64_t mix(uint64_t x) {  // splitmix64 finaliser
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// Outward unit normal of triangle (a, b, c), 0 when degenerate.
void faceNormal(const float* p, const uint32_t tri[3], float n[3]) {
  const float* a = p + 3 * size_t(tri[0]);
  const float* b = p + 3 * size_t(tri[1]);
  const float* c = p + 3 * size_t(tri[2]);
  float u[3], v[3];
  for (int k = 0; k < 3; ++k) u[k] = b[k] - a[k], v[k] = c[k] - a[k];
  n[0] = u[1] * v[2] - u[2] * v[1];
  n[1] = u[2] * v[0] - u[0] * v[2];
  n[2] = u[0] * v[1] - u[1] * v[0];
  float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (int k = 0; k < 3; ++k) n[k] = len > 0 ? n[k] / len : 0.f;
}

// The values of the chosen field on the current level, empty when there is none.
std::span<const float> fieldValues(const ViewerState& s) {
  const TetMesh& mesh = s.dataset.pm.mesh;
  if (s.field < 0 || mesh.tetCount() == 0) return {};
  int f = mesh.findField(s.dataset.manifest.fields[size_t(s.field)].name);
  if (f < 0 || mesh.fields[size_t(f)].values.size() != mesh.vertexCount()) return {};
  return mesh.fields[size_t(f)].values;
}

// The values of the colour field on the current level, empty when there is none.
std::span<const float> colourValues(const ViewerState& s) {
  const TetMesh& mesh = s.dataset.pm.mesh;
  if (s.colourField < 0 || size_t(s.colourField) >= s.dataset.manifest.fields.size()) return {};
  int f = mesh.findField(s.dataset.manifest.fields[size_t(s.colourField)].name);
  if (f < 0 || mesh.fields[size_t(f)].values.size() != mesh.vertexCount()) return {};
  return mesh.fields[size_t(f)].values;
}

// The whole surface of the current level (isovalue or field changed, or the base arrived).
void extract(ViewerState& s) {
  s.surfaceDirty = true;
  std::span<const float> values = fieldValues(s);
  if (values.empty()) {
    s.surface.reset();
    s.extractMs = 0;
    return;
  }
  double t0 = nowMs();
  s.surface.rebuild(s.dataset.pm.mesh, values, s.isovalue, colourValues(s));
  s.extractMs = nowMs() - t0;
  s.surfaceReady = true;
}

// The whole slice of the current level (plane moved, turned on, or the base arrived).
void extractSlice(ViewerState& s) {
  s.sliceDirty = true;
  if (!s.sliceOn || s.dataset.pm.mesh.tetCount() == 0) {
    s.slice.clear();
    return;
  }
  s.slice.rebuild(s.dataset.pm.mesh, colourValues(s));
}

// Growing the mesh arrays by doubling while streaming would copy tens of MB inside one frame
// (~20 ms natively at 1 M tets): size them once for the last level that will be streamed (the
// full mesh unless memory is limited), as the manifest announces it. The manifest is untrusted,
// so only up to 4 M tets (~100 MB) without a memory limit; bigger meshes grow as usual.
void reserveLevel(ViewerState& s) {
  constexpr uint32_t kMaxReservedTets = 4u << 20;
  Dataset& ds = s.dataset;
  const Manifest& m = ds.manifest;
  if (s.chunksAllowed == 0) return;
  const ChunkInfo& last = m.chunks[s.chunksAllowed - 1];
  if (!s.memoryLimitBytes && (last.tets > kMaxReservedTets || last.vertices > kMaxReservedTets)) return;
  ProgressiveMesh& pm = ds.pm;
  pm.mesh.positions.reserve(3 * size_t(last.vertices));
  pm.mesh.tets.reserve(4 * size_t(last.tets));
  for (ScalarField& f : pm.mesh.fields) f.values.reserve(last.vertices);
  pm.stars.reserve(last.vertices, 4 * size_t(last.tets));
  pm.splitJ.reserve(last.vertices);
  pm.splitTetsBefore.reserve(last.vertices);
  s.surface.reserveTets(last.tets);
}

// "part 12 of 30" as people count.
std::string partName(const ViewerState& s, uint32_t index) {
  return "part " + std::to_string(index + 1) + " of " + std::to_string(s.chunksTotal);
}

// The stop at the last level that fits, in plain words.
void stopForMemory(ViewerState& s) {
  const Manifest& m = s.dataset.manifest;
  const uint32_t k = s.dataset.chunksReceived;
  char level[32];
  std::snprintf(level, sizeof level, "%.1f%%", m.vertices ? 100.0 * m.chunks[k - 1].vertices / m.vertices : 0.0);
  s.memoryLimited = true;
  failLoad(s, "This dataset needs about " + formatBytes(s.memoryNeededBytes) + " of memory at full detail, more " +
                  "than the " + formatBytes(s.memoryLimitBytes) + " this page may use. Streaming stopped after " +
                  partName(s, k - 1) + " (" + level + " of the vertices); that level stays fully usable.");
}

void updateState(ViewerState& s) {
  if (s.state == LoadState::Idle || s.state == LoadState::Error) return;
  const Dataset& ds = s.dataset;
  if (ds.chunksReceived == 0)
    s.state = LoadState::Loading;
  else if (ds.chunksReceived == s.chunksTotal && ds.splitsApplied() == ds.splitsReceived())
    s.state = LoadState::Complete;
  else
    s.state = LoadState::Streaming;
}

// One work slice (advance or growTree) of `ms` into the histogram of slice durations.
void noteSlice(ViewerState& s, double ms) {
  size_t bin = 0;
  while (bin < kSliceEdgesMs.size() && ms >= kSliceEdgesMs[bin]) ++bin;
  ++s.sliceCounts[bin];
}

}  // namespace

const char* loadStateName(LoadState s) {
  switch (s) {
    case LoadState::Idle: return "idle";
    case LoadState::Loading: return "loading";
    case LoadState::Streaming: return "streaming";
    case LoadState::Complete: return "complete";
    case LoadState::Error: return "error";
  }
  return "error";
}

// ------------------------------------------------------------------ loading and level

Result openManifest(ViewerState& s, std::string_view manifestJson) {
  s.surface.reset();
  // The interval tree waits until the level settles (growTree): see IncrementalIsosurface.
  s.surface.setTreeDeferred(true);
  s.hull.clear();
  s.surfaceDirty = s.hullDirty = true;
  s.surfaceReady = false;
  s.chunksTotal = 0;
  s.slice.clear();
  s.sliceOn = false;
  s.sliceDirty = true;
  s.field = -1;
  s.colourField = -1;
  s.colourMin = 0;
  s.colourMax = 1;
  s.targetSplits = 0;
  s.live = true;
  s.paused = false;
  s.networkBytes = s.datasetBytes = 0;
  s.rate.reset();
  s.rateBytesPerSec = 0;
  s.completeMs = -1;
  s.notice.clear();
  s.memoryNeededBytes = 0;
  s.chunksAllowed = 0;
  s.memoryLimited = false;
  if (Result r = openDataset(s.dataset, manifestJson); !r) {
    s.dataset.manifest = {};
    s.dataset.pm = {};
    s.dataset.chunksReceived = 0;
    failLoad(s, "The dataset description (manifest.json) is not usable: " + r.message);
    return r;
  }
  const Manifest& m = s.dataset.manifest;
  s.chunksTotal = uint32_t(m.chunks.size());
  s.error.clear();
  s.state = LoadState::Loading;
  s.frameRequested = true;
  int f = m.findField(m.isoField);
  if (f < 0 && !m.fields.empty()) f = 0;
  s.field = f;
  if (f >= 0) s.isovalue = middleOf(m.fields[size_t(f)].range);
  s.slice.setPlane({0, 0, 1}, 0.5f * (m.bounds.min[2] + m.bounds.max[2]));

  s.memoryNeededBytes = s.memoryBaseBytes + estimateLevelBytes(m, s.chunksTotal);
  s.chunksAllowed = s.chunksTotal;
  if (s.memoryLimitBytes) {
    const uint64_t budget = s.memoryLimitBytes > s.memoryBaseBytes ? s.memoryLimitBytes - s.memoryBaseBytes : 0;
    s.chunksAllowed = chunksThatFit(m, budget);
    if (s.chunksAllowed == 0) {
      s.memoryLimited = true;
      const std::string message = "This dataset needs about " +
                                  formatBytes(s.memoryBaseBytes + estimateLevelBytes(m, 1)) +
                                  " of memory even at its coarsest level, more than the " +
                                  formatBytes(s.memoryLimitBytes) + " this page may use.";
      failLoad(s, message);
      return fail(Status::TooLarge, message);
    }
  }
  return Result::success();
}

ChunkCheck checkChunk(const ViewerState& s, uint32_t index, std::span<const uint8_t> bytes) {
  const Manifest& m = s.dataset.manifest;
  if (index >= m.chunks.size()) return ChunkCheck::NoSuchChunk;
  const ChunkInfo& info = m.chunks[index];
  if (bytes.size() != info.bytes) return ChunkCheck::WrongSize;
  return contentHash(bytes) == info.hash ? ChunkCheck::Ok : ChunkCheck::WrongHash;
}

Result addChunk(ViewerState& s, uint32_t index, std::span<const uint8_t> bytes) {
  if (s.state != LoadState::Loading && s.state != LoadState::Streaming) {
    Result r = fail(Status::BadArgument, std::string("chunk ") + std::to_string(index) + " arrived while the viewer is " +
                                             loadStateName(s.state));
    if (s.state != LoadState::Error) failLoad(s, r.message);
    return r;
  }
  Dataset& ds = s.dataset;
  if (index >= s.chunksAllowed) {
    Result r = fail(Status::TooLarge, partName(s, index) + " does not fit in memory");
    failLoad(s, r.message);
    return r;
  }
  // Memory for the level this chunk makes, asked for before anything grows: a refusal stops
  // here with a message instead of failing an allocation half way through. With the base, the
  // arrays are sized for the last level that will come (reserveLevel), so that much is asked
  // for first; if the browser will not give it now, the arrays grow as levels come instead.
  const uint64_t need = s.memoryBaseBytes + estimateLevelBytes(ds.manifest, index + 1);
  const bool reserveAll = index == 0 && (!s.reserveHeap ||
                                         s.reserveHeap(s.memoryBaseBytes + estimateLevelBytes(ds.manifest, s.chunksAllowed)));
  if (s.reserveHeap && !reserveAll && !s.reserveHeap(need)) {
    s.memoryLimited = true;
    Result r = fail(Status::TooLarge, "The browser did not give the viewer the " + formatBytes(need) +
                                          " of memory that " + partName(s, index) + " needs." +
                                          (ds.chunksReceived ? " Showing the last complete level." : ""));
    failLoad(s, r.message);
    return r;
  }
  if (Result r = receiveChunk(ds, index, bytes); !r) {
    failLoad(s, "Part " + std::to_string(index + 1) + " of " + std::to_string(s.chunksTotal) +
                    " of the dataset could not be used: " + r.message +
                    (ds.chunksReceived ? ". Showing the last complete level." : "."));
    return r;
  }
  if (ds.chunksReceived == 1) {  // the base: shown at once
    if (reserveAll) reserveLevel(s);
    extract(s);
    extractSlice(s);
    s.hull.rebuild(ds.pm);
    s.hullDirty = true;
  }
  if (s.live) s.targetSplits = ds.splitsReceived();
  updateState(s);
  if (ds.chunksReceived == s.chunksAllowed && s.chunksAllowed < s.chunksTotal) stopForMemory(s);
  return Result::success();
}

bool advance(ViewerState& s, double deadlineMs, Clock now) {
  Dataset& ds = s.dataset;
  if (ds.chunksReceived == 0 || std::min(s.targetSplits, ds.splitsReceived()) == ds.splitsApplied()) {
    updateState(s);
    return false;
  }
  const double t0 = now();
  const uint32_t base = ds.pm.baseVertices;
  uint32_t steps = 0;
  do {
    const uint32_t target = std::min(s.targetSplits, ds.splitsReceived());
    const uint32_t a0 = ds.splitsApplied();
    if (a0 == target) break;
    const uint32_t n = std::min(kStepBatch, a0 > target ? a0 - target : target - a0);
    s.changed.clear();
    s.splitVertices.clear();
    // The hull needs every split's i and j; an undo forgets j, so read it first.
    if (a0 > target)
      for (uint32_t g = a0; g-- > a0 - n;) s.splitVertices.insert(s.splitVertices.end(), {base + g, ds.pm.splitJ[g]});
    bool reached = false;
    Result r = stepTowards(ds, target, n, s.changed, &reached);
    const uint32_t a1 = ds.splitsApplied();
    for (uint32_t g = a0; g < a1; ++g) s.splitVertices.insert(s.splitVertices.end(), {base + g, ds.pm.splitJ[g]});
    steps += a1 > a0 ? a1 - a0 : a0 - a1;
    // Paper §4.3: only the changed tets (T_new, T_moved, and the removed ones) are looked at.
    if (std::span<const float> values = fieldValues(s); !values.empty())
      s.surface.updateTets(ds.pm.mesh, values, s.changed, colourValues(s));
    if (s.sliceOn && s.slice.built()) s.slice.update(ds.pm.mesh, s.changed, colourValues(s));
    if (!r) {
      // The bad chunk and everything after it are gone (undone further than this batch): the
      // surface followed through `changed`, the hull is rebuilt once.
      s.hull.rebuild(ds.pm);
      s.targetSplits = std::min(s.targetSplits, ds.splitsReceived());
      failLoad(s, "Part " + std::to_string(ds.chunksReceived + 1) + " of " + std::to_string(s.chunksTotal) +
                      " of the dataset is damaged (" + r.message + "). Showing the last complete level.");
      break;
    }
    s.hull.update(ds.pm, s.splitVertices);
  } while (now() < deadlineMs);
  s.surfaceDirty = s.hullDirty = true;
  if (s.sliceOn) s.sliceDirty = true;
  s.refineMs = now() - t0;
  noteSlice(s, s.refineMs);
  s.maxRefineMs = std::max(s.maxRefineMs, s.refineMs);
  s.refineTotalMs += s.refineMs;
  s.refineSteps = steps;
  updateState(s);
  return true;
}

void setLevel(ViewerState& s, uint32_t splits) {
  const uint32_t received = s.dataset.splitsReceived();
  s.targetSplits = std::min(splits, received);
  s.live = splits >= received;
  updateState(s);
}

void setLevelFraction(ViewerState& s, double fraction) {
  if (!std::isfinite(fraction)) return;
  const Dataset& ds = s.dataset;
  if (fraction >= 1) return setLevel(s, ~0u);
  double vertices = std::round(std::max(0.0, fraction) * ds.manifest.vertices);
  setLevel(s, vertices > ds.pm.baseVertices ? uint32_t(vertices - ds.pm.baseVertices) : 0);
}

void setPaused(ViewerState& s, bool paused) {
  if (s.paused == paused) return;
  s.paused = paused;
  s.pausedChanged = true;
}

void setIsovalue(ViewerState& s, float value) {
  if (!std::isfinite(value) || value == s.isovalue) return;
  s.isovalue = value;
  extract(s);
}

bool setField(ViewerState& s, int index) {
  const Manifest& m = s.dataset.manifest;
  if (index < 0 || size_t(index) >= m.fields.size()) return false;
  s.field = index;
  s.isovalue = middleOf(m.fields[size_t(index)].range);
  s.surface.reset();  // another field: the interval tree is built again
  extract(s);
  return true;
}

bool setField(ViewerState& s, std::string_view name) { return setField(s, s.dataset.manifest.findField(name)); }

bool setColourField(ViewerState& s, int index) {
  const Manifest& m = s.dataset.manifest;
  if (index < -1 || index >= int(m.fields.size())) return false;
  s.colourField = index;
  if (index >= 0) {
    s.colourMin = float(m.fields[size_t(index)].range.min);
    s.colourMax = float(m.fields[size_t(index)].range.max);
  }
  s.surface.recolour(colourValues(s));
  s.surfaceDirty = true;
  if (s.slice.built()) {
    s.slice.recolour(colourValues(s));
    s.sliceDirty = true;
  }
  return true;
}

bool setColourField(ViewerState& s, std::string_view name) {
  if (name.empty() || name == "none") return setColourField(s, -1);
  const int f = s.dataset.manifest.findField(name);
  return f >= 0 && setColourField(s, f);
}

void setColourMap(ViewerState& s, ColourMap map) { s.colourMap = map; }

void setColourRange(ViewerState& s, float lo, float hi) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) return;
  if (lo > hi) std::swap(lo, hi);
  s.colourMin = lo;
  s.colourMax = hi;
}

bool fitColourRange(ViewerState& s) {
  if (s.colourField < 0) return false;
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  auto cover = [&](const IncrementalIsosurface& surface) {
    std::span<const float> colours = surface.colours();
    for (uint32_t v : surface.indices()) {  // live vertices only: free slots hold stale values
      lo = std::min(lo, colours[v]);
      hi = std::max(hi, colours[v]);
    }
  };
  cover(s.surface);
  if (s.sliceOn && s.slice.built()) cover(s.slice.surface());
  if (!(lo <= hi)) return false;
  if (lo == hi) {  // a flat colour: a small range around it, so the map still shows where it is
    const Range fr = s.dataset.manifest.fields[size_t(s.colourField)].range;
    const float pad = std::max(1e-6f * std::abs(lo), float(fr.max - fr.min) * 1e-3f);
    lo -= pad;
    hi += pad;
  }
  setColourRange(s, lo, hi);
  return true;
}

void setSliceEnabled(ViewerState& s, bool on) {
  if (on == s.sliceOn) return;
  s.sliceOn = on;
  if (on && s.colourField < 0 && s.field >= 0) setColourField(s, s.field);
  extractSlice(s);
}

bool setSlicePlane(ViewerState& s, std::array<float, 3> normal, float offset) {
  const bool changed = s.slice.setPlane(normal, offset);
  if (changed) extractSlice(s);
  return changed || (std::isfinite(offset) && (normal[0] != 0 || normal[1] != 0 || normal[2] != 0));
}

void sliceOffsetRange(const ViewerState& s, float& lo, float& hi) {
  const Bounds& b = s.dataset.manifest.bounds;
  SliceTracker::offsetRange(s.slice.normal(), b.min, b.max, lo, hi);
}

void failLoad(ViewerState& s, std::string_view message) {
  s.state = LoadState::Error;
  s.error = message.empty() ? "Unknown error." : std::string(message);
}

void setNotice(ViewerState& s, std::string_view message) { s.notice = message; }

uint64_t memoryInUse(const ViewerState& s) {
  return datasetMemoryBytes(s.dataset) + s.surface.memoryBytes() + s.hull.memoryBytes() + s.slice.memoryBytes();
}

// ------------------------------------------------------------------ download figures

void RateMeter::add(double nowMs, double totalBytes) {
  latestT_ = nowMs;
  latestBytes_ = totalBytes;
  if (count_ > 0 && nowMs - t_[(head_ + kSamples - 1) % kSamples] < 100) return;
  t_[head_] = nowMs;
  bytes_[head_] = totalBytes;
  head_ = (head_ + 1) % kSamples;
  count_ = std::min(count_ + 1, kSamples);
}

double RateMeter::bytesPerSecond(double nowMs, double windowMs) const {
  // The oldest sample inside the window is the reference; bytes since then over time since then.
  for (int i = count_; i > 0; --i) {
    int k = (head_ + kSamples - i) % kSamples;
    if (t_[k] < nowMs - windowMs) continue;
    double dt = std::max(nowMs, latestT_) - t_[k];
    return dt > 0 ? (latestBytes_ - bytes_[k]) * 1000.0 / dt : 0;
  }
  return 0;
}

void noteDownload(ViewerState& s, uint64_t networkBytes, uint64_t datasetBytes, double nowMs) {
  s.networkBytes = networkBytes;
  s.datasetBytes = datasetBytes;
  s.rate.add(nowMs, double(networkBytes));
}

void tick(ViewerState& s, double nowMs) { s.rateBytesPerSec = downloading(s) ? s.rate.bytesPerSecond(nowMs) : 0; }

bool downloading(const ViewerState& s) {
  return (s.state == LoadState::Loading || s.state == LoadState::Streaming) && !s.paused &&
         s.dataset.chunksReceived < s.chunksAllowed;
}

bool treePending(const ViewerState& s) {
  return s.surfaceReady && !refining(s) && !downloading(s) && s.state != LoadState::Loading &&
         s.surface.treeCoverage() < s.dataset.pm.mesh.tetCount() && !fieldValues(s).empty();
}

bool growTree(ViewerState& s, double deadlineMs, Clock now) {
  if (!treePending(s)) return false;
  const TetMesh& mesh = s.dataset.pm.mesh;
  // A small mesh at once (a bulk build is faster than inserting); a big one in steps.
  constexpr uint32_t kAtOnce = 1u << 16, kStep = 2048;
  const uint32_t step = s.surface.treeCoverage() == 0 && mesh.tetCount() <= kAtOnce ? kAtOnce : kStep;
  const double t0 = now();
  bool whole;
  do whole = s.surface.extendTree(mesh, fieldValues(s), step);
  while (!whole && now() < deadlineMs);
  noteSlice(s, now() - t0);
  return !whole;
}

bool refining(const ViewerState& s) {
  const Dataset& ds = s.dataset;
  return ds.chunksReceived > 0 && std::min(s.targetSplits, ds.splitsReceived()) != ds.splitsApplied();
}

double secondsLeft(const ViewerState& s) {
  if (!downloading(s) || s.rateBytesPerSec <= 0) return -1;
  uint64_t total = 0;  // of the chunks that will be fetched
  for (uint32_t c = 0; c < s.chunksAllowed; ++c) total += s.dataset.manifest.chunks[c].bytes;
  uint64_t have = std::max(s.datasetBytes, s.dataset.bytesReceived);
  return have >= total ? 0 : double(total - have) / s.rateBytesPerSec;
}

double levelFraction(const ViewerState& s) {
  uint32_t full = s.dataset.manifest.vertices;
  return full ? double(s.dataset.pm.vertexCount()) / full : 0;
}

double fieldErrorBound(const ViewerState& s) {
  const ChunkInfo* c = levelChunk(s);
  return c ? c->fieldError : -1;
}

const ChunkInfo* levelChunk(const ViewerState& s) {
  uint32_t c = s.dataset.chunksApplied();
  return c ? &s.dataset.manifest.chunks[c - 1] : nullptr;
}

// ------------------------------------------------------------------ the hull, from scratch

void buildBoundary(const TetMesh& mesh, BoundaryMesh& out) {
  out = {};
  if (mesh.tetCount() == 0) return;
  FaceAdjacency adj;
  buildFaceAdjacency(mesh.tets, mesh.vertexCount(), adj);
  std::vector<uint32_t> tris;
  extractBoundary(mesh.tets, adj, tris);

  const float* p = mesh.positions.data();
  const size_t nt = tris.size() / 3;
  std::vector<float> faceNormals(3 * nt);
  out.positions.reserve(9 * nt);
  out.normals.reserve(9 * nt);
  for (size_t t = 0; t < nt; ++t) {
    float n[3];
    faceNormal(p, &tris[3 * t], n);
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

// ------------------------------------------------------------------ the hull, kept up to date

void HullTracker::clear() {
  faces_.clear();
  positions_.clear();
  normals_.clear();
  head_.clear();
  next_.clear();
  prev_.clear();
  lines_.clear();
  lineKeys_.clear();
  lineOfEdge_.clear();
  dirtyEdges_.clear();
  changedTriangles_.clear();
  changedLines_.clear();
  fullUpload_ = true;
}

size_t HullTracker::memoryBytes() const {
  auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  return bytes(faces_) + bytes(positions_) + bytes(normals_) + bytes(head_) + bytes(next_) + bytes(prev_) +
         bytes(lines_) + bytes(lineKeys_) + lineOfEdge_.memoryBytes() + bytes(dirtyEdges_) + bytes(entries_) +
         bytes(vertexScratch_) + bytes(dropScratch_) + bytes(changedTriangles_) + bytes(changedLines_);
}

void HullTracker::clearChanges() {
  changedTriangles_.clear();
  changedLines_.clear();
  fullUpload_ = false;
}

void HullTracker::rebuild(const ProgressiveMesh& pm) {
  clear();
  const TetMesh& mesh = pm.mesh;
  head_.assign(mesh.vertexCount(), kNone);
  if (mesh.tetCount() == 0) return;
  FaceAdjacency adj;
  buildFaceAdjacency(mesh.tets, mesh.vertexCount(), adj);
  std::vector<uint32_t> tris;
  extractBoundary(mesh.tets, adj, tris);
  for (size_t t = 0; t + 2 < tris.size(); t += 3) addFace(mesh.positions.data(), &tris[t]);
  std::sort(dirtyEdges_.begin(), dirtyEdges_.end());
  dirtyEdges_.erase(std::unique(dirtyEdges_.begin(), dirtyEdges_.end()), dirtyEdges_.end());
  for (uint64_t e : dirtyEdges_) updateEdge(mesh.positions.data(), e);
  dirtyEdges_.clear();
  fullUpload_ = true;
}

void HullTracker::update(const ProgressiveMesh& pm, std::span<const uint32_t> vertices) {
  const uint32_t nv = pm.vertexCount();
  // A split or undo of (i, j) with neither on the hull changes no hull face: the tets it changes
  // fill star(i) ∪ star(j), whose faces through i or j are then all interior, before and after
  // (the region's outer faces contain neither). About nine in ten splits of a volume mesh are
  // such, and recounting their stars was a quarter of the refinement time. A vertex that an
  // earlier split of the batch did touch may have changed sides: those are recounted.
  const uint32_t known = uint32_t(head_.size());  // vertices the hull has seen
  if (head_.size() < nv) head_.resize(nv, kNone);
  vertexScratch_.clear();
  touched_.clear();
  auto onHull = [&](uint32_t v) { return v < known && head_[v] != kNone; };
  auto touched = [&](uint32_t v) { return std::find(touched_.begin(), touched_.end(), v) != touched_.end(); };
  for (size_t k = 0; k + 1 < vertices.size(); k += 2) {
    const uint32_t i = vertices[k], j = vertices[k + 1];
    if (!onHull(i) && !onHull(j) && !touched(i) && !touched(j)) continue;
    touched_.insert(touched_.end(), {i, j});
    vertexScratch_.insert(vertexScratch_.end(), {i, j});
  }
  std::sort(vertexScratch_.begin(), vertexScratch_.end());
  vertexScratch_.erase(std::unique(vertexScratch_.begin(), vertexScratch_.end()), vertexScratch_.end());
  // Removed vertices first (their faces go), then a recount around each remaining one. Every
  // face whose set of tets changed contains a split's i or j, so nothing else can change.
  std::vector<uint32_t>& drop = dropScratch_;
  for (uint32_t v : vertexScratch_) {
    if (v < nv || v >= head_.size()) continue;
    drop.clear();
    for (uint32_t c = head_[v]; c != kNone; c = next_[c]) drop.push_back(c / 3);
    std::sort(drop.begin(), drop.end(), std::greater<>());
    for (uint32_t slot : drop) removeFace(slot);
  }
  for (uint32_t v : vertexScratch_)
    if (v < nv) recount(pm, v);
  std::sort(dirtyEdges_.begin(), dirtyEdges_.end());
  dirtyEdges_.erase(std::unique(dirtyEdges_.begin(), dirtyEdges_.end()), dirtyEdges_.end());
  for (uint64_t e : dirtyEdges_) updateEdge(pm.mesh.positions.data(), e);
  dirtyEdges_.clear();
}

// The faces containing v: a face with one tet is on the boundary, with two it is inside.
// Keyed by the two other vertices. Most split vertices are inside the domain: an XOR of the
// faces' hashes, where every face seen twice cancels, tells so without sorting (a boundary face
// would have to hash to exactly the XOR of the others to go unnoticed: p ~ 2^-64).
void HullTracker::recount(const ProgressiveMesh& pm, uint32_t v) {
  const uint32_t* tets = pm.mesh.tets.data();
  entries_.clear();
  uint64_t parity = 0;
  for (uint32_t c : pm.stars.corners(v)) {
    const uint32_t t = c >> 2, k = c & 3;
    for (uint32_t f = 0; f < 4; ++f) {
      if (f == k) continue;  // face f is opposite local vertex f: the others contain v
      uint32_t other[2], n = 0;
      for (int i = 0; i < 3; ++i)
        if (kTetFaces[f][i] != k) other[n++] = tets[4 * t + kTetFaces[f][i]];
      const uint64_t key = edgeKey(other[0], other[1]);
      parity ^= mix(key);
      entries_.push_back({key, t << 2 | f});
    }
  }
  if (parity == 0 && head_[v] == kNone) return;
  std::sort(entries_.begin(), entries_.end(), [](const FaceEntry& x, const FaceEntry& y) { return x.key < y.key; });
  auto countOf = [&](uint64_t key) {
    auto lo = std::lower_bound(entries_.begin(), entries_.end(), key,
                               [](const FaceEntry& e, uint64_t k) { return e.key < k; });
    size_t n = 0;
    for (; lo != entries_.end() && lo->key == key; ++lo) ++n;
    return n;
  };
  auto keyWithout = [&](uint32_t slot) {
    const uint32_t* f = &faces_[3 * size_t(slot)];
    return f[0] == v ? edgeKey(f[1], f[2]) : f[1] == v ? edgeKey(f[0], f[2]) : edgeKey(f[0], f[1]);
  };

  std::vector<uint32_t>& drop = dropScratch_;
  drop.clear();
  for (uint32_t c = head_[v]; c != kNone; c = next_[c])
    if (countOf(keyWithout(c / 3)) != 1) drop.push_back(c / 3);
  std::sort(drop.begin(), drop.end(), std::greater<>());
  for (uint32_t slot : drop) removeFace(slot);

  for (size_t i = 0; i < entries_.size();) {
    size_t j = i + 1;
    while (j < entries_.size() && entries_[j].key == entries_[i].key) ++j;
    if (j - i == 1) {
      bool present = false;
      for (uint32_t c = head_[v]; c != kNone && !present; c = next_[c]) present = keyWithout(c / 3) == entries_[i].key;
      if (!present) {
        const uint32_t t = entries_[i].tetFace >> 2, f = entries_[i].tetFace & 3;
        const uint32_t tri[3] = {tets[4 * t + kTetFaces[f][0]], tets[4 * t + kTetFaces[f][1]],
                                 tets[4 * t + kTetFaces[f][2]]};
        addFace(pm.mesh.positions.data(), tri);
      }
    }
    i = j;
  }
}

void HullTracker::link(uint32_t corner, uint32_t v) {
  next_[corner] = head_[v];
  prev_[corner] = kNone;
  if (head_[v] != kNone) prev_[head_[v]] = corner;
  head_[v] = corner;
}

void HullTracker::unlink(uint32_t corner) {
  const uint32_t v = faces_[corner];
  if (prev_[corner] != kNone)
    next_[prev_[corner]] = next_[corner];
  else
    head_[v] = next_[corner];
  if (next_[corner] != kNone) prev_[next_[corner]] = prev_[corner];
}

void HullTracker::markEdges(const uint32_t tri[3]) {
  for (int k = 0; k < 3; ++k) dirtyEdges_.push_back(edgeKey(tri[k], tri[(k + 1) % 3]));
}

void HullTracker::addFace(const float* p, const uint32_t tri[3]) {
  const uint32_t slot = triangleCount();
  faces_.insert(faces_.end(), tri, tri + 3);
  float n[3];
  faceNormal(p, tri, n);
  for (int k = 0; k < 3; ++k) {
    const float* q = p + 3 * size_t(tri[k]);
    positions_.insert(positions_.end(), q, q + 3);
    normals_.insert(normals_.end(), n, n + 3);
  }
  next_.resize(faces_.size());
  prev_.resize(faces_.size());
  for (uint32_t k = 0; k < 3; ++k) link(3 * slot + k, tri[k]);
  markEdges(tri);
  if (!fullUpload_) changedTriangles_.push_back(slot);
}

void HullTracker::removeFace(uint32_t slot) {
  markEdges(&faces_[3 * size_t(slot)]);
  for (uint32_t k = 0; k < 3; ++k) unlink(3 * slot + k);
  const uint32_t last = triangleCount() - 1;
  if (slot != last) {
    for (uint32_t k = 0; k < 3; ++k) unlink(3 * last + k);
    std::copy_n(&faces_[3 * size_t(last)], 3, &faces_[3 * size_t(slot)]);
    std::copy_n(&positions_[9 * size_t(last)], 9, &positions_[9 * size_t(slot)]);
    std::copy_n(&normals_[9 * size_t(last)], 9, &normals_[9 * size_t(slot)]);
    for (uint32_t k = 0; k < 3; ++k) link(3 * slot + k, faces_[3 * slot + k]);
    if (!fullUpload_) changedTriangles_.push_back(slot);
  }
  faces_.resize(3 * size_t(last));
  positions_.resize(9 * size_t(last));
  normals_.resize(9 * size_t(last));
  next_.resize(faces_.size());
  prev_.resize(faces_.size());
}

void HullTracker::updateEdge(const float* p, uint64_t key) {
  const uint32_t a = uint32_t(key >> 32), b = uint32_t(key);
  uint32_t count = 0, slots[2] = {kNone, kNone};
  if (a < head_.size())
    for (uint32_t c = head_[a]; c != kNone; c = next_[c]) {
      const uint32_t* f = &faces_[3 * size_t(c / 3)];
      if (f[0] != b && f[1] != b && f[2] != b) continue;
      if (count < 2) slots[count] = c / 3;
      ++count;
    }
  bool draw = count == 1 || count > 2;
  if (count == 2) {
    const float* n0 = &normals_[9 * size_t(slots[0])];
    const float* n1 = &normals_[9 * size_t(slots[1])];
    draw = n0[0] * n1[0] + n0[1] * n1[1] + n0[2] * n1[2] < kCreaseCos;
  }
  const uint32_t line = lineOfEdge_.find(key);
  if (draw && line == FlatMap::kNone) {
    const uint32_t slot = lineCount();
    lines_.insert(lines_.end(), p + 3 * size_t(a), p + 3 * size_t(a) + 3);
    lines_.insert(lines_.end(), p + 3 * size_t(b), p + 3 * size_t(b) + 3);
    lineKeys_.push_back(key);
    bool inserted;
    lineOfEdge_.findOrInsert(key, slot, &inserted);
    if (!fullUpload_) changedLines_.push_back(slot);
  } else if (!draw && line != FlatMap::kNone) {
    removeLine(line);
  }
}

void HullTracker::removeLine(uint32_t slot) {
  lineOfEdge_.erase(lineKeys_[slot]);
  const uint32_t last = lineCount() - 1;
  if (slot != last) {
    const uint64_t moved = lineKeys_[last];
    lineOfEdge_.erase(moved);
    bool inserted;
    lineOfEdge_.findOrInsert(moved, slot, &inserted);
    lineKeys_[slot] = moved;
    std::copy_n(&lines_[6 * size_t(last)], 6, &lines_[6 * size_t(slot)]);
    if (!fullUpload_) changedLines_.push_back(slot);
  }
  lineKeys_.pop_back();
  lines_.resize(6 * size_t(last));
}

// ------------------------------------------------------------------ stats

std::string statsJson(const ViewerState& s) {
  using json = nlohmann::json;
  const Dataset& ds = s.dataset;
  const Manifest& m = ds.manifest;
  json fields = json::array();
  for (const FieldInfo& f : m.fields) fields.push_back(json{{"name", f.name}, {"min", f.range.min}, {"max", f.range.max}});
  auto rect = [](const Rect& r) { return json{{"x", r.x}, {"y", r.y}, {"w", r.w}, {"h", r.h}}; };
  auto time = [](double t) { return t >= 0 ? json(t) : json(nullptr); };
  uint32_t splitsTotal = 0;
  for (size_t c = 1; c < m.chunks.size(); ++c) splitsTotal += m.chunks[c].splits;
  const double fieldError = fieldErrorBound(s);
  const double left = secondsLeft(s);
  json j = {
      {"state", loadStateName(s.state)},
      {"error", s.error},
      {"name", m.name},
      {"vertices", ds.pm.mesh.vertexCount()},
      {"tets", ds.pm.mesh.tetCount()},
      {"triangles", s.surface.triangleCount()},
      {"surfaceVertices", s.surface.vertexCount()},
      {"isovalue", s.isovalue},
      {"surfaceArea", s.surface.area()},
      {"field", s.field >= 0 ? json(m.fields[size_t(s.field)].name) : json(nullptr)},
      {"colourField", s.colourField >= 0 ? json(m.fields[size_t(s.colourField)].name) : json(nullptr)},
      {"colourMap", colourMapName(s.colourMap)},
      {"colourRange", json::array({s.colourMin, s.colourMax})},
      {"slice", {{"on", s.sliceOn},
                 {"normal", json::array({s.slice.normal()[0], s.slice.normal()[1], s.slice.normal()[2]})},
                 {"offset", s.slice.offset()},
                 {"triangles", s.slice.surface().triangleCount()},
                 {"area", s.slice.surface().area()}}},
      {"fields", std::move(fields)},
      {"chunksReceived", ds.chunksReceived},
      {"chunksApplied", ds.chunksApplied()},
      {"chunksTotal", s.chunksTotal},
      {"bytesReceived", ds.bytesReceived},
      {"bytesDownloaded", s.networkBytes},
      {"bytesTotal", m.totalBytes()},
      {"rateBytesPerSec", s.rateBytesPerSec},
      {"secondsLeft", left >= 0 ? json(left) : json(nullptr)},
      {"splitsApplied", ds.splitsApplied()},
      {"splitsReceived", ds.splitsReceived()},
      {"splitsTotal", splitsTotal},
      {"targetSplits", std::min(s.targetSplits, ds.splitsReceived())},
      {"level", levelFraction(s)},
      {"live", s.live},
      {"paused", s.paused},
      {"fieldError", fieldError >= 0 ? json(fieldError) : json(nullptr)},
      {"fieldRms", levelChunk(s) && levelChunk(s)->fieldRms >= 0 ? json(levelChunk(s)->fieldRms) : json(nullptr)},
      {"fieldMax", levelChunk(s) && levelChunk(s)->fieldMax >= 0 ? json(levelChunk(s)->fieldMax) : json(nullptr)},
      {"baseVertices", ds.pm.baseVertices},
      {"hullTriangles", s.hull.triangleCount()},
      {"hullLines", s.hull.lineCount()},
      {"firstSurfaceMs", time(s.firstSurfaceMs)},
      {"completeMs", time(s.completeMs)},
      {"extractMs", s.extractMs},
      {"refineMs", s.refineMs},
      {"maxRefineMs", s.maxRefineMs},
      {"refineTotalMs", s.refineTotalMs},
      {"refineSteps", s.refineSteps},
      {"sliceEdgesMs", kSliceEdgesMs},
      {"sliceCounts", s.sliceCounts},
      {"frameMs", s.frameMs},
      {"maxFrameMs", s.maxFrameMs},
      {"maxFrameGapMs", s.maxFrameGapMs},
      {"drawMs", s.drawMs},
      {"treeTets", s.surface.treeCoverage()},
      {"maxDrawMs", s.maxDrawMs},
      {"drawTotalMs", s.drawTotalMs},
      {"reducedFrames", s.reducedFrames},
      {"softwareGl", s.softwareGl},
      {"samples", s.samples},
      {"contextLost", s.contextLost},
      {"uploadBytes", s.uploadBytes},
      {"fullUploads", s.fullUploads},
      {"partialUploads", s.partialUploads},
      {"grownUploads", s.grownUploads},
      {"showBoundary", s.showBoundary},
      {"notice", s.notice},
      {"chunksAllowed", s.chunksAllowed},
      {"memoryLimited", s.memoryLimited},
      {"memory",
       {{"heapBytes", s.heapBytes},
        {"dataBytes", memoryInUse(s)},
        {"gpuBytes", s.gpuBytes},
        {"limitBytes", s.memoryLimitBytes ? json(s.memoryLimitBytes) : json(nullptr)},
        {"neededBytes", s.memoryNeededBytes},
        {"allowedBytes", s.chunksAllowed ? s.memoryBaseBytes + estimateLevelBytes(m, s.chunksAllowed) : 0}}},
      {"sliderRect", rect(s.sliderRect)},
      {"levelSliderRect", rect(s.levelSliderRect)},
      {"pauseButtonRect", rect(s.pauseButtonRect)},
      {"sliceSliderRect", rect(s.sliceSliderRect)},
      {"panelRect", rect(s.panelRect)},
      {"showHelp", s.showHelp},
      {"targetLevel", s.live ? 1.0 : m.vertices ? double(s.dataset.pm.baseVertices + s.targetSplits) / m.vertices : 0.0},
  };
  // Messages may carry bytes from the network: never let invalid UTF-8 abort the dump.
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

}  // namespace tetstream::viewer
