#include "slice.h"

#include <algorithm>
#include <cmath>

namespace tetstream {

bool SliceTracker::normalise(std::array<float, 3>& normal) {
  const double len =
      std::sqrt(double(normal[0]) * normal[0] + double(normal[1]) * normal[1] + double(normal[2]) * normal[2]);
  if (!(len > 0) || !std::isfinite(len)) return false;
  for (int k = 0; k < 3; ++k) normal[size_t(k)] = float(normal[size_t(k)] / len);
  return true;
}

bool SliceTracker::setPlane(std::array<float, 3> normal, float offset) {
  std::array<float, 3> n = normal;
  if (!normalise(n) || !std::isfinite(offset)) return false;
  if (n == normal_ && offset == offset_) return false;
  normal_ = n;
  offset_ = offset;
  built_ = false;
  distances_.clear();
  return true;
}

void SliceTracker::syncDistances(const TetMesh& mesh) {
  const uint32_t n = mesh.vertexCount();
  if (distances_.size() > n) distances_.resize(n);  // vertices removed by undo
  for (uint32_t v = uint32_t(distances_.size()); v < n; ++v) {
    const float* p = &mesh.positions[3 * size_t(v)];
    // In double, so a vertex exactly on the plane gets exactly 0.
    const double d = double(normal_[0]) * p[0] + double(normal_[1]) * p[1] + double(normal_[2]) * p[2] - offset_;
    distances_.push_back(float(d));
  }
}

void SliceTracker::rebuild(const TetMesh& mesh, std::span<const float> colour) {
  surface_.reset();
  surface_.setTreeDeferred(true);
  distances_.clear();
  syncDistances(mesh);
  surface_.rebuild(mesh, distances_, 0.f, colour);
  built_ = true;
}

void SliceTracker::update(const TetMesh& mesh, std::span<const uint32_t> changedTets, std::span<const float> colour) {
  if (!built_) return;
  syncDistances(mesh);
  surface_.updateTets(mesh, distances_, changedTets, colour);
}

void SliceTracker::clear() {
  surface_.reset();
  distances_.clear();
  built_ = false;
}

void SliceTracker::offsetRange(std::array<float, 3> normal, const float boxMin[3], const float boxMax[3], float& lo,
                               float& hi) {
  lo = hi = 0;
  for (int c = 0; c < 8; ++c) {
    double d = 0;
    for (int k = 0; k < 3; ++k) d += double(normal[size_t(k)]) * ((c >> k) & 1 ? boxMax[k] : boxMin[k]);
    if (c == 0 || d < lo) lo = float(d);
    if (c == 0 || d > hi) hi = float(d);
  }
}

}  // namespace tetstream
