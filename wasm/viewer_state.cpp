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
#include "partial.h"
#include "tet_tables.h"
#include "view_settings.h"
#include "viewer_memory.h"

namespace tetstream::viewer {
namespace {

double nowMs() {
  using namespace std::chrono;
  return duration<double, std::milli>(steady_clock::now().time_since_epoch()).count();
}

float middleOf(const Range& r) { return r.min + 0.5f * (r.max - r.min); }

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
  if (s.colour.field < 0 || size_t(s.colour.field) >= s.dataset.manifest.fields.size()) return {};
  int f = mesh.findField(s.dataset.manifest.fields[size_t(s.colour.field)].name);
  if (f < 0 || mesh.fields[size_t(f)].values.size() != mesh.vertexCount()) return {};
  return mesh.fields[size_t(f)].values;
}

// The whole surface of the current level (isovalue or field changed, or the base arrived).
void extract(ViewerState& s) {
  s.dirty.surface = true;
  std::span<const float> values = fieldValues(s);
  if (values.empty()) {
    s.surface.reset();
    s.telemetry.extractMs = 0;
    return;
  }
  double t0 = nowMs();
  s.surface.rebuild(s.dataset.pm.mesh, values, s.isovalue, colourValues(s));
  s.telemetry.extractMs = nowMs() - t0;
  s.surfaceReady = true;
}

// The whole slice of the current level (plane moved, turned on, or the base arrived).
void extractSlice(ViewerState& s) {
  s.dirty.slice = true;
  if (!s.sliceOn || s.dataset.pm.mesh.tetCount() == 0) {
    s.slice.clear();
    return;
  }
  s.slice.rebuild(s.dataset.pm.mesh, colourValues(s));
}

// Growing the mesh arrays by doubling while streaming would copy tens of MB inside one frame
// (~20 ms natively at 1 M tets): size them once for the last level that will be streamed (the
// full mesh unless memory is limited; with a patch hierarchy, what the view needs now:
// neededCounts), as the manifest announces it. The manifest is untrusted, so only up to 4 M tets
// (~100 MB) without a memory limit; bigger meshes grow as usual.
void reserveLevel(ViewerState& s) {
  constexpr uint32_t kMaxReservedTets = 4u << 20;
  Dataset& ds = s.dataset;
  const Manifest& m = ds.manifest;
  if (s.memory.chunksAllowed == 0) return;
  const ChunkInfo& last = m.chunks[s.memory.chunksAllowed - 1];
  uint32_t vertices = last.vertices, tets = last.tets;
  if (!m.nodes.empty()) {
    const std::pair<uint32_t, uint32_t> needed = neededCounts(s);
    vertices = std::min(vertices, needed.first);
    tets = std::min(tets, needed.second);
  }
  if (!s.memory.limitBytes && (tets > kMaxReservedTets || vertices > kMaxReservedTets)) return;
  ProgressiveMesh& pm = ds.pm;
  pm.mesh.positions.reserve(3 * size_t(vertices));
  pm.mesh.tets.reserve(4 * size_t(tets));
  for (ScalarField& f : pm.mesh.fields) f.values.reserve(vertices);
  pm.stars.reserve(vertices, 4 * size_t(tets));
  pm.splitJ.reserve(vertices);
  pm.splitTetsBefore.reserve(vertices);
  s.surface.reserveTets(tets);
}

// What the last level that will be streamed takes (estimateLevelBytes); with a patch hierarchy,
// the share of it the view needs now, by tets.
uint64_t plannedLevelBytes(const ViewerState& s) {
  const Manifest& m = s.dataset.manifest;
  const uint64_t all = estimateLevelBytes(m, s.memory.chunksAllowed);
  if (m.nodes.empty() || s.memory.chunksAllowed == 0) return all;
  const uint64_t tets = m.chunks[s.memory.chunksAllowed - 1].tets;
  return tets ? uint64_t(double(all) * std::min(1.0, double(neededCounts(s).second) / double(tets))) : all;
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
  std::snprintf(level, sizeof level, "%.1f%%", m.vertices ? 100.0 * s.dataset.pm.vertexCount() / m.vertices : 0.0);
  s.memory.limited = true;
  failLoad(s, "This dataset needs about " + formatBytes(s.memory.neededBytes) + " of memory at full detail, more " +
                  "than the " + formatBytes(s.memory.limitBytes) + " this page may use. Streaming stopped after " +
                  partName(s, k - 1) + " (" + level + " of the vertices); that level stays fully usable.");
}

void updateState(ViewerState& s) {
  if (s.state == LoadState::Idle || s.state == LoadState::Error) return;
  const Dataset& ds = s.dataset;
  if (ds.chunksReceived == 0)
    s.state = LoadState::Loading;
  else if ((s.fetch.missing == 0 || s.evict.memoryFull) && s.evict.nodes.empty() &&
           ds.splitsApplied() == ds.splitsReceived())
    s.state = LoadState::Complete;
  else
    s.state = LoadState::Streaming;
}

// One work slice (advance or growTree) of `ms` into the histogram of slice durations.
void noteSlice(ViewerState& s, double ms) {
  size_t bin = 0;
  while (bin < kSliceEdgesMs.size() && ms >= kSliceEdgesMs[bin]) ++bin;
  ++s.telemetry.sliceCounts[bin];
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
  s.dirty.surface = s.dirty.hull = true;
  s.surfaceReady = false;
  s.chunksTotal = 0;
  s.slice.clear();
  s.sliceOn = false;
  s.dirty.slice = true;
  s.field = -1;
  s.colour.field = -1;
  s.colour.min = 0;
  s.colour.max = 1;
  s.level.targetSplits = 0;
  s.level.live = true;
  s.network = {};
  s.pendingChunks.clear();
  s.unavailable.clear();
  s.telemetry.completeMs = -1;
  s.memory.neededBytes = 0;
  s.memory.chunksAllowed = 0;
  s.memory.limited = false;
  s.evict = {};
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
  s.dirty.bounds = true;
  int f = m.findField(m.isoField);
  if (f < 0 && !m.fields.empty()) f = 0;
  s.field = f;
  if (f >= 0) s.isovalue = middleOf(m.fields[size_t(f)].range);
  s.slice.setPlane({0, 0, 1}, 0.5f * (m.bounds.min[2] + m.bounds.max[2]));

  resetPlan(s);
  s.memory.received = {};
  s.memory.neededBytes = s.memory.baseBytes + estimateLevelBytes(m, s.chunksTotal);
  s.memory.chunksAllowed = s.chunksTotal;
  if (s.memory.limitBytes) {
    const uint64_t budget = s.memory.limitBytes > s.memory.baseBytes ? s.memory.limitBytes - s.memory.baseBytes : 0;
    s.memory.chunksAllowed = chunksThatFit(m, budget);
    if (s.memory.chunksAllowed == 0) {
      s.memory.limited = true;
      const std::string message = "This dataset needs about " +
                                  formatBytes(s.memory.baseBytes + estimateLevelBytes(m, 1)) +
                                  " of memory even at its coarsest level, more than the " +
                                  formatBytes(s.memory.limitBytes) + " this page may use.";
      failLoad(s, message);
      return fail(Status::TooLarge, message);
    }
    // Regions are fetched as far as they fit and given back when the view moves on (eviction.h),
    // not cut at a count of chunks in the manifest's order.
    if (budgetedByRegions(s)) s.memory.chunksAllowed = s.chunksTotal;
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

ChunkCheck offerChunk(ViewerState& s, uint32_t index, uint8_t* bytes, size_t size) {
  PendingChunk chunk;
  chunk.bytes.reset(bytes);
  chunk.size = size;
  if ((s.state != LoadState::Loading && s.state != LoadState::Streaming && s.state != LoadState::Complete) ||
      s.dataset.chunksReceived >= s.memory.chunksAllowed || s.dataset.hasChunk(index))
    return ChunkCheck::NoSuchChunk;
  if (ChunkCheck c = checkChunk(s, index, {bytes, size}); c != ChunkCheck::Ok) return c;
  s.pendingChunks.insert_or_assign(index, std::move(chunk));
  // Every chunk whose turn has come (after the chunks of its node before it and its node's
  // parent); one that fails ends in Error (addChunk says why).
  for (bool added = true; added;) {
    added = false;
    for (auto next = s.pendingChunks.begin(); next != s.pendingChunks.end(); ++next) {
      if (!s.dataset.canReceive(next->first)) continue;
      const uint32_t i = next->first;
      const PendingChunk ready = std::move(next->second);
      s.pendingChunks.erase(next);
      if (!addChunk(s, i, {ready.bytes.get(), ready.size}, /*hashChecked=*/true).ok() && s.state == LoadState::Error) {
        s.pendingChunks.clear();
        return ChunkCheck::Ok;
      }
      added = true;
      break;
    }
  }
  return ChunkCheck::Ok;
}

Result addChunk(ViewerState& s, uint32_t index, std::span<const uint8_t> bytes, bool hashChecked) {
  if (s.state != LoadState::Loading && s.state != LoadState::Streaming && s.state != LoadState::Complete) {
    Result r = fail(Status::BadArgument, std::string("chunk ") + std::to_string(index) +
                                             " arrived while the viewer is " + loadStateName(s.state));
    if (s.state != LoadState::Error) failLoad(s, r.message);
    return r;
  }
  Dataset& ds = s.dataset;
  if (ds.chunksReceived >= s.memory.chunksAllowed) {
    Result r = fail(Status::TooLarge, partName(s, index) + " does not fit in memory");
    failLoad(s, r.message);
    return r;
  }
  // Memory for the level this chunk makes, asked for before anything grows: a refusal stops
  // here with a message instead of failing an allocation half way through. With the base, the
  // arrays are sized for the last level that will come (reserveLevel), so that much is asked
  // for first; if the browser will not give it now, the arrays grow as levels come instead.
  // What the chunks received so far and this one bring (chunks of a patch hierarchy come in any
  // order, so not the manifest's first chunks).
  LevelCounts after = s.memory.received;
  addCounts(after, chunkCounts(ds.manifest, index));
  const uint64_t need = s.memory.baseBytes + estimateBytes(ds.manifest, after);
  // A region that came after the view moved on and no longer fits is given back, not an error
  // (the plan asks only for what fits once the regions being given back are gone: eviction.h);
  // the page may fetch it again later.
  LevelCounts kept = keptCounts(s);
  addCounts(kept, chunkCounts(ds.manifest, index));
  if (budgetedByRegions(s) && index > 0 &&
      s.memory.baseBytes + estimateBytes(ds.manifest, kept) > s.memory.limitBytes) {
    s.evict.forgottenChunks.push_back(index);
    ++s.fetch.version;
    return fail(Status::TooLarge, partName(s, index) + " does not fit in memory now");
  }
  const bool reserveAll =
      index == 0 && (!s.memory.reserveHeap || s.memory.reserveHeap(s.memory.baseBytes + plannedLevelBytes(s)));
  if (s.memory.reserveHeap && !reserveAll && !s.memory.reserveHeap(need)) {
    s.memory.limited = true;
    Result r = fail(Status::TooLarge, "The browser did not give the viewer the " + formatBytes(need) +
                                          " of memory that " + partName(s, index) + " needs." +
                                          (ds.chunksReceived ? " Showing the last complete level." : ""));
    failLoad(s, r.message);
    return r;
  }
  if (Result r = receiveChunk(ds, index, bytes, hashChecked); !r) {
    failLoad(s, "Part " + std::to_string(index + 1) + " of " + std::to_string(s.chunksTotal) +
                    " of the dataset could not be used: " + r.message +
                    (ds.chunksReceived ? ". Showing the last complete level." : "."));
    return r;
  }
  s.memory.received = after;
  notePlannedChunk(s, index);
  planEviction(s);
  if (ds.chunksReceived == 1) {  // the base: shown at once
    if (reserveAll) reserveLevel(s);
    extract(s);
    extractSlice(s);
    s.hull.rebuild(ds.pm);
    s.dirty.hull = true;
  }
  if (s.level.live) s.level.targetSplits = ds.splitsReceived();
  updateState(s);
  if (ds.chunksReceived == s.memory.chunksAllowed && s.fetch.missing > 0) stopForMemory(s);
  return Result::success();
}

bool advance(ViewerState& s, double deadlineMs, Clock now) {
  Dataset& ds = s.dataset;
  forgetEvicted(s);  // (once the level is down to the regions given back)
  if (ds.chunksReceived == 0 || levelCap(s) == ds.splitsApplied()) {
    updateState(s);
    return false;
  }
  const double t0 = now();
  const uint32_t base = ds.pm.baseVertices;
  uint32_t steps = 0;
  do {
    const uint32_t target = levelCap(s);
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
      s.level.targetSplits = std::min(s.level.targetSplits, ds.splitsReceived());
      failLoad(s, "Part " + std::to_string(ds.chunksReceived + 1) + " of " + std::to_string(s.chunksTotal) +
                      " of the dataset is damaged (" + r.message + "). Showing the last complete level.");
      break;
    }
    s.hull.update(ds.pm, s.splitVertices);
  } while (now() < deadlineMs);
  forgetEvicted(s);
  s.dirty.surface = s.dirty.hull = true;
  if (s.sliceOn) s.dirty.slice = true;
  s.telemetry.refineMs = now() - t0;
  noteSlice(s, s.telemetry.refineMs);
  s.telemetry.maxRefineMs = std::max(s.telemetry.maxRefineMs, s.telemetry.refineMs);
  s.telemetry.refineTotalMs += s.telemetry.refineMs;
  s.telemetry.refineSteps = steps;
  updateState(s);
  return true;
}

void setLevel(ViewerState& s, uint32_t splits) {
  const uint32_t received = s.dataset.splitsReceived();
  s.level.targetSplits = std::min(splits, received);
  s.level.live = splits >= received;
  updateState(s);
}

void setLevelFraction(ViewerState& s, double fraction) {
  if (!std::isfinite(fraction)) return;
  const Dataset& ds = s.dataset;
  if (fraction >= 1) return setLevel(s, ~0u);
  double vertices = std::round(std::max(0.0, fraction) * ds.manifest.vertices);
  setLevel(s, vertices > ds.pm.baseVertices ? uint32_t(vertices - ds.pm.baseVertices) : 0);
}

void setNetwork(ViewerState& s, NetworkStatus network) { s.network = std::move(network); }

void requestPauseToggle(ViewerState& s) { s.pauseToggleRequested = true; }

void setIsovalue(ViewerState& s, float value) {
  if (!std::isfinite(value) || value == s.isovalue) return;
  s.isovalue = value;
  extract(s);
  replan(s);
  updateState(s);
}

bool setField(ViewerState& s, int index) {
  const Manifest& m = s.dataset.manifest;
  if (index < 0 || size_t(index) >= m.fields.size()) return false;
  s.field = index;
  s.isovalue = middleOf(m.fields[size_t(index)].range);
  s.surface.reset();  // another field: the interval tree is built again
  extract(s);
  replan(s);
  updateState(s);
  return true;
}

bool setField(ViewerState& s, std::string_view name) { return setField(s, s.dataset.manifest.findField(name)); }

bool setColourField(ViewerState& s, int index) {
  const Manifest& m = s.dataset.manifest;
  if (index < -1 || index >= int(m.fields.size())) return false;
  s.colour.field = index;
  if (index >= 0) {
    s.colour.min = float(m.fields[size_t(index)].range.min);
    s.colour.max = float(m.fields[size_t(index)].range.max);
  }
  s.surface.recolour(colourValues(s));
  s.dirty.surface = true;
  if (s.slice.built()) {
    s.slice.recolour(colourValues(s));
    s.dirty.slice = true;
  }
  return true;
}

bool setColourField(ViewerState& s, std::string_view name) {
  if (name.empty() || name == "none") return setColourField(s, -1);
  const int f = s.dataset.manifest.findField(name);
  return f >= 0 && setColourField(s, f);
}

void setColourMap(ViewerState& s, ColourMap map) { s.colour.map = map; }

void setColourRange(ViewerState& s, float lo, float hi) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) return;
  if (lo > hi) std::swap(lo, hi);
  s.colour.min = lo;
  s.colour.max = hi;
}

bool fitColourRange(ViewerState& s) {
  if (s.colour.field < 0) return false;
  ColourSpan span;
  span.cover(s.surface);
  if (s.sliceOn && s.slice.built()) span.cover(s.slice.surface());
  float lo = 0, hi = 0;
  if (!span.fitted(s.dataset.manifest.fields[size_t(s.colour.field)].range, lo, hi)) return false;
  setColourRange(s, lo, hi);
  return true;
}

void setSliceEnabled(ViewerState& s, bool on) {
  if (on == s.sliceOn) return;
  s.sliceOn = on;
  if (on && s.colour.field < 0 && s.field >= 0) setColourField(s, s.field);
  extractSlice(s);
  replan(s);
  updateState(s);
}

bool setSlicePlane(ViewerState& s, std::array<float, 3> normal, float offset) {
  const bool changed = s.slice.setPlane(normal, offset);
  if (changed) extractSlice(s);
  if (changed && s.sliceOn) {
    replan(s);
    updateState(s);
  }
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

void setFetchMode(ViewerState& s, FetchMode mode) {
  if (mode == s.fetch.mode) return;
  s.fetch.mode = mode;
  replan(s);
  updateState(s);
}

void chunkUnavailable(ViewerState& s, uint32_t index, std::string_view message) {
  const Dataset& ds = s.dataset;
  const int32_t k = ds.nodeOfChunk(index);
  if (k < 0) return failLoad(s, message);
  const Bounds& b = ds.manifest.nodes[size_t(k)].bounds;
  char region[160];
  std::snprintf(region, sizeof region, "The region [%g, %g, %g] .. [%g, %g, %g] stays coarse: ", b.min[0], b.min[1],
                b.min[2], b.max[0], b.max[1], b.max[2]);
  s.unavailable = region + std::string(message);
  giveUpChunk(s, index);
  updateState(s);
}

uint64_t memoryInUse(const ViewerState& s) {
  return datasetMemoryBytes(s.dataset) + s.surface.memoryBytes() + s.hull.memoryBytes() + s.slice.memoryBytes();
}

bool downloading(const ViewerState& s) {
  return (s.state == LoadState::Loading || s.state == LoadState::Streaming) && !s.network.paused &&
         s.fetch.missing > 0 && s.dataset.chunksReceived < s.memory.chunksAllowed && !s.evict.memoryFull;
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
  // (Regions to give back whose splits are not applied wait for advance() too.)
  return ds.chunksReceived > 0 && (levelCap(s) != ds.splitsApplied() || !s.evict.nodes.empty());
}

double levelFraction(const ViewerState& s) {
  uint32_t full = s.dataset.manifest.vertices;
  return full ? double(s.dataset.pm.vertexCount()) / full : 0;
}

double targetLevel(const ViewerState& s) {
  const Manifest& m = s.dataset.manifest;
  if (s.level.live) return 1.0;
  return m.vertices ? double(s.dataset.pm.baseVertices + s.level.targetSplits) / m.vertices : 0.0;
}

ShownError shownFieldError(const ViewerState& s) {
  ShownError e;
  if (const ChunkInfo* c = levelChunk(s)) {
    e.estimate = c->fieldError;
    e.rms = c->fieldRms;
    e.max = c->fieldMax;
    return e;
  }
  const Dataset& ds = s.dataset;
  const Manifest& m = ds.manifest;
  if (m.nodes.empty() || ds.chunksReceived == 0) return e;
  // A node is applied when every split of its chunks is.
  std::vector<uint8_t> chunkApplied(m.chunks.size(), 0);
  for (uint32_t p = 0; p < ds.chunksApplied() && p < ds.received.size(); ++p) chunkApplied[ds.received[p]] = 1;
  std::vector<uint8_t> applied(m.nodes.size(), 0);
  for (size_t k = 0; k < m.nodes.size(); ++k) {
    applied[k] = 1;
    for (uint32_t c = m.nodes[k].firstChunk; c < m.nodes[k].firstChunk + m.nodes[k].chunkCount; ++c)
      applied[k] &= chunkApplied[c];
  }
  const FrontierError f = frontierFieldError(m, applied);
  e.estimate = f.estimate;
  e.max = f.measured;
  return e;
}

const ChunkInfo* levelChunk(const ViewerState& s) {
  // A chunk's figures are those of the stream in manifest order up to it: a level made of other
  // chunks (a plan of nodes, fetch_plan.h) has none.
  const Dataset& ds = s.dataset;
  const uint32_t c = ds.chunksApplied();
  return c && ds.inManifestOrder ? &ds.manifest.chunks[ds.received[c - 1]] : nullptr;
}

nlohmann::json viewObject(const ViewerState& s) {
  using json = nlohmann::json;
  const Manifest& m = s.dataset.manifest;
  return {
      {"field", s.field >= 0 ? json(m.fields[size_t(s.field)].name) : json(nullptr)},
      {"isovalue", s.isovalue},
      {"colourField", s.colour.field >= 0 ? json(m.fields[size_t(s.colour.field)].name) : json(nullptr)},
      {"colourMap", colourMapName(s.colour.map)},
      {"colourRange", json::array({s.colour.min, s.colour.max})},
      {"slice",
       {{"on", s.sliceOn},
        {"normal", json::array({s.slice.normal()[0], s.slice.normal()[1], s.slice.normal()[2]})},
        {"offset", s.slice.offset()}}},
      {"level", targetLevel(s)},
      {"showBoundary", s.view.showBoundary},
  };
}

std::string viewJson(const ViewerState& s) {
  return viewObject(s).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

bool applyView(ViewerState& s, const nlohmann::json& view) {
  using json = nlohmann::json;
  if (!view.is_object()) return false;
  const Manifest& m = s.dataset.manifest;
  auto fieldOf = [&](const char* key) {
    const json& name = view.value(key, json(nullptr));
    return name.is_string() ? m.findField(name.get<std::string>()) : -1;
  };
  auto number = [&](const json& j, float fallback) { return j.is_number() ? j.get<float>() : fallback; };
  const int field = fieldOf("field");
  if (field >= 0 && field != s.field) setField(s, field);
  setIsovalue(s, number(view.value("isovalue", json(nullptr)), s.isovalue));
  const int colour = fieldOf("colourField");
  if (colour != s.colour.field) setColourField(s, colour);
  if (const json& range = view.value("colourRange", json(nullptr)); range.is_array() && range.size() == 2)
    setColourRange(s, number(range[0], s.colour.min), number(range[1], s.colour.max));
  if (const json& map = view.value("colourMap", json(nullptr)); map.is_string())
    if (std::optional<ColourMap> c = parseColourMap(map.get<std::string>())) setColourMap(s, *c);
  if (const json& slice = view.value("slice", json(nullptr)); slice.is_object()) {
    const json& n = slice.value("normal", json(nullptr));
    if (n.is_array() && n.size() == 3)
      setSlicePlane(s, {number(n[0], 0), number(n[1], 0), number(n[2], 0)},
                    number(slice.value("offset", json(nullptr)), s.slice.offset()));
    setSliceEnabled(s, slice.value("on", false));
  }
  if (const json& fetch = view.value("fetch", json(nullptr)); fetch.is_string())
    setFetchMode(s, fetch.get<std::string>() == "everything" ? FetchMode::Everything : FetchMode::Needed);
  s.view.showBoundary = view.value("showBoundary", s.view.showBoundary);
  return true;
}

}  // namespace tetstream::viewer
