// The page's viewer program: its state, shared by the Emscripten platform (platform.cpp: canvas,
// input, frames) and the exported functions (api.cpp; docs/js-api.md). The dataset and its model
// live in the refinement worker (worker_api.cpp); the page holds what it shows (page_state.h).
// Neither this header nor page_state.h includes Emscripten.
#pragma once
#include <GLES3/gl3.h>

#include <string>

#include "camera.h"
#include "page_state.h"
#include "renderer.h"

struct GLFWwindow;

namespace tetstream::viewer {

// The canvas and its WebGL 2 context.
struct Canvas {
  GLFWwindow* window = nullptr;
  std::string platformError;  // set when WebGL 2 / GLFW could not start; sticky
  bool softwareGl = false;    // SwiftShader & co: drawn without multisampling, reduced while refining
  int width = 0, height = 0;  // canvas size in device pixels (= GLFW window and framebuffer size)
  double pixelRatio = 1;      // device pixels per CSS pixel
  float uiScale = 1;
};

// The camera and who placed it.
struct CameraControl {
  OrbitCamera camera;
  bool moved = false;   // by the user since the last framing; if not, a resize re-frames
  bool pinned = false;  // set by the page (a shared link): the framing keeps it
};

// The mouse drag under way.
struct Drag {
  int button = -1;     // mouse button that started a camera drag, -1 when none
  bool slice = false;  // the drag moves the slice (shift + left drag)
  double lastX = 0, lastY = 0;
};

// When to draw, and the work slices between frames.
struct FramePacing {
  int redrawFrames = 2;       // frames still to draw; 0 = idle, nothing changed
  GLsync gpuFence = nullptr;  // after the last drawn frame: signalled once the GPU has done it
  double fenceSince = 0;
  double lastFrameStart = -1;     // emscripten_get_now() of the previous frame callback
  double lastDrawStart = -1;      // ... of the previous frame that drew
  bool captureRequested = false;  // the page wants the next drawn frame (screenshot)
  bool reducedShown = false;      // the last drawn frame's scene was drawn at reduced resolution
};

struct App {
  PageState page;
  OrbitCamera cameraSent;  // the camera the worker last heard of (sendCamera)
  double cameraSentMs = -1e9;
  Renderer renderer;
  Canvas canvas;
  CameraControl view;
  Drag drag;
  FramePacing pacing;
};

extern App g_app;

// Draws the next `frames` frames (something changed).
void requestRedraw(int frames = 2);
// Tells the page's script that a command for the worker is waiting (takeCommand), when one is.
void sendCommands();
// Passes a pause or resume asked for in the panel on to the page (Module.onPauseChange).
void notifyPause();

}  // namespace tetstream::viewer
