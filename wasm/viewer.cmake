# Browser viewer (Emscripten only; included from the root CMakeLists.txt).
#   tetstream_imgui   Dear ImGui 1.86 + GLFW and OpenGL3 backends (sources in build/_deps/imgui)
#   tetstream_viewer  tetstream.js + tetstream.wasm in ${TETSTREAM_WEB_DIR}, plus every file of web/
# One program for both threads: the page runs main() (platform.cpp, api.cpp: drawing, panel,
# input) and the refinement worker instantiates the same module without it (worker_api.cpp:
# dataset, splits, surfaces). Those and imgui_gl_queries.cpp are the only viewer files with
# Emscripten; the model (the tetstream_viewer_model library of the root CMakeLists.txt, with
# page_state and frame_policy.h) has no GL and no Emscripten and also compiles natively, for the
# unit tests and the model benchmark.

set(TETSTREAM_IMGUI_DIR "${TETSTREAM_DEPS_DIR}/imgui")
if(NOT EXISTS "${TETSTREAM_IMGUI_DIR}/imgui.cpp")
  message(FATAL_ERROR "Dear ImGui sources not found in ${TETSTREAM_IMGUI_DIR}: run scripts/setup.sh")
endif()

add_library(tetstream_imgui STATIC
  ${TETSTREAM_IMGUI_DIR}/imgui.cpp
  ${TETSTREAM_IMGUI_DIR}/imgui_draw.cpp
  ${TETSTREAM_IMGUI_DIR}/imgui_tables.cpp
  ${TETSTREAM_IMGUI_DIR}/imgui_widgets.cpp
  ${TETSTREAM_IMGUI_DIR}/backends/imgui_impl_glfw.cpp
  ${TETSTREAM_IMGUI_DIR}/backends/imgui_impl_opengl3.cpp
)
target_include_directories(tetstream_imgui PUBLIC ${TETSTREAM_IMGUI_DIR} ${CMAKE_CURRENT_LIST_DIR})
# The backend's questions to WebGL that wait on the GPU process, answered without asking where
# the viewer knows the answer (imgui_gl_queries.cpp).
target_sources(tetstream_imgui PRIVATE ${CMAKE_CURRENT_LIST_DIR}/imgui_gl_queries.cpp)
set_source_files_properties(${TETSTREAM_IMGUI_DIR}/backends/imgui_impl_opengl3.cpp PROPERTIES
  COMPILE_DEFINITIONS "glGetIntegerv=tetstreamImGuiGetIntegerv;glGetShaderiv=tetstreamImGuiGetShaderiv;glGetProgramiv=tetstreamImGuiGetProgramiv")
# One config header for every ImGui file, ours included: WebGL2 (GLES3) everywhere.
target_compile_definitions(tetstream_imgui PUBLIC IMGUI_USER_CONFIG="imconfig_tetstream.h")

add_executable(tetstream_viewer
  ${CMAKE_CURRENT_LIST_DIR}/platform.cpp
  ${CMAKE_CURRENT_LIST_DIR}/api.cpp
  ${CMAKE_CURRENT_LIST_DIR}/worker_api.cpp
  ${CMAKE_CURRENT_LIST_DIR}/page_state.cpp
  ${CMAKE_CURRENT_LIST_DIR}/renderer.cpp
  ${CMAKE_CURRENT_LIST_DIR}/panel.cpp
)
target_link_libraries(tetstream_viewer PRIVATE tetstream_viewer_model tetstream_imgui)
set_target_properties(tetstream_viewer PROPERTIES LINK_DEPENDS ${CMAKE_CURRENT_LIST_DIR}/platform_calls.js)
tetstream_warnings(tetstream_viewer)
# GLM 0.9.9.8 (type_half.inl) uses `volatile float f; f *= f;`, deprecated in C++20.
target_compile_options(tetstream_viewer PRIVATE -Wno-deprecated-volatile)

target_link_options(tetstream_viewer PRIVATE
  -sUSE_GLFW=3
  -sUSE_WEBGL2=1 -sMIN_WEBGL_VERSION=2 -sMAX_WEBGL_VERSION=2
  # The viewer uses WebGL 2's core only. Emscripten would otherwise enable every extension the
  # browser offers as the context is made, each a wait on the GPU process (24 in Chromium with
  # SwiftShader, ~110 ms on the way to the first picture).
  -sGL_SUPPORT_AUTOMATIC_ENABLE_EXTENSIONS=0
  -sALLOW_MEMORY_GROWTH=1 -sMAXIMUM_MEMORY=4GB
  -sMODULARIZE=1 -sEXPORT_NAME=createTetstream -sINVOKE_RUN=0
  -sENVIRONMENT=web,worker -sFILESYSTEM=0
  # The ts_* functions are exported by EMSCRIPTEN_KEEPALIVE (api.cpp); these are the rest.
  -sEXPORTED_FUNCTIONS=_main,_malloc,_free
  # The program's calls into the page, written in JavaScript (platform_calls.h).
  --js-library ${CMAKE_CURRENT_LIST_DIR}/platform_calls.js
  -sEXPORTED_RUNTIME_METHODS=callMain,ccall,cwrap,UTF8ToString,HEAPU8
  $<$<CONFIG:Release>:-O3>
  $<$<CONFIG:Debug>:-sASSERTIONS=1>
)
set_target_properties(tetstream_viewer PROPERTIES
  OUTPUT_NAME tetstream
  SUFFIX ".js"
  RUNTIME_OUTPUT_DIRECTORY ${TETSTREAM_WEB_DIR})

# The static shell: copied on every build so edits to web/ show up after a rebuild; index.html
# is written after the link, with the wasm's size in it (web_page.cmake).
file(GLOB TETSTREAM_WEB_FILES CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/web/*)
list(FILTER TETSTREAM_WEB_FILES EXCLUDE REGEX "/index\\.html$")
add_custom_target(tetstream_web_files
  COMMAND ${CMAKE_COMMAND} -E make_directory ${TETSTREAM_WEB_DIR}
  COMMAND ${CMAKE_COMMAND} -E copy_if_different ${TETSTREAM_WEB_FILES} ${TETSTREAM_WEB_DIR}
  COMMENT "Copying web/ to ${TETSTREAM_WEB_DIR}"
  VERBATIM)
add_dependencies(tetstream_viewer tetstream_web_files)
add_custom_command(OUTPUT ${TETSTREAM_WEB_DIR}/index.html
  COMMAND ${CMAKE_COMMAND} -DIN=${CMAKE_CURRENT_SOURCE_DIR}/web/index.html -DOUT=${TETSTREAM_WEB_DIR}/index.html
          -DWASM=${TETSTREAM_WEB_DIR}/tetstream.wasm -P ${CMAKE_CURRENT_LIST_DIR}/web_page.cmake
  DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/web/index.html ${CMAKE_CURRENT_LIST_DIR}/web_page.cmake tetstream_viewer
  COMMENT "Writing ${TETSTREAM_WEB_DIR}/index.html"
  VERBATIM)
add_custom_target(tetstream_web_page ALL DEPENDS ${TETSTREAM_WEB_DIR}/index.html)
