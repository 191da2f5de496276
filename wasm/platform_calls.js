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

  // What the view needs changed (isovalue, field, slice, fetch mode, a node given up): the page
  // asks for the plan again (ts_plan_json) and hands it to its chunk loader.
  tsjs_plan_changed: function () {
    if (Module.onPlanChanged) Module.onPlanChanged();
  },

  // A message to a MessageChannel port runs as its own task soon after, without setTimeout's
  // 4 ms clamp; rendering, input and network callbacks get their turns in between.
  tsjs_queue_work: function () {
    if (!Module.tsWorkChannel) {
      Module.tsWorkChannel = new MessageChannel();
      Module.tsWorkChannel.port1.onmessage = () => Module._ts_work();
    }
    Module.tsWorkChannel.port2.postMessage(0);
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
