#include "colourmap.h"

#include <algorithm>
#include <cmath>

namespace tetstream::viewer {
namespace {

const float kTables[kColourMapCount][kColourMapSize][3] = {
#include "colourmap_tables.inc"
};

}  // namespace

const char* colourMapName(ColourMap m) {
  switch (m) {
    case ColourMap::Viridis: return "viridis";
    case ColourMap::Magma: return "magma";
    case ColourMap::Turbo: return "turbo";
    case ColourMap::CoolWarm: return "coolwarm";
    case ColourMap::Grey: return "grey";
  }
  return "viridis";
}

std::optional<ColourMap> parseColourMap(std::string_view name) {
  for (int i = 0; i < kColourMapCount; ++i)
    if (name == colourMapName(ColourMap(i))) return ColourMap(i);
  if (name == "cool-warm") return ColourMap::CoolWarm;
  if (name == "gray") return ColourMap::Grey;
  return std::nullopt;
}

const float (*colourMapTable(ColourMap m))[3] { return kTables[int(m)]; }

float colourPosition(float value, float lo, float hi) {
  if (std::isnan(value)) return 0.f;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) return 0.5f;
  return std::clamp((value - lo) / (hi - lo), 0.f, 1.f);
}

std::array<float, 3> mapColour(ColourMap m, float value, float lo, float hi) {
  const float(*t)[3] = colourMapTable(m);
  const float x = colourPosition(value, lo, hi) * float(kColourMapSize - 1);
  const int i = std::min(int(x), kColourMapSize - 2);
  const float f = x - float(i);
  std::array<float, 3> c;
  for (int k = 0; k < 3; ++k) c[size_t(k)] = t[i][k] + f * (t[i + 1][k] - t[i][k]);
  return c;
}

}  // namespace tetstream::viewer
