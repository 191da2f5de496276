#include "panel.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "colourmap.h"
#include "imgui.h"
#include "viewer_memory.h"

namespace tetstream::viewer {
namespace {

// 1234567 -> "1,234,567"
std::string grouped(uint64_t n) {
  std::string s = std::to_string(n);
  for (int i = int(s.size()) - 3; i > 0; i -= 3) s.insert(size_t(i), ",");
  return s;
}

std::string duration(double seconds) {
  char buf[32];
  if (seconds < 90)
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

const ImVec4 kWarning(1.f, 0.75f, 0.35f, 1.f);
const ImVec4 kError(1.f, 0.45f, 0.4f, 1.f);

void coloredWrapped(const ImVec4& color, const std::string& text) {
  ImGui::PushStyleColor(ImGuiCol_Text, color);
  ImGui::TextWrapped("%s", text.c_str());
  ImGui::PopStyleColor();
}

void section(const char* title) {
  ImGui::Spacing();
  ImGui::TextDisabled("%s", title);
  ImGui::Separator();
}

// With a patch hierarchy (FORMAT.md §1.1): whether the surface is exact, what was fetched of
// the whole, and the choice to fetch everything.
void selectionLines(PageState& s) {
  const ModelReport& r = s.model;
  const Manifest& m = s.manifest;
  if (m.nodes.empty() || r.chunksReceived == 0) return;
  char line[160];
  const char* field = s.settings.field >= 0 ? m.fields[size_t(s.settings.field)].name.c_str() : "";
  if (shownExact(s))
    std::snprintf(line, sizeof line, "exact for %s = %.4g", field, s.settings.isovalue);
  else
    std::snprintf(line, sizeof line, "refining towards the exact surface for %.4g", s.settings.isovalue);
  ImGui::TextUnformatted(line);
  std::snprintf(line, sizeof line, "%u of %zu regions, %s of %s", r.nodesLoaded, m.nodes.size(),
                formatBytes(r.bytesReceived).c_str(), formatBytes(m.totalBytes()).c_str());
  ImGui::TextDisabled("%s", line);
  if (!r.unavailable.empty()) coloredWrapped(kWarning, r.unavailable);
  if (r.memoryFull)
    coloredWrapped(kWarning, "Memory is full (" + formatBytes(r.limitBytes) +
                                 "): the regions shown are those that fit; the rest of this view stays coarse.");
  bool everything = s.settings.fetch == FetchMode::Everything;
  if (ImGui::Checkbox("load everything", &everything))
    setFetchMode(s, everything ? FetchMode::Everything : FetchMode::Needed);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(everything ? "Every region is fetched, whatever the isovalue."
                                 : "Only the regions the isovalue (and the slice) need are fetched.");
}

void downloadSection(PageState& s, float width, float pixelsPerCssPixel) {
  const ModelReport& r = s.model;
  const Manifest& m = s.manifest;
  const uint32_t chunksTotal = uint32_t(m.chunks.size());
  const LoadState state = shownState(s);
  const bool selective = !m.nodes.empty();
  const uint64_t total = selective ? r.bytesNeeded : m.totalBytes();
  const bool allReceived = selective ? r.chunksMissing == 0 : r.chunksReceived == chunksTotal;
  section("download");
  const NetworkStatus& net = s.network;
  if (state == LoadState::Loading && !net.paused)
    ImGui::TextUnformatted("loading the base mesh...");
  else if (allReceived && !selective)
    ImGui::Text("all %u parts received", chunksTotal);
  else if (allReceived)
    ImGui::Text("all %u parts this view needs received", r.chunksReceived);
  else if (r.memoryFull)
    ImGui::Text("%u parts received; %u more of this view do not fit", r.chunksReceived, r.chunksMissing);
  else
    ImGui::Text("%u of %u parts received", r.chunksReceived,
                selective ? r.chunksReceived + r.chunksMissing : chunksTotal);
  selectionLines(s);

  const uint64_t have = allReceived ? r.bytesReceived : std::max(net.receivedBytes, r.bytesReceived);
  std::string label = formatBytes(have) + " of " + formatBytes(std::max(total, have));
  ImGui::ProgressBar(total ? float(double(have) / double(total)) : 0.f, ImVec2(width, 0), label.c_str());

  s.telemetry.screen.pauseButton = {};
  if (!net.notice.empty() && state != LoadState::Error) coloredWrapped(kWarning, net.notice);
  if (allReceived || r.memoryFull || state == LoadState::Error) return;  // (nothing is coming)
  // One line that is always there, so the button below does not move under the mouse.
  if (net.paused) {
    ImGui::TextUnformatted("download paused");
  } else {
    const double left = net.secondsLeft;
    std::string line =
        net.bytesPerSecond > 0 ? formatBytes(uint64_t(net.bytesPerSecond)) + "/s" : std::string("waiting for data");
    if (left >= 1)
      line += ", about " + duration(left) + " left";
    else if (left >= 0)
      line += ", less than a second left";
    ImGui::TextUnformatted(line.c_str());
  }
  if (ImGui::Button(net.paused ? "resume download" : "pause download")) requestPauseToggle(s);
  ImVec2 lo = ImGui::GetItemRectMin(), hi = ImGui::GetItemRectMax();
  const float k = 1.f / pixelsPerCssPixel;
  s.telemetry.screen.pauseButton = {lo.x * k, lo.y * k, (hi.x - lo.x) * k, (hi.y - lo.y) * k};
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(net.paused ? "Downloads the remaining parts."
                                 : "Stops downloading at once. What has arrived is still applied\n"
                                   "up to the level chosen below.");
}

void levelSection(PageState& s, float width, float pixelsPerCssPixel) {
  const ModelReport& r = s.model;
  const Manifest& m = s.manifest;
  const LoadState state = shownState(s);
  section("level of detail");
  // The slider sets the target in splits, from the base (0) to the newest split received.
  const uint32_t received = r.splitsReceived;
  uint32_t target = shownTargetSplits(s);
  const uint32_t zero = 0;
  const double targetFraction = m.vertices ? double(r.baseVertices + target) / m.vertices : 0;
  char format[64];
  std::snprintf(format, sizeof format, "%.1f%%%% of the vertices%s", 100 * targetFraction,
                received && target == received ? " (newest)" : "");
  ImGui::PushItemWidth(width - ImGui::GetFontSize() * 3.5f);
  ImGui::BeginDisabled(received == 0);
  if (ImGui::SliderScalar("level", ImGuiDataType_U32, &target, &zero, &received, format,
                          ImGuiSliderFlags_AlwaysClamp | ImGuiSliderFlags_NoInput))
    setLevelSplits(s, target);
  ImGui::EndDisabled();
  s.telemetry.screen.levelSlider = cssRect(pixelsPerCssPixel);
  ImGui::PopItemWidth();

  const uint32_t applied = r.splitsApplied;
  const bool live = viewCurrent(s) ? r.live : target == received;
  if (applied < target)
    ImGui::Text("refining: %s splits to go", grouped(target - applied).c_str());
  else if (applied > target)
    ImGui::Text("coarsening: %s splits to undo", grouped(applied - target).c_str());
  else if (!live && r.chunksMissing > 0 && state != LoadState::Error)
    ImGui::TextDisabled("held here; move to the right end to follow new data");
  else if (!live)
    ImGui::TextDisabled("held here");
  else if (r.chunksMissing > 0 && state != LoadState::Error)
    ImGui::TextDisabled(s.network.paused ? "follows new data once the download resumes"
                                         : "follows new data as it arrives");

  const uint32_t nv = r.vertices, nt = r.tets;
  char pct[32];
  std::snprintf(pct, sizeof pct, " (%.1f%%)", 100 * r.level);
  row("vertices", grouped(nv) + (nv != m.vertices ? " of " + grouped(m.vertices) + pct : ""));
  row("tets", grouped(nt) + (nt != m.tets ? " of " + grouped(m.tets) : ""));
  // The error of the field that steered the simplification, in its units: measured at the
  // input's vertices when the manifest has it (RMS and max of a level of the stream; the max alone
  // where a set of nodes made the mesh), the simplifier's estimate otherwise.
  const int iso = m.findField(m.isoField);
  if (iso >= 0 && (r.fieldMax >= 0 || r.fieldError >= 0)) {
    const Range range = m.fields[size_t(iso)].range;
    const double span = range.max - range.min;
    char buf[96];
    if (r.fieldMax == 0 || (r.fieldMax < 0 && r.fieldError == 0))
      std::snprintf(buf, sizeof buf, "none (full mesh)");
    else if (r.fieldMax >= 0 && r.fieldRms >= 0 && span > 0)
      std::snprintf(buf, sizeof buf, "RMS %.2g%%, max %.2g%% of range", 100 * r.fieldRms / span,
                    100 * r.fieldMax / span);
    else if (r.fieldMax >= 0 && r.fieldRms >= 0)
      std::snprintf(buf, sizeof buf, "RMS %.3g, max %.3g", r.fieldRms, r.fieldMax);
    else if (r.fieldMax >= 0 && span > 0)
      std::snprintf(buf, sizeof buf, "max %.2g%% of range", 100 * r.fieldMax / span);
    else if (r.fieldMax >= 0)
      std::snprintf(buf, sizeof buf, "max %.3g", r.fieldMax);
    else if (span > 0)
      std::snprintf(buf, sizeof buf, "up to %.3g (%.2g%% of range)", r.fieldError, 100 * r.fieldError / span);
    else
      std::snprintf(buf, sizeof buf, "up to %.3g", r.fieldError);
    row("field error", buf);
  }
}

// What the viewer holds now and what the dataset will need, against the limit.
void memorySection(const PageState& s) {
  const ModelReport& r = s.model;
  const Manifest& m = s.manifest;
  const uint32_t chunksTotal = uint32_t(m.chunks.size());
  // Folds away while the slice is on, like the timings (the panel would outgrow the screen).
  static int lastSliceOn = -1;
  if (int(s.settings.sliceOn) != lastSliceOn) ImGui::SetNextItemOpen(!s.settings.sliceOn);
  lastSliceOn = int(s.settings.sliceOn);
  ImGui::Spacing();
  if (!ImGui::TreeNodeEx("memory", ImGuiTreeNodeFlags_NoTreePushOnOpen)) return;
  row("in use", formatBytes(r.dataBytes) + " (heaps " + formatBytes(r.heapBytes + s.pageHeapBytes) + ")");
  row("on the GPU", formatBytes(s.gpuBytes));
  if (chunksTotal == 0) return;
  std::string need = "about " + formatBytes(r.neededBytes);
  if (r.limitBytes) need += ", limit " + formatBytes(r.limitBytes);
  row("full dataset", need);
  if (r.chunksAllowed < chunksTotal && shownState(s) != LoadState::Error && r.chunksAllowed > 0) {
    char buf[160];
    std::snprintf(
        buf, sizeof buf, "Too big for this page: streaming will stop after part %u of %u (%.1f%% of the vertices).",
        r.chunksAllowed, chunksTotal, m.vertices ? 100.0 * m.chunks[r.chunksAllowed - 1].vertices / m.vertices : 0.0);
    coloredWrapped(kWarning, buf);
  }
}

// The colour bar: the map over the range, drawn in 64 bands, with five values under it.
void colourBar(const ViewSettings& s, float width, float pixelsPerCssPixel) {
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const float fs = ImGui::GetFontSize();
  const ImVec2 p = ImGui::GetCursorScreenPos();
  const float h = 1.2f * fs, inset = 1.6f * fs, w = width - 2 * inset;
  const ImVec2 lo(p.x + inset, p.y);
  constexpr int kBands = 64;
  for (int i = 0; i < kBands; ++i) {
    auto c0 = mapColour(s.colourMap, float(i) / kBands, 0, 1);
    auto c1 = mapColour(s.colourMap, float(i + 1) / kBands, 0, 1);
    ImU32 a = ImGui::ColorConvertFloat4ToU32(ImVec4(c0[0], c0[1], c0[2], 1));
    ImU32 b = ImGui::ColorConvertFloat4ToU32(ImVec4(c1[0], c1[1], c1[2], 1));
    dl->AddRectFilledMultiColor(ImVec2(lo.x + w * i / kBands, lo.y),
                                ImVec2(lo.x + w * (i + 1) / kBands + 0.5f, lo.y + h), a, b, b, a);
  }
  dl->AddRect(ImVec2(lo.x - 1, lo.y - 1), ImVec2(lo.x + w + 1, lo.y + h + 1), IM_COL32(200, 200, 200, 160));
  const ImU32 text = ImGui::GetColorU32(ImGuiCol_Text);
  for (int k = 0; k <= 4; ++k) {
    const float x = lo.x + w * k / 4;
    dl->AddLine(ImVec2(x, lo.y + h), ImVec2(x, lo.y + h + 0.35f * fs), text);
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", s.colourMin + (s.colourMax - s.colourMin) * k / 4.f);
    const float tw = ImGui::CalcTextSize(buf).x;
    dl->AddText(ImVec2(x - 0.5f * tw, lo.y + h + 0.4f * fs), text, buf);
  }
  ImGui::Dummy(ImVec2(width, h + 1.5f * fs));
  (void)pixelsPerCssPixel;
}

void colourSection(PageState& s, float width, float pixelsPerCssPixel) {
  const Manifest& m = s.manifest;
  const ViewSettings& v = s.settings;
  section("colour");
  ImGui::PushItemWidth(width - ImGui::GetFontSize() * 5.5f);
  const char* current = v.colourField >= 0 ? m.fields[size_t(v.colourField)].name.c_str() : "none (two-sided)";
  if (ImGui::BeginCombo("colour by", current)) {
    if (ImGui::Selectable("none (two-sided)", v.colourField < 0)) setColourField(s, -1);
    for (size_t i = 0; i < m.fields.size(); ++i)
      if (ImGui::Selectable(m.fields[i].name.c_str(), int(i) == v.colourField)) setColourField(s, int(i));
    ImGui::EndCombo();
  }
  if (v.colourField >= 0) {
    if (ImGui::BeginCombo("colour map", colourMapName(v.colourMap))) {
      for (int i = 0; i < kColourMapCount; ++i)
        if (ImGui::Selectable(colourMapName(ColourMap(i)), int(v.colourMap) == i)) setColourMap(s, ColourMap(i));
      ImGui::EndCombo();
    }
    float range[2] = {v.colourMin, v.colourMax};
    const Range fr = m.fields[size_t(v.colourField)].range;
    const float speed = float(fr.max - fr.min) / 500.f;
    if (ImGui::DragFloat2("range", range, speed > 0 ? speed : 0.01f, 0, 0, "%.4g"))
      setColourRange(s, range[0], range[1]);
    ImGui::SameLine();
    if (ImGui::SmallButton("fit")) fitColourRange(s);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("the range of the values on the visible surface (F)");
    ImGui::SameLine(0, 2);
    if (ImGui::SmallButton("reset")) setColourRange(s, float(fr.min), float(fr.max));
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("the field's whole range");
  }
  ImGui::PopItemWidth();
  if (v.colourField >= 0) colourBar(v, width, pixelsPerCssPixel);
}

// The slice: on/off, x/y/z or free orientation (two angles), and its position.
void sliceSection(PageState& s, float width, float pixelsPerCssPixel) {
  section("slice");
  bool on = s.settings.sliceOn;
  if (ImGui::Checkbox("slice plane", &on)) setSliceEnabled(s, on);
  if (!s.settings.sliceOn) return;
  const auto n = s.settings.sliceNormal;
  const Bounds& b = s.manifest.bounds;
  float lo = 0, hi = 0;
  sliceOffsetRange(s, lo, hi);
  static const char* kAxes[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    ImGui::SameLine();
    if (ImGui::SmallButton(kAxes[k])) {
      std::array<float, 3> axis{0, 0, 0};
      axis[size_t(k)] = 1;
      setSlicePlane(s, axis, 0.5f * (b.min[k] + b.max[k]));
    }
  }
  ImGui::PushItemWidth(width - ImGui::GetFontSize() * 5.5f);
  // Free orientation: azimuth around z and elevation from the xy plane.
  float az = std::atan2(n[1], n[0]) * 57.29578f, el = std::asin(std::clamp(n[2], -1.f, 1.f)) * 57.29578f;
  bool turned = ImGui::SliderFloat("azimuth", &az, -180.f, 180.f, "%.0f deg");
  turned |= ImGui::SliderFloat("elevation", &el, -90.f, 90.f, "%.0f deg");
  if (turned) {
    const float a = az / 57.29578f, e = el / 57.29578f;
    // The same relative position across the bounds for the new normal.
    const float frac = hi > lo ? (s.settings.sliceOffset - lo) / (hi - lo) : 0.5f;
    const std::array<float, 3> m{std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)};
    float lo2 = 0, hi2 = 0;
    SliceTracker::offsetRange(m, b.min, b.max, lo2, hi2);
    setSlicePlane(s, m, lo2 + frac * (hi2 - lo2));
  }
  float offset = s.settings.sliceOffset;
  if (ImGui::SliderFloat("position", &offset, lo, hi, "%.4g")) setSlicePlane(s, s.settings.sliceNormal, offset);
  s.telemetry.screen.sliceSlider = cssRect(pixelsPerCssPixel);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Or shift + drag in the view, or [ and ].");
  ImGui::PopItemWidth();
  row("triangles", grouped(s.slice.triangleCount()));
}

}  // namespace

PanelActions drawPanel(PageState& s, float uiScale, float pixelsPerCssPixel) {
  PanelActions actions;
  const Manifest& m = s.manifest;
  const ModelReport& r = s.model;
  const LoadState state = shownState(s);
  const float width = 320.f * uiScale;

  ImGui::SetNextWindowPos(ImVec2(10.f * uiScale, 10.f * uiScale), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowBgAlpha(0.82f);
  ImGui::Begin("tetstream", nullptr, ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings);
  ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + width);

  const bool haveDataset = !m.chunks.empty();
  ImGui::TextUnformatted(!haveDataset ? "no dataset" : m.name.empty() ? "(unnamed dataset)" : m.name.c_str());
  if (state == LoadState::Idle) ImGui::TextDisabled("waiting for a dataset");
  if (state == LoadState::Complete)
    ImGui::TextDisabled(r.memoryFull ? "complete: every part that fits in memory received and applied"
                        : s.settings.fetch == FetchMode::Needed && !m.nodes.empty()
                            ? "complete: every part this view needs received and applied"
                            : "complete: every part received and applied");
  if (state == LoadState::Error)
    coloredWrapped(kError, (r.memoryLimited && s.pageError.empty() ? "Stopped: " : "Error: ") +
                               (s.pageError.empty() ? r.error : s.pageError));
  if (ImGui::SmallButton("copy link")) actions.copyLink = true;
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("Copies a link that opens this view: dataset, fields, colours, slice,\nlevel and camera (L).");
  ImGui::SameLine();
  if (ImGui::SmallButton("screenshot")) actions.screenshot = true;
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Saves the picture as a PNG (S).");
  ImGui::SameLine();
  if (ImGui::SmallButton("keys (?)")) actions.toggleHelp = true;
  if (!s.view.linkNote.empty()) {
    ImGui::SameLine();
    ImGui::TextDisabled("%s", s.view.linkNote.c_str());
  }

  if (haveDataset) {
    downloadSection(s, width, pixelsPerCssPixel);
    if (r.chunksReceived > 0) levelSection(s, width, pixelsPerCssPixel);
  }

  const int field = s.settings.field;
  if (field >= 0) {
    section("isosurface");
    ImGui::PushItemWidth(width - ImGui::GetFontSize() * 5.5f);
    if (ImGui::BeginCombo("field", m.fields[size_t(field)].name.c_str())) {
      for (size_t i = 0; i < m.fields.size(); ++i) {
        bool selected = int(i) == field;
        if (ImGui::Selectable(m.fields[i].name.c_str(), selected)) setField(s, int(i));
        if (selected) ImGui::SetItemDefaultFocus();
      }
      ImGui::EndCombo();
    }
    const Range range = m.fields[size_t(field)].range;
    float iso = s.settings.isovalue;
    if (ImGui::SliderFloat("isovalue", &iso, range.min, range.max, "%.5g")) setIsovalue(s, iso);
    s.telemetry.screen.slider = cssRect(pixelsPerCssPixel);
    ImGui::PopItemWidth();
    if (haveDataset) {
      row("triangles", grouped(s.surface.triangleCount()));
      char area[48];
      std::snprintf(area, sizeof area, "%.6g", s.surface.area());
      row("surface area", area);
    }
  }

  if (field >= 0) colourSection(s, width, pixelsPerCssPixel);
  if (field >= 0 && haveDataset) sliceSection(s, width, pixelsPerCssPixel);

  memorySection(s);

  ImGui::Spacing();
  if (ImGui::Checkbox("show boundary", &s.settings.showBoundary)) s.settingsDirty = true;
  ImGui::SameLine();
  if (ImGui::Button("reset view")) actions.resetView = true;

  ImGui::Separator();
  // Timings fold away while the slice is on (the panel would outgrow a laptop screen).
  static int lastSliceOn = -1;
  if (int(s.settings.sliceOn) != lastSliceOn) ImGui::SetNextItemOpen(!s.settings.sliceOn);
  lastSliceOn = int(s.settings.sliceOn);
  if (ImGui::TreeNodeEx("timings", ImGuiTreeNodeFlags_NoTreePushOnOpen)) {
    ImGui::TextDisabled("frames every %.1f ms, longest frame %.0f ms", s.telemetry.frameMs, s.telemetry.maxFrameMs);
    if (r.refineSteps)
      ImGui::TextDisabled("last refinement %.1f ms (%u splits, in the worker)", r.refineMs, r.refineSteps);
    ImGui::TextDisabled("last full extraction %.1f ms", r.extractMs);
    if (s.telemetry.firstSurfaceMs >= 0) {
      if (s.telemetry.completeMs >= 0)
        ImGui::TextDisabled("first surface at %.2f s, complete at %.1f s", s.telemetry.firstSurfaceMs / 1000,
                            s.telemetry.completeMs / 1000);
      else
        ImGui::TextDisabled("first surface at %.2f s", s.telemetry.firstSurfaceMs / 1000);
    }
  }
  ImGui::TextDisabled("drag rotates, right-drag pans, wheel zooms; ? for keys");

  ImGui::PopTextWrapPos();
  // An auto-resizing window takes its size from the previous frame's content.
  static ImVec2 lastSize;
  ImVec2 size = ImGui::GetWindowSize();
  {
    const ImVec2 pos = ImGui::GetWindowPos();
    const float k = 1.f / pixelsPerCssPixel;
    s.telemetry.screen.panel = {pos.x * k, pos.y * k, size.x * k, size.y * k};
  }
  actions.layoutChanged = size.x != lastSize.x || size.y != lastSize.y;
  lastSize = size;
  ImGui::End();
  return actions;
}

const Shortcut kShortcuts[] = {
    {"? or F1", "show / hide this help"},
    {"R", "reset the view"},
    {"B", "show / hide the domain boundary"},
    {"P", "slice plane on / off"},
    {"X, Y, Z", "slice across the x, y or z axis"},
    {"[ and ]", "move the slice back / forward (or shift + drag)"},
    {"C", "colour by: next field (or none)"},
    {"M", "next colour map"},
    {"F", "fit the colour range to the visible surface"},
    {"L", "copy a link to this view"},
    {"S", "save a screenshot (PNG)"},
    {"Space", "pause / resume the download"},
    {"O", "open a packed dataset folder from the disk (or drop it)"},
    {"Esc", "close this help"},
};
const int kShortcutCount = int(sizeof kShortcuts / sizeof kShortcuts[0]);

void drawHelp(bool& open, float uiScale) {
  if (!open) return;
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos(ImVec2(vp->Size.x * 0.5f, vp->Size.y * 0.5f), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowBgAlpha(0.92f);
  ImGui::Begin("keyboard shortcuts", &open,
               ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoCollapse);
  if (ImGui::BeginTable("keys", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingFixedFit)) {
    for (int i = 0; i < kShortcutCount; ++i) {
      ImGui::TableNextRow();
      ImGui::TableSetColumnIndex(0);
      ImGui::TextUnformatted(kShortcuts[i].key);
      ImGui::TableSetColumnIndex(1);
      ImGui::TextUnformatted(kShortcuts[i].action);
    }
    ImGui::EndTable();
  }
  ImGui::Spacing();
  ImGui::TextDisabled("mouse: drag rotates, right-drag pans, wheel zooms");
  ImGui::TextDisabled("touch: one finger rotates, pinch zooms, two fingers pan");
  (void)uiScale;
  ImGui::End();
}

}  // namespace tetstream::viewer
