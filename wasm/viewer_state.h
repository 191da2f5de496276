// The viewer's model: the dataset streamed so far, the level of detail shown, the chosen field
// and isovalue, colouring, the slice, the isosurface and domain hull kept up to date by local
// edits, and the loading state; with the memory budget (viewer_memory.h) and the telemetry
// (telemetry.h) as parts of their own. No GL, no ImGui, no Emscripten: it compiles natively so the viewer's logic can
// be unit-tested and debugged without a browser.
//
// Flow (driven by the refinement worker, wasm/worker_api.cpp, from the messages in docs/js-api.md):
//   openManifest(bytes)          state idle/error -> loading (or error)
//   offerChunk(i, bytes)         a downloaded chunk, in any order: checked against the manifest
//                                (size, hash) once, kept, and added (addChunk) in order
//   addChunk(i, bytes)           verification only (cheap): the chunk is kept; the base chunk is
//                                shown at once (surface and hull built)      loading -> streaming
//   advance(deadline) per frame  applies or undoes splits toward the level target until the
//                                deadline, updating surface and hull from the changed tets only
//                                (paper §4.3)        streaming -> complete once all is applied
//   setLevel / setLevelFraction  moves the target (the level slider); at the newest level the
//                                target follows new data ("live")
//   setIsovalue / setField       the whole surface again, through the interval tree (§4.2)
//   setNetwork(snapshot)         what the page's network side reports: bytes in hand, rate, time
//                                left, paused, a notice in plain words (the page owns the network)
//   failLoad(message)            network problems reported by JS -> error
// Memory: openManifest estimates what each level needs (viewer_memory.h) and, with a limit set
// (memory.limitBytes), allows only the chunks whose level fits; addChunk asks the platform to
// grow the heap for the next level first (memory.reserveHeap). Past the last chunk that fits, or when
// the browser refuses memory, the state becomes Error with a plain message and the level
// reached stays usable.
// Errors never drop what is on screen: the last valid level, its surface and hull stay, and the
// level slider keeps working over the chunks that did arrive.
#pragma once
#include <array>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "colourmap.h"
#include "dataset.h"
#include "eviction.h"
#include "fetch_plan.h"
#include "hull.h"
#include "isosurface_incremental.h"
#include "slice.h"
#include "telemetry.h"
#include "viewer_memory.h"

namespace tetstream::viewer {

enum class LoadState : uint8_t { Idle, Loading, Streaming, Complete, Error };
// "idle", "loading" (no base yet), "streaming" (base shown; chunks still to come or splits not
// yet applied), "complete" (every chunk the view needs received and every split applied; with a
// patch hierarchy, the view's nodes: fetch_plan.h), "error".
const char* loadStateName(LoadState s);

// The network as the page reports it (one snapshot, docs/js-api.md: ts_set_network): the page
// owns downloading, retries and pausing; the viewer only shows this.
struct NetworkStatus {
  uint64_t receivedBytes = 0;  // of the dataset in hand: verified chunks plus partial downloads
  uint64_t totalBytes = 0;     // of the chunks that will be fetched
  double bytesPerSecond = 0;   // 0: unknown
  double secondsLeft = -1;     // < 0: unknown
  bool paused = false;         // downloading paused by the user
  std::string notice;          // a network problem being retried, in plain words; "" when all is well
};

// A chunk that arrived before the ones it follows: its bytes (malloc'd, owned here) wait for
// their turn.
struct PendingChunk {
  std::unique_ptr<uint8_t, decltype(&std::free)> bytes{nullptr, &std::free};
  size_t size = 0;
};

// Splits per stepTowards call inside advance(), between two looks at the clock: small enough to
// stop close to the deadline (a split with its surface and hull updates costs ~15-25 us in wasm,
// so a batch ~0.6 ms).
inline constexpr uint32_t kStepBatch = 32;

// Colour by field: the surface's vertices carry this field (any point field, independent of the
// isovalue's), mapped through `map` over [min, max]. field -1: no colouring (the two-sided tint).
struct Colouring {
  int field = -1;  // index into the manifest's fields
  ColourMap map = ColourMap::Viridis;
  float min = 0, max = 1;
};

// Level of detail: splits to have applied. `live`: the target follows new data (the slider sits
// at the newest level); cleared when the user moves it back.
struct LevelTarget {
  uint32_t targetSplits = 0;
  bool live = true;
};

// Set by the model, cleared by whoever consumes them (the platform's frame).
struct Changes {
  bool surface = false;  // surface changed: the renderer uploads the changed ranges
  bool slice = false;    // slice changed (or turned off): the renderer uploads it
  bool hull = false;     // hull changed: the renderer uploads the changed ranges
  bool bounds = false;   // new bounds known: the camera should frame them
};

// View options and UI feedback.
struct ViewOptions {
  bool showBoundary = true;
  bool showHelp = false;  // the keyboard shortcuts panel
  std::string linkNote;   // "link copied" and the like, from the page
};

// The viewer's model: what is loaded and what is shown. The memory budget (viewer_memory.h) and
// the telemetry (telemetry.h) are parts of their own.
struct ViewerState {
  Dataset dataset;
  LoadState state = LoadState::Idle;
  std::string error;        // plain words, shown in the panel; empty unless state == Error
  std::string unavailable;  // a region left coarse because its chunk could not be had (chunkUnavailable)
  uint32_t chunksTotal = 0;
  std::map<uint32_t, PendingChunk> pendingChunks;  // checked, waiting for an earlier chunk
  NetworkStatus network;                           // from the page

  LevelTarget level;
  int field = -1;  // index into dataset.manifest.fields, -1 before a manifest
  float isovalue = 0;
  Colouring colour;
  IncrementalIsosurface surface;
  HullTracker hull;
  // The slice plane (slice.h), coloured by the colour field, kept up to date like the surface
  // while sliceOn. The plane is kept when it is off.
  bool sliceOn = false;
  SliceTracker slice;
  bool surfaceReady = false;  // a level has been extracted (first-surface timing)
  Changes dirty;
  ViewOptions view;
  bool pauseToggleRequested = false;  // the panel or a key asked to pause or resume: the platform tells the page
  bool contextLost = false;           // the browser took the WebGL context away (not drawn until it is back)

  MemoryBudget memory;
  Telemetry telemetry;
  FetchPlan fetch;  // which chunks the view needs, most important first (fetch_plan.h)
  Eviction evict;   // regions given back to make room (eviction.h)

  // Scratch, reused every frame.
  std::vector<uint32_t> changed, splitVertices;
};

// Parses and validates the manifest (untrusted) and resets everything to the new dataset.
// The isovalue becomes the middle of the iso field's range.
Result openManifest(ViewerState& s, std::string_view manifestJson);

// Verifies and keeps chunk `index` (must be the next one); the base chunk is shown at once.
// Splits are applied later by advance(). On failure the previous level stays and the state
// becomes Error; chunks are refused once in Error.
// hashChecked: checkChunk has compared the content hash already (offerChunk).
Result addChunk(ViewerState& s, uint32_t index, std::span<const uint8_t> bytes, bool hashChecked = false);

// Applies or undoes splits toward targetSplits until now() passes deadlineMs (checked every
// kStepBatch splits), updating surface and hull locally. Returns true when the level changed.
// A record that fails to decode ends in Error with the level at the last valid chunk.
using Clock = double (*)();
bool advance(ViewerState& s, double deadlineMs, Clock now);

// Level target in splits (clamped to those received) or as a fraction of the full mesh's
// vertices (clamped likewise). At the newest level the target becomes live.
void setLevel(ViewerState& s, uint32_t splits);
void setLevelFraction(ViewerState& s, double fraction);

// The network snapshot from the page (replaces the previous one).
void setNetwork(ViewerState& s, NetworkStatus network);
// Asks the page to pause or resume downloading (the page decides and reports back).
void requestPauseToggle(ViewerState& s);

// Re-extracts when the value changes (non-finite values are ignored).
void setIsovalue(ViewerState& s, float value);

// Selects a field by index or name; the isovalue moves to the middle of its range.
// False (and nothing changes) when there is no such field.
bool setField(ViewerState& s, int index);
bool setField(ViewerState& s, std::string_view name);

// Colour by field (index or name; -1 / "" = none): the range becomes the field's range.
// False (and nothing changes) when there is no such field.
bool setColourField(ViewerState& s, int index);
bool setColourField(ViewerState& s, std::string_view name);
void setColourMap(ViewerState& s, ColourMap map);
// Non-finite values are ignored; lo > hi are swapped.
void setColourRange(ViewerState& s, float lo, float hi);
// Sets the colour range to the colour field's values on what is shown (the isosurface and, when
// on, the slice): a surface that spans a small part of the field's range gets the whole colour
// map. False (range unchanged) when no colour field is chosen or nothing is shown.
bool fitColourRange(ViewerState& s);

// The slice plane: on/off and the plane n·p = offset (n normalised; a zero normal is refused).
// Turning it on without a colour field colours by the isovalue's field.
void setSliceEnabled(ViewerState& s, bool on);
bool setSlicePlane(ViewerState& s, std::array<float, 3> normal, float offset);
// The range of offsets that cut the dataset's bounds for the current normal.
void sliceOffsetRange(const ViewerState& s, float& lo, float& hi);

// Reports a failure from outside the model (network, platform) in plain words.
void failLoad(ViewerState& s, std::string_view message);

// Fetch what the view needs (the default) or everything (fetch_plan.h).
void setFetchMode(ViewerState& s, FetchMode mode);
// A chunk that cannot be had (the page gave up on it): with a patch hierarchy its node's region
// stays coarse, said in plain words, and the rest of the view goes on; without one the stream
// stops there (failLoad).
void chunkUnavailable(ViewerState& s, uint32_t index, std::string_view message);

// Checks a downloaded chunk against the manifest (size, then content hash) without changing
// anything: the page fetches a chunk again when it does not match.
enum class ChunkCheck : uint8_t { Ok, WrongSize, WrongHash, NoSuchChunk };
ChunkCheck checkChunk(const ViewerState& s, uint32_t index, std::span<const uint8_t> bytes);

// A downloaded chunk, in any order. `bytes` was allocated with malloc and belongs to the viewer
// from now on (freed when used or refused). Checked once (checkChunk); a chunk that matches is
// kept and added (addChunk) as soon as every chunk before it is in, at once when it is the next.
// Ok also when adding it ended in Error (the state says why); NoSuchChunk also once in Error or
// for a chunk past those allowed.
ChunkCheck offerChunk(ViewerState& s, uint32_t index, uint8_t* bytes, size_t size);

// Heap bytes held by the dataset, the surface and the hull now.
uint64_t memoryInUse(const ViewerState& s);

// Derived figures for panel and stats.
double levelFraction(const ViewerState& s);         // vertices shown / vertices of the full mesh
double targetLevel(const ViewerState& s);           // the level asked for, as levelFraction; 1 while live
const ChunkInfo* levelChunk(const ViewerState& s);  // the last complete chunk (its measured errors), or null

// The field error of the mesh shown (-1 where not known). A level of the stream in manifest order
// has its last chunk's figures (levelChunk); a set of nodes (a plan) the largest of the regions
// still before their splits (partial.h's frontierFieldError), without an RMS (nodes do not count
// their input vertices).
struct ShownError {
  double estimate = -1, rms = -1, max = -1;
};
ShownError shownFieldError(const ViewerState& s);
bool downloading(const ViewerState& s);  // chunks still to fetch, not paused, no error
bool refining(const ViewerState& s);     // splits to apply or undo toward the target

// The interval tree (paper §4.2) is not kept while a level streams in: each split would cost a
// third more, for isovalue changes that meanwhile test every tet (~10 ms at 1.5M tets in
// wasm). Once nothing more is coming (complete, paused, stopped) and the level is reached,
// growTree builds it in slices until the deadline; true while more is to do.
bool treePending(const ViewerState& s);
bool growTree(ViewerState& s, double deadlineMs, Clock now);

// The view a link keeps, as JSON: {field, isovalue, colourField, colourMap, colourRange, slice:
// {on, normal, offset}, level (the level asked for as a fraction of the full mesh's vertices; 1
// while live), showBoundary} (docs/js-api.md). viewObject is the same object, which stats()
// extends (telemetry.cpp).
nlohmann::json viewObject(const ViewerState& s);
std::string viewJson(const ViewerState& s);

// Applies a view chosen elsewhere (the page's settings: view_settings.h, settingsObject) as it
// is: field, isovalue, colour field, map and range, slice, fetch mode, showBoundary. Missing or
// unknown keys leave their part alone; a field name the dataset lacks changes nothing.
bool applyView(ViewerState& s, const nlohmann::json& view);

}  // namespace tetstream::viewer
