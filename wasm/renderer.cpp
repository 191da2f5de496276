#include "renderer.h"

#include <GLES3/gl3.h>

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

void upload(GLenum target, GLuint buffer, const void* data, size_t bytes) {
  glBindBuffer(target, buffer);
  glBufferData(target, GLsizeiptr(bytes), bytes ? data : nullptr, GL_STATIC_DRAW);
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

  glGenBuffers(3, r.isoBuffers);
  glGenVertexArrays(1, &r.isoVao);
  glBindVertexArray(r.isoVao);
  bindFloat3(0, r.isoBuffers[0]);
  bindFloat3(1, r.isoBuffers[1]);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, r.isoBuffers[2]);  // recorded in the VAO

  glGenBuffers(2, r.hullBuffers);
  glGenVertexArrays(1, &r.hullVao);
  glBindVertexArray(r.hullVao);
  bindFloat3(0, r.hullBuffers[0]);
  bindFloat3(1, r.hullBuffers[1]);

  glGenBuffers(1, &r.lineBuffer);
  glGenVertexArrays(1, &r.lineVao);
  glBindVertexArray(r.lineVao);
  bindFloat3(0, r.lineBuffer);

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
  glDeleteBuffers(3, r.isoBuffers);
  glDeleteBuffers(2, r.hullBuffers);
  glDeleteBuffers(1, &r.lineBuffer);
  GLuint vaos[4] = {r.isoVao, r.hullVao, r.lineVao, r.emptyVao};
  glDeleteVertexArrays(4, vaos);
  r = Renderer{};
}

void uploadSurface(Renderer& r, const IsoSurface& s) {
  glBindVertexArray(0);  // keep the VAO's element binding untouched by the upload below
  upload(GL_ARRAY_BUFFER, r.isoBuffers[0], s.positions.data(), s.positions.size() * sizeof(float));
  upload(GL_ARRAY_BUFFER, r.isoBuffers[1], s.normals.data(), s.normals.size() * sizeof(float));
  glBindVertexArray(r.isoVao);
  upload(GL_ELEMENT_ARRAY_BUFFER, r.isoBuffers[2], s.indices.data(), s.indices.size() * sizeof(uint32_t));
  glBindVertexArray(0);
  r.isoIndexCount = int32_t(s.indices.size());
}

void uploadBoundary(Renderer& r, const BoundaryMesh& b) {
  glBindVertexArray(0);
  upload(GL_ARRAY_BUFFER, r.hullBuffers[0], b.positions.data(), b.positions.size() * sizeof(float));
  upload(GL_ARRAY_BUFFER, r.hullBuffers[1], b.normals.data(), b.normals.size() * sizeof(float));
  upload(GL_ARRAY_BUFFER, r.lineBuffer, b.featureLines.data(), b.featureLines.size() * sizeof(float));
  r.hullVertexCount = int32_t(b.positions.size() / 3);
  r.lineVertexCount = int32_t(b.featureLines.size() / 3);
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
