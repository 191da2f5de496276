// IMGUI_USER_CONFIG for every ImGui file of the viewer (library sources, backends, panel):
// they must agree on the GL flavour. Dear ImGui 1.86's OpenGL3 backend assumes GLES2/WebGL1
// under Emscripten unless told otherwise; the viewer is WebGL2 only.
#pragma once
#define IMGUI_IMPL_OPENGL_ES3
#define IMGUI_DISABLE_OBSOLETE_FUNCTIONS
