#include "generators.h"

#include <cassert>
#include <cmath>

namespace tetstream {

TetMesh makeGridMesh(uint32_t n) {
  assert(n >= 2);
  TetMesh m;
  m.positions.reserve(3 * size_t(n) * n * n);
  for (uint32_t k = 0; k < n; ++k)
    for (uint32_t j = 0; j < n; ++j)
      for (uint32_t i = 0; i < n; ++i) {
        m.positions.push_back(-1.0f + 2.0f * float(i) / float(n - 1));
        m.positions.push_back(-1.0f + 2.0f * float(j) / float(n - 1));
        m.positions.push_back(-1.0f + 2.0f * float(k) / float(n - 1));
      }
  // Kuhn split: for each ordering (a, b, c) of the axes, the path 000 → e_a → e_a+e_b → 111.
  // Odd permutations give negatively oriented tets; swapping the middle two vertices fixes that.
  static constexpr int kPerm[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
  const uint32_t stride[3] = {1, n, n * n};
  m.tets.reserve(size_t(n - 1) * (n - 1) * (n - 1) * 24);
  for (uint32_t k = 0; k + 1 < n; ++k)
    for (uint32_t j = 0; j + 1 < n; ++j)
      for (uint32_t i = 0; i + 1 < n; ++i) {
        const uint32_t base = i + j * n + k * n * n;
        for (int p = 0; p < 6; ++p) {
          uint32_t v1 = base + stride[kPerm[p][0]];
          uint32_t v2 = v1 + stride[kPerm[p][1]];
          uint32_t v3 = base + stride[0] + stride[1] + stride[2];
          if (p < 3)
            m.tets.insert(m.tets.end(), {base, v1, v2, v3});
          else
            m.tets.insert(m.tets.end(), {base, v2, v1, v3});
        }
      }
  return m;
}

void addHarmonicField(TetMesh& m) {
  const double scale = 9.0 / 8.0 * std::exp(2.0);
  ScalarField f{"harmonic", std::vector<float>(m.vertexCount())};
  for (uint32_t v = 0; v < m.vertexCount(); ++v) {
    double x = m.positions[3 * size_t(v)], y = m.positions[3 * size_t(v) + 1], z = m.positions[3 * size_t(v) + 2];
    double r = std::sqrt(x * x + y * y + z * z);
    f.values[v] = float(scale * (2 * z * z - x * x - y * y) * std::exp(-3.0 * r));
  }
  m.fields.push_back(std::move(f));
}

void addDistanceField(TetMesh& m) {
  ScalarField f{"distance", std::vector<float>(m.vertexCount())};
  for (uint32_t v = 0; v < m.vertexCount(); ++v) {
    double x = m.positions[3 * size_t(v)], y = m.positions[3 * size_t(v) + 1], z = m.positions[3 * size_t(v) + 2];
    f.values[v] = float(std::sqrt(x * x + y * y + z * z));
  }
  m.fields.push_back(std::move(f));
}

}  // namespace tetstream
