#include "panel.h"

#include <algorithm>
#include <cmath>
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

std::string rate(double bytesPerSec) {
  char buf[32];
  if (bytesPerSec >= 1 << 20)
    std::snprintf(buf, sizeof buf, "%.1f MB/s", bytesPerSec / (1 << 20));
  else
    std::snprintf(buf, sizeof buf, "%.0f KB/s", bytesPerSec / 1024);
  return buf;
}

std::string duration(double seconds) {
  char buf[32];
  if (seconds < 1)
    return "under a second";
  else if (seconds < 90)
    std::snprintf(buf, sizeof buf, "%.0f s", seconds);
  else
    std::snprintf(buf, sizeof buf, "%.0f min", seconds / 60);
  return buf;
}

void row(const char* label, const std::string& value) {
  ImGui::TextDisabled("%s", label);
  ImGui::SameLine(ImGui::GetFontSize() * 8.5f);
  ImGui::TextUnformatted(value.c_str());
}

Rect cssRect(float pixelsPerCssPixel) {
  // GetItemRect covers the label too; the draggable frame is the item width from the left.
  ImVec2 lo = ImGui::GetItemRectMin(), hi = ImGui::GetItemRectMax();
  float k = 1.f / pixelsPerCssPixel;
  return {lo.x * k, lo.y * k, ImGui::CalcItemWidth() * k, (hi.y - lo.y) * k};
}

void section(const char* title) {
  ImGui::Spacing();
  ImGui::TextDisabled("%s", title);
  ImGui::Separator();
}

void downloadSection(ViewerState& s, float width, float pixelsPerCssPixel) {
  const Dataset& ds = s.dataset;
  const uint64_t total = ds.manifest.totalBytes();
  const bool allReceived = ds.chunksReceived == s.chunksTotal;
  section("download");
  if (s.state == LoadState::Loading && !s.paused)
    ImGui::TextUnformatted("loading the base mesh...");
  else if (allReceived)
    ImGui::Text("all %u parts received", s.chunksTotal);
  else
    ImGui::Text("%u of %u parts received", ds.chunksReceived, s.chunksTotal);

  const uint64_t have = allReceived ? ds.bytesReceived : std::max(s.datasetBytes, ds.bytesReceived);
  std::string label = megabytes(have) + " of " + megabytes(total);
  ImGui::ProgressBar(total ? float(double(have) / double(total)) : 0.f, ImVec2(width, 0), label.c_str());

  s.pauseButtonRect = {};
  if (allReceived || s.state == LoadState::Error) return;
  // One line that is always there, so the button below does not move under the mouse.
  if (s.paused) {
    ImGui::TextUnformatted("download paused");
  } else {
    double left = secondsLeft(s);
    std::string line = s.rateBytesPerSec > 0 ? rate(s.rateBytesPerSec) : std::string("waiting for data");
    if (left >= 0) line += ", about " + duration(left) + " left";
    ImGui::TextUnformatted(line.c_str());
  }
  if (ImGui::Button(s.paused ? "resume download" : "pause download")) setPaused(s, !s.paused);
  ImVec2 lo = ImGui::GetItemRectMin(), hi = ImGui::GetItemRectMax();
  const float k = 1.f / pixelsPerCssPixel;
  s.pauseButtonRect = {lo.x * k, lo.y * k, (hi.x - lo.x) * k, (hi.y - lo.y) * k};
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(s.paused ? "Downloads the remaining parts."
                               : "Stops downloading at once. What has arrived is still applied\n"
                                 "up to the level chosen below.");
}

void levelSection(ViewerState& s, float width, float pixelsPerCssPixel) {
  const Dataset& ds = s.dataset;
  const Manifest& m = ds.manifest;
  section("level of detail");
  // The slider sets the target in splits, from the base (0) to the newest split received.
  const uint32_t received = ds.splitsReceived();
  uint32_t target = std::min(s.targetSplits, received);
  const uint32_t zero = 0;
  const double targetFraction = m.vertices ? double(ds.pm.baseVertices + target) / m.vertices : 0;
  char format[64];
  std::snprintf(format, sizeof format, "%.1f%%%% of the vertices%s", 100 * targetFraction,
                received && target == received ? " (newest)" : "");
  ImGui::PushItemWidth(width - ImGui::GetFontSize() * 3.5f);
  ImGui::BeginDisabled(received == 0);
  if (ImGui::SliderScalar("level", ImGuiDataType_U32, &target, &zero, &received, format,
                          ImGuiSliderFlags_AlwaysClamp | ImGuiSliderFlags_NoInput))
    setLevel(s, target);
  ImGui::EndDisabled();
  s.levelSliderRect = cssRect(pixelsPerCssPixel);
  ImGui::PopItemWidth();

  const uint32_t applied = ds.splitsApplied();
  if (applied < std::min(s.targetSplits, received))
    ImGui::Text("refining: %s splits to go", grouped(std::min(s.targetSplits, received) - applied).c_str());
  else if (applied > s.targetSplits)
    ImGui::Text("coarsening: %s splits to undo", grouped(applied - s.targetSplits).c_str());
  else if (!s.live && ds.chunksReceived < s.chunksTotal && s.state != LoadState::Error)
    ImGui::TextDisabled("held here; move to the right end to follow new data");
  else if (!s.live)
    ImGui::TextDisabled("held here");
  else if (ds.chunksReceived < s.chunksTotal && s.state != LoadState::Error)
    ImGui::TextDisabled(s.paused ? "follows new data once the download resumes" : "follows new data as it arrives");

  const uint32_t nv = ds.pm.mesh.vertexCount(), nt = ds.pm.mesh.tetCount();
  char pct[32];
  std::snprintf(pct, sizeof pct, " (%.1f%%)", 100 * levelFraction(s));
  row("vertices", grouped(nv) + (nv != m.vertices ? " of " + grouped(m.vertices) + pct : ""));
  row("tets", grouped(nt) + (nt != m.tets ? " of " + grouped(m.tets) : ""));
  double err = fieldErrorBound(s);
  if (err >= 0 && s.field >= 0) {
    const Range r = m.fields[size_t(s.field)].range;
    char buf[64];
    if (err == 0)
      std::snprintf(buf, sizeof buf, "none (full mesh)");
    else if (r.max > r.min)
      std::snprintf(buf, sizeof buf, "up to %.3g (%.2g%% of range)", err, 100 * err / (r.max - r.min));
    else
      std::snprintf(buf, sizeof buf, "up to %.3g", err);
    row("field error", buf);
  }
}

}  // namespace

PanelActions drawPanel(ViewerState& s, float uiScale, float pixelsPerCssPixel) {
  PanelActions actions;
  const Manifest& m = s.dataset.manifest;
  const float width = 320.f * uiScale;

  ImGui::SetNextWindowPos(ImVec2(10.f * uiScale, 10.f * uiScale), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowBgAlpha(0.82f);
  ImGui::Begin("tetstream", nullptr, ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings);
  ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + width);

  const bool haveDataset = !m.chunks.empty();
  ImGui::TextUnformatted(!haveDataset ? "no dataset" : m.name.empty() ? "(unnamed dataset)" : m.name.c_str());
  if (s.state == LoadState::Idle) ImGui::TextDisabled("waiting for a dataset");
  if (s.state == LoadState::Complete) ImGui::TextDisabled("complete: every part received and applied");
  if (s.state == LoadState::Error) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.f, 0.45f, 0.4f, 1.f));
    ImGui::TextWrapped("Error: %s", s.error.c_str());
    ImGui::PopStyleColor();
  }

  if (haveDataset) {
    downloadSection(s, width, pixelsPerCssPixel);
    if (s.dataset.chunksReceived > 0) levelSection(s, width, pixelsPerCssPixel);
  }

  if (s.field >= 0) {
    section("isosurface");
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
    s.sliderRect = cssRect(pixelsPerCssPixel);
    ImGui::PopItemWidth();
    if (haveDataset) {
      row("triangles", grouped(s.surface.triangleCount()));
      char area[48];
      std::snprintf(area, sizeof area, "%.6g", s.surface.area());
      row("surface area", area);
    }
  }

  ImGui::Spacing();
  ImGui::Checkbox("show boundary", &s.showBoundary);
  ImGui::SameLine();
  if (ImGui::Button("reset view")) actions.resetView = true;

  ImGui::Separator();
  ImGui::TextDisabled("frames every %.1f ms, longest frame %.0f ms", s.frameMs, s.maxFrameMs);
  if (s.refineSteps)
    ImGui::TextDisabled("last refinement %.1f ms (%u splits)", s.refineMs, s.refineSteps);
  ImGui::TextDisabled("last full extraction %.1f ms", s.extractMs);
  if (s.firstSurfaceMs >= 0) {
    if (s.completeMs >= 0)
      ImGui::TextDisabled("first surface at %.2f s, complete at %.1f s", s.firstSurfaceMs / 1000, s.completeMs / 1000);
    else
      ImGui::TextDisabled("first surface at %.2f s", s.firstSurfaceMs / 1000);
  }
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
