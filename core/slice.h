// The slice plane through the volume: the plane n·p = offset cut through every tet, a polygon
// mesh kept up to date by the same local updates as the isosurface (paper §4.3). The slice is
// the zero set of the per-vertex signed distance d(v) = n·p(v) - offset, so it is an
// IncrementalIsosurface over that distance field at isovalue 0, with the colour field
// interpolated at its vertices; the distances of vertices a split adds are computed as they
// appear (a vertex keeps its position once it exists, so the others stay valid).
//
// No interval tree: the distance field changes with every move of the plane, and a tree costs
// more to build (~150 ms at 1.5M tets in wasm) than testing every tet's interval once (~10 ms);
// the tree stays deferred with nothing covered, so rebuild() tests every tet.
// Memory: 4 bytes per mesh vertex (the distances) plus the slice's surface.
#pragma once
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "isosurface_incremental.h"
#include "mesh.h"

namespace tetstream {

class SliceTracker {
 public:
  // The plane n·p = offset; n is normalised here (a zero or non-finite normal is refused).
  // Returns false when nothing changed. The slice is stale until rebuild().
  bool setPlane(std::array<float, 3> normal, float offset);
  // Scales `normal` to unit length; false for a zero or non-finite one.
  static bool normalise(std::array<float, 3>& normal);
  std::array<float, 3> normal() const { return normal_; }
  float offset() const { return offset_; }

  // The whole slice of the current mesh, colour empty or one value per vertex.
  void rebuild(const TetMesh& mesh, std::span<const float> colour);
  // After splits or undos: the changed tets as IncrementalIsosurface::updateTets wants them.
  // Precondition: rebuild() since the last setPlane() or clear().
  void update(const TetMesh& mesh, std::span<const uint32_t> changedTets, std::span<const float> colour);
  void recolour(std::span<const float> colour) { surface_.recolour(colour); }
  void clear();
  bool built() const { return built_; }

  const IncrementalIsosurface& surface() const { return surface_; }
  IncrementalIsosurface& surface() { return surface_; }
  std::span<const float> distances() const { return distances_; }
  size_t memoryBytes() const { return surface_.memoryBytes() + distances_.capacity() * sizeof(float); }

  // The range of n·p over the corners of a box (the slider's range for this normal).
  static void offsetRange(std::array<float, 3> normal, const float boxMin[3], const float boxMax[3], float& lo,
                          float& hi);

 private:
  void syncDistances(const TetMesh& mesh);
  std::array<float, 3> normal_{0, 0, 1};
  float offset_ = 0;
  bool built_ = false;
  std::vector<float> distances_;
  IncrementalIsosurface surface_;
};

}  // namespace tetstream
