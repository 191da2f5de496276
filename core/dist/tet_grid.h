// Point location in a coarse mesh (the distributed pack's base, a few hundred thousand tets) for
// many points: a uniform grid of cells over its bounding box, each tet listed in every cell its
// box meets, about one tet a cell. A point outside the mesh (where a coarse boundary cuts across
// a curved one) takes the tet it is least outside of among those near it.
#pragma once
#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <vector>

#include "mesh.h"

namespace tetstream::dist {

class TetGrid {
 public:
  explicit TetGrid(const TetMesh& m) : m_(m) {
    b_ = computeBounds(m.positions);
    const double cells = std::clamp(double(m.tetCount()), 1.0, 128.0 * 128 * 128);
    for (int k = 0; k < 3; ++k) {
      n_[k] = std::max(1, int(std::cbrt(cells)));
      const double extent = double(b_.max[k]) - b_.min[k];
      scale_[k] = extent > 0 ? n_[k] / extent : 0;
    }
    std::vector<uint32_t> count(size_t(n_[0]) * n_[1] * n_[2] + 1, 0);
    forCells([&](uint32_t, size_t c) { ++count[c + 1]; });
    for (size_t c = 1; c < count.size(); ++c) count[c] += count[c - 1];
    start_ = count;
    items_.resize(count.back());
    forCells([&](uint32_t t, size_t c) { items_[count[c]++] = t; });
  }

  // Where x is: the four vertices of the tet of its cell that x is least outside of (searching
  // ever wider boxes of cells when its own has none) and x's coordinates there, clamped to the
  // tet. False for an empty mesh.
  struct Location {
    uint32_t vertex[4];
    double w[4];
  };
  bool locate(const float* x, Location& out) const {
    int c[3];
    for (int k = 0; k < 3; ++k) c[k] = cellOf(x[k], k);
    for (int r = 0; r < std::max({n_[0], n_[1], n_[2]}); ++r) {
      double best = -INFINITY, l[4], bestL[4] = {0, 0, 0, 0};
      uint32_t bestTet = ~0u;
      for (int i = std::max(0, c[0] - r); i <= std::min(n_[0] - 1, c[0] + r); ++i)
        for (int j = std::max(0, c[1] - r); j <= std::min(n_[1] - 1, c[1] + r); ++j)
          for (int k = std::max(0, c[2] - r); k <= std::min(n_[2] - 1, c[2] + r); ++k) {
            const size_t cell = (size_t(k) * n_[1] + j) * n_[0] + i;
            for (uint32_t a = start_[cell]; a < start_[cell + 1]; ++a) {
              const uint32_t t = items_[a];
              const uint32_t* v = &m_.tets[4 * size_t(t)];
              const float* q[4] = {&m_.positions[3 * size_t(v[0])], &m_.positions[3 * size_t(v[1])],
                                   &m_.positions[3 * size_t(v[2])], &m_.positions[3 * size_t(v[3])]};
              const double least = barycentric(q, x, l);
              if (least > best) {
                best = least;
                bestTet = t;
                std::copy(l, l + 4, bestL);
              }
            }
          }
      if (bestTet == ~0u) continue;
      double sum = 0;
      for (double& w : bestL) sum += w = std::max(w, 0.0);
      const uint32_t* v = &m_.tets[4 * size_t(bestTet)];
      for (int k = 0; k < 4; ++k) {
        out.vertex[k] = v[k];
        out.w[k] = sum > 0 ? bestL[k] / sum : 0.25;
      }
      return true;
    }
    return false;
  }

 private:
  int cellOf(double x, int k) const { return std::clamp(int((x - b_.min[k]) * scale_[k]), 0, n_[k] - 1); }
  template <typename F>
  void forCells(F f) const {
    for (uint32_t t = 0; t < m_.tetCount(); ++t) {
      int lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {-1, -1, -1};
      for (int c = 0; c < 4; ++c)
        for (int k = 0; k < 3; ++k) {
          const int cell = cellOf(m_.positions[3 * size_t(m_.tets[4 * size_t(t) + size_t(c)]) + size_t(k)], k);
          lo[k] = std::min(lo[k], cell);
          hi[k] = std::max(hi[k], cell);
        }
      for (int k = lo[2]; k <= hi[2]; ++k)
        for (int j = lo[1]; j <= hi[1]; ++j)
          for (int i = lo[0]; i <= hi[0]; ++i) f(t, (size_t(k) * n_[1] + j) * n_[0] + i);
    }
  }

  const TetMesh& m_;
  Bounds b_;
  int n_[3] = {1, 1, 1};
  double scale_[3] = {0, 0, 0};
  std::vector<uint32_t> start_, items_;
};

}  // namespace tetstream::dist
