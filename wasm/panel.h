// The ImGui control panel (top-left): dataset, download progress (parts, bytes, rate, time left)
// with pause/resume, the level of detail (slider from the base to the newest level received,
// counts, estimated field error), field and isovalue, view options, timings, and errors in
// plain words. Reads and edits the ViewerState; it
// never touches GL or the platform, so the same code runs under any ImGui backend.
#pragma once
#include "viewer_state.h"

namespace tetstream::viewer {

struct PanelActions {
  bool resetView = false;
  bool layoutChanged = false;  // the panel changed size: draw another frame so it settles
};

// Call between ImGui::NewFrame() and ImGui::Render(). `uiScale` multiplies sizes given in CSS
// pixels; `pixelsPerCssPixel` converts ImGui coordinates back to CSS pixels for the slider
// rectangles (sliderRect, levelSliderRect).
PanelActions drawPanel(ViewerState& s, float uiScale, float pixelsPerCssPixel);

}  // namespace tetstream::viewer
