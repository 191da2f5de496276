// The viewer's model: the dataset streamed so far, the chosen field and isovalue, the current
// isosurface and the loading state. No GL, no ImGui, no Emscripten: it compiles natively so the
// viewer's logic can be unit-tested and debugged without a browser.
//
// Flow (driven by wasm/main.cpp from the JS calls documented there):
//   openManifest(bytes)         state idle/error -> loading (or error)
//   addChunk(i, bytes) ...      loading -> streaming -> complete; every applied chunk re-extracts
//   setIsovalue / setField      re-extract at once (a slider drag calls this once a frame)
//   failLoad(message)           network problems reported by JS -> error
// Errors never drop what is on screen: the last valid level and its surface stay.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dataset.h"
#include "isosurface.h"

namespace tetstream::viewer {

enum class LoadState : uint8_t { Idle, Loading, Streaming, Complete, Error };
const char* loadStateName(LoadState s);  // "idle", "loading", "streaming", "complete", "error"

// The domain boundary of the current level, for the translucent hull (GL-free; the renderer
// uploads it). Triangles are unshared so each carries its flat normal.
struct BoundaryMesh {
  std::vector<float> positions;     // 3 per corner, 9 per triangle
  std::vector<float> normals;       // 3 per corner, outward unit normal of the triangle
  std::vector<float> featureLines;  // 6 per segment: boundary edges whose faces meet at a crease
  uint32_t triangleCount() const { return uint32_t(positions.size() / 9); }
  uint32_t lineCount() const { return uint32_t(featureLines.size() / 6); }
};

// Screen rectangle in CSS pixels relative to the canvas' top-left corner.
struct Rect {
  float x = 0, y = 0, w = 0, h = 0;
};

struct ViewerState {
  Dataset dataset;
  int field = -1;        // index into dataset.manifest.fields, -1 before a manifest
  float isovalue = 0;
  IsoSurface surface;
  IsoExtractor extractor;  // reused for every extraction
  BoundaryMesh boundary;

  LoadState state = LoadState::Idle;
  std::string error;       // plain words, shown in the panel; empty unless state == Error

  uint64_t bytesLoaded = 0;  // manifest + chunk bytes handed to the viewer
  uint32_t chunksLoaded = 0, chunksTotal = 0;
  double firstSurfaceMs = -1;  // performance.now() when the first surface was drawn; -1 = not yet
  double extractMs = 0;        // duration of the last extraction
  double frameMs = 0;          // smoothed frame time, set by the main loop
  double surfaceArea = 0;

  // Set by the model, cleared by whoever consumes them.
  bool surfaceDirty = false;   // surface changed: renderer re-uploads the isosurface buffers
  bool boundaryStale = false;  // level changed: the hull must be rebuilt (updateBoundary)
  bool boundaryDirty = false;  // hull rebuilt: renderer re-uploads it
  bool frameRequested = false; // new bounds known: the camera should frame them
  bool surfaceReady = false;   // at least one level has been extracted (first-surface timing)

  // View options and UI feedback.
  bool showBoundary = true;
  Rect sliderRect;  // the isovalue slider, recorded by the panel so tests can drag it
};

// Parses and validates the manifest (untrusted) and resets everything to the new dataset.
// The isovalue becomes the middle of the iso field's range.
Result openManifest(ViewerState& s, std::string_view manifestJson);

// Verifies and applies chunk `index` (must be the next one), then re-extracts the surface and
// marks the boundary stale. On failure the previous level stays and the state becomes Error.
Result addChunk(ViewerState& s, uint32_t index, std::span<const uint8_t> bytes);

// Re-extracts when the value changes (non-finite values are ignored).
void setIsovalue(ViewerState& s, float value);

// Selects a field by index or name; the isovalue moves to the middle of its range.
// False (and nothing changes) when there is no such field.
bool setField(ViewerState& s, int index);
bool setField(ViewerState& s, std::string_view name);

// Reports a failure from outside the model (network, platform) in plain words.
void failLoad(ViewerState& s, std::string_view message);

// Extracts the surface of the current level for the current field and isovalue.
void extract(ViewerState& s);

// Rebuilds the hull when it is stale. Kept out of addChunk because face adjacency costs more
// than extraction (~0.2 s for 1.5 M tets natively): the platform layer calls this after the
// first surface is on screen.
void updateBoundary(ViewerState& s);

// Boundary triangles of a mesh and their crease edges (dihedral angle above ~30 degrees).
void buildBoundary(const TetMesh& mesh, BoundaryMesh& out);

// Everything a test or the JS shell wants to know, as one JSON object:
// {state, error, name, vertices, tets, triangles, surfaceVertices, isovalue, surfaceArea, field,
//  fields:[{name,min,max}], bytesLoaded, bytesTotal, chunksLoaded, chunksTotal, firstSurfaceMs,
//  extractMs, frameMs, showBoundary, sliderRect:{x,y,w,h}}. Times in ms; firstSurfaceMs is null
// until the first surface is drawn.
std::string statsJson(const ViewerState& s);

}  // namespace tetstream::viewer
