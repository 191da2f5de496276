// The viewer's model: the dataset streamed so far, the level of detail shown, the chosen field
// and isovalue, the isosurface and domain hull kept up to date by local edits, and the loading
// state. No GL, no ImGui, no Emscripten: it compiles natively so the viewer's logic can be
// unit-tested and debugged without a browser.
//
// Flow (driven by wasm/main.cpp from the JS calls documented there):
//   openManifest(bytes)          state idle/error -> loading (or error)
//   addChunk(i, bytes)           verification only (cheap): the chunk is kept; the base chunk is
//                                shown at once (surface and hull built)      loading -> streaming
//   advance(deadline) per frame  applies or undoes splits toward the level target until the
//                                deadline, updating surface and hull from the changed tets only
//                                (paper §4.3)        streaming -> complete once all is applied
//   setLevel / setLevelFraction  moves the target (the level slider); at the newest level the
//                                target follows new data ("live")
//   setIsovalue / setField       the whole surface again, through the interval tree (§4.2)
//   setPaused                    the shell stops or restarts downloading; applying goes on
//   noteDownload                 network progress reported by the shell (for the rate)
//   failLoad(message)            network problems reported by JS -> error
//   setNotice(message)           what the network is doing (retrying, offline), shown as is
// Memory: openManifest estimates what each level needs (viewer_memory.h) and, with a limit set
// (memoryLimitBytes), allows only the chunks whose level fits; addChunk asks the platform to
// grow the heap for the next level first (reserveHeap). Past the last chunk that fits, or when
// the browser refuses memory, the state becomes Error with a plain message and the level
// reached stays usable.
// Errors never drop what is on screen: the last valid level, its surface and hull stay, and the
// level slider keeps working over the chunks that did arrive.
#pragma once
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "colourmap.h"
#include "dataset.h"
#include "isosurface_incremental.h"
#include "slice.h"

namespace tetstream::viewer {

enum class LoadState : uint8_t { Idle, Loading, Streaming, Complete, Error };
// "idle", "loading" (no base yet), "streaming" (base shown; chunks still to come or splits not
// yet applied), "complete" (every chunk received and every split applied), "error".
const char* loadStateName(LoadState s);

// The domain boundary of a mesh, built from scratch (reference for tests; the viewer keeps a
// HullTracker instead). Triangles are unshared so each carries its flat normal.
struct BoundaryMesh {
  std::vector<float> positions;     // 3 per corner, 9 per triangle
  std::vector<float> normals;       // 3 per corner, outward unit normal of the triangle
  std::vector<float> featureLines;  // 6 per segment: boundary edges whose faces meet at a crease
  uint32_t triangleCount() const { return uint32_t(positions.size() / 9); }
  uint32_t lineCount() const { return uint32_t(featureLines.size() / 6); }
};

// Boundary triangles of a mesh and their crease edges (dihedral angle above ~30 degrees, or an
// edge not shared by exactly two boundary triangles).
void buildBoundary(const TetMesh& mesh, BoundaryMesh& out);

// The domain boundary (translucent hull and crease lines) of a ProgressiveMesh, kept up to date
// across vertex splits and their undo without looking at the whole mesh: only faces and edges
// at the split vertices can change (a split touches star(i) ∪ star(j) only, paper §4.3), so
// update() recounts the faces around those vertices.
//
// Renderer-facing arrays, dense (a removed slot is refilled with the last one):
//   trianglePositions(): 9 floats per triangle slot (3 corners), triangleNormals(): the same
//   layout, the triangle's outward unit normal at each corner; lineVertices(): 6 floats per
//   crease segment. Change tracking as IncrementalIsosurface: changedTriangles()/changedLines()
//   list slots written since clearChanges() (possibly >= the current count: ignore those);
//   fullUploadNeeded() after rebuild().
// Memory: per boundary triangle about 110 bytes, per vertex 4 bytes, per crease line ~40 bytes.
class HullTracker {
 public:
  static constexpr uint32_t kNone = ~uint32_t(0);

  void clear();
  // From scratch (face adjacency over the whole mesh): the base level, or after a failure.
  void rebuild(const ProgressiveMesh& pm);
  // After splits or undos: `vertices` holds every split's i and j as pairs, in the order the
  // splits or undos were applied (ids may repeat; ids >= pm.vertexCount() are vertices removed
  // by undo).
  void update(const ProgressiveMesh& pm, std::span<const uint32_t> vertices);

  uint32_t triangleCount() const { return uint32_t(faces_.size() / 3); }
  uint32_t lineCount() const { return uint32_t(lineKeys_.size()); }
  std::span<const float> trianglePositions() const { return positions_; }
  std::span<const float> triangleNormals() const { return normals_; }
  std::span<const float> lineVertices() const { return lines_; }
  // Boundary triangles as outward-wound vertex id triples (tests).
  std::span<const uint32_t> faces() const { return faces_; }
  size_t memoryBytes() const;  // vector capacities

  bool fullUploadNeeded() const { return fullUpload_; }
  std::span<const uint32_t> changedTriangles() const { return changedTriangles_; }
  std::span<const uint32_t> changedLines() const { return changedLines_; }
  void clearChanges();

 private:
  struct FaceEntry {
    uint64_t key;      // the face's two vertices other than the one recounted (edge key)
    uint32_t tetFace;  // tet << 2 | local face
  };
  void recount(const ProgressiveMesh& pm, uint32_t v);
  void addFace(const float* positions, const uint32_t tri[3]);
  void removeFace(uint32_t slot);
  void link(uint32_t corner, uint32_t v);
  void unlink(uint32_t corner);
  void markEdges(const uint32_t tri[3]);
  void updateEdge(const float* positions, uint64_t key);
  void removeLine(uint32_t slot);

  // Triangle slots: faces_ 3 vertex ids, positions_/normals_ 9 floats. Corner c = 3 slot + k is
  // linked into the list of vertex faces_[c] (head_, next_, prev_; kNone ends a list).
  std::vector<uint32_t> faces_;
  std::vector<float> positions_, normals_;
  std::vector<uint32_t> head_, next_, prev_;
  // Crease lines: lines_ 6 floats per slot, lineKeys_ the edge of each slot, lineOfEdge_ the
  // reverse (edge key lo << 32 | hi -> slot).
  std::vector<float> lines_;
  std::vector<uint64_t> lineKeys_;
  FlatMap lineOfEdge_;

  std::vector<uint64_t> dirtyEdges_;
  std::vector<FaceEntry> entries_;        // recount scratch
  std::vector<uint32_t> vertexScratch_, dropScratch_, touched_;  // update scratch
  std::vector<uint32_t> changedTriangles_, changedLines_;
  bool fullUpload_ = false;
};

// Download throughput over a sliding window, from cumulative byte counts and times (ms).
class RateMeter {
 public:
  void reset() { count_ = 0; }
  void add(double nowMs, double totalBytes);
  double bytesPerSecond(double nowMs, double windowMs = 2000) const;

 private:
  static constexpr int kSamples = 40;  // at >= 100 ms apart: 4 s of history
  double t_[kSamples] = {}, bytes_[kSamples] = {};
  int head_ = 0, count_ = 0;  // newest sample at head_ - 1
  double latestT_ = 0, latestBytes_ = 0;
};

// Screen rectangle in CSS pixels relative to the canvas' top-left corner.
struct Rect {
  float x = 0, y = 0, w = 0, h = 0;
};

// Splits per stepTowards call inside advance(), between two looks at the clock: small enough to
// stop close to the deadline (a split with its surface and hull updates costs ~15-25 us in wasm,
// so a batch ~0.6 ms).
inline constexpr uint32_t kStepBatch = 32;

// Bin edges (ms) of ViewerState::sliceCounts. 30 ms is the most refinement may add to a frame.
inline constexpr std::array<double, 6> kSliceEdgesMs = {4, 8, 12, 16, 30, 60};

struct ViewerState {
  Dataset dataset;
  int field = -1;        // index into dataset.manifest.fields, -1 before a manifest
  float isovalue = 0;
  // Colour by field: the surface's vertices carry this field (any point field, independent of
  // the isovalue's), mapped through colourMap over [colourMin, colourMax]. -1: no colouring (the
  // two-sided tint).
  int colourField = -1;
  ColourMap colourMap = ColourMap::Viridis;
  float colourMin = 0, colourMax = 1;
  IncrementalIsosurface surface;
  HullTracker hull;
  // The slice plane (slice.h), coloured by the colour field, kept up to date like the surface
  // while sliceOn. The plane is kept when it is off.
  bool sliceOn = false;
  SliceTracker slice;

  LoadState state = LoadState::Idle;
  std::string error;       // plain words, shown in the panel; empty unless state == Error
  std::string notice;      // from the shell: a network problem being retried, in plain words
  uint32_t chunksTotal = 0;

  // Memory (bytes). The platform sets the limit (the browser's wasm maximum, or the page's
  // ?maxMemoryMB=; 0 = none), the heap in use before any dataset (code, stack, UI), the heap
  // size and the GPU buffers, and may install reserveHeap. openManifest sets the rest.
  uint64_t memoryLimitBytes = 0, memoryBaseBytes = 0;
  uint64_t heapBytes = 0, gpuBytes = 0;
  uint64_t memoryNeededBytes = 0;  // estimate for the whole dataset
  uint32_t chunksAllowed = 0;      // chunks whose level fits the limit (chunksTotal without one)
  bool memoryLimited = false;      // stopped short of the full dataset for lack of memory
  // Grows the heap to at least `bytes` now; false when the browser refuses.
  bool (*reserveHeap)(uint64_t bytes) = nullptr;

  // Level of detail: splits to have applied. `live`: the target follows new data (the slider
  // sits at the newest level); cleared when the user moves it back.
  uint32_t targetSplits = 0;
  bool live = true;
  bool paused = false;  // downloading paused by the user (the shell stops fetching)

  // Network, as reported by the shell: bytes off the wire (aborted requests included, for the
  // rate) and bytes of the dataset in hand (verified chunks plus partial downloads).
  uint64_t networkBytes = 0, datasetBytes = 0;
  RateMeter rate;
  double rateBytesPerSec = 0;  // refreshed by tick()

  // Timings (ms). performance.now()-based absolute times are -1 until they happen.
  double firstSurfaceMs = -1;  // when the first surface was drawn
  double completeMs = -1;      // when the frame loop first found the state complete
  double extractMs = 0;        // duration of the last full extraction (rebuild)
  double refineMs = 0;         // refinement work in the last frame that did any
  double maxRefineMs = 0;      // longest refinement work in one frame
  double refineTotalMs = 0;    // all refinement work so far (the main thread's share, for benchmarks)
  uint32_t refineSteps = 0;    // splits applied or undone in the last frame that did any
  // Work slices (advance, growTree) by duration, bins split at kSliceEdgesMs: the budget is a few
  // ms a slice; a slice far over it is a stall the user feels (an occasional one is the OS or the
  // browser taking the core, which no budget prevents, so tests look at the share).
  std::array<uint32_t, kSliceEdgesMs.size() + 1> sliceCounts{};
  // Set by the main loop, counted from the first surface on (before it, start-up work such as
  // WebGL and ImGui set-up is not the viewer's frame rate):
  double frameMs = 0;          // smoothed interval between frame callbacks
  double maxFrameMs = 0;       // longest frame callback (uploads, drawing, UI)
  double drawMs = 0, maxDrawMs = 0;  // the last / longest drawn frame's callback
  double drawTotalMs = 0;            // all drawn frames' callbacks so far
  uint32_t reducedFrames = 0;        // frames whose scene was drawn at reduced resolution (software GL)
  bool softwareGl = false;           // SwiftShader & co (set by the platform layer)
  int samples = 0;                   // multisampling of the scene (0: none; set by the platform layer)
  bool contextLost = false;          // the browser took the WebGL context away (not drawn until it is back)
  double maxFrameGapMs = 0;    // longest interval between two frame callbacks (browser included)
  uint64_t uploadBytes = 0;    // GPU bytes uploaded in all (renderer)
  uint32_t fullUploads = 0, partialUploads = 0;
  uint32_t grownUploads = 0;   // full uploads that were a buffer growing (renderer)

  // Set by the model, cleared by whoever consumes them.
  bool surfaceDirty = false;   // surface changed: renderer uploads the changed ranges
  bool sliceDirty = false;     // slice changed (or turned off): renderer uploads it
  bool hullDirty = false;      // hull changed: renderer uploads the changed ranges
  bool frameRequested = false; // new bounds known: the camera should frame them
  bool surfaceReady = false;   // a level has been extracted (first-surface timing)
  bool pausedChanged = false;  // the panel toggled pause: the platform tells the shell

  // View options and UI feedback.
  bool showBoundary = true;
  bool showHelp = false;  // the keyboard shortcuts panel
  std::string linkNote;   // "link copied" and the like, from the platform
  Rect sliderRect;       // the isovalue slider, recorded by the panel so tests can drag it
  Rect levelSliderRect;  // the level slider
  Rect sliceSliderRect;  // the slice position slider (while the slice is on)
  Rect panelRect;        // the whole panel (touches there go to the panel, not the camera)
  Rect pauseButtonRect;  // the pause/resume button (while parts are still to come)

  // Scratch, reused every frame.
  std::vector<uint32_t> changed, splitVertices;
};

// Parses and validates the manifest (untrusted) and resets everything to the new dataset.
// The isovalue becomes the middle of the iso field's range.
Result openManifest(ViewerState& s, std::string_view manifestJson);

// Verifies and keeps chunk `index` (must be the next one); the base chunk is shown at once.
// Splits are applied later by advance(). On failure the previous level stays and the state
// becomes Error; chunks are refused once in Error.
Result addChunk(ViewerState& s, uint32_t index, std::span<const uint8_t> bytes);

// Applies or undoes splits toward targetSplits until now() passes deadlineMs (checked every
// kStepBatch splits), updating surface and hull locally. Returns true when the level changed.
// A record that fails to decode ends in Error with the level at the last valid chunk.
using Clock = double (*)();
bool advance(ViewerState& s, double deadlineMs, Clock now);

// Level target in splits (clamped to those received) or as a fraction of the full mesh's
// vertices (clamped likewise). At the newest level the target becomes live.
void setLevel(ViewerState& s, uint32_t splits);
void setLevelFraction(ViewerState& s, double fraction);

void setPaused(ViewerState& s, bool paused);

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

// What the shell's network side is doing, in plain words ("" when all is well).
void setNotice(ViewerState& s, std::string_view message);

// Checks a downloaded chunk against the manifest (size, then content hash) without changing
// anything: the shell fetches a chunk again when it does not match.
enum class ChunkCheck : uint8_t { Ok, WrongSize, WrongHash, NoSuchChunk };
ChunkCheck checkChunk(const ViewerState& s, uint32_t index, std::span<const uint8_t> bytes);

// Heap bytes held by the dataset, the surface and the hull now.
uint64_t memoryInUse(const ViewerState& s);

// Network progress from the shell (cumulative counts), and the rate refresh (once a frame).
void noteDownload(ViewerState& s, uint64_t networkBytes, uint64_t datasetBytes, double nowMs);
void tick(ViewerState& s, double nowMs);

// Derived figures for panel and stats.
double levelFraction(const ViewerState& s);      // vertices shown / vertices of the full mesh
double fieldErrorBound(const ViewerState& s);    // manifest estimate for the last complete chunk
const ChunkInfo* levelChunk(const ViewerState& s);  // the last complete chunk (its measured errors), or null
bool downloading(const ViewerState& s);          // chunks still to fetch, not paused, no error
bool refining(const ViewerState& s);             // splits to apply or undo toward the target

// The interval tree (paper §4.2) is not kept while a level streams in: each split would cost a
// third more, for isovalue changes that meanwhile test every tet (~10 ms at 1.5M tets in
// wasm). Once nothing more is coming (complete, paused, stopped) and the level is reached,
// growTree builds it in slices until the deadline; true while more is to do.
bool treePending(const ViewerState& s);
bool growTree(ViewerState& s, double deadlineMs, Clock now);
double secondsLeft(const ViewerState& s);        // at the current rate; < 0 when unknown

// Everything a test or the JS shell wants to know, as one JSON object:
// {state, error, name, vertices, tets, triangles, surfaceVertices, isovalue, surfaceArea, field,
//  colourField (null: none), colourMap, colourRange:[lo,hi], slice:{on, normal:[x,y,z], offset,
//  triangles, area},
//  fields:[{name,min,max}], chunksReceived, chunksApplied, chunksTotal, bytesReceived,
//  bytesDownloaded, bytesTotal, rateBytesPerSec, secondsLeft, splitsApplied, splitsReceived,
//  splitsTotal, targetSplits, level, live, paused, fieldError, baseVertices, hullTriangles,
//  hullLines, firstSurfaceMs, completeMs, extractMs, refineMs, maxRefineMs, refineTotalMs, refineSteps,
//  sliceEdgesMs, sliceCounts (work slices by duration, bins split at the edges),
//  frameMs, maxFrameMs, maxFrameGapMs, drawMs, maxDrawMs, drawTotalMs, reducedFrames, softwareGl, samples, contextLost, treeTets (tets the interval tree covers), uploadBytes, fullUploads, partialUploads,
//  grownUploads (full uploads because a buffer grew), showBoundary,
//  notice, chunksAllowed, memoryLimited, memory:{heapBytes, dataBytes, gpuBytes, limitBytes,
//  neededBytes, allowedBytes}, sliderRect:{x,y,w,h}, levelSliderRect:{x,y,w,h},
//  pauseButtonRect:{x,y,w,h}, sliceSliderRect:{x,y,w,h}, panelRect:{x,y,w,h}, targetLevel (the
//  level asked for as a fraction of the full mesh's vertices; 1 while live), showBoundary,
//  showHelp}. memory: heapBytes the wasm memory's size, dataBytes what the
//  dataset, surface and hull hold, gpuBytes the GPU buffers and offscreen targets (a
//  multisampled scene: 32 bytes a device pixel), limitBytes the limit (null: none),
//  neededBytes / allowedBytes the estimates for the full dataset / the last level that fits.
// Times in ms; absolute times (firstSurfaceMs, completeMs) are null until they happen.
std::string statsJson(const ViewerState& s);

}  // namespace tetstream::viewer
