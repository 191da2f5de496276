#include "telemetry.h"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "viewer_state.h"

namespace tetstream::viewer {

std::string statsJson(const ViewerState& s) {
  using json = nlohmann::json;
  const Dataset& ds = s.dataset;
  const Manifest& m = ds.manifest;
  json fields = json::array();
  for (const FieldInfo& f : m.fields)
    fields.push_back(json{{"name", f.name}, {"min", f.range.min}, {"max", f.range.max}});
  auto rect = [](const Rect& r) { return json{{"x", r.x}, {"y", r.y}, {"w", r.w}, {"h", r.h}}; };
  auto known = [](double x) { return x >= 0 ? json(x) : json(nullptr); };  // (-1: not known)
  uint32_t splitsTotal = 0;
  for (size_t c = 1; c < m.chunks.size(); ++c) splitsTotal += m.chunks[c].splits;
  const ShownError fieldError = shownFieldError(s);
  // The view a link keeps (field, isovalue, colour, slice, showBoundary), then everything else;
  // "level" here is the level shown, not the one asked for.
  json j = viewObject(s);
  j.update(json{
      {"state", loadStateName(s.state)},
      {"error", s.error},
      {"name", m.name},
      {"vertices", ds.pm.mesh.vertexCount()},
      {"tets", ds.pm.mesh.tetCount()},
      {"triangles", s.surface.triangleCount()},
      {"surfaceVertices", s.surface.vertexCount()},
      {"surfaceArea", s.surface.area()},
      {"fields", std::move(fields)},
      {"chunksReceived", ds.chunksReceived},
      {"chunksApplied", ds.chunksApplied()},
      {"chunksTotal", s.chunksTotal},
      {"exact", exactSurface(s)},
      {"refining", refining(s)},
      {"surfaceReady", s.surfaceReady},
      {"nodesLoaded", nodesLoaded(s)},
      {"nodesTotal", m.nodes.size()},
      {"fetchMode", s.fetch.mode == FetchMode::Everything ? "everything" : "needed"},
      {"bytesNeeded", neededBytes(s)},
      {"chunksMissing", s.fetch.missing},
      {"unavailable", s.unavailable},
      {"bytesReceived", ds.bytesReceived},
      {"bytesTotal", m.totalBytes()},
      {"rateBytesPerSec", s.network.bytesPerSecond},
      {"secondsLeft", s.network.secondsLeft >= 0 ? json(s.network.secondsLeft) : json(nullptr)},
      {"splitsApplied", ds.splitsApplied()},
      {"splitsReceived", ds.splitsReceived()},
      {"splitsTotal", splitsTotal},
      {"targetSplits", std::min(s.level.targetSplits, ds.splitsReceived())},
      {"level", levelFraction(s)},
      {"live", s.level.live},
      {"paused", s.network.paused},
      {"fieldError", known(fieldError.estimate)},
      {"fieldRms", known(fieldError.rms)},
      {"fieldMax", known(fieldError.max)},
      {"baseVertices", ds.pm.baseVertices},
      {"hullTriangles", s.hull.triangleCount()},
      {"hullLines", s.hull.lineCount()},
      {"firstSurfaceMs", known(s.telemetry.firstSurfaceMs)},
      {"completeMs", known(s.telemetry.completeMs)},
      {"extractMs", s.telemetry.extractMs},
      {"refineMs", s.telemetry.refineMs},
      {"maxRefineMs", s.telemetry.maxRefineMs},
      {"refineTotalMs", s.telemetry.refineTotalMs},
      {"refineSteps", s.telemetry.refineSteps},
      {"sliceEdgesMs", kSliceEdgesMs},
      {"sliceCounts", s.telemetry.sliceCounts},
      {"frameMs", s.telemetry.frameMs},
      {"maxFrameMs", s.telemetry.maxFrameMs},
      {"maxFrameGapMs", s.telemetry.maxFrameGapMs},
      {"drawMs", s.telemetry.drawMs},
      {"treeTets", s.surface.treeCoverage()},
      {"maxDrawMs", s.telemetry.maxDrawMs},
      {"drawTotalMs", s.telemetry.drawTotalMs},
      {"reducedFrames", s.telemetry.reducedFrames},
      {"busyFrames", s.telemetry.busyFrames},
      {"softwareGl", s.telemetry.softwareGl},
      {"samples", s.telemetry.samples},
      {"contextLost", s.contextLost},
      {"uploadBytes", s.telemetry.uploadBytes},
      {"fullUploads", s.telemetry.fullUploads},
      {"partialUploads", s.telemetry.partialUploads},
      {"grownUploads", s.telemetry.grownUploads},
      {"notice", s.network.notice},
      {"chunksAllowed", s.memory.chunksAllowed},
      {"chunksWaiting", s.pendingChunks.size()},
      {"memoryLimited", s.memory.limited},
      {"memory",
       {{"heapBytes", s.memory.heapBytes},
        {"allocatedBytes", s.memory.allocatedBytes},
        {"dataBytes", memoryInUse(s)},
        {"gpuBytes", s.memory.gpuBytes},
        {"limitBytes", s.memory.limitBytes ? json(s.memory.limitBytes) : json(nullptr)},
        {"neededBytes", s.memory.neededBytes},
        {"allowedBytes", budgetedByRegions(s)     ? s.memory.limitBytes
                         : s.memory.chunksAllowed ? s.memory.baseBytes + estimateLevelBytes(m, s.memory.chunksAllowed)
                                                  : 0},
        {"budgetedBytes", s.memory.baseBytes + estimateBytes(m, s.memory.received)},
        {"full", s.evict.memoryFull},
        {"nodesForgotten", s.evict.nodesForgotten},
        {"nodesToForget", s.evict.nodes.size()}}},
      {"sliderRect", rect(s.telemetry.screen.slider)},
      {"levelSliderRect", rect(s.telemetry.screen.levelSlider)},
      {"pauseButtonRect", rect(s.telemetry.screen.pauseButton)},
      {"sliceSliderRect", rect(s.telemetry.screen.sliceSlider)},
      {"panelRect", rect(s.telemetry.screen.panel)},
      {"showHelp", s.view.showHelp},
      {"targetLevel", targetLevel(s)},
  });
  j["slice"]["triangles"] = s.slice.surface().triangleCount();
  j["slice"]["area"] = s.slice.surface().area();
  // Messages may carry bytes from the network: never let invalid UTF-8 abort the dump.
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

}  // namespace tetstream::viewer
