// The domain boundary of a progressive mesh (translucent hull and crease lines), kept up to date
// across vertex splits and their undo.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "isosurface_incremental.h"
#include "progressive.h"

namespace tetstream {

// Boundary edges whose two triangles' normals differ by more than ~30 degrees are creases.
inline constexpr float kCreaseCos = 0.866f;

// Outward unit normal n of triangle tri (vertex ids into positions p, 3 floats each), 0 when
// degenerate.
void triangleNormal(const float* p, const uint32_t tri[3], float n[3]);

// The domain boundary (translucent hull and crease lines) of a ProgressiveMesh, kept up to date
// across vertex splits and their undo without looking at the whole mesh: only faces and edges
// at the split vertices can change (a split touches star(i) ∪ star(j) only, paper §4.3), so
// update() recounts the faces around those vertices.
//
// Renderer-facing arrays, dense (a removed slot is refilled with the last one):
//   trianglePositions(): 9 floats per triangle slot (3 corners), triangleNormals(): the same
//   layout, the triangle's outward unit normal at each corner; lineVertices(): 6 floats per
//   crease segment. Change tracking as IncrementalIsosurface: changedTriangles()/changedLines()
//   list slots written since clearChanges() (possibly >= the current count: ignore those);
//   fullUploadNeeded() after rebuild().
// Memory: per boundary triangle about 110 bytes, per vertex 4 bytes, per crease line ~40 bytes.
class HullTracker {
 public:
  static constexpr uint32_t kNone = ~uint32_t(0);

  void clear();
  // From scratch (face adjacency over the whole mesh): the base level, or after a failure.
  void rebuild(const ProgressiveMesh& pm);
  // After splits or undos: `vertices` holds every split's i and j as pairs, in the order the
  // splits or undos were applied (ids may repeat; ids >= pm.vertexCount() are vertices removed
  // by undo).
  void update(const ProgressiveMesh& pm, std::span<const uint32_t> vertices);

  uint32_t triangleCount() const { return uint32_t(faces_.size() / 3); }
  uint32_t lineCount() const { return uint32_t(lineKeys_.size()); }
  std::span<const float> trianglePositions() const { return positions_; }
  std::span<const float> triangleNormals() const { return normals_; }
  std::span<const float> lineVertices() const { return lines_; }
  // Boundary triangles as outward-wound vertex id triples (tests).
  std::span<const uint32_t> faces() const { return faces_; }
  size_t memoryBytes() const;  // vector capacities

  bool fullUploadNeeded() const { return fullUpload_; }
  std::span<const uint32_t> changedTriangles() const { return changedTriangles_; }
  std::span<const uint32_t> changedLines() const { return changedLines_; }
  void clearChanges();

 private:
  struct FaceEntry {
    uint64_t key;      // the face's two vertices other than the one recounted (edge key)
    uint32_t tetFace;  // tet << 2 | local face
  };
  void recount(const ProgressiveMesh& pm, uint32_t v);
  void addFace(const float* positions, const uint32_t tri[3]);
  void removeFace(uint32_t slot);
  void link(uint32_t corner, uint32_t v);
  void unlink(uint32_t corner);
  void markEdges(const uint32_t tri[3]);
  void updateEdge(const float* positions, uint64_t key);
  void removeLine(uint32_t slot);

  // Triangle slots: faces_ 3 vertex ids, positions_/normals_ 9 floats. Corner c = 3 slot + k is
  // linked into the list of vertex faces_[c] (head_, next_, prev_; kNone ends a list).
  std::vector<uint32_t> faces_;
  std::vector<float> positions_, normals_;
  std::vector<uint32_t> head_, next_, prev_;
  // Crease lines: lines_ 6 floats per slot, lineKeys_ the edge of each slot, lineOfEdge_ the
  // reverse (edge key lo << 32 | hi -> slot).
  std::vector<float> lines_;
  std::vector<uint64_t> lineKeys_;
  FlatMap lineOfEdge_;

  std::vector<uint64_t> dirtyEdges_;
  std::vector<FaceEntry> entries_;                               // recount scratch
  std::vector<uint32_t> vertexScratch_, dropScratch_, touched_;  // update scratch
  std::vector<uint32_t> changedTriangles_, changedLines_;
  bool fullUpload_ = false;
};

}  // namespace tetstream
