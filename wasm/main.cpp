// tetstream viewer: the browser platform layer (GLFW window on the canvas, ImGui, main loop) and
// the one JS <-> wasm boundary. This is the only file that includes <emscripten.h>.
//
// ---------------------------------------------------------------------------------------------
// JS surface (the module is built with -sMODULARIZE -sEXPORT_NAME=createTetstream):
//
//   const Module = await createTetstream({ canvas, onPauseChange(paused) { ... } });
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
//   _ts_add_chunk(i, ptr, len) -> 1 | 0
//       The complete bytes of chunk i, which must be the next one: hand each over as soon as it
//       (and every chunk before it) has arrived. JS copies each file into wasm memory once
//       (_malloc + HEAPU8.set) and frees it after the call; the viewer keeps nothing pointing
//       into it. Verifies (size, hash, zstd, header) and keeps the chunk: cheap, ~1 ms for
//       256 KB. The base chunk is shown at once; split chunks are applied by the frame loop
//       within its per-frame budget. 0 = rejected (or the viewer is in "error"): stop sending.
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
//   _ts_fail(message)                  (C string) a failure JS saw (HTTP status, network) in
//                                      plain words; state "error", the shown level stays
//   _ts_stats_json() -> const char*    JSON described in viewer_state.h (statsJson); the buffer
//                                      stays valid until the next call
//   _malloc, _free                     for the byte buffers above
//
// Runtime methods exported for the shell: callMain, ccall, cwrap, UTF8ToString, HEAPU8 (memory
// view; re-read it after every call, memory can grow).
//
// Frame loop: every animation frame first spends up to its refinement budget applying or undoing
// splits toward the level target (measured with emscripten_get_now, checked every kStepBatch
// splits), with the isosurface and hull updated from the changed tets only, then uploads the
// changed buffer ranges and draws. A frame with nothing to apply and nothing changed draws
// nothing.
// ---------------------------------------------------------------------------------------------
#include <emscripten.h>
#include <emscripten/html5.h>

#include <GLES3/gl3.h>
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
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
  bool softwareGl = false;    // SwiftShader & co: drawn without multisampling

  int width = 0, height = 0;  // canvas size in device pixels (= GLFW window and framebuffer size)
  double pixelRatio = 1;      // device pixels per CSS pixel
  float uiScale = 1;

  int dragButton = -1;  // mouse button that started a camera drag, -1 when none
  bool cameraMoved = false;  // by the user since the last framing; if not, a resize re-frames
  double lastX = 0, lastY = 0;

  int redrawFrames = 2;        // frames still to draw; 0 = idle, nothing changed
  GLsync gpuFence = nullptr;   // after the last drawn frame: signalled once the GPU has done it
  double fenceSince = 0;
  double lastFrameStart = -1;  // emscripten_get_now() of the previous frame callback
  std::string statsBuffer;
};

// Refinement work per frame. While the user drags (the view or a slider) 8 ms, half of a 60 Hz
// frame, so interaction stays smooth; otherwise 16 ms, which still keeps every frame well under
// 30 ms and doubles how fast a level fills in.
constexpr double kInteractiveBudgetMs = 8.0;
constexpr double kIdleBudgetMs = 16.0;

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
void onMouseButton(GLFWwindow*, int button, int action, int) {
  requestRedraw();
  if (action == GLFW_PRESS && g_app.dragButton < 0 && !ImGui::GetIO().WantCaptureMouse) {
    g_app.dragButton = button;
    glfwGetCursorPos(g_app.window, &g_app.lastX, &g_app.lastY);
  } else if (action == GLFW_RELEASE && button == g_app.dragButton) {
    g_app.dragButton = -1;
  }
}

void onCursorPos(GLFWwindow*, double x, double y) {
  requestRedraw();
  if (g_app.dragButton < 0) return;
  float dx = float(x - g_app.lastX), dy = float(y - g_app.lastY);
  g_app.lastX = x;
  g_app.lastY = y;
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

void onKey(GLFWwindow*, int, int, int, int) { requestRedraw(); }

// Tells the shell that downloading was paused or resumed (it owns the fetches).
void notifyPause() {
  ViewerState& s = g_app.state;
  if (!s.pausedChanged) return;
  s.pausedChanged = false;
  EM_ASM({ if (Module.onPauseChange) Module.onPauseChange(!!$0); }, s.paused);
}

// ---------------------------------------------------------------- drawing
void drawFrame() {
  App& a = g_app;
  ViewerState& s = a.state;
  if (s.frameRequested) {
    a.camera.setBounds(s.dataset.manifest.bounds.min, s.dataset.manifest.bounds.max, aspect());
    a.cameraMoved = false;
    s.frameRequested = false;
  }

  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  PanelActions actions = drawPanel(s, a.uiScale, float(a.pixelRatio));
  if (actions.layoutChanged) requestRedraw();
  if (actions.resetView) {
    a.camera.reset(aspect());
    a.cameraMoved = false;
  }
  ImGui::Render();

  if (s.surfaceDirty) {
    uploadSurface(a.renderer, s.surface);
    s.surface.clearChanges();
    s.surfaceDirty = false;
  }
  if (s.hullDirty) {
    uploadHull(a.renderer, s.hull);
    s.hull.clearChanges();
    s.hullDirty = false;
  }
  s.uploadBytes = a.renderer.uploads.bytes;
  s.fullUploads = a.renderer.uploads.full;
  s.partialUploads = a.renderer.uploads.partial;
  FrameParams p;
  p.view = a.camera.view();
  p.projection = a.camera.projection(aspect());
  p.framebufferWidth = a.width;
  p.framebufferHeight = a.height;
  p.showBoundary = s.showBoundary;
  drawScene(a.renderer, p);
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

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
  const bool interacting = a.dragButton >= 0 || (ImGui::GetCurrentContext() && ImGui::IsAnyItemActive());
  const double budget = interacting ? kInteractiveBudgetMs : kIdleBudgetMs;
  if (advance(s, start + budget, emscripten_get_now)) requestRedraw();
  if (s.state == LoadState::Complete && s.completeMs < 0) s.completeMs = emscripten_get_now();
  if (downloading(s)) requestRedraw(1);  // progress and rate move
  // Draw only when something changed: on a software GL (SwiftShader) or a slow GPU a frame can
  // take tens of milliseconds of main-thread time that downloading and decoding need more.
  if (s.surfaceDirty || s.hullDirty || s.frameRequested || a.dragButton >= 0) requestRedraw();
  if (a.redrawFrames > 0 && !gpuBusy(start)) {
    --a.redrawFrames;
    drawFrame();
    a.gpuFence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    a.fenceSince = start;
  }
  notifyPause();
  const double end = emscripten_get_now();
  if (measuring) s.maxFrameMs = std::max(s.maxFrameMs, end - start);
}

bool initPlatform(std::string& error) {
  if (!glfwInit()) {
    error = "The viewer could not start its window system (GLFW).";
    return false;
  }
  glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_ES_API);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 0);
  // A software rasterizer (SwiftShader or llvmpipe: also Chrome's fallback when the GPU is
  // unusable) pays for 4x multisampling with 2-3x the frame time, hardware hardly notices it.
  // The renderer's name is only visible through a context, so a throwaway one is asked first.
  g_app.softwareGl = EM_ASM_INT({
    try {
      const gl = document.createElement('canvas').getContext('webgl2');
      if (!gl) return 0;
      const info = gl.getExtension('WEBGL_debug_renderer_info');
      const name = String(info ? gl.getParameter(info.UNMASKED_RENDERER_WEBGL) : 0);
      const lose = gl.getExtension('WEBGL_lose_context');
      if (lose) lose.loseContext();
      return /swiftshader|llvmpipe|softpipe|software/i.test(name) ? 1 : 0;
    } catch (e) {
      return 0;
    }
  }) != 0;
  glfwWindowHint(GLFW_SAMPLES, g_app.softwareGl ? 0 : 4);
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
  glfwSetMouseButtonCallback(g_app.window, onMouseButton);
  glfwSetCursorPosCallback(g_app.window, onCursorPos);
  emscripten_set_wheel_callback("#canvas", nullptr, EM_TRUE, onWheel);
  glfwSetKeyCallback(g_app.window, onKey);

  std::string info;
  if (!initRenderer(g_app.renderer, info, error)) {
    std::fprintf(stderr, "tetstream: renderer setup failed: %s\n", error.c_str());
    error = "The viewer's WebGL 2 shaders could not be set up: " + error;
    return false;
  }
  std::printf("tetstream viewer: %s%s\n", info.c_str(), g_app.softwareGl ? " | software rasterizer: no MSAA" : "");
  warmUpRenderer(g_app.renderer);

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
  ImGui_ImplOpenGL3_Init("#version 300 es");
  glfwSetScrollCallback(g_app.window, ignoreScroll);  // wheel goes through onWheel instead
  return true;
}

}  // namespace

// ---------------------------------------------------------------- the JS boundary
extern "C" {

EMSCRIPTEN_KEEPALIVE int ts_open_manifest(const char* json, int len) {
  requestRedraw();
  if (!g_app.platformError.empty()) return 0;  // nothing could be shown; keep that error visible
  if (!json || len < 0) return 0;
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
  return addChunk(g_app.state, uint32_t(index), std::span<const uint8_t>(bytes, size_t(len))).ok() ? 1 : 0;
}

EMSCRIPTEN_KEEPALIVE void ts_download_progress(double networkBytes, double datasetBytes) {
  if (!(networkBytes >= 0) || !(datasetBytes >= 0)) return;
  noteDownload(g_app.state, uint64_t(networkBytes), uint64_t(datasetBytes), emscripten_get_now());
}

EMSCRIPTEN_KEEPALIVE void ts_set_paused(int paused) {
  requestRedraw();
  setPaused(g_app.state, paused != 0);
  notifyPause();
}

EMSCRIPTEN_KEEPALIVE void ts_set_level(double fraction) {
  requestRedraw();
  setLevelFraction(g_app.state, fraction);
}

EMSCRIPTEN_KEEPALIVE void ts_set_isovalue(float value) {
  requestRedraw();
  setIsovalue(g_app.state, value);
}

EMSCRIPTEN_KEEPALIVE int ts_set_field(const char* name) {
  requestRedraw();
  return name && setField(g_app.state, std::string_view(name)) ? 1 : 0;
}

EMSCRIPTEN_KEEPALIVE void ts_fail(const char* message) {
  requestRedraw();
  failLoad(g_app.state, message ? message : "");
}

EMSCRIPTEN_KEEPALIVE const char* ts_stats_json() {
  tick(g_app.state, emscripten_get_now());
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
