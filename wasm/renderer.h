// WebGL2 renderer (OpenGL ES 3.0, "#version 300 es" shaders): the isosurface lit and shaded
// from a headlight, two-sided (the low-field side has a cool tint, the high-field side a warm
// one), and the domain boundary as a faint translucent hull with its crease edges drawn as lines.
//
// Uploads follow the change lists of the mirrors the worker's deltas keep (geometry_sync.h): while splits stream in,
// only the slots written since the last frame go to the GPU (bufferSubData over runs of nearby slots); a whole buffer
// is sent only after a full extraction (isovalue, field) or when it has to grow (doubling, so rarely). Needs a current
// GL context; everything else about the viewer lives in GL-free files.
#pragma once
#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "colourmap.h"
#include "geometry_sync.h"

namespace tetstream::viewer {

// A GL buffer and how many elements (of the caller's element size) it can hold.
struct GpuBuffer {
  uint32_t id = 0;
  uint32_t capacity = 0;
  uint64_t bytes = 0;  // allocated on the GPU
};

// What went to the GPU, for the stats (tests check that streaming uploads stay partial).
struct UploadStats {
  uint64_t bytes = 0;
  uint32_t full = 0, partial = 0;  // buffer uploads of each kind
  uint32_t grown = 0;              // full uploads because the buffer had to grow (first one too)
};

// The GPU side of a surface (the isosurface, or the slice).
struct SurfaceGpu {
  GpuBuffer positions, normals, colours, indices;  // elements: vertex slots (x3) and triangles
  uint32_t vao = 0;
  int32_t indexCount = 0;
};

// Where a frame's scene is drawn before it is copied to the canvas: at reduced resolution (then
// scaled up), or multisampled (then resolved).
struct OffscreenTarget {
  uint32_t framebuffer = 0, colour = 0, depth = 0;  // renderbuffers
  int width = 0, height = 0, samples = 0;
  uint64_t bytes = 0;
};

struct Renderer {
  // Multisampling: the scene is drawn into `multisampled` with this many samples per pixel and
  // resolved into the canvas, whose own buffer has none (0: drawn straight into the canvas).
  int samples = 0;
  OffscreenTarget reduced, multisampled;
  uint32_t isoProgram = 0, hullProgram = 0, lineProgram = 0, backgroundProgram = 0;
  uint32_t hullVao = 0, lineVao = 0, emptyVao = 0;
  SurfaceGpu iso, slice;
  uint32_t colourMapTexture = 0;                // 256x1 RGBA8, the current colour map
  int colourMapLoaded = -1;                     // the ColourMap in it
  GpuBuffer hullPositions, hullNormals, lines;  // elements: triangles, triangles, segments
  int32_t isoColourBy = -1, isoColourRange = -1, isoUnlit = -1;
  int32_t isoView = -1, isoProj = -1, hullView = -1, hullProj = -1, lineViewProj = -1;
  int32_t hullVertexCount = 0, lineVertexCount = 0;
  UploadStats uploads;
  std::vector<uint32_t> scratch;  // sorted change lists
};

// Compiles shaders and creates buffers. On failure returns false with the GL log in `error`.
bool initRenderer(Renderer& r, std::string& error);

// Draws one clipped-away triangle through every program and state drawScene uses, so that the
// GL implementation compiles its pipelines now (while the dataset downloads) and not at the
// first surface (~0.3 s on SwiftShader).
// reducedToo: also through drawSceneScaled's reduced target (a software GL uses it); the
// multisampled one whenever r.samples is set.
void warmUpRenderer(Renderer& r, bool reducedToo);

// Sends what changed since the mirror's last clearChanges(); the caller clears them afterwards.
void uploadSurface(Renderer& r, const SurfaceMirror& surface);
void uploadSlice(Renderer& r, const SurfaceMirror& slice);  // an empty one hides it
void uploadHull(Renderer& r, const HullMirror& hull);

struct FrameParams {
  glm::mat4 view{1.f}, projection{1.f};
  int framebufferWidth = 1, framebufferHeight = 1;
  bool showBoundary = true;
  bool colourBy = false;  // colour the surface by its colour field (else the two-sided tint)
  float colourMin = 0, colourMax = 1;
  bool showSlice = false;  // the slice, always coloured by the colour field
};

// Loads a colour map into the texture (nothing when it is loaded already).
void setColourMap(Renderer& r, ColourMap map);

// Bytes allocated in the GPU buffers and the offscreen targets (the panel's memory line; the
// colour map texture and the canvas's own buffers are not counted).
uint64_t gpuBufferBytes(const Renderer& r);

// Clears to the background gradient and draws surface, then hull and crease lines.
void drawScene(const Renderer& r, const FrameParams& p);

// drawScene at `scale` (< 1) of the framebuffer's width and height into an offscreen target,
// then scaled up (linear filter) onto the canvas: on a software GL the fragments are most of a
// frame's cost, and that CPU time is taken from refinement. At scale >= 1 drawScene, into the
// multisampled target when r.samples is set (then resolved onto the canvas). The canvas itself
// is single-sampled (a blit cannot resolve into a multisampled one).
void drawSceneScaled(Renderer& r, const FrameParams& p, float scale);

}  // namespace tetstream::viewer
