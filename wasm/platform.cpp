// The viewer's Emscripten platform on the page's thread: the GLFW window on the canvas, mouse,
// wheel and keys, the frame loop (drawing only when something changed and the GPU has finished
// the last frame), the view and camera passed on to the refinement worker, and WebGL context
// loss. The exported functions are in
// api.cpp; the JS surface is described in docs/js-api.md.
#include <GLES3/gl3.h>
#include <GLFW/glfw3.h>
#include <emscripten.h>
#include <emscripten/html5.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "app.h"
#include "backends/imgui_impl_glfw.h"
#include "backends/imgui_impl_opengl3.h"
#include "frame_policy.h"
#include "imgui.h"
#include "panel.h"
#include "platform_calls.h"

namespace tetstream::viewer {

App g_app;

namespace {
// Refinement runs in the worker (worker_api.cpp); this thread draws what it reports. Download progress alone (no new
// level) redraws the panel at most this often: each drawn frame costs a software GPU tens of ms that the first surface
// and refinement need more.
constexpr double kProgressRedrawMs = 250.0;
// On a software GL the GPU process renders each frame on the same CPU cores the refinement runs
// on (~100 ms a frame for Harmonic 64 in SwiftShader), so a level that is only refining, with
// nobody touching the view, is redrawn at most this often; input still redraws at once.
constexpr double kSoftwareRefineRedrawMs = 200.0;
// ... and such a frame, or one while the user drags, draws its scene smaller (frame_policy.h).
// Harmonic 64 over 10 Mbit/s in SwiftShader refined at 73-91k splits/s in a 1280x800 window,
// 126-131k in a 640x400 one.

}  // namespace

void requestRedraw(int frames) {
  if (g_app.pacing.redrawFrames < frames) g_app.pacing.redrawFrames = frames;
}

namespace {

float aspect() { return g_app.canvas.height > 0 ? float(g_app.canvas.width) / float(g_app.canvas.height) : 1.f; }

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
  g_app.canvas.pixelRatio = ratio > 0 ? ratio : 1;
  if (w == g_app.canvas.width && h == g_app.canvas.height) return;
  // Browser.setCanvasSize resizes the backing store and notifies GLFW (window size callbacks,
  // glfwGetWindowSize). glfwSetWindowSize would do the same but turns a canvas exactly as big
  // as the screen into a fullscreen request.
  tsjs_set_canvas_size(w, h);
  g_app.canvas.width = w;
  g_app.canvas.height = h;
  if (!g_app.view.moved) g_app.view.camera.reset(aspect());
  requestRedraw();
}

// ---------------------------------------------------------------- mouse -> camera
// Installed before ImGui's GLFW backend, which chains to them. Camera input only when ImGui
// does not want the mouse; a drag that started on the canvas keeps going over the panel.
// Shift + left drag moves the slice along its normal (up = forward): the whole range over the
// canvas height.
void onMouseButton(GLFWwindow* w, int button, int action, int mods) {
  requestRedraw();
  if (action == GLFW_PRESS && g_app.drag.button < 0 && !ImGui::GetIO().WantCaptureMouse) {
    g_app.drag.button = button;
    const bool shift = (mods & GLFW_MOD_SHIFT) || glfwGetKey(w, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
                       glfwGetKey(w, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
    g_app.drag.slice = button == GLFW_MOUSE_BUTTON_LEFT && shift && g_app.page.settings.sliceOn;
    glfwGetCursorPos(g_app.canvas.window, &g_app.drag.lastX, &g_app.drag.lastY);
  } else if (action == GLFW_RELEASE && button == g_app.drag.button) {
    g_app.drag.button = -1;
    g_app.drag.slice = false;
  }
}

void onCursorPos(GLFWwindow*, double x, double y) {
  requestRedraw();
  if (g_app.drag.button < 0) return;
  float dx = float(x - g_app.drag.lastX), dy = float(y - g_app.drag.lastY);
  g_app.drag.lastX = x;
  g_app.drag.lastY = y;
  if (g_app.drag.slice) {
    PageState& p = g_app.page;
    float lo = 0, hi = 0;
    sliceOffsetRange(p, lo, hi);
    const float offset = p.settings.sliceOffset - dy * (hi - lo) / float(std::max(g_app.canvas.height, 1));
    setSlicePlane(p, p.settings.sliceNormal, std::clamp(offset, lo, hi));
    sendCommands();
    return;
  }
  g_app.view.moved = true;
  if (g_app.drag.button == GLFW_MOUSE_BUTTON_LEFT)
    g_app.view.camera.orbit(dx, dy, float(g_app.canvas.height));
  else
    g_app.view.camera.pan(dx, dy, float(g_app.canvas.height));
}

// Wheel: read from the DOM event for both ImGui and the camera, because Emscripten 3.1.6's
// GLFW passes the raw deltaY (pixels, lines or pages; positive = away from the user) as the
// scroll offset. ImGui's GLFW scroll callback is replaced by a no-op in initPlatform.
EM_BOOL onWheel(int, const EmscriptenWheelEvent* e, void*) {
  requestRedraw();
  double steps = e->deltaY;
  if (e->deltaMode == DOM_DELTA_PIXEL)
    steps /= 100.0;  // 100 px make a notch
  else if (e->deltaMode == DOM_DELTA_LINE)
    steps /= 3.0;
  steps = std::clamp(-steps, -5.0, 5.0);  // positive = toward the user = zoom in
  if (ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureMouse)
    ImGui::GetIO().MouseWheel += float(steps);
  else {
    g_app.view.camera.zoom(float(steps));
    g_app.view.moved = true;
  }
  return EM_TRUE;  // no page scrolling
}

void ignoreScroll(GLFWwindow*, double, double) {}

void resetView() {
  g_app.view.camera.reset(aspect());
  g_app.view.moved = false;
  g_app.view.pinned = false;
}

// Moves the slice by a fiftieth of its range (sign: forward / back).
void nudgeSlice(float sign) {
  PageState& p = g_app.page;
  float lo = 0, hi = 0;
  sliceOffsetRange(p, lo, hi);
  setSlicePlane(p, p.settings.sliceNormal, std::clamp(p.settings.sliceOffset + sign * (hi - lo) / 50.f, lo, hi));
}

// Keyboard shortcuts (panel.cpp lists them in the help panel). Printable ones come as
// characters (layout-independent: '?' is whatever the keyboard makes it), the others as keys.
// None while ImGui edits text.
bool keysForUs() { return !(ImGui::GetCurrentContext() && ImGui::GetIO().WantTextInput); }

void onChar(GLFWwindow*, unsigned int c) {
  requestRedraw();
  if (!keysForUs()) return;
  PageState& s = g_app.page;
  const Manifest& m = s.manifest;
  switch (c) {
    case '?': s.view.showHelp = !s.view.showHelp; break;
    case 'r':
    case 'R': resetView(); break;
    case 'b':
    case 'B':
      s.settings.showBoundary = !s.settings.showBoundary;
      s.settingsDirty = true;
      break;
    case 'p':
    case 'P': setSliceEnabled(s, !s.settings.sliceOn); break;
    case 'x':
    case 'X':
    case 'y':
    case 'Y':
    case 'z':
    case 'Z': {
      const int k = (c | 0x20) - 'x';
      std::array<float, 3> axis{0, 0, 0};
      axis[size_t(k)] = 1;
      setSlicePlane(s, axis, 0.5f * (m.bounds.min[k] + m.bounds.max[k]));
      setSliceEnabled(s, true);
      break;
    }
    case '[': nudgeSlice(-1); break;
    case ']': nudgeSlice(1); break;
    case 'c':
    case 'C':
      if (!m.fields.empty())
        setColourField(s, s.settings.colourField + 1 >= int(m.fields.size()) ? -1 : s.settings.colourField + 1);
      break;
    case 'm':
    case 'M': setColourMap(s, ColourMap((int(s.settings.colourMap) + 1) % kColourMapCount)); break;
    case 'f':
    case 'F': fitColourRange(s); break;
    case 'l':
    case 'L': tsjs_copy_link(); break;
    case 's':
    case 'S': tsjs_screenshot(); break;
    case ' ':
      if (downloading(s) || s.network.paused) requestPauseToggle(s);
      break;
    default: break;
  }
  sendCommands();
}

void onKey(GLFWwindow*, int key, int, int action, int) {
  requestRedraw();
  if (action != GLFW_PRESS || !keysForUs()) return;
  if (key == GLFW_KEY_F1) g_app.page.view.showHelp = !g_app.page.view.showHelp;
  if (key == GLFW_KEY_ESCAPE) g_app.page.view.showHelp = false;
}

}  // namespace

// The panel or a key asked to pause or resume: the page owns the fetches and decides
// (docs/js-api.md, Module.onPauseChange); its next network snapshot shows the result.
void notifyPause() {
  PageState& s = g_app.page;
  if (!s.pauseToggleRequested) return;
  s.pauseToggleRequested = false;
  tsjs_pause_change(!s.network.paused);
}

namespace {

// ---------------------------------------------------------------- drawing
bool interacting();  // below, with the worker

// Whether a software GL draws this frame's scene at reduced resolution (frame_policy.h).
// Splits are being applied, or the worker has yet to answer the latest view.
bool refining(const PageState& p) { return p.model.refining || !viewCurrent(p); }

bool reducedWanted(const PageState& p) { return g_app.canvas.softwareGl && (refining(p) || interacting()); }

void drawFrame() {
  App& a = g_app;
  PageState& s = a.page;
  if (s.dirty.bounds) {
    const OrbitCamera pinned = a.view.camera;
    a.view.camera.setBounds(s.manifest.bounds.min, s.manifest.bounds.max, aspect());
    if (a.view.pinned) {  // a view from a link: the bounds change, the view does not
      a.view.camera.target = pinned.target;
      a.view.camera.distance = pinned.distance;
      a.view.camera.yaw = pinned.yaw;
      a.view.camera.pitch = pinned.pitch;
    }
    a.view.moved = a.view.pinned;
    s.dirty.bounds = false;
  }

  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  PanelActions actions = drawPanel(s, a.canvas.uiScale, float(a.canvas.pixelRatio));
  const bool helpWasOpen = s.view.showHelp;
  drawHelp(s.view.showHelp, a.canvas.uiScale);
  if (actions.layoutChanged || helpWasOpen != s.view.showHelp) requestRedraw();
  if (actions.resetView) resetView();
  if (actions.toggleHelp) {
    s.view.showHelp = !s.view.showHelp;
    requestRedraw();
  }
  if (actions.copyLink) tsjs_copy_link();
  if (actions.screenshot) tsjs_screenshot();
  ImGui::Render();

  if (s.dirty.surface) {
    uploadSurface(a.renderer, s.surface);
    s.surface.clearChanges();
    s.dirty.surface = false;
  }
  if (s.dirty.slice) {
    uploadSlice(a.renderer, s.slice);
    s.slice.clearChanges();
    s.dirty.slice = false;
  }
  if (s.dirty.hull) {
    uploadHull(a.renderer, s.hull);
    s.hull.clearChanges();
    s.dirty.hull = false;
  }
  s.gpuBytes = gpuBufferBytes(a.renderer);
  s.telemetry.uploadBytes = a.renderer.uploads.bytes;
  s.telemetry.fullUploads = a.renderer.uploads.full;
  s.telemetry.partialUploads = a.renderer.uploads.partial;
  s.telemetry.grownUploads = a.renderer.uploads.grown;
  FrameParams p;
  p.view = a.view.camera.view();
  p.projection = a.view.camera.projection(aspect());
  p.framebufferWidth = a.canvas.width;
  p.framebufferHeight = a.canvas.height;
  p.showBoundary = s.settings.showBoundary;
  p.colourBy = s.settings.colourField >= 0;
  p.colourMin = s.settings.colourMin;
  p.colourMax = s.settings.colourMax;
  p.showSlice = s.settings.sliceOn;
  setColourMap(a.renderer, s.settings.colourMap);
  const bool busy = refining(s) || interacting();
  const float scale = sceneScale(a.canvas.softwareGl, busy, a.pacing.captureRequested, a.canvas.width, a.canvas.height);
  drawSceneScaled(a.renderer, p, scale);
  a.pacing.reducedShown = scale < 1.f;
  s.telemetry.reducedFrames += a.pacing.reducedShown ? 1 : 0;
  s.telemetry.busyFrames += busy && !a.pacing.captureRequested ? 1 : 0;
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  if (a.pacing.captureRequested) {
    // Read back in the same task as the drawing (the drawing buffer is not preserved after).
    a.pacing.captureRequested = false;
    tsjs_capture();
  }

  // The surface's draw calls are submitted; the browser presents them when this callback returns.
  const double now = emscripten_get_now();
  if (s.model.surfaceReady && s.telemetry.firstSurfaceMs < 0) {
    s.telemetry.firstSurfaceMs = now;
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
  if (!a.pacing.gpuFence) return false;
  GLint status = GL_UNSIGNALED;
  glGetSynciv(a.pacing.gpuFence, GL_SYNC_STATUS, 1, nullptr, &status);
  if (status != GL_SIGNALED && now - a.pacing.fenceSince < 250) return true;
  glDeleteSync(a.pacing.gpuFence);
  a.pacing.gpuFence = nullptr;
  return false;
}

// ---------------------------------------------------------------- the worker
bool interacting() { return g_app.drag.button >= 0 || (ImGui::GetCurrentContext() && ImGui::IsAnyItemActive()); }

void noteComplete(PageState& p) {
  if (shownState(p) == LoadState::Complete && p.telemetry.completeMs < 0) p.telemetry.completeMs = emscripten_get_now();
}

bool commandsWaiting(const PageState& p) {
  return p.opened && (p.settingsDirty || ((p.levelRequest >= 0 || p.levelSplitsRequest >= 0) && p.levelVersion == 0));
}
}  // namespace

void sendCommands() {
  if (commandsWaiting(g_app.page)) tsjs_command_ready();
}

namespace {

// ---------------------------------------------------------------- frame
// While a dataset of nodes streams in, turning the camera changes which regions come first
// (fetch_plan.h: what a region covers on screen): the worker hears of the camera at most twice a
// second (each is a new plan: a pass over the nodes and a new order for the loader).
void sendCamera(App& a, double now) {
  const PageState& p = a.page;
  const OrbitCamera& c = a.view.camera;
  const OrbitCamera& sent = a.cameraSent;
  if (p.manifest.nodes.empty() || p.model.chunksMissing == 0 || now - a.cameraSentMs < 500) return;
  if (c.target == sent.target && c.distance == sent.distance && c.yaw == sent.yaw && c.pitch == sent.pitch) return;
  a.cameraSent = c;
  a.cameraSentMs = now;
  tsjs_camera_changed(c.target.x, c.target.y, c.target.z, c.distance, c.yaw, c.pitch, aspect());
}

void frame() {
  App& a = g_app;
  PageState& s = a.page;
  const double start = emscripten_get_now();
  const bool measuring = s.telemetry.firstSurfaceMs >= 0;  // frame times count once the first surface is up
  if (a.pacing.lastFrameStart >= 0) {
    double dt = start - a.pacing.lastFrameStart;
    s.telemetry.frameMs = s.telemetry.frameMs > 0 ? 0.9 * s.telemetry.frameMs + 0.1 * dt : dt;
    if (measuring) s.telemetry.maxFrameGapMs = std::max(s.telemetry.maxFrameGapMs, dt);
  }
  a.pacing.lastFrameStart = start;
  syncCanvasSize();
  noteComplete(s);
  sendCamera(a, start);
  if (downloading(s) && start - a.pacing.lastDrawStart >= kProgressRedrawMs)
    requestRedraw(1);  // progress and rate move
  // Draw only when something changed: on a software GL (SwiftShader) or a slow GPU a frame can
  // take tens of milliseconds of main-thread time that downloading and decoding need more.
  const bool overPanel = ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureMouse;  // keep the panel live
  const bool refinedOnly = a.canvas.softwareGl && refining(s) && !interacting() && !overPanel && !s.dirty.bounds &&
                           s.telemetry.firstSurfaceMs >= 0 && start - a.pacing.lastDrawStart < kSoftwareRefineRedrawMs;
  if (((s.dirty.surface || s.dirty.hull || s.dirty.slice) && !refinedOnly) || s.dirty.bounds || a.drag.button >= 0)
    requestRedraw();
  if (a.pacing.reducedShown && !reducedWanted(s)) requestRedraw(1);  // the still frame, full size
  // The first surface is drawn at once, even behind a frame the GPU has not finished.
  const bool firstSurface = s.model.surfaceReady && s.telemetry.firstSurfaceMs < 0;
  if (a.pacing.redrawFrames > 0 && !s.contextLost && (firstSurface || !gpuBusy(start))) {
    --a.pacing.redrawFrames;
    a.pacing.lastDrawStart = start;
    drawFrame();
    if (a.pacing.gpuFence) glDeleteSync(a.pacing.gpuFence);
    a.pacing.gpuFence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    a.pacing.fenceSince = start;
    s.telemetry.drawMs = emscripten_get_now() - start;
    if (measuring) s.telemetry.maxDrawMs = std::max(s.telemetry.maxDrawMs, s.telemetry.drawMs);
    s.telemetry.drawTotalMs += s.telemetry.drawMs;
  }
  notifyPause();
  sendCommands();
  const double end = emscripten_get_now();
  if (measuring) s.telemetry.maxFrameMs = std::max(s.telemetry.maxFrameMs, end - start);
}

// The GLSL of Dear ImGui's shaders: WebGL 2's (started at init and again after a lost context).
constexpr const char* kImGuiGlsl = "#version 300 es";

// ---------------------------------------------------------------- WebGL context loss
// The browser may take the GPU context away (a driver reset, another GPU, too many contexts):
// every GL object goes with it. Streaming and refinement go on meanwhile; drawing waits. When the
// browser gives a context back, the renderer's and the panel's GL objects are made again and
// everything is uploaded in full.
EM_BOOL onContextLost(int, const void*, void*) {
  g_app.page.contextLost = true;
  g_app.pacing.gpuFence = nullptr;  // (a sync object of the lost context)
  return EM_TRUE;                   // (the event's default is prevented: the browser may restore it)
}

EM_BOOL onContextRestored(int, const void*, void*) {
  App& a = g_app;
  PageState& s = a.page;
  const Renderer lost = a.renderer;
  a.renderer = Renderer{};
  a.renderer.samples = lost.samples;
  a.renderer.uploads = lost.uploads;
  std::string error;
  if (!initRenderer(a.renderer, error)) {
    std::fprintf(stderr, "tetstream: renderer setup failed after the context came back: %s\n", error.c_str());
    return EM_TRUE;  // (still lost to the viewer: the page says so)
  }
  warmUpRenderer(a.renderer, a.canvas.softwareGl);
  // The panel's backend starts afresh (Dear ImGui 1.86 keeps its buffers' sizes past
  // DestroyDeviceObjects, and would write past the new, empty buffers).
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplOpenGL3_Init(kImGuiGlsl);
  s.dirty.surface = s.dirty.slice = s.dirty.hull = true;
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
  g_app.canvas.pixelRatio = std::max(1.0, emscripten_get_device_pixel_ratio());
  g_app.canvas.width = std::max(1, int(std::lround(cssW * g_app.canvas.pixelRatio)));
  g_app.canvas.height = std::max(1, int(std::lround(cssH * g_app.canvas.pixelRatio)));
  g_app.canvas.window = glfwCreateWindow(g_app.canvas.width, g_app.canvas.height, "tetstream", nullptr, nullptr);
  if (!g_app.canvas.window) {
    error = "WebGL 2 is not available in this browser, so the viewer cannot draw.";
    return false;
  }
  glfwMakeContextCurrent(g_app.canvas.window);
  // A software rasterizer (SwiftShader or llvmpipe: also Chrome's fallback when the GPU is
  // unusable) pays for 4x multisampling with 2-3x the frame time, hardware hardly notices it. The
  // renderer's name is asked of the viewer's own context: before, a throwaway context asked it
  // first (the canvas's multisampling is fixed when its context is made), which on SwiftShader
  // cost the main thread ~350 ms and, asked from a worker, made a third context in the GPU process
  // just as the first frames were drawn.
  g_app.canvas.softwareGl = tsjs_software_gl() != 0;
  g_app.page.telemetry.softwareGl = g_app.canvas.softwareGl;
  const int antialias = tsjs_antialias();
  g_app.renderer.samples = antialias == 1 || (antialias < 0 && !g_app.canvas.softwareGl) ? 4 : 0;
  g_app.page.telemetry.samples = g_app.renderer.samples;
  emscripten_set_webglcontextlost_callback("#canvas", nullptr, EM_FALSE, onContextLost);
  emscripten_set_webglcontextrestored_callback("#canvas", nullptr, EM_FALSE, onContextRestored);
  glfwSetMouseButtonCallback(g_app.canvas.window, onMouseButton);
  glfwSetCursorPosCallback(g_app.canvas.window, onCursorPos);
  emscripten_set_wheel_callback("#canvas", nullptr, EM_TRUE, onWheel);
  glfwSetKeyCallback(g_app.canvas.window, onKey);
  glfwSetCharCallback(g_app.canvas.window, onChar);

  if (!initRenderer(g_app.renderer, error)) {
    std::fprintf(stderr, "tetstream: renderer setup failed: %s\n", error.c_str());
    error = "The viewer's WebGL 2 shaders could not be set up: " + error;
    return false;
  }
  // (The renderer's name, already asked: WebGL's version strings would each wait for the GPU
  // process, for a line on the console.)
  tsjs_log_renderer(g_app.canvas.softwareGl, g_app.renderer.samples);
  warmUpRenderer(g_app.renderer, g_app.canvas.softwareGl);

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // no settings file in the browser
  // ImGui works in device pixels (see syncCanvasSize): scale fonts and sizes by the ratio,
  // rounded so the bitmap-style default font stays crisp.
  g_app.canvas.uiScale = float(std::max(1.0, std::round(g_app.canvas.pixelRatio)));
  ImFontConfig font;
  font.SizePixels = 13.f * g_app.canvas.uiScale;
  io.Fonts->AddFontDefault(&font);
  ImGui::StyleColorsDark();
  ImGuiStyle& style = ImGui::GetStyle();
  style.WindowRounding = 6.f;
  style.FrameRounding = 3.f;
  style.GrabRounding = 3.f;
  style.WindowPadding = ImVec2(10.f, 10.f);
  style.ItemSpacing = ImVec2(8.f, 6.f);
  style.ScaleAllSizes(g_app.canvas.uiScale);
  ImGui_ImplGlfw_InitForOpenGL(g_app.canvas.window, true);
  ImGui_ImplOpenGL3_Init(kImGuiGlsl);
  glfwSetScrollCallback(g_app.canvas.window, ignoreScroll);  // wheel goes through onWheel instead
  return true;
}

}  // namespace

}  // namespace tetstream::viewer

using namespace tetstream::viewer;

int main() {
  std::string error;
  if (!initPlatform(error)) {
    g_app.canvas.platformError = error;
    failPage(g_app.page, error);
    std::fprintf(stderr, "tetstream: %s\n", error.c_str());
    return 0;  // the exported functions keep working: JS still sees the state and the error
  }
  emscripten_set_main_loop(frame, 0, false);
  return 0;
}
