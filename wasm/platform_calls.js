// The viewer program's calls into the page (linked with --js-library; declared in
// wasm/platform_calls.h). JavaScript lives here rather than in EM_ASM strings inside C++, so each
// language is written, read and formatted as itself. The page's callbacks are in docs/js-api.md.
mergeInto(LibraryManager.library, {
  // Resizes the canvas's backing store and tells GLFW (window size callbacks, glfwGetWindowSize).
  tsjs_set_canvas_size__deps: ['$Browser'],
  tsjs_set_canvas_size: function (width, height) {
    Browser.setCanvasSize(width, height);
  },

  tsjs_copy_link: function () {
    if (Module.onCopyLink) Module.onCopyLink();
  },

  tsjs_screenshot: function () {
    if (Module.onScreenshot) Module.onScreenshot();
  },

  // The frame just drawn may be read back now (the drawing buffer is not preserved after).
  tsjs_capture: function () {
    if (Module.onCapture) Module.onCapture();
  },

  tsjs_pause_change: function (paused) {
    if (Module.onPauseChange) Module.onPauseChange(!!paused);
  },

  // The view changed (page_state.h): the page's script takes the command (ts_take_command) and
  // posts it to the refinement worker, once per task however many changes came.
  tsjs_command_ready: function () {
    if (Module.onCommandReady) Module.onCommandReady();
  },

  // The camera moved while regions are still to come: the worker orders them by what each
  // covers on screen.
  tsjs_camera_changed: function (tx, ty, tz, distance, yaw, pitch, aspect) {
    if (Module.onCameraChanged) Module.onCameraChanged([tx, ty, tz, distance, yaw, pitch, aspect]);
  },

  // 1 when the viewer's WebGL 2 context is drawn by a software rasterizer. Remembers the
  // renderer's name for tsjs_log_renderer.
  tsjs_software_gl: function () {
    try {
      const gl = Module.canvas.getContext('webgl2');
      const info = gl && gl.getExtension('WEBGL_debug_renderer_info');
      const name = String(info ? gl.getParameter(info.UNMASKED_RENDERER_WEBGL) : 0);
      Module.glRendererName = name;
      return /swiftshader|llvmpipe|softpipe|software/i.test(name) ? 1 : 0;
    } catch (e) {
      return 0;
    }
  },

  // The page's `antialias` choice: 1 on, 0 off, -1 not given.
  tsjs_antialias: function () {
    return typeof Module.antialias === 'boolean' ? (Module.antialias ? 1 : 0) : -1;
  },

  tsjs_log_renderer: function (software, samples) {
    console.log('tetstream viewer: WebGL 2 on ' + (Module.glRendererName || 'an unnamed renderer') +
                (software ? ' (software), ' : ', ') + (samples ? samples + 'x multisampling' : 'no multisampling'));
  },
});
