// The ImGui control panel (top-left): dataset, counts, field and isovalue, view options,
// timings, loading progress and errors in plain words. Reads and edits the ViewerState; it
// never touches GL or the platform, so the same code runs under any ImGui backend.
#pragma once
#include "viewer_state.h"

namespace tetstream::viewer {

struct PanelActions {
  bool resetView = false;
  bool layoutChanged = false;  // the panel changed size: draw another frame so it settles
};

// Call between ImGui::NewFrame() and ImGui::Render(). `uiScale` multiplies sizes given in CSS
// pixels; `pixelsPerCssPixel` converts ImGui coordinates back to CSS pixels for sliderRect.
PanelActions drawPanel(ViewerState& s, float uiScale, float pixelsPerCssPixel);

}  // namespace tetstream::viewer
