// The quantization grid of the vertex-split stream (FORMAT.md §4): positions over the bounding
// box and each field over its range, on 2^bits - 1 steps. The packer snaps every value to this
// grid before simplifying, so every check it makes (no inverted tetrahedron at any level) holds
// for exactly the values a viewer decodes. Both sides call the same functions, so the floats
// agree bit for bit.
#pragma once
#include <cmath>
#include <cstdint>
#include <vector>

#include "manifest.h"

namespace tetstream {

struct QuantAxis {
  float min = 0, step = 1;
  uint32_t maxQ = 0;

  uint32_t quantize(float x) const {
    if (step <= 0) return 0;
    double q = std::nearbyint((double(x) - min) / step);
    return q >= 0 ? (q > maxQ ? maxQ : uint32_t(q)) : 0;  // NaN lands on 0 too
  }
  float dequantize(uint32_t q) const { return min + float(q) * step; }
  // x as a reader decodes it: the nearest grid value.
  float snap(float x) const { return dequantize(quantize(x)); }
};

inline QuantAxis makeAxis(float lo, float hi, int bits) {
  QuantAxis a;
  a.maxQ = (1u << bits) - 1;
  a.min = lo;
  a.step = hi > lo ? float((double(hi) - lo) / a.maxQ) : 0.0f;
  return a;
}

struct Quantizer {
  bool lossless = false;
  QuantAxis position[3];
  std::vector<QuantAxis> field;  // one per manifest field
};

inline Quantizer makeQuantizer(const Manifest& m) {
  Quantizer q;
  q.lossless = m.lossless;
  for (int k = 0; k < 3; ++k) q.position[k] = makeAxis(m.bounds.min[k], m.bounds.max[k], m.positionBits);
  for (const FieldInfo& f : m.fields) q.field.push_back(makeAxis(f.range.min, f.range.max, m.fieldBits));
  return q;
}

}  // namespace tetstream
