#include "dist/base_error.h"

#include <algorithm>
#include <cmath>

namespace tetstream::dist {
namespace {

// The base's tets by a uniform grid of cells over its bounding box (each tet in every cell its box
// meets): about one tet a cell, so a point is located by testing the few tets of its cell.
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

  // The value of `values` at x, interpolated in the tet of x's cell that x is least outside of;
  // false when the cell has none (then the nearest cells along a widening box are searched).
  bool interpolate(const float* x, const std::vector<float>& values, double& out) const {
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
      double sum = 0, value = 0;
      for (double& w : bestL) sum += w = std::max(w, 0.0);
      const uint32_t* v = &m_.tets[4 * size_t(bestTet)];
      for (int k = 0; k < 4; ++k) value += (sum > 0 ? bestL[k] / sum : 0.25) * values[v[k]];
      out = value;
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

}  // namespace

void measureBaseError(Comm& comm, const TetMesh* base, const PartMesh& input, int field, double& rms, double& max) {
  Bytes mine;
  if (base) {
    Writer w(mine);
    w.putVector(base->positions);
    w.putVector(base->tets);
    w.putVector(base->fields[size_t(field)].values);
  }
  TetMesh shared;
  std::vector<float> values;
  for (const Bytes& b : comm.allGather(mine)) {
    if (b.empty()) continue;
    Reader in(b);
    shared.positions = in.getVector<float>();
    shared.tets = in.getVector<uint32_t>();
    values = in.getVector<float>();
  }
  std::vector<double> sums(2, 0), largest(1, 0);  // squared errors, vertices; the largest
  if (!shared.tets.empty() && values.size() == shared.vertexCount()) {
    const TetGrid grid(shared);
    const std::vector<float>& samples = input.mesh.fields[size_t(field)].values;
    for (uint32_t v = 0; v < input.mesh.vertexCount(); ++v) {
      double at;
      if (!input.owned[v] || !std::isfinite(samples[v]) ||
          !grid.interpolate(&input.mesh.positions[3 * size_t(v)], values, at) || !std::isfinite(at))
        continue;
      const double e = std::abs(at - samples[v]);
      sums[0] += e * e;
      sums[1] += 1;
      largest[0] = std::max(largest[0], e);
    }
  }
  comm.sumInPlace(sums);
  comm.maxInPlace(largest);
  rms = sums[1] > 0 ? std::sqrt(sums[0] / sums[1]) : 0;
  max = largest[0];
}

}  // namespace tetstream::dist
