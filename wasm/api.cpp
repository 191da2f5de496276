// The functions the page calls (exported with EMSCRIPTEN_KEEPALIVE): thin wrappers that check
// their arguments, change the model (viewer_state.h) and ask for a redraw. What each one does,
// for the page's side, is in docs/js-api.md.
#include <emscripten.h>
#include <emscripten/heap.h>
#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>

#include "app.h"

using namespace tetstream;
using namespace tetstream::viewer;

namespace {

// Grows the wasm memory now to hold `bytes`, so that a refusal (past the 4 GB maximum, or the
// browser short of memory) is an answer here rather than a failed allocation deep inside a
// vector, which would abort the module.
bool reserveHeap(uint64_t bytes) {
  if (bytes > emscripten_get_heap_max()) return false;
  if (bytes <= emscripten_get_heap_size()) return true;
  return emscripten_resize_heap(size_t(bytes)) != 0;
}

// Heap in use before a dataset, plus what the UI and the page's chunk copies take later.
constexpr uint64_t kUiAndTransferBytes = 16u << 20;

// Strings handed to the page stay valid until the next call that returns one of the same kind.
std::string g_statsBuffer, g_viewBuffer, g_planBuffer;

// What a region covers on screen (fetch_plan.h): the square of its bounding sphere's angular
// radius, 0 when the sphere lies wholly outside the view cone.
double screenWeight(const Bounds& b) {
  const OrbitCamera& c = g_app.view.camera;
  const glm::vec3 lo(b.min[0], b.min[1], b.min[2]), hi(b.max[0], b.max[1], b.max[2]);
  const glm::vec3 center = 0.5f * (lo + hi), eye = c.eye();
  const float r = 0.5f * glm::length(hi - lo), d = glm::length(center - eye);
  if (d <= r) return 1.0;  // the eye inside: it covers the view
  const float aspect = g_app.canvas.height > 0 ? float(g_app.canvas.width) / float(g_app.canvas.height) : 1.f;
  const float halfView = 0.5f * c.fovY * std::max(1.f, aspect);
  const float off = std::acos(std::clamp(glm::dot(center - eye, glm::normalize(c.target - eye)) / d, -1.f, 1.f));
  if (off - std::asin(r / d) > halfView) return 0.0;
  return double(r / d) * double(r / d);
}

const Manifest& manifest() { return g_app.state.dataset.manifest; }

}  // namespace

extern "C" {

EMSCRIPTEN_KEEPALIVE void ts_set_memory_limit(double megabytes) {
  const uint64_t max = emscripten_get_heap_max();
  g_app.state.memory.limitBytes =
      megabytes > 0 && megabytes * (1 << 20) < double(max) ? uint64_t(megabytes * (1 << 20)) : max;
}

// ---------------------------------------------------------------- the dataset
EMSCRIPTEN_KEEPALIVE int ts_open_manifest(const char* json, int len) {
  requestRedraw();
  if (!g_app.canvas.platformError.empty()) return 0;  // nothing could be shown; keep that error visible
  g_app.view.pinned = false;                          // a new dataset is framed unless the page sets a view again
  if (!json || len < 0) return 0;
  ViewerState& s = g_app.state;
  if (!s.memory.limitBytes) ts_set_memory_limit(0);
  s.memory.baseBytes = uint64_t(reinterpret_cast<uintptr_t>(sbrk(0))) + kUiAndTransferBytes;
  s.memory.reserveHeap = reserveHeap;
  return openManifest(g_app.state, std::string_view(json, size_t(len))).ok() ? 1 : 0;
}

EMSCRIPTEN_KEEPALIVE int ts_chunk_count() { return int(manifest().chunks.size()); }

EMSCRIPTEN_KEEPALIVE int ts_node_count() { return int(manifest().nodes.size()); }

// The chunks to fetch next, most important first, as a JSON array of indices (fetch_plan.h); at
// most as many as memory allows. Changes whenever ts_plan_version() does.
EMSCRIPTEN_KEEPALIVE const char* ts_plan_json() {
  ViewerState& s = g_app.state;
  s.fetch.screenWeight = screenWeight;
  const uint32_t room =
      s.memory.chunksAllowed > s.dataset.chunksReceived ? s.memory.chunksAllowed - s.dataset.chunksReceived : 0;
  g_planBuffer = "[";
  for (uint32_t c : plannedChunks(s, room)) g_planBuffer += (g_planBuffer.size() > 1 ? "," : "") + std::to_string(c);
  g_planBuffer += "]";
  return g_planBuffer.c_str();
}

EMSCRIPTEN_KEEPALIVE int ts_plan_version() { return int(g_app.state.fetch.version); }

// Chunks the view needs that are not in yet (every chunk not in, without nodes).
EMSCRIPTEN_KEEPALIVE int ts_chunks_missing() { return int(g_app.state.fetch.missing); }

// Compressed bytes of the chunks the view needs, base included (every chunk without nodes).
EMSCRIPTEN_KEEPALIVE double ts_needed_bytes() { return double(neededBytes(g_app.state)); }

// 1 when chunk `index` has been added.
EMSCRIPTEN_KEEPALIVE int ts_has_chunk(int index) {
  return index >= 0 && g_app.state.dataset.hasChunk(uint32_t(index)) ? 1 : 0;
}

// The page gave up on a chunk (it cannot be had): its region stays coarse (chunkUnavailable).
EMSCRIPTEN_KEEPALIVE void ts_chunk_unavailable(int index, const char* message) {
  requestRedraw();
  if (index >= 0) chunkUnavailable(g_app.state, uint32_t(index), message ? message : "");
}

// 1: fetch every node; 0: the nodes the view needs (the default).
EMSCRIPTEN_KEEPALIVE void ts_set_fetch_everything(int on) {
  requestRedraw();
  setFetchMode(g_app.state, on ? FetchMode::Everything : FetchMode::Needed);
  workOnChange();
}

EMSCRIPTEN_KEEPALIVE int ts_chunks_allowed() { return int(g_app.state.memory.chunksAllowed); }

EMSCRIPTEN_KEEPALIVE const char* ts_chunk_file(int index) {
  const auto& chunks = manifest().chunks;
  return index >= 0 && size_t(index) < chunks.size() ? chunks[size_t(index)].file.c_str() : "";
}

EMSCRIPTEN_KEEPALIVE double ts_chunk_bytes(int index) {
  const auto& chunks = manifest().chunks;
  return index >= 0 && size_t(index) < chunks.size() ? double(chunks[size_t(index)].bytes) : 0;
}

// 1 kept (added now or once the chunks before it are in), 2 wrong size, 3 wrong hash, 0 no such
// chunk (or already added, or the viewer stopped). The buffer is the viewer's from now on.
EMSCRIPTEN_KEEPALIVE int ts_offer_chunk(int index, uint8_t* bytes, int len) {
  requestRedraw();
  if (index < 0 || len < 0 || (!bytes && len > 0)) {
    std::free(bytes);
    return 0;
  }
  const ChunkCheck c = offerChunk(g_app.state, uint32_t(index), bytes, size_t(len));
  workOnChange();
  switch (c) {
    case ChunkCheck::Ok: return 1;
    case ChunkCheck::WrongSize: return 2;
    case ChunkCheck::WrongHash: return 3;
    case ChunkCheck::NoSuchChunk: return 0;
  }
  return 0;
}

EMSCRIPTEN_KEEPALIVE void ts_set_network(double receivedBytes, double totalBytes, double bytesPerSecond,
                                         double secondsLeft, int paused, const char* notice) {
  ViewerState& s = g_app.state;
  NetworkStatus n;
  n.receivedBytes = receivedBytes > 0 ? uint64_t(receivedBytes) : 0;
  n.totalBytes = totalBytes > 0 ? uint64_t(totalBytes) : 0;
  n.bytesPerSecond = std::isfinite(bytesPerSecond) && bytesPerSecond > 0 ? bytesPerSecond : 0;
  n.secondsLeft = std::isfinite(secondsLeft) && secondsLeft >= 0 ? secondsLeft : -1;
  n.paused = paused != 0;
  n.notice = notice ? notice : "";
  const bool resumed = s.network.paused && !n.paused;
  if (n.paused != s.network.paused || n.notice != s.network.notice) requestRedraw();
  setNetwork(s, std::move(n));
  if (resumed) workOnChange();
}

EMSCRIPTEN_KEEPALIVE void ts_fail(const char* message) {
  requestRedraw();
  failLoad(g_app.state, message ? message : "");
}

// ---------------------------------------------------------------- what is shown
EMSCRIPTEN_KEEPALIVE void ts_set_level(double fraction) {
  requestRedraw();
  setLevelFraction(g_app.state, fraction);
  workOnChange();
}

EMSCRIPTEN_KEEPALIVE void ts_set_isovalue(float value) {
  requestRedraw();
  setIsovalue(g_app.state, value);
}

EMSCRIPTEN_KEEPALIVE int ts_set_field(const char* name) {
  requestRedraw();
  return name && setField(g_app.state, std::string_view(name)) ? 1 : 0;
}

EMSCRIPTEN_KEEPALIVE int ts_set_colour_field(const char* name) {
  requestRedraw();
  return name && setColourField(g_app.state, std::string_view(name)) ? 1 : 0;
}

EMSCRIPTEN_KEEPALIVE int ts_set_colour_map(const char* name) {
  requestRedraw();
  std::optional<ColourMap> m = name ? parseColourMap(name) : std::nullopt;
  if (m) setColourMap(g_app.state, *m);
  return m ? 1 : 0;
}

EMSCRIPTEN_KEEPALIVE const char* ts_colour_map_name(int i) {
  return i >= 0 && i < kColourMapCount ? colourMapName(ColourMap(i)) : "";
}

EMSCRIPTEN_KEEPALIVE void ts_set_colour_range(double lo, double hi) {
  requestRedraw();
  setColourRange(g_app.state, float(lo), float(hi));
}

EMSCRIPTEN_KEEPALIVE int ts_fit_colour_range() {
  requestRedraw();
  return fitColourRange(g_app.state) ? 1 : 0;
}

EMSCRIPTEN_KEEPALIVE void ts_set_slice(int on, double nx, double ny, double nz, double offset) {
  requestRedraw();
  setSlicePlane(g_app.state, {float(nx), float(ny), float(nz)}, float(offset));
  setSliceEnabled(g_app.state, on != 0);
}

EMSCRIPTEN_KEEPALIVE void ts_set_view_option(const char* name, int value) {
  requestRedraw();
  if (!name) return;
  const std::string_view n(name);
  if (n == "boundary") g_app.state.view.showBoundary = value != 0;
  if (n == "help") g_app.state.view.showHelp = value != 0;
}

EMSCRIPTEN_KEEPALIVE void ts_set_link_note(const char* note) {
  requestRedraw();
  g_app.state.view.linkNote = note ? note : "";
}

// Draws a frame soon and calls Module.onCapture() right after it (screenshot).
EMSCRIPTEN_KEEPALIVE void ts_request_capture() {
  g_app.pacing.captureRequested = true;
  requestRedraw(1);
}

// ---------------------------------------------------------------- camera
// The camera as six numbers: target x, y, z, distance, yaw, pitch (camera.h).
EMSCRIPTEN_KEEPALIVE double ts_camera_get(int i) {
  const OrbitCamera& c = g_app.view.camera;
  const double v[6] = {c.target.x, c.target.y, c.target.z, c.distance, c.yaw, c.pitch};
  return i >= 0 && i < 6 ? v[i] : 0;
}

EMSCRIPTEN_KEEPALIVE void ts_camera_set(double tx, double ty, double tz, double distance, double yaw, double pitch) {
  const double v[6] = {tx, ty, tz, distance, yaw, pitch};
  for (double x : v)
    if (!std::isfinite(x)) return;
  if (!(distance > 0)) return;
  OrbitCamera& c = g_app.view.camera;
  c.target = glm::vec3(float(tx), float(ty), float(tz));
  c.distance = float(distance);
  c.yaw = float(yaw);
  c.pitch = std::clamp(float(pitch), -1.55f, 1.55f);
  g_app.view.moved = g_app.view.pinned = true;
  requestRedraw();
}

// Touch gestures from the page (pointer events, CSS pixels): 0 orbit, 1 pan by (dx, dy);
// 2 zoom by dx wheel steps.
EMSCRIPTEN_KEEPALIVE void ts_camera_gesture(int kind, double dx, double dy) {
  if (!std::isfinite(dx) || !std::isfinite(dy)) return;
  OrbitCamera& c = g_app.view.camera;
  const float k = float(g_app.canvas.pixelRatio);
  if (kind == 0)
    c.orbit(float(dx) * k, float(dy) * k, float(g_app.canvas.height));
  else if (kind == 1)
    c.pan(float(dx) * k, float(dy) * k, float(g_app.canvas.height));
  else if (kind == 2)
    c.zoom(float(dx));
  else
    return;
  g_app.view.moved = true;
  requestRedraw();
}

// ---------------------------------------------------------------- reading the state
// A few typed figures for the page's status line and touch handling (no JSON on that path).
EMSCRIPTEN_KEEPALIVE int ts_load_state() { return int(g_app.state.state); }

EMSCRIPTEN_KEEPALIVE const char* ts_error() { return g_app.state.error.c_str(); }

EMSCRIPTEN_KEEPALIVE const char* ts_name() { return manifest().name.c_str(); }

EMSCRIPTEN_KEEPALIVE int ts_chunks_received() { return int(g_app.state.dataset.chunksReceived); }

EMSCRIPTEN_KEEPALIVE double ts_level() { return levelFraction(g_app.state); }

EMSCRIPTEN_KEEPALIVE int ts_context_lost() { return g_app.state.contextLost ? 1 : 0; }

// The panel's rectangle in CSS pixels of the canvas: x, y, w, h (i = 0..3).
EMSCRIPTEN_KEEPALIVE double ts_panel_rect(int i) {
  const Rect& r = g_app.state.telemetry.screen.panel;
  const float v[4] = {r.x, r.y, r.w, r.h};
  return i >= 0 && i < 4 ? v[i] : 0;
}

// The view as JSON (what a link keeps), valid until the next call.
EMSCRIPTEN_KEEPALIVE const char* ts_view_json() {
  g_viewBuffer = viewJson(g_app.state);
  return g_viewBuffer.c_str();
}

// Everything, as JSON, for tests and scripts; valid until the next call.
EMSCRIPTEN_KEEPALIVE const char* ts_stats_json() {
  g_app.state.memory.heapBytes = emscripten_get_heap_size();
  g_app.state.memory.allocatedBytes = uint64_t(mallinfo().uordblks);
  g_statsBuffer = statsJson(g_app.state);
  return g_statsBuffer.c_str();
}

}  // extern "C"
