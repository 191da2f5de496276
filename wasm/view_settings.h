// What the user chose to see, as the page holds it: the field and isovalue, colouring, the slice
// plane and what to fetch. The page owns these (its panel and window.tetstream change them at
// once) and hands them to the refinement worker as the view object (viewObject's keys), which
// applies them to its model (applyView in viewer_state.h). The rules of a choice (another field
// puts the isovalue in the middle of its range, a colour field brings its range, a slice without
// a colour field colours by the isovalue's field) are made here only: the worker takes the
// values as they are. GL-free and Emscripten-free.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <nlohmann/json_fwd.hpp>
#include <span>

#include "colourmap.h"
#include "fetch_plan.h"
#include "manifest.h"

namespace tetstream::viewer {

struct ViewSettings {
  int field = -1;  // index into the manifest's fields
  float isovalue = 0;
  int colourField = -1;  // -1: the two-sided tint
  ColourMap colourMap = ColourMap::Viridis;
  float colourMin = 0, colourMax = 1;
  bool sliceOn = false;
  std::array<float, 3> sliceNormal{0, 0, 1};  // unit length
  float sliceOffset = 0;
  FetchMode fetch = FetchMode::Needed;
  bool showBoundary = true;
};

// The settings a newly opened dataset starts from: its isovalue field at the middle of its
// range, no colouring, the slice across z through the middle (off).
ViewSettings initialSettings(const Manifest& m);

// Each returns false (and changes nothing) for a choice that does not exist.
bool chooseField(ViewSettings& v, const Manifest& m, int index);
bool chooseIsovalue(ViewSettings& v, float value);  // non-finite values are refused
bool chooseColourField(ViewSettings& v, const Manifest& m, int index);
void chooseColourRange(ViewSettings& v, float lo, float hi);           // non-finite refused; swapped when reversed
void chooseSliceEnabled(ViewSettings& v, const Manifest& m, bool on);  // colours by the isovalue's field when none
bool chooseSlicePlane(ViewSettings& v, std::array<float, 3> normal, float offset);  // a zero normal is refused
// The range of offsets that cut the dataset's bounds for the slice's normal.
void sliceOffsetRange(const ViewSettings& v, const Manifest& m, float& lo, float& hi);

// What "fit" makes the colour range: the colour values at the vertices the shown triangles use
// (free slots hold stale values), padded around a flat colour so the map still shows where it
// is. Works on the model's surfaces and on the page's mirrors alike.
struct ColourSpan {
  float lo = std::numeric_limits<float>::infinity(), hi = -std::numeric_limits<float>::infinity();

  template <class Surface>
  void cover(const Surface& surface) {
    std::span<const float> colours = surface.colours();
    for (uint32_t v : surface.indices()) {
      lo = std::min(lo, colours[v]);
      hi = std::max(hi, colours[v]);
    }
  }
  // False when nothing was covered. `field`: the colour field's whole range.
  bool fitted(const Range& field, float& outLo, float& outHi) const;
};

// The view object (docs/js-api.md: field, isovalue, colourField, colourMap, colourRange,
// slice {on, normal, offset}, showBoundary, fetch) without the level, which the model keeps.
nlohmann::json settingsObject(const ViewSettings& v, const Manifest& m);

}  // namespace tetstream::viewer
