// Dear ImGui's OpenGL backend reads back the GL state before it draws the panel and sets it again
// after (ImGui_ImplOpenGL3_RenderDrawData). In WebGL most of it is answered in the page, but the
// viewport, the scissor box and the six blend settings each go to the GPU process and wait for its
// answer: a wait for everything queued before, that is for the frame just drawn. Measured in
// headless Chromium (SwiftShader, 2 cores): 7-9 such waits a frame, 0.5-3 ms each once the GPU
// process is idle, and the first frame with a surface waited 488 ms in one of them while
// SwiftShader built its pipelines. The backend's file is compiled with glGetIntegerv renamed to
// this function (viewer.cmake), which answers those eight without asking. drawScene() sets
// everything it draws with at the start of each frame, so the values the backend sets back after
// the panel need only be valid: the whole drawing buffer, and the viewer's own blending
// (premultiplied alpha, renderer.cpp).
#include <GLES3/gl3.h>
#include <emscripten/html5.h>

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
