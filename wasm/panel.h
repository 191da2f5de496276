// The ImGui control panel (top-left): dataset, download progress (parts, bytes, rate, time left)
// with pause/resume, the level of detail (slider from the base to the newest level received,
// counts, estimated field error), field and isovalue, view options, timings, and errors in
// plain words. Reads and edits the PageState (what the page holds; the model is in the
// refinement worker); it never touches GL or the platform, so the same code runs under any
// ImGui backend.
#pragma once
#include "page_state.h"

namespace tetstream::viewer {

struct PanelActions {
  bool resetView = false;
  bool layoutChanged = false;  // the panel changed size: draw another frame so it settles
  bool copyLink = false;       // "copy link": the platform puts the view's URL on the clipboard
  bool screenshot = false;     // "screenshot": the platform saves the next frame as a PNG
  bool toggleHelp = false;     // "help": show or hide the keyboard shortcuts
};

// The keyboard shortcuts, as the help panel lists them: {key, what it does}.
struct Shortcut {
  const char* key;
  const char* action;
};
extern const Shortcut kShortcuts[];
extern const int kShortcutCount;

// The help panel (keyboard shortcuts and mouse/touch gestures); `open` is cleared by its close
// button.
void drawHelp(bool& open, float uiScale);

// Call between ImGui::NewFrame() and ImGui::Render(). `uiScale` multiplies sizes given in CSS
// pixels; `pixelsPerCssPixel` converts ImGui coordinates back to CSS pixels for the slider
// rectangles (sliderRect, levelSliderRect).
PanelActions drawPanel(PageState& s, float uiScale, float pixelsPerCssPixel);

}  // namespace tetstream::viewer
