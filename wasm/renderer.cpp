#include "renderer.h"

#include <GLES3/gl3.h>

#include <algorithm>
#include <span>

#include <glm/gtc/type_ptr.hpp>

namespace tetstream::viewer {
namespace {

// ---------------------------------------------------------------- shaders
const char* kSurfaceVs = R"(#version 300 es
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
uniform mat4 uView;
uniform mat4 uProj;
out vec3 vPosition;  // view space
out vec3 vNormal;    // view space (uView is rigid, so its 3x3 part transforms normals)
void main() {
  vec4 p = uView * vec4(aPosition, 1.0);
  vPosition = p.xyz;
  vNormal = mat3(uView) * aNormal;
  gl_Position = uProj * p;
}
)";

// Headlight shading: a key light above and left of the eye, a weaker fill from the eye itself,
// Blinn-Phong highlights and a little sky/ground ambient. Triangle normals point toward
// increasing field, so a front face is seen from the high side. The low side (the outside of
// the region above the isovalue) gets the warm colour, the high side a cool one.
const char* kSurfaceFs = R"(#version 300 es
precision highp float;
in vec3 vPosition;
in vec3 vNormal;
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
  vec3 key = normalize(vec3(-0.5, 0.7, 0.75));
  float diffuse = 0.72 * max(dot(n, key), 0.0) + 0.26 * max(dot(n, v), 0.0);
  float ambient = 0.08 + 0.08 * (0.5 + 0.5 * n.y);
  float spec = 0.25 * pow(max(dot(n, normalize(key + v)), 0.0), 40.0);
  vec3 color = base * (ambient + diffuse) + vec3(spec);
  fragColor = vec4(color, 1.0);
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
GLuint compile(GLenum type, const char* src, std::string& error) {
  GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &src, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    error += std::string(type == GL_VERTEX_SHADER ? "vertex" : "fragment") + " shader: " + log;
    glDeleteShader(s);
    return 0;
  }
  return s;
}

GLuint link(const char* vs, const char* fs, std::string& error) {
  GLuint v = compile(GL_VERTEX_SHADER, vs, error), f = compile(GL_FRAGMENT_SHADER, fs, error);
  if (!v || !f) {
    glDeleteShader(v);
    glDeleteShader(f);
    return 0;
  }
  GLuint p = glCreateProgram();
  glAttachShader(p, v);
  glAttachShader(p, f);
  glLinkProgram(p);
  glDeleteShader(v);
  glDeleteShader(f);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetProgramInfoLog(p, sizeof log, nullptr, log);
    error += std::string("program: ") + log;
    glDeleteProgram(p);
    return 0;
  }
  return p;
}

std::string glString(GLenum name) {
  const GLubyte* s = glGetString(name);
  return s ? reinterpret_cast<const char*>(s) : "?";
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
    full = true;
  }
  if (full) {
    if (count) glBufferSubData(target, 0, GLsizeiptr(size_t(count) * elemBytes), bytes);
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

bool initRenderer(Renderer& r, std::string& info, std::string& error) {
  info = "GL_VERSION: " + glString(GL_VERSION) + " | GLSL: " + glString(GL_SHADING_LANGUAGE_VERSION) +
         " | GL_RENDERER: " + glString(GL_RENDERER);
  r.isoProgram = link(kSurfaceVs, kSurfaceFs, error);
  r.hullProgram = link(kSurfaceVs, kHullFs, error);
  r.lineProgram = link(kLineVs, kLineFs, error);
  r.backgroundProgram = link(kBackgroundVs, kBackgroundFs, error);
  if (!r.isoProgram || !r.hullProgram || !r.lineProgram || !r.backgroundProgram) return false;
  r.isoView = glGetUniformLocation(r.isoProgram, "uView");
  r.isoProj = glGetUniformLocation(r.isoProgram, "uProj");
  r.hullView = glGetUniformLocation(r.hullProgram, "uView");
  r.hullProj = glGetUniformLocation(r.hullProgram, "uProj");
  r.lineViewProj = glGetUniformLocation(r.lineProgram, "uViewProj");

  for (GpuBuffer* b : {&r.isoPositions, &r.isoNormals, &r.isoIndices, &r.hullPositions, &r.hullNormals, &r.lines})
    glGenBuffers(1, &b->id);
  glGenVertexArrays(1, &r.isoVao);
  glBindVertexArray(r.isoVao);
  bindFloat3(0, r.isoPositions.id);
  bindFloat3(1, r.isoNormals.id);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, r.isoIndices.id);  // recorded in the VAO

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

void destroyRenderer(Renderer& r) {
  glDeleteProgram(r.isoProgram);
  glDeleteProgram(r.hullProgram);
  glDeleteProgram(r.lineProgram);
  glDeleteProgram(r.backgroundProgram);
  for (GpuBuffer* b : {&r.isoPositions, &r.isoNormals, &r.isoIndices, &r.hullPositions, &r.hullNormals, &r.lines})
    glDeleteBuffers(1, &b->id);
  GLuint vaos[4] = {r.isoVao, r.hullVao, r.lineVao, r.emptyVao};
  glDeleteVertexArrays(4, vaos);
  r = Renderer{};
}

void warmUpRenderer(Renderer& r) {
  const float tri[9] = {0, 0, 2, 1, 0, 2, 0, 1, 2};  // z = 2: outside the clip volume
  const uint32_t indices[3] = {0, 1, 2};
  glBindVertexArray(0);
  for (GpuBuffer* b : {&r.isoPositions, &r.isoNormals, &r.hullPositions, &r.hullNormals, &r.lines}) {
    glBindBuffer(GL_ARRAY_BUFFER, b->id);
    glBufferData(GL_ARRAY_BUFFER, sizeof tri, tri, GL_DYNAMIC_DRAW);
    b->capacity = 0;  // the first real upload allocates again
  }
  glBindVertexArray(r.isoVao);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, sizeof indices, indices, GL_DYNAMIC_DRAW);
  r.isoIndices.capacity = 0;
  glBindVertexArray(0);
  r.isoIndexCount = 3;
  r.hullVertexCount = 3;
  r.lineVertexCount = 2;
  drawScene(r, FrameParams{});
  r.isoIndexCount = r.hullVertexCount = r.lineVertexCount = 0;
}

void uploadSurface(Renderer& r, const IncrementalIsosurface& s) {
  const bool full = s.fullUploadNeeded();
  glBindVertexArray(0);  // keep the VAO's element binding untouched by the array uploads
  sync(r, GL_ARRAY_BUFFER, r.isoPositions, s.positions().data(), s.vertexSlotCount(), 12, s.changedVertices(), full);
  sync(r, GL_ARRAY_BUFFER, r.isoNormals, s.normals().data(), s.vertexSlotCount(), 12, s.changedVertices(), full);
  glBindVertexArray(r.isoVao);  // the element buffer is bound through the VAO
  sync(r, GL_ELEMENT_ARRAY_BUFFER, r.isoIndices, s.indices().data(), s.triangleCount(), 12, s.changedTriangles(), full);
  glBindVertexArray(0);
  r.isoIndexCount = int32_t(3 * s.triangleCount());
}

void uploadHull(Renderer& r, const HullTracker& h) {
  const bool full = h.fullUploadNeeded();
  glBindVertexArray(0);
  sync(r, GL_ARRAY_BUFFER, r.hullPositions, h.trianglePositions().data(), h.triangleCount(), 36, h.changedTriangles(), full);
  sync(r, GL_ARRAY_BUFFER, r.hullNormals, h.triangleNormals().data(), h.triangleCount(), 36, h.changedTriangles(), full);
  sync(r, GL_ARRAY_BUFFER, r.lines, h.lineVertices().data(), h.lineCount(), 24, h.changedLines(), full);
  r.hullVertexCount = int32_t(3 * h.triangleCount());
  r.lineVertexCount = int32_t(2 * h.lineCount());
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
  if (r.isoIndexCount > 0) {
    glUseProgram(r.isoProgram);
    glUniformMatrix4fv(r.isoView, 1, GL_FALSE, glm::value_ptr(p.view));
    glUniformMatrix4fv(r.isoProj, 1, GL_FALSE, glm::value_ptr(p.projection));
    glBindVertexArray(r.isoVao);
    glDrawElements(GL_TRIANGLES, r.isoIndexCount, GL_UNSIGNED_INT, nullptr);
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

}  // namespace tetstream::viewer
