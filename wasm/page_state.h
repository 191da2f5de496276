// What the page's thread holds while the refinement worker holds the dataset: the manifest (for
// names, fields, ranges and bounds), the view settings the user chose (view_settings.h), the
// worker's latest report of its model, mirrors of the surface, slice and hull it sent
// (geometry_sync.h), and what only the page knows (network, drawing, panel). The panel and the
// renderer read this; nothing here refines, extracts or touches the dataset's chunks.
//
// The worker applies what the page sends in order, numbered: settingsVersion is the last view
// sent, settingsSeen the last one the worker's report took into account. Until they agree a
// "complete" or "exact" report is about the previous view, so the page does not repeat it.
// GL-free and Emscripten-free.
#pragma once
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "geometry_sync.h"
#include "manifest.h"
#include "telemetry.h"
#include "view_settings.h"
#include "viewer_state.h"

namespace tetstream::viewer {

// The worker's model as its report (statsJson, telemetry.cpp) describes it.
struct ModelReport {
  LoadState state = LoadState::Idle;
  std::string error, unavailable;
  uint32_t chunksReceived = 0, chunksAllowed = 0, chunksMissing = 0, nodesLoaded = 0;
  uint64_t bytesReceived = 0, bytesNeeded = 0;
  bool exact = false, refining = false, surfaceReady = false, memoryLimited = false;
  bool memoryFull = false;  // regions the view needs do not fit in memory (eviction.h)
  uint32_t splitsReceived = 0, splitsApplied = 0, targetSplits = 0;
  bool live = true;
  uint32_t baseVertices = 0, vertices = 0, tets = 0;
  double level = 0, targetLevel = 1;
  double fieldError = -1, fieldRms = -1, fieldMax = -1;  // -1: not known
  uint64_t dataBytes = 0, heapBytes = 0, neededBytes = 0, limitBytes = 0;
  double refineMs = 0, extractMs = 0;
  uint32_t refineSteps = 0;
};

// What crossed between the page and the worker (stats(), and the tests' proof of who refined).
struct WorkerTraffic {
  uint32_t commands = 0;  // messages to the worker
  uint32_t updates = 0;   // reports from it
  uint64_t deltaBytes = 0;
};

struct PageState {
  Manifest manifest;
  bool opened = false;  // a manifest was read
  ViewSettings settings;
  uint32_t settingsVersion = 0, settingsSeen = 0;
  bool settingsDirty = false;  // changed since last sent to the worker
  // A level asked for: a fraction of the full mesh's vertices (window.tetstream, a link) or
  // splits (the panel's slider), -1 when none; kept until the worker has it (levelVersion: the
  // command that carried it, 0 while unsent).
  double levelRequest = -1;
  int64_t levelSplitsRequest = -1;
  uint32_t levelVersion = 0;

  ModelReport model;
  nlohmann::json modelStats = nlohmann::json::object();  // the report as sent
  WorkerTraffic traffic;
  SurfaceMirror surface, slice;
  HullMirror hull;

  NetworkStatus network;  // from the page's network side
  ViewOptions view;
  std::string pageError;  // a failure outside the model (network, platform, worker): shown over its state
  bool pauseToggleRequested = false;
  bool contextLost = false;
  Changes dirty;
  Telemetry telemetry;  // the page's own figures: frames, uploads, rectangles
  uint64_t gpuBytes = 0, pageHeapBytes = 0;
};

// A new dataset: its manifest read and validated (the worker reads it too), the settings reset,
// the mirrors emptied. On failure the page's error says why.
bool openPage(PageState& p, std::string_view manifestJson);

// A report from the worker: its model's figures (JSON: statsJson), the settings version it took
// into account and a geometry delta. A malformed one changes nothing and returns false.
bool takeReport(PageState& p, std::string_view statsJson, uint32_t settingsSeen, std::span<const uint8_t> delta,
                std::string& error);

// The next command for the worker, as JSON ({version, view, level?}: worker.js), or "" when
// nothing changed since the last one.
std::string takeCommand(PageState& p);

// The state the page shows: its own error first; "complete" only once the worker has the
// current view.
LoadState shownState(const PageState& p);
bool shownExact(const PageState& p);
bool viewCurrent(const PageState& p);  // the worker has applied the latest settings

// Choices: each marks the settings to be sent (settingsDirty); false for one that does not exist.
bool setField(PageState& p, int index);
bool setField(PageState& p, std::string_view name);
void setIsovalue(PageState& p, float value);
bool setColourField(PageState& p, int index);
bool setColourField(PageState& p, std::string_view name);  // "" or "none": no colouring
void setColourMap(PageState& p, ColourMap map);
void setColourRange(PageState& p, float lo, float hi);
bool fitColourRange(PageState& p);  // the colour field's range over what the mirrors show
void setSliceEnabled(PageState& p, bool on);
bool setSlicePlane(PageState& p, std::array<float, 3> normal, float offset);
void sliceOffsetRange(const PageState& p, float& lo, float& hi);
void setFetchMode(PageState& p, FetchMode mode);
void setLevelFraction(PageState& p, double fraction);
void setLevelSplits(PageState& p, uint32_t splits);
void requestPauseToggle(PageState& p);
void failPage(PageState& p, std::string_view message);

// The slider's level while a level request is on its way: what was asked, else the model's.
uint32_t shownTargetSplits(const PageState& p);
bool downloading(const PageState& p);  // parts still to fetch, not paused, no error

// The view a link keeps (settings and the level asked for) and everything for stats().
nlohmann::json viewObject(const PageState& p);
std::string statsJson(const PageState& p);

}  // namespace tetstream::viewer
