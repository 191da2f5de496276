#include "view_settings.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <utility>

#include "slice.h"

namespace tetstream::viewer {
namespace {
float middleOf(const Range& r) { return r.min + 0.5f * (r.max - r.min); }
}  // namespace

ViewSettings initialSettings(const Manifest& m) {
  ViewSettings v;
  int f = m.findField(m.isoField);
  if (f < 0 && !m.fields.empty()) f = 0;
  v.field = f;
  if (f >= 0) v.isovalue = middleOf(m.fields[size_t(f)].range);
  v.sliceOffset = 0.5f * (m.bounds.min[2] + m.bounds.max[2]);
  return v;
}

bool chooseField(ViewSettings& v, const Manifest& m, int index) {
  if (index < 0 || size_t(index) >= m.fields.size()) return false;
  v.field = index;
  v.isovalue = middleOf(m.fields[size_t(index)].range);
  return true;
}

bool chooseIsovalue(ViewSettings& v, float value) {
  if (!std::isfinite(value)) return false;
  v.isovalue = value;
  return true;
}

bool chooseColourField(ViewSettings& v, const Manifest& m, int index) {
  if (index < -1 || index >= int(m.fields.size())) return false;
  v.colourField = index;
  if (index >= 0) {
    v.colourMin = float(m.fields[size_t(index)].range.min);
    v.colourMax = float(m.fields[size_t(index)].range.max);
  }
  return true;
}

void chooseColourRange(ViewSettings& v, float lo, float hi) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) return;
  if (lo > hi) std::swap(lo, hi);
  v.colourMin = lo;
  v.colourMax = hi;
}

void chooseSliceEnabled(ViewSettings& v, const Manifest& m, bool on) {
  if (on && !v.sliceOn && v.colourField < 0) chooseColourField(v, m, v.field);
  v.sliceOn = on;
}

bool chooseSlicePlane(ViewSettings& v, std::array<float, 3> normal, float offset) {
  if (!SliceTracker::normalise(normal) || !std::isfinite(offset)) return false;
  v.sliceNormal = normal;
  v.sliceOffset = offset;
  return true;
}

void sliceOffsetRange(const ViewSettings& v, const Manifest& m, float& lo, float& hi) {
  SliceTracker::offsetRange(v.sliceNormal, m.bounds.min, m.bounds.max, lo, hi);
}

bool ColourSpan::fitted(const Range& field, float& outLo, float& outHi) const {
  if (!(lo <= hi)) return false;
  outLo = lo;
  outHi = hi;
  if (lo == hi) {
    const float pad = std::max(1e-6f * std::abs(lo), float(field.max - field.min) * 1e-3f);
    outLo -= pad;
    outHi += pad;
  }
  return true;
}

nlohmann::json settingsObject(const ViewSettings& v, const Manifest& m) {
  using json = nlohmann::json;
  auto name = [&](int f) {
    return f >= 0 && size_t(f) < m.fields.size() ? json(m.fields[size_t(f)].name) : json(nullptr);
  };
  return {
      {"field", name(v.field)},
      {"isovalue", v.isovalue},
      {"colourField", name(v.colourField)},
      {"colourMap", colourMapName(v.colourMap)},
      {"colourRange", json::array({v.colourMin, v.colourMax})},
      {"slice",
       {{"on", v.sliceOn},
        {"normal", json::array({v.sliceNormal[0], v.sliceNormal[1], v.sliceNormal[2]})},
        {"offset", v.sliceOffset}}},
      {"showBoundary", v.showBoundary},
      {"fetch", v.fetch == FetchMode::Everything ? "everything" : "needed"},
  };
}

}  // namespace tetstream::viewer
