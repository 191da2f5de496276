#include "renderer.h"

#include <GLES3/gl3.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/type_ptr.hpp>
#include <span>
#include <tuple>

namespace tetstream::viewer {
namespace {

// ---------------------------------------------------------------- shaders
const char* kSurfaceVs = R"(#version 300 es
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in float aColour;  // the colour field (0 where no buffer is bound)
uniform mat4 uView;
uniform mat4 uProj;
out vec3 vPosition;  // view space
out vec3 vNormal;    // view space (uView is rigid, so its 3x3 part transforms normals)
out float vColour;
void main() {
  vec4 p = uView * vec4(aPosition, 1.0);
  vPosition = p.xyz;
  vNormal = mat3(uView) * aNormal;
  vColour = aColour;
  gl_Position = uProj * p;
}
)";

// Headlight shading: a key light above and left of the eye, a weaker fill from the eye itself,
// Blinn-Phong highlights and a little sky/ground ambient. Triangle normals point toward
// increasing field, so a front face is seen from the high side. The low side (the outside of
// the region above the isovalue) gets the warm colour, the high side a cool one. Coloured by a
// field (uColourBy), both sides take the colour map's colour of the interpolated value: the
// 256x1 map texture at the texel centres, (v - lo) / (hi - lo) clamped (colourmap.h).
const char* kSurfaceFs = R"(#version 300 es
precision highp float;
in vec3 vPosition;
in vec3 vNormal;
in float vColour;
uniform bool uColourBy;
uniform vec2 uColourRange;
uniform sampler2D uColourMap;
uniform float uUnlit;  // 0: lit; up to 1: the plain colour (the slice)
out vec4 fragColor;
const vec3 kLowSide = vec3(0.92, 0.56, 0.24);
const vec3 kHighSide = vec3(0.33, 0.55, 0.80);
void main() {
  vec3 faceN = normalize(cross(dFdx(vPosition), dFdy(vPosition)));
  float len = length(vNormal);
  vec3 n = len > 1e-6 ? vNormal / len : faceN;  // isolated surface points carry a zero normal
  if (!gl_FrontFacing) n = -n;
  vec3 v = normalize(-vPosition);
  if (dot(n, v) < 0.0) n = normalize(n - 1.01 * dot(n, v) * v);  // interpolated normal past the silhouette
  vec3 base = gl_FrontFacing ? kHighSide : kLowSide;
  if (uColourBy) {
    float span = uColourRange.y - uColourRange.x;
    float x = span > 0.0 ? clamp((vColour - uColourRange.x) / span, 0.0, 1.0) : 0.5;
    base = texture(uColourMap, vec2((x * 255.0 + 0.5) / 256.0, 0.5)).rgb;
  }
  vec3 key = normalize(vec3(-0.5, 0.7, 0.75));
  float diffuse = 0.72 * max(dot(n, key), 0.0) + 0.26 * max(dot(n, v), 0.0);
  float ambient = 0.08 + 0.08 * (0.5 + 0.5 * n.y);
  float spec = 0.25 * pow(max(dot(n, normalize(key + v)), 0.0), 40.0);
  vec3 color = base * (ambient + diffuse) + vec3(spec);
  fragColor = vec4(mix(color, base * (0.8 + 0.2 * max(dot(n, v), 0.0)), uUnlit), 1.0);
}
)";

// Translucent hull: nearly invisible where it faces the viewer, stronger at grazing angles, so
// the domain's silhouette frames the surface without hiding it. Premultiplied alpha.
const char* kHullFs = R"(#version 300 es
precision highp float;
in vec3 vPosition;
in vec3 vNormal;
out vec4 fragColor;
void main() {
  vec3 n = normalize(vNormal);
  vec3 v = normalize(-vPosition);
  float grazing = 1.0 - abs(dot(n, v));
  float a = 0.035 + 0.22 * grazing * grazing * grazing;
  fragColor = vec4(vec3(0.75, 0.82, 0.95) * a, a);
}
)";

const char* kLineVs = R"(#version 300 es
layout(location = 0) in vec3 aPosition;
uniform mat4 uViewProj;
void main() { gl_Position = uViewProj * vec4(aPosition, 1.0); }
)";

const char* kLineFs = R"(#version 300 es
precision mediump float;
out vec4 fragColor;
void main() { fragColor = vec4(vec3(0.70, 0.76, 0.86) * 0.55, 0.55); }
)";

// One triangle covering the screen, no vertex buffer: a vertical gradient.
const char* kBackgroundVs = R"(#version 300 es
out float vY;
void main() {
  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2)) * 2.0 - 1.0;
  vY = 0.5 * p.y + 0.5;
  gl_Position = vec4(p, 0.999, 1.0);
}
)";

const char* kBackgroundFs = R"(#version 300 es
precision mediump float;
in float vY;
out vec4 fragColor;
void main() { fragColor = vec4(mix(vec3(0.07, 0.08, 0.10), vec3(0.23, 0.26, 0.31), vY), 1.0); }
)";

// ---------------------------------------------------------------- helpers
// Shaders are compiled and linked without asking how it went: in WebGL each such question waits
// for the GPU process to finish everything queued before it (on SwiftShader 2-30 ms each, twelve
// of them on the way to the first picture). linkStatus() asks once per program after all of them
// are queued, and reads the logs only when a link failed.
GLuint compile(GLenum type, const char* src) {
  GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &src, nullptr);
  glCompileShader(s);
  return s;
}

struct Program {
  GLuint program, vertex, fragment;
};

Program link(const char* vs, const char* fs) {
  Program p{glCreateProgram(), compile(GL_VERTEX_SHADER, vs), compile(GL_FRAGMENT_SHADER, fs)};
  glAttachShader(p.program, p.vertex);
  glAttachShader(p.program, p.fragment);
  glLinkProgram(p.program);
  return p;
}

// The program, or 0 with what went wrong in `error` (its shaders' logs first, as a failed
// compile is the usual cause of a failed link). Its shaders are released either way.
GLuint linkStatus(const Program& p, std::string& error) {
  GLint ok = 0;
  glGetProgramiv(p.program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048];
    for (const auto& [shader, what] :
         {std::pair{p.vertex, "vertex shader: "}, std::pair{p.fragment, "fragment shader: "}}) {
      GLint compiled = 0;
      glGetShaderiv(shader, GL_COMPILE_STATUS, &compiled);
      if (compiled) continue;
      log[0] = 0;
      glGetShaderInfoLog(shader, sizeof log, nullptr, log);
      error += std::string(what) + log;
    }
    log[0] = 0;
    glGetProgramInfoLog(p.program, sizeof log, nullptr, log);
    error += std::string("program: ") + log;
  }
  glDeleteShader(p.vertex);
  glDeleteShader(p.fragment);
  if (!ok) glDeleteProgram(p.program);
  return ok ? p.program : 0;
}

void bindFloat3(GLuint location, GLuint buffer) {
  glBindBuffer(GL_ARRAY_BUFFER, buffer);
  glEnableVertexAttribArray(location);
  glVertexAttribPointer(location, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
}

// Changed slots closer than this are sent in one bufferSubData (re-sending a few unchanged
// elements is cheaper than another call); past kMaxRuns calls the bounding range goes at once.
constexpr uint32_t kRunGap = 32;
constexpr size_t kMaxRuns = 256;

// Brings `buf` (bound to `target` by the caller's VAO state) up to date with `count` elements
// of `elemBytes` bytes at `data`: everything when `full` or when the buffer has to grow,
// otherwise the runs covering `changed` (slots >= count are ignored).
void sync(Renderer& r, GLenum target, GpuBuffer& buf, const void* data, uint32_t count, uint32_t elemBytes,
          std::span<const uint32_t> changed, bool full) {
  const auto* bytes = static_cast<const uint8_t*>(data);
  glBindBuffer(target, buf.id);
  if (count > buf.capacity) {
    buf.capacity = std::max(2 * count, 4096u);  // doubling: a whole upload is rare
    glBufferData(target, GLsizeiptr(size_t(buf.capacity) * elemBytes), nullptr, GL_DYNAMIC_DRAW);
    buf.bytes = uint64_t(buf.capacity) * elemBytes;
    ++r.uploads.grown;
    full = true;
  }
  if (full) {
    if (count == 0) return;  // nothing to send (a cleared hull before the base)
    glBufferSubData(target, 0, GLsizeiptr(size_t(count) * elemBytes), bytes);
    r.uploads.bytes += uint64_t(count) * elemBytes;
    ++r.uploads.full;
    return;
  }
  std::vector<uint32_t>& slots = r.scratch;
  slots.clear();
  for (uint32_t v : changed)
    if (v < count) slots.push_back(v);
  if (slots.empty()) return;
  std::sort(slots.begin(), slots.end());
  slots.erase(std::unique(slots.begin(), slots.end()), slots.end());
  size_t runs = 1;
  for (size_t i = 1; i < slots.size(); ++i) runs += slots[i] - slots[i - 1] > kRunGap;
  auto send = [&](uint32_t begin, uint32_t end) {
    const size_t offset = size_t(begin) * elemBytes, size = size_t(end - begin) * elemBytes;
    glBufferSubData(target, GLintptr(offset), GLsizeiptr(size), bytes + offset);
    r.uploads.bytes += size;
  };
  if (runs > kMaxRuns) {
    send(slots.front(), slots.back() + 1);
  } else {
    uint32_t begin = slots[0], end = slots[0] + 1;
    for (size_t i = 1; i < slots.size(); ++i) {
      if (slots[i] - (end - 1) > kRunGap) {
        send(begin, end);
        begin = slots[i];
      }
      end = slots[i] + 1;
    }
    send(begin, end);
  }
  ++r.uploads.partial;
}

}  // namespace

uint64_t gpuBufferBytes(const Renderer& r) {
  uint64_t n = 0;
  for (const GpuBuffer* b :
       {&r.iso.positions, &r.iso.normals, &r.iso.colours, &r.iso.indices, &r.slice.positions, &r.slice.normals,
        &r.slice.colours, &r.slice.indices, &r.hullPositions, &r.hullNormals, &r.lines})
    n += b->bytes;
  return n + r.reduced.bytes + r.multisampled.bytes;
}

bool initRenderer(Renderer& r, std::string& error) {
  const Program programs[4] = {link(kSurfaceVs, kSurfaceFs), link(kSurfaceVs, kHullFs), link(kLineVs, kLineFs),
                               link(kBackgroundVs, kBackgroundFs)};
  r.isoProgram = linkStatus(programs[0], error);
  r.hullProgram = linkStatus(programs[1], error);
  r.lineProgram = linkStatus(programs[2], error);
  r.backgroundProgram = linkStatus(programs[3], error);
  if (!r.isoProgram || !r.hullProgram || !r.lineProgram || !r.backgroundProgram) return false;
  r.isoView = glGetUniformLocation(r.isoProgram, "uView");
  r.isoProj = glGetUniformLocation(r.isoProgram, "uProj");
  r.isoColourBy = glGetUniformLocation(r.isoProgram, "uColourBy");
  r.isoColourRange = glGetUniformLocation(r.isoProgram, "uColourRange");
  r.isoUnlit = glGetUniformLocation(r.isoProgram, "uUnlit");
  glUseProgram(r.isoProgram);
  glUniform1i(glGetUniformLocation(r.isoProgram, "uColourMap"), 0);  // texture unit 0
  glUseProgram(0);
  glGenTextures(1, &r.colourMapTexture);
  glBindTexture(GL_TEXTURE_2D, r.colourMapTexture);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glBindTexture(GL_TEXTURE_2D, 0);
  r.colourMapLoaded = -1;
  setColourMap(r, ColourMap::Viridis);
  r.hullView = glGetUniformLocation(r.hullProgram, "uView");
  r.hullProj = glGetUniformLocation(r.hullProgram, "uProj");
  r.lineViewProj = glGetUniformLocation(r.lineProgram, "uViewProj");

  for (GpuBuffer* b : {&r.hullPositions, &r.hullNormals, &r.lines}) glGenBuffers(1, &b->id);
  for (SurfaceGpu* g : {&r.iso, &r.slice}) {
    for (GpuBuffer* b : {&g->positions, &g->normals, &g->colours, &g->indices}) glGenBuffers(1, &b->id);
    glGenVertexArrays(1, &g->vao);
    glBindVertexArray(g->vao);
    bindFloat3(0, g->positions.id);
    bindFloat3(1, g->normals.id);
    glBindBuffer(GL_ARRAY_BUFFER, g->colours.id);
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 1, GL_FLOAT, GL_FALSE, 0, nullptr);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g->indices.id);  // recorded in the VAO
  }

  glGenVertexArrays(1, &r.hullVao);
  glBindVertexArray(r.hullVao);
  bindFloat3(0, r.hullPositions.id);
  bindFloat3(1, r.hullNormals.id);

  glGenVertexArrays(1, &r.lineVao);
  glBindVertexArray(r.lineVao);
  bindFloat3(0, r.lines.id);

  glGenVertexArrays(1, &r.emptyVao);
  glBindVertexArray(0);
  if (GLenum e = glGetError(); e != GL_NO_ERROR) {
    error = "GL error " + std::to_string(e) + " while creating the renderer's buffers";
    return false;
  }
  return true;
}

void warmUpRenderer(Renderer& r, bool reducedToo) {
  const float tri[9] = {0, 0, 2, 1, 0, 2, 0, 1, 2};  // z = 2: outside the clip volume
  const uint32_t indices[3] = {0, 1, 2};
  glBindVertexArray(0);
  for (GpuBuffer* b : {&r.iso.positions, &r.iso.normals, &r.iso.colours, &r.hullPositions, &r.hullNormals, &r.lines}) {
    glBindBuffer(GL_ARRAY_BUFFER, b->id);
    glBufferData(GL_ARRAY_BUFFER, sizeof tri, tri, GL_DYNAMIC_DRAW);
    b->capacity = 0;  // the first real upload allocates again
  }
  glBindVertexArray(r.iso.vao);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, sizeof indices, indices, GL_DYNAMIC_DRAW);
  r.iso.indices.capacity = 0;
  glBindVertexArray(0);
  r.iso.indexCount = 3;
  r.hullVertexCount = 3;
  r.lineVertexCount = 2;
  drawScene(r, FrameParams{});
  // The offscreen targets' formats and the blits compile pipelines of their own (the first real
  // frame allocates the targets again at its size).
  FrameParams tiny;
  tiny.framebufferWidth = tiny.framebufferHeight = 2;
  if (reducedToo) drawSceneScaled(r, tiny, 0.5f);
  if (r.samples > 0) drawSceneScaled(r, tiny, 1.f);
  r.iso.indexCount = r.hullVertexCount = r.lineVertexCount = 0;
}

namespace {
void uploadTo(Renderer& r, SurfaceGpu& g, const SurfaceMirror& s) {
  const bool full = s.fullUploadNeeded();
  glBindVertexArray(0);  // keep the VAO's element binding untouched by the array uploads
  sync(r, GL_ARRAY_BUFFER, g.positions, s.positions().data(), s.vertexSlotCount(), 12, s.changedVertices(), full);
  sync(r, GL_ARRAY_BUFFER, g.normals, s.normals().data(), s.vertexSlotCount(), 12, s.changedVertices(), full);
  sync(r, GL_ARRAY_BUFFER, g.colours, s.colours().data(), s.vertexSlotCount(), 4, s.changedVertices(), full);
  glBindVertexArray(g.vao);  // the element buffer is bound through the VAO
  sync(r, GL_ELEMENT_ARRAY_BUFFER, g.indices, s.indices().data(), s.triangleCount(), 12, s.changedTriangles(), full);
  glBindVertexArray(0);
  g.indexCount = int32_t(3 * s.triangleCount());
}
}  // namespace

void uploadSurface(Renderer& r, const SurfaceMirror& s) { uploadTo(r, r.iso, s); }
void uploadSlice(Renderer& r, const SurfaceMirror& s) { uploadTo(r, r.slice, s); }

void uploadHull(Renderer& r, const HullMirror& h) {
  const bool full = h.fullUploadNeeded();
  glBindVertexArray(0);
  sync(r, GL_ARRAY_BUFFER, r.hullPositions, h.trianglePositions().data(), h.triangleCount(), 36, h.changedTriangles(),
       full);
  sync(r, GL_ARRAY_BUFFER, r.hullNormals, h.triangleNormals().data(), h.triangleCount(), 36, h.changedTriangles(),
       full);
  sync(r, GL_ARRAY_BUFFER, r.lines, h.lineVertices().data(), h.lineCount(), 24, h.changedLines(), full);
  r.hullVertexCount = int32_t(3 * h.triangleCount());
  r.lineVertexCount = int32_t(2 * h.lineCount());
}

void setColourMap(Renderer& r, ColourMap map) {
  if (r.colourMapLoaded == int(map)) return;
  const float(*t)[3] = colourMapTable(map);
  uint8_t texels[kColourMapSize * 4];
  for (int i = 0; i < kColourMapSize; ++i) {
    for (int k = 0; k < 3; ++k) texels[4 * i + k] = uint8_t(std::lround(255.f * std::clamp(t[i][k], 0.f, 1.f)));
    texels[4 * i + 3] = 255;
  }
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, r.colourMapTexture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, kColourMapSize, 1, 0, GL_RGBA, GL_UNSIGNED_BYTE, texels);
  glBindTexture(GL_TEXTURE_2D, 0);
  r.colourMapLoaded = int(map);
}

void drawScene(const Renderer& r, const FrameParams& p) {
  glViewport(0, 0, p.framebufferWidth, p.framebufferHeight);
  glDisable(GL_SCISSOR_TEST);
  glDepthMask(GL_TRUE);
  glClearDepthf(1.f);
  glClear(GL_DEPTH_BUFFER_BIT);

  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glDisable(GL_DEPTH_TEST);
  glUseProgram(r.backgroundProgram);
  glBindVertexArray(r.emptyVao);
  glDrawArrays(GL_TRIANGLES, 0, 3);

  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  const bool slice = p.showSlice && r.slice.indexCount > 0;
  if (r.iso.indexCount > 0 || slice) {
    glUseProgram(r.isoProgram);
    glUniformMatrix4fv(r.isoView, 1, GL_FALSE, glm::value_ptr(p.view));
    glUniformMatrix4fv(r.isoProj, 1, GL_FALSE, glm::value_ptr(p.projection));
    glUniform2f(r.isoColourRange, p.colourMin, p.colourMax);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, r.colourMapTexture);
  }
  if (r.iso.indexCount > 0) {
    glUniform1i(r.isoColourBy, p.colourBy ? 1 : 0);
    glUniform1f(r.isoUnlit, 0.f);
    glBindVertexArray(r.iso.vao);
    glDrawElements(GL_TRIANGLES, r.iso.indexCount, GL_UNSIGNED_INT, nullptr);
  }
  if (slice) {
    // Mostly unlit, so the colours read as the map's; pushed back a little in depth so the
    // isosurface wins where the two meet.
    glUniform1i(r.isoColourBy, 1);
    glUniform1f(r.isoUnlit, 0.75f);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.f, 1.f);
    glBindVertexArray(r.slice.vao);
    glDrawElements(GL_TRIANGLES, r.slice.indexCount, GL_UNSIGNED_INT, nullptr);
    glDisable(GL_POLYGON_OFFSET_FILL);
  }

  if (p.showBoundary) {
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);  // premultiplied
    glDepthMask(GL_FALSE);
    if (r.lineVertexCount > 0) {
      glm::mat4 vp = p.projection * p.view;
      glUseProgram(r.lineProgram);
      glUniformMatrix4fv(r.lineViewProj, 1, GL_FALSE, glm::value_ptr(vp));
      glBindVertexArray(r.lineVao);
      glDrawArrays(GL_LINES, 0, r.lineVertexCount);
    }
    if (r.hullVertexCount > 0) {
      glUseProgram(r.hullProgram);
      glUniformMatrix4fv(r.hullView, 1, GL_FALSE, glm::value_ptr(p.view));
      glUniformMatrix4fv(r.hullProj, 1, GL_FALSE, glm::value_ptr(p.projection));
      glBindVertexArray(r.hullVao);
      glDrawArrays(GL_TRIANGLES, 0, r.hullVertexCount);
    }
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
  }
  glBindVertexArray(0);
  glUseProgram(0);
}

namespace {
// Binds t as the framebuffer, its renderbuffers (re)allocated for this size and sample count.
void bindTarget(OffscreenTarget& t, int width, int height, int samples) {
  if (!t.framebuffer) {
    glGenFramebuffers(1, &t.framebuffer);
    glGenRenderbuffers(1, &t.colour);
    glGenRenderbuffers(1, &t.depth);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, t.framebuffer);
  if (t.width == width && t.height == height && t.samples == samples) return;
  for (const auto& [buffer, format, attachment] :
       {std::tuple{t.colour, GLenum(GL_RGBA8), GLenum(GL_COLOR_ATTACHMENT0)},
        std::tuple{t.depth, GLenum(GL_DEPTH_COMPONENT24), GLenum(GL_DEPTH_ATTACHMENT)}}) {
    glBindRenderbuffer(GL_RENDERBUFFER, buffer);
    if (samples > 0)
      glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, format, width, height);
    else
      glRenderbufferStorage(GL_RENDERBUFFER, format, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, attachment, GL_RENDERBUFFER, buffer);
  }
  // No glCheckFramebufferStatus: in WebGL it waits for the GPU process to catch up (hundreds of
  // ms behind a SwiftShader frame), and RGBA8 colour with DEPTH_COMPONENT24 depth of equal
  // sizes and sample counts (4 at most, which every WebGL 2 allows) is complete by the GLES 3.0
  // spec.
  t.width = width;
  t.height = height;
  t.samples = samples;
  t.bytes = uint64_t(width) * uint64_t(height) * uint64_t(std::max(samples, 1)) * 8;  // 4 bytes colour, 4 depth
}
}  // namespace

void drawSceneScaled(Renderer& r, const FrameParams& p, float scale) {
  const int w = std::max(1, int(std::lround(p.framebufferWidth * scale)));
  const int h = std::max(1, int(std::lround(p.framebufferHeight * scale)));
  const bool reduced = scale < 1.f && (w != p.framebufferWidth || h != p.framebufferHeight);
  if (!reduced && r.samples == 0) return drawScene(r, p);
  OffscreenTarget& t = reduced ? r.reduced : r.multisampled;
  bindTarget(t, w, h, reduced ? 0 : r.samples);
  FrameParams offscreen = p;
  offscreen.framebufferWidth = w;
  offscreen.framebufferHeight = h;
  drawScene(r, offscreen);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, t.framebuffer);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glDisable(GL_SCISSOR_TEST);
  // Scaled up with a linear filter, or resolved (a multisampled source needs equal sizes).
  glBlitFramebuffer(0, 0, w, h, 0, 0, p.framebufferWidth, p.framebufferHeight, GL_COLOR_BUFFER_BIT,
                    reduced ? GL_LINEAR : GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glViewport(0, 0, p.framebufferWidth, p.framebufferHeight);
}

}  // namespace tetstream::viewer
