// The viewer program's calls into the page, implemented in JavaScript (wasm/platform_calls.js,
// linked with --js-library). Only the Emscripten platform (platform.cpp) calls them.
#pragma once

extern "C" {
void tsjs_set_canvas_size(int width, int height);
void tsjs_copy_link();
void tsjs_screenshot();
void tsjs_capture();
void tsjs_pause_change(int paused);
void tsjs_command_ready();
void tsjs_camera_changed(double tx, double ty, double tz, double distance, double yaw, double pitch, double aspect);
int tsjs_software_gl();
int tsjs_antialias();
void tsjs_log_renderer(int software, int samples);
}
