// WebGL2 renderer (OpenGL ES 3.0, "#version 300 es" shaders): the isosurface lit and shaded
// from a headlight, two-sided (the low-field side has a cool tint, the high-field side a warm
// one), and the domain boundary as a faint translucent hull with its crease edges drawn as lines.
// Buffers are uploaded only when the viewer state says the surface or the level changed.
// Needs a current GL context; everything else about the viewer lives in GL-free files.
#pragma once
#include <cstdint>
#include <string>

#include <glm/glm.hpp>

#include "isosurface.h"
#include "viewer_state.h"

namespace tetstream::viewer {

struct Renderer {
  uint32_t isoProgram = 0, hullProgram = 0, lineProgram = 0, backgroundProgram = 0;
  uint32_t isoVao = 0, isoBuffers[3] = {};  // positions, normals, indices
  uint32_t hullVao = 0, hullBuffers[2] = {};
  uint32_t lineVao = 0, lineBuffer = 0;
  uint32_t emptyVao = 0;
  int32_t isoView = -1, isoProj = -1, hullView = -1, hullProj = -1, lineViewProj = -1;
  int32_t isoIndexCount = 0, hullVertexCount = 0, lineVertexCount = 0;
};

// Compiles shaders and creates buffers. On failure returns false with the GL log in `error`.
// `info` receives GL_VERSION, GL_SHADING_LANGUAGE_VERSION and GL_RENDERER for the console.
bool initRenderer(Renderer& r, std::string& info, std::string& error);
void destroyRenderer(Renderer& r);

void uploadSurface(Renderer& r, const IsoSurface& surface);
void uploadBoundary(Renderer& r, const BoundaryMesh& boundary);

struct FrameParams {
  glm::mat4 view{1.f}, projection{1.f};
  int framebufferWidth = 1, framebufferHeight = 1;
  bool showBoundary = true;
};

// Clears to the background gradient and draws surface, then hull and crease lines.
void drawScene(const Renderer& r, const FrameParams& p);

}  // namespace tetstream::viewer
