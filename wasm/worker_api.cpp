// The functions the refinement worker (web/worker.js) calls: the same program as the page's,
// instantiated a second time in a Web Worker, where it holds the dataset and its model
// (viewer_state.h) and never draws. It checks and adds chunks, applies the view the page sends,
// refines in slices, and hands back what changed: the model's figures (statsJson), a geometry
// delta (geometry_sync.h) and the fetch plan. docs/js-api.md describes the messages.
#include <emscripten.h>
#include <emscripten/heap.h>
#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "camera.h"
#include "geometry_sync.h"
#include "telemetry.h"
#include "update_pacing.h"
#include "viewer_state.h"

using namespace tetstream;
using namespace tetstream::viewer;

namespace {

ViewerState g_model;
OrbitCamera g_camera;  // the page's camera, for what each region covers on screen
float g_aspect = 1.f;
std::vector<uint8_t> g_delta;
UpdatePacing g_pacing;  // when the page is sent the next update
// Strings handed to the worker's script stay valid until the next call that returns one of the same kind.
std::string g_stats, g_plan;

std::string jsonArray(const std::vector<uint32_t>& values) {
  std::string out = "[";
  for (uint32_t v : values) out += (out.size() > 1 ? "," : "") + std::to_string(v);
  return out + "]";
}

// Heap in use before a dataset, plus the worker's copies of chunks on their way in.
constexpr uint64_t kTransferBytes = 16u << 20;

// Grows the wasm memory now to hold `bytes`, so that a refusal (past the 4 GB maximum, or the
// browser short of memory) is an answer here rather than a failed allocation deep inside a
// vector, which would abort the module.
bool reserveHeap(uint64_t bytes) {
  if (bytes > emscripten_get_heap_max()) return false;
  if (bytes <= emscripten_get_heap_size()) return true;
  return emscripten_resize_heap(size_t(bytes)) != 0;
}

// What a region covers on screen (fetch_plan.h): the square of its bounding sphere's angular
// radius, 0 when the sphere lies wholly outside the view cone.
double screenWeight(const Bounds& b) {
  const OrbitCamera& c = g_camera;
  const glm::vec3 lo(b.min[0], b.min[1], b.min[2]), hi(b.max[0], b.max[1], b.max[2]);
  const glm::vec3 center = 0.5f * (lo + hi), eye = c.eye();
  const float r = 0.5f * glm::length(hi - lo), d = glm::length(center - eye);
  if (d <= r) return 1.0;  // the eye inside: it covers the view
  const float halfView = 0.5f * c.fovY * std::max(1.f, g_aspect);
  const float off = std::acos(std::clamp(glm::dot(center - eye, glm::normalize(c.target - eye)) / d, -1.f, 1.f));
  if (off - std::asin(r / d) > halfView) return 0.0;
  return double(r / d) * double(r / d);
}

double now() { return emscripten_get_now(); }

}  // namespace

extern "C" {

EMSCRIPTEN_KEEPALIVE void tw_set_memory_limit(double megabytes) {
  const uint64_t max = emscripten_get_heap_max();
  g_model.memory.limitBytes =
      megabytes > 0 && megabytes * (1 << 20) < double(max) ? uint64_t(megabytes * (1 << 20)) : max;
}

// 1 when the manifest is usable (the page has read it too); else the report says why.
EMSCRIPTEN_KEEPALIVE int tw_open(const char* json, int len) {
  if (!json || len < 0) return 0;
  ViewerState& s = g_model;
  if (!s.memory.limitBytes) tw_set_memory_limit(0);
  s.memory.baseBytes = uint64_t(reinterpret_cast<uintptr_t>(sbrk(0))) + kTransferBytes;
  s.memory.reserveHeap = reserveHeap;
  s.fetch.screenWeight = screenWeight;
  s.telemetry = {};
  return openManifest(s, std::string_view(json, size_t(len))).ok() ? 1 : 0;
}

EMSCRIPTEN_KEEPALIVE int tw_chunks_allowed() { return int(g_model.memory.chunksAllowed); }

// 1 kept (added now or once the chunks before it are in), 2 wrong size, 3 wrong hash, 0 no such
// chunk (or already added, or the model stopped). The buffer is the model's from now on.
EMSCRIPTEN_KEEPALIVE int tw_offer(int index, uint8_t* bytes, int len) {
  if (index < 0 || len < 0 || (!bytes && len > 0)) {
    std::free(bytes);
    return 0;
  }
  switch (offerChunk(g_model, uint32_t(index), bytes, size_t(len))) {
    case ChunkCheck::Ok: return 1;
    case ChunkCheck::WrongSize: return 2;
    case ChunkCheck::WrongHash: return 3;
    case ChunkCheck::NoSuchChunk: return 0;
  }
  return 0;
}

// 1 when chunk `index` has been added.
EMSCRIPTEN_KEEPALIVE int tw_has_chunk(int index) {
  return index >= 0 && g_model.dataset.hasChunk(uint32_t(index)) ? 1 : 0;
}

EMSCRIPTEN_KEEPALIVE void tw_chunk_unavailable(int index, const char* message) {
  if (index >= 0) chunkUnavailable(g_model, uint32_t(index), message ? message : "");
}

EMSCRIPTEN_KEEPALIVE void tw_set_paused(int paused) { g_model.network.paused = paused != 0; }

EMSCRIPTEN_KEEPALIVE void tw_fail(const char* message) { failLoad(g_model, message ? message : ""); }

// A command from the page (page_state.h, takeCommand): the view as the user chose it, and a
// level asked for. 0 when it is not JSON.
EMSCRIPTEN_KEEPALIVE int tw_command(const char* text) {
  const nlohmann::json c = nlohmann::json::parse(text ? text : "", nullptr, false);
  if (!c.is_object()) return 0;
  g_pacing.commandApplied();
  if (c.contains("view")) applyView(g_model, c["view"]);
  if (const auto level = c.find("level"); level != c.end() && level->is_object()) {
    if (const auto f = level->find("fraction"); f != level->end() && f->is_number())
      setLevelFraction(g_model, f->get<double>());
    if (const auto n = level->find("splits"); n != level->end() && n->is_number_unsigned())
      setLevel(g_model, uint32_t(std::min<uint64_t>(n->get<uint64_t>(), ~0u)));
  }
  return 1;
}

// The page's camera (six numbers as ts_camera_get, and the canvas's aspect): the plan's order
// follows what each region covers on screen.
EMSCRIPTEN_KEEPALIVE void tw_camera(double tx, double ty, double tz, double distance, double yaw, double pitch,
                                    double aspect) {
  const double v[7] = {tx, ty, tz, distance, yaw, pitch, aspect};
  for (double x : v)
    if (!std::isfinite(x)) return;
  g_camera.target = glm::vec3(float(tx), float(ty), float(tz));
  g_camera.distance = float(distance);
  g_camera.yaw = float(yaw);
  g_camera.pitch = float(pitch);
  g_aspect = aspect > 0 ? float(aspect) : 1.f;
  if (!g_model.dataset.manifest.nodes.empty() && g_model.fetch.missing > 0) ++g_model.fetch.version;
}

// Refines (or grows the interval tree) for about `ms`. Bit 0: more is to do; bit 1: an update
// is due (update_pacing.h: the page is then sent tw_delta, tw_stats and the plan).
EMSCRIPTEN_KEEPALIVE int tw_work(double ms) {
  ViewerState& s = g_model;
  const double deadline = now() + ms;
  if (refining(s))
    advance(s, deadline, now);
  else
    growTree(s, deadline, now);
  if (s.state == LoadState::Complete && s.telemetry.completeMs < 0) s.telemetry.completeMs = now();
  const bool more = refining(s) || treePending(s);
  return (more ? 1 : 0) | (g_pacing.due(now(), more, s.fetch.version) ? 2 : 0);
}

// What changed in the surface, slice and hull since the last call, as a delta; its address
// (tw_delta_size bytes, valid until the next call). The start of an update to the page.
EMSCRIPTEN_KEEPALIVE const uint8_t* tw_delta() {
  ViewerState& s = g_model;
  g_pacing.sent(now(), s.fetch.version);
  g_delta.clear();
  const bool any = s.dirty.surface || s.dirty.slice || s.dirty.hull;
  if (any) {
    writeDelta(s.dirty.surface ? &s.surface : nullptr, s.dirty.slice ? &s.slice.surface() : nullptr,
               s.dirty.hull ? &s.hull : nullptr, g_delta);
    if (s.dirty.surface) s.surface.clearChanges();
    if (s.dirty.slice) s.slice.surface().clearChanges();
    if (s.dirty.hull) s.hull.clearChanges();
    s.dirty.surface = s.dirty.slice = s.dirty.hull = false;
  }
  return g_delta.data();
}

EMSCRIPTEN_KEEPALIVE int tw_delta_size() { return int(g_delta.size()); }

// The model's figures as JSON (statsJson), valid until the next call.
EMSCRIPTEN_KEEPALIVE const char* tw_stats() {
  g_model.memory.heapBytes = emscripten_get_heap_size();
  // mallinfo's fields are ints: past 2 GB the count wraps negative. The heap is at most 4 GB
  // (wasm32), so its 32 bits read unsigned are the count.
  g_model.memory.allocatedBytes = uint64_t(uint32_t(mallinfo().uordblks));
  g_stats = statsJson(g_model);
  return g_stats.c_str();
}

EMSCRIPTEN_KEEPALIVE int tw_plan_version() { return int(g_model.fetch.version); }

// The chunks to fetch next, most important first, as a JSON array of indices (fetch_plan.h); at
// most as many as memory allows.
EMSCRIPTEN_KEEPALIVE const char* tw_plan() {
  g_plan = jsonArray(chunksToFetch(g_model));
  return g_plan.c_str();
}

// The chunks the model gave back since the last call (eviction.h), as a JSON array: the page's
// loader may fetch them again.
EMSCRIPTEN_KEEPALIVE const char* tw_forgotten() {
  g_plan = jsonArray(g_model.evict.forgottenChunks);
  g_model.evict.forgottenChunks.clear();
  return g_plan.c_str();
}

}  // extern "C"
