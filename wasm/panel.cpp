#include "panel.h"

#include <cstdio>
#include <string>

#include "imgui.h"

namespace tetstream::viewer {
namespace {

// 1234567 -> "1,234,567"
std::string grouped(uint64_t n) {
  std::string s = std::to_string(n);
  for (int i = int(s.size()) - 3; i > 0; i -= 3) s.insert(size_t(i), ",");
  return s;
}

std::string megabytes(uint64_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, bytes < 10u << 20 ? "%.2f MB" : "%.1f MB", double(bytes) / (1 << 20));
  return buf;
}

void row(const char* label, const std::string& value) {
  ImGui::TextDisabled("%s", label);
  ImGui::SameLine(ImGui::GetFontSize() * 8.5f);
  ImGui::TextUnformatted(value.c_str());
}

}  // namespace

PanelActions drawPanel(ViewerState& s, float uiScale, float pixelsPerCssPixel) {
  PanelActions actions;
  const Manifest& m = s.dataset.manifest;
  const float width = 300.f * uiScale;

  ImGui::SetNextWindowPos(ImVec2(10.f * uiScale, 10.f * uiScale), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowBgAlpha(0.82f);
  ImGui::Begin("tetstream", nullptr, ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings);
  ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + width);

  const bool haveDataset = !m.chunks.empty();
  ImGui::TextUnformatted(!haveDataset ? "no dataset" : m.name.empty() ? "(unnamed dataset)" : m.name.c_str());

  // Loading state and progress.
  const uint64_t total = m.totalBytes();
  switch (s.state) {
    case LoadState::Idle: ImGui::TextDisabled("waiting for a dataset"); break;
    case LoadState::Loading:
    case LoadState::Streaming: {
      ImGui::Text("%s: part %u of %u", s.state == LoadState::Loading ? "loading" : "streaming", s.chunksLoaded + 1,
                  s.chunksTotal);
      float frac = total ? float(double(s.dataset.bytesApplied) / double(total)) : 0.f;
      std::string label = megabytes(s.dataset.bytesApplied) + " of " + megabytes(total);
      ImGui::ProgressBar(frac, ImVec2(width, 0), label.c_str());
      break;
    }
    case LoadState::Complete:
      ImGui::TextDisabled("complete: %u part%s, %s", s.chunksTotal, s.chunksTotal == 1 ? "" : "s",
                          megabytes(s.bytesLoaded).c_str());
      break;
    case LoadState::Error: break;
  }
  if (s.state == LoadState::Error) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.f, 0.45f, 0.4f, 1.f));
    ImGui::TextWrapped("Error: %s", s.error.c_str());
    ImGui::PopStyleColor();
  }

  if (haveDataset) {
    ImGui::Separator();
    row("vertices", grouped(s.dataset.pm.mesh.vertexCount()) +
                        (s.dataset.pm.mesh.vertexCount() != m.vertices ? " of " + grouped(m.vertices) : ""));
    row("tets", grouped(s.dataset.pm.mesh.tetCount()));
    row("triangles", grouped(s.surface.triangleCount()));
    char area[48];
    std::snprintf(area, sizeof area, "%.6g", s.surfaceArea);
    row("surface area", area);
  }

  ImGui::Separator();
  if (s.field >= 0) {
    ImGui::PushItemWidth(width - ImGui::GetFontSize() * 5.5f);
    if (ImGui::BeginCombo("field", m.fields[size_t(s.field)].name.c_str())) {
      for (size_t i = 0; i < m.fields.size(); ++i) {
        bool selected = int(i) == s.field;
        if (ImGui::Selectable(m.fields[i].name.c_str(), selected)) setField(s, int(i));
        if (selected) ImGui::SetItemDefaultFocus();
      }
      ImGui::EndCombo();
    }
    const Range range = m.fields[size_t(s.field)].range;
    float iso = s.isovalue;
    if (ImGui::SliderFloat("isovalue", &iso, range.min, range.max, "%.5g")) setIsovalue(s, iso);
    // GetItemRect covers the label too; the draggable frame is the item width from the left.
    ImVec2 lo = ImGui::GetItemRectMin(), hi = ImGui::GetItemRectMax();
    float k = 1.f / pixelsPerCssPixel;
    s.sliderRect = {lo.x * k, lo.y * k, ImGui::CalcItemWidth() * k, (hi.y - lo.y) * k};
    ImGui::PopItemWidth();
  }

  ImGui::Checkbox("show boundary", &s.showBoundary);
  ImGui::SameLine();
  if (ImGui::Button("reset view")) actions.resetView = true;

  ImGui::Separator();
  ImGui::TextDisabled("frame %.1f ms  extract %.1f ms", s.frameMs, s.extractMs);
  if (s.firstSurfaceMs >= 0) ImGui::TextDisabled("first surface after %.0f ms", s.firstSurfaceMs);
  ImGui::TextDisabled("drag rotates, right-drag pans, wheel zooms");

  ImGui::PopTextWrapPos();
  // An auto-resizing window takes its size from the previous frame's content.
  static ImVec2 lastSize;
  ImVec2 size = ImGui::GetWindowSize();
  actions.layoutChanged = size.x != lastSize.x || size.y != lastSize.y;
  lastSize = size;
  ImGui::End();
  return actions;
}

}  // namespace tetstream::viewer
