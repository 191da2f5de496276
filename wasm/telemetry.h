// What the viewer measures about itself: timings, work-slice and upload counters, and the
// screen rectangles of the panel's controls. Read by stats() (statsJson, for tests and scripts;
// the keys are described in docs/js-api.md); the frame loop only writes here.
#pragma once
#include <array>
#include <cstdint>
#include <string>

namespace tetstream::viewer {

struct ViewerState;

// Screen rectangle in CSS pixels relative to the canvas' top-left corner.
struct Rect {
  float x = 0, y = 0, w = 0, h = 0;
};

// The panel's controls, recorded as it draws them so tests can drag and click them; `panel`
// also routes touches (those on the panel go to it, not to the camera).
struct ScreenRects {
  Rect slider;       // the isovalue slider
  Rect levelSlider;  // the level slider
  Rect sliceSlider;  // the slice position slider (while the slice is on)
  Rect panel;        // the whole panel
  Rect pauseButton;  // the pause/resume button (while parts are still to come)
};

// Bin edges (ms) of Telemetry::sliceCounts. 30 ms is the most refinement may add to a frame.
inline constexpr std::array<double, 6> kSliceEdgesMs = {4, 8, 12, 16, 30, 60};

// Times in ms; absolute times (performance.now()-based) are -1 until they happen.
struct Telemetry {
  double firstSurfaceMs = -1;  // when the first surface was drawn
  double completeMs = -1;      // when the frame loop first found the state complete
  double extractMs = 0;        // duration of the last full extraction (rebuild)
  double refineMs = 0;         // refinement work in the last slice that did any
  double maxRefineMs = 0;      // longest refinement work in one slice
  double refineTotalMs = 0;    // all refinement work so far (the main thread's share, for benchmarks)
  uint32_t refineSteps = 0;    // splits applied or undone in the last slice that did any
  // Work slices (advance, growTree) by duration, bins split at kSliceEdgesMs: the budget is a few
  // ms a slice; a slice far over it is a stall the user feels (an occasional one is the OS or the
  // browser taking the core, which no budget prevents, so tests look at the share).
  std::array<uint32_t, kSliceEdgesMs.size() + 1> sliceCounts{};

  // Set by the frame loop, counted from the first surface on (before it, start-up work such as
  // WebGL and ImGui set-up is not the viewer's frame rate).
  double frameMs = 0;                // smoothed interval between frame callbacks
  double maxFrameMs = 0;             // longest frame callback (uploads, drawing, UI)
  double maxFrameGapMs = 0;          // longest interval between two frame callbacks (browser included)
  double drawMs = 0, maxDrawMs = 0;  // the last / longest drawn frame's callback
  double drawTotalMs = 0;            // all drawn frames' callbacks so far
  uint32_t reducedFrames = 0;        // frames whose scene was drawn at reduced resolution (software GL)
  uint32_t busyFrames = 0;           // frames drawn while refining or interacting (screenshots aside)
  bool softwareGl = false;           // SwiftShader & co
  int samples = 0;                   // multisampling of the scene (0: none)
  uint64_t uploadBytes = 0;          // GPU bytes uploaded in all (renderer)
  uint32_t fullUploads = 0, partialUploads = 0;
  uint32_t grownUploads = 0;  // full uploads that were a buffer growing

  ScreenRects screen;
};

// Everything a test or script wants to know, as one JSON object (docs/js-api.md, stats()).
std::string statsJson(const ViewerState& s);

}  // namespace tetstream::viewer
