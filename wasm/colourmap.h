// Perceptual colour maps for colouring by a field (isosurface and slice): viridis, magma,
// turbo, cool-warm (diverging) and grey, each a 256-entry table from the published data
// (wasm/colourmap_tables.inc, written by scripts/gen_colourmaps.py). No GL: the renderer
// uploads colourMapTable() as a 256x1 texture and the shader does what mapColour() does.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace tetstream::viewer {

enum class ColourMap : uint8_t { Viridis, Magma, Turbo, CoolWarm, Grey };
inline constexpr int kColourMapCount = 5;
inline constexpr int kColourMapSize = 256;

// "viridis", "magma", "turbo", "coolwarm", "grey".
const char* colourMapName(ColourMap m);
// Accepts the names above (and "cool-warm", "gray"); nullopt otherwise.
std::optional<ColourMap> parseColourMap(std::string_view name);

// The table: kColourMapSize entries of {r, g, b} in 0..1.
const float (*colourMapTable(ColourMap m))[3];

// Where `value` falls in [lo, hi], clamped to [0, 1] (0.5 when the range is empty or not
// finite; 0 for a NaN value).
float colourPosition(float value, float lo, float hi);

// The colour of `value` for the range [lo, hi]: values outside clamp to the end colours;
// between table entries linear interpolation (the texture's filtering does the same).
std::array<float, 3> mapColour(ColourMap m, float value, float lo, float hi);

}  // namespace tetstream::viewer
