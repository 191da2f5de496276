// The functions the page calls (exported with EMSCRIPTEN_KEEPALIVE): thin wrappers that check
// their arguments, change what the page holds (page_state.h), ask for a redraw and pass the view
// on to the refinement worker (whose own functions are in worker_api.cpp). What each one does,
// for the page's side, is in docs/js-api.md.
#include <emscripten.h>
#include <emscripten/heap.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "app.h"

using namespace tetstream;
using namespace tetstream::viewer;

namespace {

// Strings handed to the page stay valid until the next call that returns one of the same kind.
std::string g_statsBuffer, g_viewBuffer, g_commandBuffer;

PageState& page() { return g_app.page; }
const Manifest& manifest() { return g_app.page.manifest; }

// After a change of the view: redraw, and the worker hears of it (sendCommands).
void viewChanged() {
  requestRedraw();
  sendCommands();
}

}  // namespace

extern "C" {

// ---------------------------------------------------------------- the dataset
// Reads the manifest for the page (names, fields, chunks); the worker reads it too (worker.js).
EMSCRIPTEN_KEEPALIVE int ts_open_manifest(const char* json, int len) {
  requestRedraw();
  if (!g_app.canvas.platformError.empty()) return 0;  // nothing could be shown; keep that error visible
  g_app.view.pinned = false;                          // a new dataset is framed unless the page sets a view again
  if (!json || len < 0) return 0;
  return openPage(page(), std::string_view(json, size_t(len))) ? 1 : 0;
}

EMSCRIPTEN_KEEPALIVE int ts_chunk_count() { return int(manifest().chunks.size()); }

EMSCRIPTEN_KEEPALIVE int ts_node_count() { return int(manifest().nodes.size()); }

// Chunks the view needs that are not in yet (every chunk not in, without nodes).
EMSCRIPTEN_KEEPALIVE int ts_chunks_missing() { return int(page().model.chunksMissing); }

// Compressed bytes of the chunks the view needs, base included (every chunk without nodes).
EMSCRIPTEN_KEEPALIVE double ts_needed_bytes() { return double(page().model.bytesNeeded); }

// 1: fetch every node; 0: the nodes the view needs (the default).
EMSCRIPTEN_KEEPALIVE void ts_set_fetch_everything(int on) {
  setFetchMode(page(), on ? FetchMode::Everything : FetchMode::Needed);
  viewChanged();
}

// Chunks memory allows (from the worker's report; every chunk without a limit).
EMSCRIPTEN_KEEPALIVE int ts_chunks_allowed() { return int(page().model.chunksAllowed); }

EMSCRIPTEN_KEEPALIVE const char* ts_chunk_file(int index) {
  const auto& chunks = manifest().chunks;
  return index >= 0 && size_t(index) < chunks.size() ? chunks[size_t(index)].file.c_str() : "";
}

EMSCRIPTEN_KEEPALIVE double ts_chunk_bytes(int index) {
  const auto& chunks = manifest().chunks;
  return index >= 0 && size_t(index) < chunks.size() ? double(chunks[size_t(index)].bytes) : 0;
}

EMSCRIPTEN_KEEPALIVE void ts_set_network(double receivedBytes, double totalBytes, double bytesPerSecond,
                                         double secondsLeft, int paused, const char* notice) {
  PageState& p = page();
  NetworkStatus n;
  n.receivedBytes = receivedBytes > 0 ? uint64_t(receivedBytes) : 0;
  n.totalBytes = totalBytes > 0 ? uint64_t(totalBytes) : 0;
  n.bytesPerSecond = std::isfinite(bytesPerSecond) && bytesPerSecond > 0 ? bytesPerSecond : 0;
  n.secondsLeft = std::isfinite(secondsLeft) && secondsLeft >= 0 ? secondsLeft : -1;
  n.paused = paused != 0;
  n.notice = notice ? notice : "";
  if (n.paused != p.network.paused || n.notice != p.network.notice) requestRedraw();
  p.network = std::move(n);
}

EMSCRIPTEN_KEEPALIVE void ts_fail(const char* message) {
  requestRedraw();
  failPage(page(), message ? message : "");
}

// ---------------------------------------------------------------- the worker
// The next command for the worker (page_state.h, takeCommand) as JSON, "" when none; valid
// until the next call.
EMSCRIPTEN_KEEPALIVE const char* ts_take_command() {
  g_commandBuffer = takeCommand(page());
  return g_commandBuffer.c_str();
}

// A report from the worker: its model's figures (JSON), the command version it has applied and
// a geometry delta (`delta`, `len` bytes; the caller frees it). 0 when malformed (the page's
// error says so).
EMSCRIPTEN_KEEPALIVE int ts_take_report(const char* stats, int seen, const uint8_t* delta, int len) {
  PageState& p = page();
  std::string error;
  if (!stats || len < 0 ||
      !takeReport(p, stats, uint32_t(std::max(seen, 0)), {delta, size_t(std::max(len, 0))}, error)) {
    failPage(p, "The viewer's refinement worker sent " + (error.empty() ? std::string("nothing usable") : error) + ".");
    requestRedraw();
    return 0;
  }
  if (p.dirty.surface || p.dirty.slice || p.dirty.hull)
    requestRedraw();
  else if (p.network.totalBytes == 0 || shownState(p) != LoadState::Streaming)
    requestRedraw(1);
  return 1;
}

// ---------------------------------------------------------------- what is shown
EMSCRIPTEN_KEEPALIVE void ts_set_level(double fraction) {
  setLevelFraction(page(), fraction);
  viewChanged();
}

EMSCRIPTEN_KEEPALIVE void ts_set_isovalue(float value) {
  setIsovalue(page(), value);
  viewChanged();
}

EMSCRIPTEN_KEEPALIVE int ts_set_field(const char* name) {
  const bool ok = name && setField(page(), std::string_view(name));
  viewChanged();
  return ok ? 1 : 0;
}

EMSCRIPTEN_KEEPALIVE int ts_set_colour_field(const char* name) {
  const bool ok = name && setColourField(page(), std::string_view(name));
  viewChanged();
  return ok ? 1 : 0;
}

EMSCRIPTEN_KEEPALIVE int ts_set_colour_map(const char* name) {
  std::optional<ColourMap> m = name ? parseColourMap(name) : std::nullopt;
  if (m) setColourMap(page(), *m);
  viewChanged();
  return m ? 1 : 0;
}

EMSCRIPTEN_KEEPALIVE const char* ts_colour_map_name(int i) {
  return i >= 0 && i < kColourMapCount ? colourMapName(ColourMap(i)) : "";
}

EMSCRIPTEN_KEEPALIVE void ts_set_colour_range(double lo, double hi) {
  setColourRange(page(), float(lo), float(hi));
  viewChanged();
}

EMSCRIPTEN_KEEPALIVE int ts_fit_colour_range() {
  const bool ok = fitColourRange(page());
  viewChanged();
  return ok ? 1 : 0;
}

EMSCRIPTEN_KEEPALIVE void ts_set_slice(int on, double nx, double ny, double nz, double offset) {
  setSlicePlane(page(), {float(nx), float(ny), float(nz)}, float(offset));
  setSliceEnabled(page(), on != 0);
  viewChanged();
}

EMSCRIPTEN_KEEPALIVE void ts_set_view_option(const char* name, int value) {
  requestRedraw();
  if (!name) return;
  const std::string_view n(name);
  if (n == "boundary") {
    page().settings.showBoundary = value != 0;
    page().settingsDirty = true;
    sendCommands();
  }
  if (n == "help") page().view.showHelp = value != 0;
}

EMSCRIPTEN_KEEPALIVE void ts_set_link_note(const char* note) {
  requestRedraw();
  page().view.linkNote = note ? note : "";
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
// (What the model does comes from the worker's last report: page_state.h.)
// A few typed figures for the page's status line and touch handling (no JSON on that path).
EMSCRIPTEN_KEEPALIVE int ts_load_state() { return int(shownState(page())); }

EMSCRIPTEN_KEEPALIVE const char* ts_error() {
  return page().pageError.empty() ? page().model.error.c_str() : page().pageError.c_str();
}

EMSCRIPTEN_KEEPALIVE const char* ts_name() { return manifest().name.c_str(); }

EMSCRIPTEN_KEEPALIVE int ts_chunks_received() { return int(page().model.chunksReceived); }

EMSCRIPTEN_KEEPALIVE double ts_level() { return page().model.level; }

EMSCRIPTEN_KEEPALIVE int ts_context_lost() { return page().contextLost ? 1 : 0; }

// The panel's rectangle in CSS pixels of the canvas: x, y, w, h (i = 0..3).
EMSCRIPTEN_KEEPALIVE double ts_panel_rect(int i) {
  const Rect& r = page().telemetry.screen.panel;
  const float v[4] = {r.x, r.y, r.w, r.h};
  return i >= 0 && i < 4 ? v[i] : 0;
}

// The view as JSON (what a link keeps), valid until the next call.
EMSCRIPTEN_KEEPALIVE const char* ts_view_json() {
  g_viewBuffer = viewObject(page()).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  return g_viewBuffer.c_str();
}

// Everything, as JSON, for tests and scripts; valid until the next call.
EMSCRIPTEN_KEEPALIVE const char* ts_stats_json() {
  page().pageHeapBytes = emscripten_get_heap_size();
  g_statsBuffer = statsJson(page());
  return g_statsBuffer.c_str();
}

}  // extern "C"
