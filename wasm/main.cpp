// tetstream viewer: the browser platform layer (GLFW window on the canvas, ImGui, main loop) and
// the one JS <-> wasm boundary. This is the only file that includes <emscripten.h>.
//
// ---------------------------------------------------------------------------------------------
// JS surface (the module is built with -sMODULARIZE -sEXPORT_NAME=createTetstream):
//
//   const Module = await createTetstream({ canvas, onPauseChange(paused) { ... }, antialias });
//   antialias (optional boolean): multisample the scene or not; by default it is, unless WebGL
//   renders in software (SwiftShader, llvmpipe), which main() asks of its own context.
//   Module.callMain([]);   // once: creates the WebGL2 context, ImGui and the frame loop
//   Built with -sINVOKE_RUN=0 so the shell can validate the manifest and start the chunk
//   downloads first; the functions below work before main() has run. Setting up WebGL on a
//   software rasterizer takes a few hundred ms, which then overlaps the downloads.
//
//   _ts_open_manifest(ptr, len) -> 1 | 0
//       Bytes of manifest.json (UTF-8, not NUL-terminated) at wasm address ptr. Validates and
//       resets the viewer to the new dataset (state "loading"); 0 = rejected, state "error".
//   _ts_chunk_file(i) -> const char*
//       The validated "file" of chunk i (relative to the manifest's URL), "" when out of range.
//       Valid until the next manifest. Chunk count: stats().chunksTotal.
//   _ts_check_chunk(i, ptr, len) -> 1 ok | 2 wrong size | 3 wrong hash | 0 no such chunk
//       Compares downloaded bytes of chunk i with the manifest's size and content hash and
//       changes nothing: the shell checks every chunk as it arrives, in any order, and fetches
//       a damaged one again (2, 3) instead of handing it over.
//   _ts_add_chunk(i, ptr, len) -> 1 | 0
//       The complete bytes of chunk i, which must be the next one: hand each over as soon as it
//       (and every chunk before it) has arrived. JS copies each file into wasm memory once
//       (_malloc + HEAPU8.set) and frees it after the call; the viewer keeps nothing pointing
//       into it. Verifies (size, hash, zstd, header) and keeps the chunk: cheap, ~1 ms for
//       256 KB. The base chunk is shown at once; split chunks are applied by the frame loop
//       within its per-frame budget. 0 = rejected (or the viewer is in "error"): stop sending.
//       1 with stats().state "error" = accepted, and it was the last chunk that fits in memory.
//   _ts_set_memory_limit(megabytes)    (double) before _ts_open_manifest: the most memory the
//                                      dataset may take (?maxMemoryMB=); default and upper bound
//                                      the wasm maximum (4 GB - 64 KB). The viewer streams up to
//                                      the last level whose estimate fits (viewer_memory.h).
//   _ts_set_notice(message)            (C string) what the network side is doing, shown in the
//                                      panel as is ("" clears): retries, waiting for the network
//   _ts_download_progress(networkBytes, datasetBytes)   (doubles, cumulative)
//       Bytes off the wire (aborted requests included) and bytes of the dataset in hand
//       (verified chunks plus partial downloads): the panel's rate, progress and time left.
//   _ts_set_paused(0 | 1)              pause or resume downloading (the panel's button does the
//                                      same); the viewer calls Module.onPauseChange(paused) for
//                                      either, and the shell stops or restarts its fetches there
//   _ts_set_level(fraction)            (double) level target as a fraction of the full mesh's
//                                      vertices, clamped to what has been received; 1 = newest,
//                                      following new data
//   _ts_set_isovalue(value)            (float) re-extracts at once
//   _ts_set_field(name) -> 1 | 0       (C string) selects a field; isovalue -> middle of its range
//   _ts_set_colour_field(name) -> 1 | 0  (C string) colour the isosurface by this field ("" or
//                                      "none": no colouring); the range becomes its range
//   _ts_set_colour_map(name) -> 1 | 0  viridis, magma, turbo, coolwarm, grey
//   _ts_set_colour_range(lo, hi)       (doubles) the values mapped to the map's two ends
//   _ts_set_slice(on, nx, ny, nz, offset)  the slice plane n·p = offset (world units; n need not
//                                      be unit length, a zero n keeps the plane) on or off
//   _ts_camera_get(i) -> double        camera: target x, y, z, distance, yaw, pitch (i = 0..5)
//   _ts_camera_set(tx, ty, tz, distance, yaw, pitch)   sets it and keeps it when the dataset's
//                                      bounds arrive (a shared link's view)
//   _ts_camera_gesture(kind, dx, dy)   touch: 0 orbit / 1 pan by CSS pixels, 2 zoom by dx steps
//   _ts_request_capture()              draws a frame and calls Module.onCapture() right after it,
//                                      while the canvas still holds it (screenshots)
//   _ts_set_view_option(name, 0|1)     "boundary", "help"
//   _ts_set_link_note(text)            a line under the link button ("link copied")
//   Module.onCopyLink(), Module.onScreenshot(): called by the panel's buttons and the keys
//   _ts_fail(message)                  (C string) a failure JS saw (HTTP status, network) in
//                                      plain words; state "error", the shown level stays
//   _ts_stats_json() -> const char*    JSON described in viewer_state.h (statsJson); the buffer
//                                      stays valid until the next call
//   _malloc, _free                     for the byte buffers above
//
// Runtime methods exported for the shell: callMain, ccall, cwrap, UTF8ToString, HEAPU8 (memory
// view; re-read it after every call, memory can grow).
//
// Refinement and frames: splits are applied or undone toward the level target in slices of
// 8 ms (4 ms while the user drags) queued one after another as their own tasks while there is
// work (ts_work, below), with the isosurface and hull updated from the changed tets only. Every
// animation frame then uploads the changed buffer ranges and draws, but only when something
// changed and the GPU has finished the previous frame.
// ---------------------------------------------------------------------------------------------
#include <emscripten.h>
#include <emscripten/heap.h>
#include <emscripten/html5.h>
#include <unistd.h>

#include <GLES3/gl3.h>
#include <GLFW/glfw3.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "backends/imgui_impl_glfw.h"
#include "backends/imgui_impl_opengl3.h"
#include "camera.h"
#include "imgui.h"
#include "panel.h"
#include "renderer.h"
#include "viewer_state.h"

using namespace tetstream;
using namespace tetstream::viewer;

namespace {

struct App {
  ViewerState state;
  OrbitCamera camera;
  Renderer renderer;
  GLFWwindow* window = nullptr;
  std::string platformError;  // set when WebGL 2 / GLFW could not start; sticky
  bool softwareGl = false;    // SwiftShader & co: drawn without multisampling, reduced while refining

  int width = 0, height = 0;  // canvas size in device pixels (= GLFW window and framebuffer size)
  double pixelRatio = 1;      // device pixels per CSS pixel
  float uiScale = 1;

  int dragButton = -1;  // mouse button that started a camera drag, -1 when none
  bool cameraMoved = false;  // by the user since the last framing; if not, a resize re-frames
  bool cameraPinned = false; // set by the shell (a shared link): the framing keeps it
  bool captureRequested = false;  // the shell wants the next drawn frame (screenshot)
  bool reducedShown = false;      // the last drawn frame's scene was drawn at reduced resolution
  bool dragSlice = false;         // the current drag moves the slice (shift + left drag)
  double lastX = 0, lastY = 0;

  int redrawFrames = 2;        // frames still to draw; 0 = idle, nothing changed
  GLsync gpuFence = nullptr;   // after the last drawn frame: signalled once the GPU has done it
  double fenceSince = 0;
  double lastFrameStart = -1;  // emscripten_get_now() of the previous frame callback
  double lastDrawStart = -1;   // ... of the previous frame that drew
  bool workQueued = false;     // a refinement slice is queued (see work())
  std::string statsBuffer;
};

// Refinement runs in slices of its own between frames (a MessageChannel task loop), not inside
// the frame callback: on a software or slow GPU a drawn frame takes 100-200 ms to come back
// (SwiftShader with the hull), and refining only inside frames left the main thread idle most
// of that time (~11k splits/s on Harmonic 64 in SwiftShader). A slice is short enough that
// input and network callbacks wait at most that long, and a frame callback is delayed by at
// most one slice: 8 ms, 4 ms while the user drags the view or a slider.
constexpr double kSliceMs = 8.0;
constexpr double kInteractiveSliceMs = 4.0;
// Download progress alone (no new level) redraws the panel at most this often: each drawn frame
// costs a software GPU tens of ms that the first surface and refinement need more.
constexpr double kProgressRedrawMs = 250.0;
// On a software GL the GPU process renders each frame on the same CPU cores the refinement runs
// on (~100 ms a frame for Harmonic 64 in SwiftShader), so a level that is only refining, with
// nobody touching the view, is redrawn at most this often; input still redraws at once.
constexpr double kSoftwareRefineRedrawMs = 200.0;
// ... and such a frame, or one while the user drags, draws its scene with at most this many
// pixels, scaled up to the canvas (as ParaView renders while interacting); the first frame after
// is drawn at full resolution. The GPU process's fragment work is what competes with refinement
// for the CPU: Harmonic 64 over 10 Mbit/s in SwiftShader refined at 73-91k splits/s in a
// 1280x800 window, 126-131k in a 640x400 one.
constexpr double kReducedPixels = 640.0 * 400.0;

App g_app;

void requestRedraw(int frames = 2) {
  if (g_app.redrawFrames < frames) g_app.redrawFrames = frames;
}

float aspect() { return g_app.height > 0 ? float(g_app.width) / float(g_app.height) : 1.f; }

// ---------------------------------------------------------------- canvas size
// The canvas is laid out by CSS (full window); its backing store follows the CSS size times
// devicePixelRatio. Emscripten 3.1.6's GLFW knows nothing about pixel ratios, so it works in
// device pixels throughout (window = framebuffer = canvas size, mouse in canvas pixels) and
// ImGui is scaled by the ratio instead.
void syncCanvasSize() {
  double cssW = 0, cssH = 0;
  emscripten_get_element_css_size("#canvas", &cssW, &cssH);
  double ratio = emscripten_get_device_pixel_ratio();
  int w = std::max(1, int(std::lround(cssW * ratio))), h = std::max(1, int(std::lround(cssH * ratio)));
  g_app.pixelRatio = ratio > 0 ? ratio : 1;
  if (w == g_app.width && h == g_app.height) return;
  // Browser.setCanvasSize resizes the backing store and notifies GLFW (window size callbacks,
  // glfwGetWindowSize). glfwSetWindowSize would do the same but turns a canvas exactly as big
  // as the screen into a fullscreen request.
  EM_ASM({ Browser.setCanvasSize($0, $1); }, w, h);
  g_app.width = w;
  g_app.height = h;
  if (!g_app.cameraMoved) g_app.camera.reset(aspect());
  requestRedraw();
}

// ---------------------------------------------------------------- mouse -> camera
// Installed before ImGui's GLFW backend, which chains to them. Camera input only when ImGui
// does not want the mouse; a drag that started on the canvas keeps going over the panel.
// Shift + left drag moves the slice along its normal (up = forward): the whole range over the
// canvas height.
void onMouseButton(GLFWwindow* w, int button, int action, int mods) {
  requestRedraw();
  if (action == GLFW_PRESS && g_app.dragButton < 0 && !ImGui::GetIO().WantCaptureMouse) {
    g_app.dragButton = button;
    const bool shift = (mods & GLFW_MOD_SHIFT) || glfwGetKey(w, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
                       glfwGetKey(w, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
    g_app.dragSlice = button == GLFW_MOUSE_BUTTON_LEFT && shift && g_app.state.sliceOn;
    glfwGetCursorPos(g_app.window, &g_app.lastX, &g_app.lastY);
  } else if (action == GLFW_RELEASE && button == g_app.dragButton) {
    g_app.dragButton = -1;
    g_app.dragSlice = false;
  }
}

void onCursorPos(GLFWwindow*, double x, double y) {
  requestRedraw();
  if (g_app.dragButton < 0) return;
  float dx = float(x - g_app.lastX), dy = float(y - g_app.lastY);
  g_app.lastX = x;
  g_app.lastY = y;
  if (g_app.dragSlice) {
    ViewerState& s = g_app.state;
    float lo = 0, hi = 0;
    sliceOffsetRange(s, lo, hi);
    const float offset = s.slice.offset() - dy * (hi - lo) / float(std::max(g_app.height, 1));
    setSlicePlane(s, s.slice.normal(), std::clamp(offset, lo, hi));
    return;
  }
  g_app.cameraMoved = true;
  if (g_app.dragButton == GLFW_MOUSE_BUTTON_LEFT)
    g_app.camera.orbit(dx, dy, float(g_app.height));
  else
    g_app.camera.pan(dx, dy, float(g_app.height));
}

// Wheel: read from the DOM event for both ImGui and the camera, because Emscripten 3.1.6's
// GLFW passes the raw deltaY (pixels, lines or pages; positive = away from the user) as the
// scroll offset. ImGui's GLFW scroll callback is replaced by a no-op in initPlatform.
EM_BOOL onWheel(int, const EmscriptenWheelEvent* e, void*) {
  requestRedraw();
  double steps = e->deltaY;
  if (e->deltaMode == DOM_DELTA_PIXEL) steps /= 100.0;  // 100 px make a notch
  else if (e->deltaMode == DOM_DELTA_LINE) steps /= 3.0;
  steps = std::clamp(-steps, -5.0, 5.0);  // positive = toward the user = zoom in
  if (ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureMouse)
    ImGui::GetIO().MouseWheel += float(steps);
  else {
    g_app.camera.zoom(float(steps));
    g_app.cameraMoved = true;
  }
  return EM_TRUE;  // no page scrolling
}

void ignoreScroll(GLFWwindow*, double, double) {}

void resetView() {
  g_app.camera.reset(aspect());
  g_app.cameraMoved = false;
  g_app.cameraPinned = false;
}

// Moves the slice by a fiftieth of its range (sign: forward / back).
void nudgeSlice(float sign) {
  ViewerState& s = g_app.state;
  float lo = 0, hi = 0;
  sliceOffsetRange(s, lo, hi);
  setSlicePlane(s, s.slice.normal(), std::clamp(s.slice.offset() + sign * (hi - lo) / 50.f, lo, hi));
}

// Keyboard shortcuts (panel.cpp lists them in the help panel). Printable ones come as
// characters (layout-independent: '?' is whatever the keyboard makes it), the others as keys.
// None while ImGui edits text.
bool keysForUs() { return !(ImGui::GetCurrentContext() && ImGui::GetIO().WantTextInput); }

void onChar(GLFWwindow*, unsigned int c) {
  requestRedraw();
  if (!keysForUs()) return;
  ViewerState& s = g_app.state;
  const Manifest& m = s.dataset.manifest;
  switch (c) {
    case '?': s.showHelp = !s.showHelp; break;
    case 'r': case 'R': resetView(); break;
    case 'b': case 'B': s.showBoundary = !s.showBoundary; break;
    case 'p': case 'P': setSliceEnabled(s, !s.sliceOn); break;
    case 'x': case 'X': case 'y': case 'Y': case 'z': case 'Z': {
      const int k = (c | 0x20) - 'x';
      std::array<float, 3> axis{0, 0, 0};
      axis[size_t(k)] = 1;
      setSlicePlane(s, axis, 0.5f * (m.bounds.min[k] + m.bounds.max[k]));
      setSliceEnabled(s, true);
      break;
    }
    case '[': nudgeSlice(-1); break;
    case ']': nudgeSlice(1); break;
    case 'c': case 'C':
      if (!m.fields.empty()) setColourField(s, s.colourField + 1 >= int(m.fields.size()) ? -1 : s.colourField + 1);
      break;
    case 'm': case 'M': setColourMap(s, ColourMap((int(s.colourMap) + 1) % kColourMapCount)); break;
    case 'f': case 'F': fitColourRange(s); break;
    case 'l': case 'L': EM_ASM({ if (Module.onCopyLink) Module.onCopyLink(); }); break;
    case 's': case 'S': EM_ASM({ if (Module.onScreenshot) Module.onScreenshot(); }); break;
    case ' ':
      if (downloading(s) || s.paused) setPaused(s, !s.paused);
      break;
    default: break;
  }
}

void onKey(GLFWwindow*, int key, int, int action, int) {
  requestRedraw();
  if (action != GLFW_PRESS || !keysForUs()) return;
  if (key == GLFW_KEY_F1) g_app.state.showHelp = !g_app.state.showHelp;
  if (key == GLFW_KEY_ESCAPE) g_app.state.showHelp = false;
}

// Tells the shell that downloading was paused or resumed (it owns the fetches).
void notifyPause() {
  ViewerState& s = g_app.state;
  if (!s.pausedChanged) return;
  s.pausedChanged = false;
  EM_ASM({ if (Module.onPauseChange) Module.onPauseChange(!!$0); }, s.paused);
}

// ---------------------------------------------------------------- drawing
bool interacting();  // below, with the refinement slices

// Whether a software GL draws this frame's scene at reduced resolution (see kReducedPixels).
bool reducedWanted(const ViewerState& s) { return g_app.softwareGl && (refining(s) || interacting()); }

void drawFrame() {
  App& a = g_app;
  ViewerState& s = a.state;
  if (s.frameRequested) {
    const OrbitCamera pinned = a.camera;
    a.camera.setBounds(s.dataset.manifest.bounds.min, s.dataset.manifest.bounds.max, aspect());
    if (a.cameraPinned) {  // a view from a link: the bounds change, the view does not
      a.camera.target = pinned.target;
      a.camera.distance = pinned.distance;
      a.camera.yaw = pinned.yaw;
      a.camera.pitch = pinned.pitch;
    }
    a.cameraMoved = a.cameraPinned;
    s.frameRequested = false;
  }

  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  PanelActions actions = drawPanel(s, a.uiScale, float(a.pixelRatio));
  const bool helpWasOpen = s.showHelp;
  drawHelp(s.showHelp, a.uiScale);
  if (actions.layoutChanged || helpWasOpen != s.showHelp) requestRedraw();
  if (actions.resetView) resetView();
  if (actions.toggleHelp) {
    s.showHelp = !s.showHelp;
    requestRedraw();
  }
  if (actions.copyLink) EM_ASM({ if (Module.onCopyLink) Module.onCopyLink(); });
  if (actions.screenshot) EM_ASM({ if (Module.onScreenshot) Module.onScreenshot(); });
  ImGui::Render();

  if (s.surfaceDirty) {
    uploadSurface(a.renderer, s.surface);
    s.surface.clearChanges();
    s.surfaceDirty = false;
  }
  if (s.sliceDirty) {
    uploadSlice(a.renderer, s.slice.surface());
    s.slice.surface().clearChanges();
    s.sliceDirty = false;
  }
  if (s.hullDirty) {
    uploadHull(a.renderer, s.hull);
    s.hull.clearChanges();
    s.hullDirty = false;
  }
  s.gpuBytes = gpuBufferBytes(a.renderer);
  s.uploadBytes = a.renderer.uploads.bytes;
  s.fullUploads = a.renderer.uploads.full;
  s.partialUploads = a.renderer.uploads.partial;
  s.grownUploads = a.renderer.uploads.grown;
  FrameParams p;
  p.view = a.camera.view();
  p.projection = a.camera.projection(aspect());
  p.framebufferWidth = a.width;
  p.framebufferHeight = a.height;
  p.showBoundary = s.showBoundary;
  p.colourBy = s.colourField >= 0;
  p.colourMin = s.colourMin;
  p.colourMax = s.colourMax;
  p.showSlice = s.sliceOn;
  setColourMap(a.renderer, s.colourMap);
  float scale = 1.f;
  if (!a.captureRequested && reducedWanted(s))
    scale = float(std::min(1.0, std::sqrt(kReducedPixels / (double(a.width) * a.height))));
  drawSceneScaled(a.renderer, p, scale);
  a.reducedShown = scale < 1.f;
  s.reducedFrames += a.reducedShown ? 1 : 0;
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  if (a.captureRequested) {
    // Read back in the same task as the drawing (the drawing buffer is not preserved after).
    a.captureRequested = false;
    EM_ASM({ if (Module.onCapture) Module.onCapture(); });
  }

  // The surface's draw calls are submitted; the browser presents them when this callback returns.
  const double now = emscripten_get_now();
  if (s.surfaceReady && s.firstSurfaceMs < 0) {
    s.firstSurfaceMs = now;
    requestRedraw();  // the panel shows the time
  }
}

// True while the GPU is still working on the last drawn frame. Drawing then would only queue
// more work behind it, and once the command queue is full the next GL call blocks the main
// thread until the GPU catches up (~40-150 ms a frame on SwiftShader): refinement and input
// would stall with it. So a frame is drawn only when the previous one is done; on a real GPU
// that is every frame. The fence is polled, never waited on (WebGL updates its status between
// frames); after 250 ms without an answer the frame is drawn anyway.
bool gpuBusy(double now) {
  App& a = g_app;
  if (!a.gpuFence) return false;
  GLint status = GL_UNSIGNALED;
  glGetSynciv(a.gpuFence, GL_SYNC_STATUS, 1, nullptr, &status);
  if (status != GL_SIGNALED && now - a.fenceSince < 250) return true;
  glDeleteSync(a.gpuFence);
  a.gpuFence = nullptr;
  return false;
}

// ---------------------------------------------------------------- refinement between frames
void noteComplete(ViewerState& s) {
  if (s.state == LoadState::Complete && s.completeMs < 0) s.completeMs = emscripten_get_now();
}

bool interacting() {
  return g_app.dragButton >= 0 || (ImGui::GetCurrentContext() && ImGui::IsAnyItemActive());
}

void queueWork() {
  if (g_app.workQueued) return;
  g_app.workQueued = true;
  // A message to a MessageChannel port runs as its own task soon after, without setTimeout's
  // 4 ms clamp; rendering, input and network callbacks get their turns in between.
  EM_ASM({
    if (!Module.tsWorkChannel) {
      Module.tsWorkChannel = new MessageChannel();
      Module.tsWorkChannel.port1.onmessage = () => Module._ts_work();
    }
    Module.tsWorkChannel.port2.postMessage(0);
  });
}

// New work (a chunk, a level, resuming) starts at once rather than at the next frame, which on a
// software GL may be 100-200 ms away while the GPU process renders the last one.
void workOnChange() {
  if (refining(g_app.state) || treePending(g_app.state)) queueWork();
}

}  // namespace

// One refinement slice (called from the MessageChannel task queued above; not for the shell).
extern "C" EMSCRIPTEN_KEEPALIVE void ts_work() {
  App& a = g_app;
  ViewerState& s = a.state;
  a.workQueued = false;
  const double start = emscripten_get_now();
  const double deadline = start + (interacting() ? kInteractiveSliceMs : kSliceMs);
  if (refining(s)) {
    advance(s, deadline, emscripten_get_now);  // marks what changed; frame() redraws it
  } else {
    growTree(s, deadline, emscripten_get_now);
  }
  noteComplete(s);
  if (refining(s) || treePending(s)) queueWork();
}

namespace {

// ---------------------------------------------------------------- frame
void frame() {
  App& a = g_app;
  ViewerState& s = a.state;
  const double start = emscripten_get_now();
  const bool measuring = s.firstSurfaceMs >= 0;  // frame times count once the first surface is up
  if (a.lastFrameStart >= 0) {
    double dt = start - a.lastFrameStart;
    s.frameMs = s.frameMs > 0 ? 0.9 * s.frameMs + 0.1 * dt : dt;
    if (measuring) s.maxFrameGapMs = std::max(s.maxFrameGapMs, dt);
  }
  a.lastFrameStart = start;
  syncCanvasSize();
  tick(s, start);
  noteComplete(s);
  if (refining(s) || treePending(s)) queueWork();
  if (downloading(s) && start - a.lastDrawStart >= kProgressRedrawMs) requestRedraw(1);  // progress and rate move
  // Draw only when something changed: on a software GL (SwiftShader) or a slow GPU a frame can
  // take tens of milliseconds of main-thread time that downloading and decoding need more.
  const bool overPanel = ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureMouse;  // keep the panel live
  const bool refinedOnly = a.softwareGl && refining(s) && !interacting() && !overPanel && !s.frameRequested &&
                          s.firstSurfaceMs >= 0 && start - a.lastDrawStart < kSoftwareRefineRedrawMs;
  if (((s.surfaceDirty || s.hullDirty || s.sliceDirty) && !refinedOnly) || s.frameRequested || a.dragButton >= 0)
    requestRedraw();
  if (a.reducedShown && !reducedWanted(s)) requestRedraw(1);  // the still frame, full size
  // The first surface is drawn at once, even behind a frame the GPU has not finished.
  const bool firstSurface = s.surfaceReady && s.firstSurfaceMs < 0;
  if (a.redrawFrames > 0 && !s.contextLost && (firstSurface || !gpuBusy(start))) {
    --a.redrawFrames;
    a.lastDrawStart = start;
    drawFrame();
    if (a.gpuFence) glDeleteSync(a.gpuFence);
    a.gpuFence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    a.fenceSince = start;
    s.drawMs = emscripten_get_now() - start;
    if (measuring) s.maxDrawMs = std::max(s.maxDrawMs, s.drawMs);
    s.drawTotalMs += s.drawMs;
  }
  notifyPause();
  const double end = emscripten_get_now();
  if (measuring) s.maxFrameMs = std::max(s.maxFrameMs, end - start);
}

// The GLSL of Dear ImGui's shaders: WebGL 2's (started at init and again after a lost context).
constexpr const char* kImGuiGlsl = "#version 300 es";

// ---------------------------------------------------------------- WebGL context loss
// The browser may take the GPU context away (a driver reset, another GPU, too many contexts):
// every GL object goes with it. Streaming and refinement go on meanwhile; drawing waits. When the
// browser gives a context back, the renderer's and the panel's GL objects are made again and
// everything is uploaded in full.
EM_BOOL onContextLost(int, const void*, void*) {
  g_app.state.contextLost = true;
  g_app.gpuFence = nullptr;  // (a sync object of the lost context)
  return EM_TRUE;            // (the event's default is prevented: the browser may restore it)
}

EM_BOOL onContextRestored(int, const void*, void*) {
  App& a = g_app;
  ViewerState& s = a.state;
  const Renderer lost = a.renderer;
  a.renderer = Renderer{};
  a.renderer.samples = lost.samples;
  a.renderer.uploads = lost.uploads;
  std::string error;
  if (!initRenderer(a.renderer, error)) {
    std::fprintf(stderr, "tetstream: renderer setup failed after the context came back: %s\n", error.c_str());
    return EM_TRUE;  // (still lost to the viewer: the page says so)
  }
  warmUpRenderer(a.renderer, a.softwareGl);
  // The panel's backend starts afresh (Dear ImGui 1.86 keeps its buffers' sizes past
  // DestroyDeviceObjects, and would write past the new, empty buffers).
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplOpenGL3_Init(kImGuiGlsl);
  s.surfaceDirty = s.sliceDirty = s.hullDirty = true;
  s.contextLost = false;
  requestRedraw();
  return EM_TRUE;
}

bool initPlatform(std::string& error) {
  if (!glfwInit()) {
    error = "The viewer could not start its window system (GLFW).";
    return false;
  }
  glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_ES_API);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 0);
  // The canvas has no multisampling of its own: the scene is multisampled in an offscreen target
  // (renderer.h) once the context can tell whether it renders in software (below).
  glfwWindowHint(GLFW_SAMPLES, 0);
  double cssW = 0, cssH = 0;
  emscripten_get_element_css_size("#canvas", &cssW, &cssH);
  g_app.pixelRatio = std::max(1.0, emscripten_get_device_pixel_ratio());
  g_app.width = std::max(1, int(std::lround(cssW * g_app.pixelRatio)));
  g_app.height = std::max(1, int(std::lround(cssH * g_app.pixelRatio)));
  g_app.window = glfwCreateWindow(g_app.width, g_app.height, "tetstream", nullptr, nullptr);
  if (!g_app.window) {
    error = "WebGL 2 is not available in this browser, so the viewer cannot draw.";
    return false;
  }
  glfwMakeContextCurrent(g_app.window);
  // A software rasterizer (SwiftShader or llvmpipe: also Chrome's fallback when the GPU is
  // unusable) pays for 4x multisampling with 2-3x the frame time, hardware hardly notices it. The
  // renderer's name is asked of the viewer's own context: before, a throwaway context asked it
  // first (the canvas's multisampling is fixed when its context is made), which on SwiftShader
  // cost the main thread ~350 ms and, asked from a worker, made a third context in the GPU process
  // just as the first frames were drawn.
  g_app.softwareGl = EM_ASM_INT({
    try {
      const gl = Module.canvas.getContext('webgl2');
      const info = gl && gl.getExtension('WEBGL_debug_renderer_info');
      const name = String(info ? gl.getParameter(info.UNMASKED_RENDERER_WEBGL) : 0);
      Module.glRendererName = name;
      return /swiftshader|llvmpipe|softpipe|software/i.test(name) ? 1 : 0;
    } catch (e) {
      return 0;
    }
  }) != 0;
  g_app.state.softwareGl = g_app.softwareGl;
  const int antialias = EM_ASM_INT({ return typeof Module.antialias === 'boolean' ? (Module.antialias ? 1 : 0) : -1; });
  g_app.renderer.samples = antialias == 1 || (antialias < 0 && !g_app.softwareGl) ? 4 : 0;
  g_app.state.samples = g_app.renderer.samples;
  emscripten_set_webglcontextlost_callback("#canvas", nullptr, EM_FALSE, onContextLost);
  emscripten_set_webglcontextrestored_callback("#canvas", nullptr, EM_FALSE, onContextRestored);
  glfwSetMouseButtonCallback(g_app.window, onMouseButton);
  glfwSetCursorPosCallback(g_app.window, onCursorPos);
  emscripten_set_wheel_callback("#canvas", nullptr, EM_TRUE, onWheel);
  glfwSetKeyCallback(g_app.window, onKey);
  glfwSetCharCallback(g_app.window, onChar);

  if (!initRenderer(g_app.renderer, error)) {
    std::fprintf(stderr, "tetstream: renderer setup failed: %s\n", error.c_str());
    error = "The viewer's WebGL 2 shaders could not be set up: " + error;
    return false;
  }
  // (The renderer's name, already asked: WebGL's version strings would each wait for the GPU
  // process, for a line on the console.)
  EM_ASM({
    console.log('tetstream viewer: WebGL 2 on ' + (Module.glRendererName || 'an unnamed renderer') +
                ($0 ? ' (software), ' : ', ') + ($1 ? $1 + 'x multisampling' : 'no multisampling'));
  }, g_app.softwareGl, g_app.renderer.samples);
  warmUpRenderer(g_app.renderer, g_app.softwareGl);

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // no settings file in the browser
  // ImGui works in device pixels (see syncCanvasSize): scale fonts and sizes by the ratio,
  // rounded so the bitmap-style default font stays crisp.
  g_app.uiScale = float(std::max(1.0, std::round(g_app.pixelRatio)));
  ImFontConfig font;
  font.SizePixels = 13.f * g_app.uiScale;
  io.Fonts->AddFontDefault(&font);
  ImGui::StyleColorsDark();
  ImGuiStyle& style = ImGui::GetStyle();
  style.WindowRounding = 6.f;
  style.FrameRounding = 3.f;
  style.GrabRounding = 3.f;
  style.WindowPadding = ImVec2(10.f, 10.f);
  style.ItemSpacing = ImVec2(8.f, 6.f);
  style.ScaleAllSizes(g_app.uiScale);
  ImGui_ImplGlfw_InitForOpenGL(g_app.window, true);
  ImGui_ImplOpenGL3_Init(kImGuiGlsl);
  glfwSetScrollCallback(g_app.window, ignoreScroll);  // wheel goes through onWheel instead
  return true;
}

}  // namespace

// Grows the wasm memory now to hold `bytes`, so that a refusal (past the 4 GB maximum, or the
// browser short of memory) is an answer here rather than a failed allocation deep inside a
// vector, which would abort the module.
bool reserveHeap(uint64_t bytes) {
  if (bytes > emscripten_get_heap_max()) return false;
  if (bytes <= emscripten_get_heap_size()) return true;
  return emscripten_resize_heap(size_t(bytes)) != 0;
}

// Heap in use before a dataset, plus what the UI and the shell's chunk copies take later.
constexpr uint64_t kUiAndTransferBytes = 16u << 20;

// ---------------------------------------------------------------- the JS boundary
extern "C" {

EMSCRIPTEN_KEEPALIVE void ts_set_memory_limit(double megabytes) {
  const uint64_t max = emscripten_get_heap_max();
  g_app.state.memoryLimitBytes =
      megabytes > 0 && megabytes * (1 << 20) < double(max) ? uint64_t(megabytes * (1 << 20)) : max;
}

EMSCRIPTEN_KEEPALIVE int ts_check_chunk(int index, const uint8_t* bytes, int len) {
  if (index < 0 || len < 0 || (!bytes && len > 0)) return 0;
  switch (checkChunk(g_app.state, uint32_t(index), std::span<const uint8_t>(bytes, size_t(len)))) {
    case ChunkCheck::Ok: return 1;
    case ChunkCheck::WrongSize: return 2;
    case ChunkCheck::WrongHash: return 3;
    case ChunkCheck::NoSuchChunk: return 0;
  }
  return 0;
}

EMSCRIPTEN_KEEPALIVE void ts_set_notice(const char* message) {
  requestRedraw();
  setNotice(g_app.state, message ? message : "");
}

EMSCRIPTEN_KEEPALIVE int ts_open_manifest(const char* json, int len) {
  requestRedraw();
  if (!g_app.platformError.empty()) return 0;  // nothing could be shown; keep that error visible
  g_app.cameraPinned = false;  // a new dataset is framed unless the shell sets a view again
  if (!json || len < 0) return 0;
  ViewerState& s = g_app.state;
  if (!s.memoryLimitBytes) ts_set_memory_limit(0);
  s.memoryBaseBytes = uint64_t(reinterpret_cast<uintptr_t>(sbrk(0))) + kUiAndTransferBytes;
  s.reserveHeap = reserveHeap;
  return openManifest(g_app.state, std::string_view(json, size_t(len))).ok() ? 1 : 0;
}

EMSCRIPTEN_KEEPALIVE const char* ts_chunk_file(int index) {
  const auto& chunks = g_app.state.dataset.manifest.chunks;
  return index >= 0 && size_t(index) < chunks.size() ? chunks[size_t(index)].file.c_str() : "";
}

EMSCRIPTEN_KEEPALIVE int ts_add_chunk(int index, const uint8_t* bytes, int len) {
  requestRedraw();
  if (index < 0 || len < 0 || (!bytes && len > 0)) {
    failLoad(g_app.state, "The page passed an invalid chunk to the viewer.");
    return 0;
  }
  const bool ok = addChunk(g_app.state, uint32_t(index), std::span<const uint8_t>(bytes, size_t(len))).ok();
  workOnChange();
  return ok ? 1 : 0;
}

// timeMs: performance.now() when the figures were taken (samples taken before the viewer had the
// dataset come late).
EMSCRIPTEN_KEEPALIVE void ts_download_progress(double networkBytes, double datasetBytes, double timeMs) {
  if (!(networkBytes >= 0) || !(datasetBytes >= 0) || !(timeMs >= 0)) return;
  noteDownload(g_app.state, uint64_t(networkBytes), uint64_t(datasetBytes), std::min(timeMs, emscripten_get_now()));
}

EMSCRIPTEN_KEEPALIVE void ts_set_paused(int paused) {
  requestRedraw();
  setPaused(g_app.state, paused != 0);
  notifyPause();
  workOnChange();
}

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

// The camera as six numbers: target x, y, z, distance, yaw, pitch (camera.h).
EMSCRIPTEN_KEEPALIVE double ts_camera_get(int i) {
  const OrbitCamera& c = g_app.camera;
  const double v[6] = {c.target.x, c.target.y, c.target.z, c.distance, c.yaw, c.pitch};
  return i >= 0 && i < 6 ? v[i] : 0;
}

EMSCRIPTEN_KEEPALIVE void ts_camera_set(double tx, double ty, double tz, double distance, double yaw, double pitch) {
  const double v[6] = {tx, ty, tz, distance, yaw, pitch};
  for (double x : v)
    if (!std::isfinite(x)) return;
  if (!(distance > 0)) return;
  OrbitCamera& c = g_app.camera;
  c.target = glm::vec3(float(tx), float(ty), float(tz));
  c.distance = float(distance);
  c.yaw = float(yaw);
  c.pitch = std::clamp(float(pitch), -1.55f, 1.55f);
  g_app.cameraMoved = g_app.cameraPinned = true;
  requestRedraw();
}

// Touch gestures from the shell (pointer events, CSS pixels): 0 orbit, 1 pan by (dx, dy);
// 2 zoom by dx wheel steps.
EMSCRIPTEN_KEEPALIVE void ts_camera_gesture(int kind, double dx, double dy) {
  if (!std::isfinite(dx) || !std::isfinite(dy)) return;
  OrbitCamera& c = g_app.camera;
  const float k = float(g_app.pixelRatio);
  if (kind == 0) c.orbit(float(dx) * k, float(dy) * k, float(g_app.height));
  else if (kind == 1) c.pan(float(dx) * k, float(dy) * k, float(g_app.height));
  else if (kind == 2) c.zoom(float(dx));
  else return;
  g_app.cameraMoved = true;
  requestRedraw();
}

// Draws a frame soon and calls Module.onCapture() right after it (screenshot).
EMSCRIPTEN_KEEPALIVE void ts_request_capture() {
  g_app.captureRequested = true;
  requestRedraw(1);
}

EMSCRIPTEN_KEEPALIVE void ts_set_view_option(const char* name, int value) {
  requestRedraw();
  if (!name) return;
  const std::string_view n(name);
  if (n == "boundary") g_app.state.showBoundary = value != 0;
  if (n == "help") g_app.state.showHelp = value != 0;
}

EMSCRIPTEN_KEEPALIVE void ts_set_link_note(const char* note) {
  requestRedraw();
  g_app.state.linkNote = note ? note : "";
}

EMSCRIPTEN_KEEPALIVE void ts_fail(const char* message) {
  requestRedraw();
  failLoad(g_app.state, message ? message : "");
}

EMSCRIPTEN_KEEPALIVE const char* ts_stats_json() {
  tick(g_app.state, emscripten_get_now());
  g_app.state.heapBytes = emscripten_get_heap_size();
  g_app.statsBuffer = statsJson(g_app.state);
  return g_app.statsBuffer.c_str();
}

}  // extern "C"

int main() {
  std::string error;
  if (!initPlatform(error)) {
    g_app.platformError = error;
    failLoad(g_app.state, error);
    std::fprintf(stderr, "tetstream: %s\n", error.c_str());
    return 0;  // the exported functions keep working: JS still sees the state and the error
  }
  emscripten_set_main_loop(frame, 0, false);
  return 0;
}
