#include "mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tetstream {

int TetMesh::findField(std::string_view fieldName) const {
  for (size_t i = 0; i < fields.size(); ++i)
    if (fields[i].name == fieldName) return int(i);
  return -1;
}

float Bounds::diagonal() const {
  float dx = max[0] - min[0], dy = max[1] - min[1], dz = max[2] - min[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

Bounds computeBounds(std::span<const float> positions) {
  Bounds b;
  if (positions.size() < 3) return b;
  for (int k = 0; k < 3; ++k) b.min[k] = b.max[k] = positions[k];
  for (size_t i = 0; i + 2 < positions.size(); i += 3)
    for (int k = 0; k < 3; ++k) {
      float x = positions[i + k];
      if (x < b.min[k]) b.min[k] = x;
      if (x > b.max[k]) b.max[k] = x;
    }
  return b;
}

Range computeRange(std::span<const float> values) {
  Range r;
  bool any = false;
  for (float v : values) {
    if (!std::isfinite(v)) continue;
    if (!any) {
      r.min = r.max = v;
      any = true;
      continue;
    }
    if (v < r.min) r.min = v;
    if (v > r.max) r.max = v;
  }
  return r;
}

double tetVolume(const float* a, const float* b, const float* c, const float* d) {
  double u[3], v[3], w[3];
  for (int k = 0; k < 3; ++k) {
    u[k] = double(b[k]) - a[k];
    v[k] = double(c[k]) - a[k];
    w[k] = double(d[k]) - a[k];
  }
  double det =
      u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
  return det / 6.0;
}

double barycentric(const float* const q[4], const float* x, double l[4]) {
  const double det = tetVolume(q[0], q[1], q[2], q[3]);
  if (det == 0) return -std::numeric_limits<double>::infinity();
  double lo = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 4; ++k) {
    const float* r[4] = {q[0], q[1], q[2], q[3]};
    r[k] = x;
    l[k] = tetVolume(r[0], r[1], r[2], r[3]) / det;
    lo = std::min(lo, l[k]);
  }
  return lo;
}

}  // namespace tetstream
