#include "page_state.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tetstream::viewer {
namespace {

using json = nlohmann::json;

void changed(PageState& p) {
  p.settingsDirty = true;
  p.dirty.surface = true;  // (the renderer's colour range and flags: a redraw)
}

template <class T>
T number(const json& j, const char* key, T fallback) {
  const json& v = j.value(key, json(nullptr));
  return v.is_number() ? v.get<T>() : fallback;
}

std::string text(const json& j, const char* key) {
  const json& v = j.value(key, json(nullptr));
  return v.is_string() ? v.get<std::string>() : std::string();
}

bool flag(const json& j, const char* key) {
  const json& v = j.value(key, json(nullptr));
  return v.is_boolean() && v.get<bool>();
}

LoadState stateNamed(const std::string& name) {
  for (LoadState s : {LoadState::Idle, LoadState::Loading, LoadState::Streaming, LoadState::Complete, LoadState::Error})
    if (name == loadStateName(s)) return s;
  return LoadState::Error;
}

ModelReport reportOf(const json& j) {
  ModelReport r;
  r.state = stateNamed(text(j, "state"));
  r.error = text(j, "error");
  r.unavailable = text(j, "unavailable");
  r.chunksReceived = number<uint32_t>(j, "chunksReceived", 0);
  r.chunksAllowed = number<uint32_t>(j, "chunksAllowed", 0);
  r.chunksMissing = number<uint32_t>(j, "chunksMissing", 0);
  r.nodesLoaded = number<uint32_t>(j, "nodesLoaded", 0);
  r.bytesReceived = number<uint64_t>(j, "bytesReceived", 0);
  r.bytesNeeded = number<uint64_t>(j, "bytesNeeded", 0);
  r.exact = flag(j, "exact");
  r.refining = flag(j, "refining");
  r.surfaceReady = flag(j, "surfaceReady");
  r.memoryLimited = flag(j, "memoryLimited");
  r.splitsReceived = number<uint32_t>(j, "splitsReceived", 0);
  r.splitsApplied = number<uint32_t>(j, "splitsApplied", 0);
  r.targetSplits = number<uint32_t>(j, "targetSplits", 0);
  r.live = j.value("live", true);
  r.baseVertices = number<uint32_t>(j, "baseVertices", 0);
  r.vertices = number<uint32_t>(j, "vertices", 0);
  r.tets = number<uint32_t>(j, "tets", 0);
  r.level = number<double>(j, "level", 0);
  r.targetLevel = number<double>(j, "targetLevel", 1);
  r.fieldError = number<double>(j, "fieldError", -1);
  r.fieldRms = number<double>(j, "fieldRms", -1);
  r.fieldMax = number<double>(j, "fieldMax", -1);
  const json& memory = j.value("memory", json::object());
  r.dataBytes = number<uint64_t>(memory, "dataBytes", 0);
  r.heapBytes = number<uint64_t>(memory, "heapBytes", 0);
  r.neededBytes = number<uint64_t>(memory, "neededBytes", 0);
  r.limitBytes = number<uint64_t>(memory, "limitBytes", 0);
  r.memoryFull = flag(memory, "full");
  r.refineMs = number<double>(j, "refineMs", 0);
  r.extractMs = number<double>(j, "extractMs", 0);
  r.refineSteps = number<uint32_t>(j, "refineSteps", 0);
  return r;
}

}  // namespace

bool openPage(PageState& p, std::string_view manifestJson) {
  const ViewOptions view = p.view;
  const Telemetry telemetry = p.telemetry;
  const WorkerTraffic traffic = p.traffic;
  const uint32_t version = p.settingsVersion;
  const uint64_t gpu = p.gpuBytes;
  const bool lost = p.contextLost;
  p = PageState{};
  p.view = view;
  p.traffic = traffic;
  p.settingsVersion = p.settingsSeen = version;
  p.gpuBytes = gpu;
  p.contextLost = lost;
  p.telemetry = telemetry;
  p.telemetry.firstSurfaceMs = p.telemetry.completeMs = -1;
  p.dirty.surface = p.dirty.slice = p.dirty.hull = p.dirty.bounds = true;
  if (Result r = parseManifest(manifestJson, p.manifest); !r) {
    p.manifest = {};
    p.pageError = "The dataset description (manifest.json) is not usable: " + r.message;
    return false;
  }
  p.opened = true;
  p.settings = initialSettings(p.manifest);
  p.model.state = LoadState::Loading;
  p.model.chunksMissing = uint32_t(p.manifest.chunks.size());
  p.settingsDirty = true;
  return true;
}

bool takeReport(PageState& p, std::string_view statsJson, uint32_t settingsSeen, std::span<const uint8_t> delta,
                std::string& error) {
  json stats = json::parse(statsJson, nullptr, false);
  if (!stats.is_object()) {
    error = "a malformed report from the refinement worker";
    return false;
  }
  DeltaApplied applied;
  if (!delta.empty() && !applyDelta(delta, p.surface, p.slice, p.hull, applied, error)) return false;
  p.dirty.surface |= applied.surface;
  p.dirty.slice |= applied.slice;
  p.dirty.hull |= applied.hull;
  p.model = reportOf(stats);
  p.modelStats = std::move(stats);
  p.settingsSeen = settingsSeen;
  if (p.levelVersion && settingsSeen >= p.levelVersion) {
    p.levelRequest = -1;
    p.levelSplitsRequest = -1;
    p.levelVersion = 0;
  }
  ++p.traffic.updates;
  p.traffic.deltaBytes += delta.size();
  return true;
}

bool viewCurrent(const PageState& p) {
  return p.settingsSeen == p.settingsVersion && !p.settingsDirty && p.levelVersion == 0 && p.levelRequest < 0 &&
         p.levelSplitsRequest < 0;
}

std::string takeCommand(PageState& p) {
  const bool levelUnsent = (p.levelRequest >= 0 || p.levelSplitsRequest >= 0) && p.levelVersion == 0;
  if (!p.opened || (!p.settingsDirty && !levelUnsent)) return {};
  json c{{"version", ++p.settingsVersion}, {"view", settingsObject(p.settings, p.manifest)}};
  if (levelUnsent) {
    c["level"] =
        p.levelSplitsRequest >= 0 ? json{{"splits", p.levelSplitsRequest}} : json{{"fraction", p.levelRequest}};
    p.levelVersion = p.settingsVersion;
  }
  p.settingsDirty = false;
  ++p.traffic.commands;
  return c.dump(-1, ' ', false, json::error_handler_t::replace);
}

LoadState shownState(const PageState& p) {
  if (!p.pageError.empty()) return LoadState::Error;
  if (p.model.state == LoadState::Complete && !viewCurrent(p)) return LoadState::Streaming;
  return p.model.state;
}

bool shownExact(const PageState& p) { return p.model.exact && viewCurrent(p); }

bool setField(PageState& p, int index) {
  if (!chooseField(p.settings, p.manifest, index)) return false;
  changed(p);
  return true;
}

bool setField(PageState& p, std::string_view name) { return setField(p, p.manifest.findField(name)); }

void setIsovalue(PageState& p, float value) {
  if (value == p.settings.isovalue || !chooseIsovalue(p.settings, value)) return;
  changed(p);
}

bool setColourField(PageState& p, int index) {
  if (!chooseColourField(p.settings, p.manifest, index)) return false;
  changed(p);
  return true;
}

bool setColourField(PageState& p, std::string_view name) {
  if (name.empty() || name == "none") return setColourField(p, -1);
  const int f = p.manifest.findField(name);
  return f >= 0 && setColourField(p, f);
}

void setColourMap(PageState& p, ColourMap map) {
  p.settings.colourMap = map;
  changed(p);
}

void setColourRange(PageState& p, float lo, float hi) {
  chooseColourRange(p.settings, lo, hi);
  changed(p);
}

bool fitColourRange(PageState& p) {
  if (p.settings.colourField < 0) return false;
  ColourSpan span;
  span.cover(p.surface);
  if (p.settings.sliceOn) span.cover(p.slice);
  float lo = 0, hi = 0;
  if (!span.fitted(p.manifest.fields[size_t(p.settings.colourField)].range, lo, hi)) return false;
  setColourRange(p, lo, hi);
  return true;
}

void setSliceEnabled(PageState& p, bool on) {
  if (on == p.settings.sliceOn) return;
  chooseSliceEnabled(p.settings, p.manifest, on);
  changed(p);
}

bool setSlicePlane(PageState& p, std::array<float, 3> normal, float offset) {
  if (!chooseSlicePlane(p.settings, normal, offset)) return false;
  changed(p);
  return true;
}

void sliceOffsetRange(const PageState& p, float& lo, float& hi) { sliceOffsetRange(p.settings, p.manifest, lo, hi); }

void setFetchMode(PageState& p, FetchMode mode) {
  if (mode == p.settings.fetch) return;
  p.settings.fetch = mode;
  changed(p);
}

void setLevelFraction(PageState& p, double fraction) {
  if (!std::isfinite(fraction)) return;
  p.levelRequest = std::clamp(fraction, 0.0, 1.0);
  p.levelSplitsRequest = -1;
  p.levelVersion = 0;
}

void setLevelSplits(PageState& p, uint32_t splits) {
  p.levelSplitsRequest = splits;
  p.levelRequest = -1;
  p.levelVersion = 0;
}

void requestPauseToggle(PageState& p) { p.pauseToggleRequested = true; }

void failPage(PageState& p, std::string_view message) {
  p.pageError = message.empty() ? "Unknown error." : std::string(message);
}

uint32_t shownTargetSplits(const PageState& p) {
  const uint32_t received = p.model.splitsReceived;
  if (p.levelSplitsRequest >= 0) return uint32_t(std::min<int64_t>(p.levelSplitsRequest, received));
  if (p.levelRequest >= 0) {
    if (p.levelRequest >= 1) return received;
    const double v = std::round(p.levelRequest * p.manifest.vertices);
    return std::min(received, v > p.model.baseVertices ? uint32_t(v - p.model.baseVertices) : 0u);
  }
  return std::min(p.model.targetSplits, received);
}

bool downloading(const PageState& p) {
  const LoadState s = shownState(p);
  return (s == LoadState::Loading || s == LoadState::Streaming) && !p.network.paused && p.model.chunksMissing > 0 &&
         p.model.chunksReceived < std::max(p.model.chunksAllowed, 1u);
}

json viewObject(const PageState& p) {
  json j = settingsObject(p.settings, p.manifest);
  j["level"] = p.levelRequest >= 0 ? p.levelRequest : p.model.targetLevel;
  return j;
}

std::string statsJson(const PageState& p) {
  json j = p.modelStats;
  const Telemetry& t = p.telemetry;
  auto rect = [](const Rect& r) { return json{{"x", r.x}, {"y", r.y}, {"w", r.w}, {"h", r.h}}; };
  auto time = [](double v) { return v >= 0 ? json(v) : json(nullptr); };
  json view = viewObject(p);
  json slice = view["slice"];
  slice["triangles"] = p.slice.triangleCount();
  slice["area"] = p.slice.area();
  view.erase("slice");
  j.update(view);
  j.update(json{
      {"slice", std::move(slice)},
      {"state", loadStateName(shownState(p))},
      {"targetSplits", shownTargetSplits(p)},
      {"error", p.pageError.empty() ? p.model.error : p.pageError},
      {"exact", shownExact(p)},
      {"viewCurrent", viewCurrent(p)},
      {"name", p.manifest.name},
      {"triangles", p.surface.triangleCount()},
      {"surfaceVertices", p.surface.vertexCount()},
      {"surfaceArea", p.surface.area()},
      {"hullTriangles", p.hull.triangleCount()},
      {"hullLines", p.hull.lineCount()},
      {"paused", p.network.paused},
      {"notice", p.network.notice},
      {"firstSurfaceMs", time(t.firstSurfaceMs)},
      {"completeMs", time(t.completeMs)},
      {"frameMs", t.frameMs},
      {"maxFrameMs", t.maxFrameMs},
      {"maxFrameGapMs", t.maxFrameGapMs},
      {"drawMs", t.drawMs},
      {"maxDrawMs", t.maxDrawMs},
      {"drawTotalMs", t.drawTotalMs},
      {"reducedFrames", t.reducedFrames},
      {"busyFrames", t.busyFrames},
      {"softwareGl", t.softwareGl},
      {"samples", t.samples},
      {"contextLost", p.contextLost},
      {"uploadBytes", t.uploadBytes},
      {"fullUploads", t.fullUploads},
      {"partialUploads", t.partialUploads},
      {"grownUploads", t.grownUploads},
      {"sliderRect", rect(t.screen.slider)},
      {"levelSliderRect", rect(t.screen.levelSlider)},
      {"pauseButtonRect", rect(t.screen.pauseButton)},
      {"sliceSliderRect", rect(t.screen.sliceSlider)},
      {"panelRect", rect(t.screen.panel)},
      {"showHelp", p.view.showHelp},
      // Where the splits were applied: the page's thread never refines.
      {"refinement", "worker"},
      {"worker",
       {{"commands", p.traffic.commands}, {"updates", p.traffic.updates}, {"deltaBytes", p.traffic.deltaBytes}}},
  });
  json& memory = j["memory"];
  if (!memory.is_object()) memory = json::object();
  memory["gpuBytes"] = p.gpuBytes;
  memory["pageHeapBytes"] = p.pageHeapBytes;
  memory["mirrorBytes"] = p.surface.memoryBytes() + p.slice.memoryBytes() + p.hull.memoryBytes();
  // Messages may carry bytes from the network: never let invalid UTF-8 abort the dump.
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

}  // namespace tetstream::viewer
