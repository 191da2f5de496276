// Dear ImGui's OpenGL backend asks WebGL questions that wait for the GPU process to finish
// everything queued before them: before it draws the panel it reads back the viewport, the
// scissor box and the six blend settings (to set them again after), and once, as it starts, it
// asks each of its shaders how the compile went and its program how the link went. Measured in
// headless Chromium (SwiftShader, 2 cores): 7-9 such waits a frame, 0.5-3 ms each once the GPU
// process is idle, one first frame waiting 488 ms while SwiftShader built its pipelines, and
// ~45 ms for the shader questions in the first frame. The backend's file is compiled with these
// three functions renamed to the ones below (viewer.cmake), which answer without asking where
// the viewer knows the answer, and ask otherwise.
#include <GLES3/gl3.h>
#include <emscripten/html5.h>

// drawScene() sets everything it draws with at the start of each frame, so the values the
// backend sets back after the panel need only be valid: the whole drawing buffer, and the
// viewer's own blending (premultiplied alpha, renderer.cpp).
extern "C" void tetstreamImGuiGetIntegerv(GLenum name, GLint* data) {
  switch (name) {
    case GL_VIEWPORT:
    case GL_SCISSOR_BOX: {
      int width = 0, height = 0;  // (the drawing buffer's size is known in the page)
      emscripten_webgl_get_drawing_buffer_size(emscripten_webgl_get_current_context(), &width, &height);
      data[0] = 0;
      data[1] = 0;
      data[2] = width;
      data[3] = height;
      return;
    }
    case GL_BLEND_SRC_RGB:
    case GL_BLEND_SRC_ALPHA: *data = GL_ONE; return;
    case GL_BLEND_DST_RGB:
    case GL_BLEND_DST_ALPHA: *data = GL_ONE_MINUS_SRC_ALPHA; return;
    case GL_BLEND_EQUATION_RGB:
    case GL_BLEND_EQUATION_ALPHA: *data = GL_FUNC_ADD; return;
    default: glGetIntegerv(name, data);
  }
}

// A shader is taken as compiled, without a log: the backend's program, whose link status is
// still asked, fails to link if one did not compile, and the backend then prints its log.
extern "C" void tetstreamImGuiGetShaderiv(GLuint shader, GLenum name, GLint* data) {
  if (name == GL_COMPILE_STATUS)
    *data = GL_TRUE;
  else if (name == GL_INFO_LOG_LENGTH)
    *data = 0;
  else
    glGetShaderiv(shader, name, data);
}

// The log of a program found linked is not read (the backend prints any log it gets).
extern "C" void tetstreamImGuiGetProgramiv(GLuint program, GLenum name, GLint* data) {
  static GLuint linked = 0;  // the last program asked about whose link succeeded
  if (name == GL_INFO_LOG_LENGTH && program == linked) {
    *data = 0;
    return;
  }
  glGetProgramiv(program, name, data);
  if (name == GL_LINK_STATUS) linked = *data ? program : 0;
}
