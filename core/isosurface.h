// Marching tetrahedra (paper §4.1) over a TetMesh.
//
// Output is an indexed triangle mesh. Surface vertices are shared: one per cut mesh edge, so
// the surface is watertight wherever the field is continuous. A mesh vertex whose value equals
// the isovalue exactly becomes one surface vertex shared by all edges that meet there
// (classification rule in tet_tables.h); triangles that degenerate to a repeated vertex are
// dropped. Triangle normals point toward increasing field. Per-vertex normals are the
// area-weighted average of the incident triangle normals, normalised.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "edge_map.h"
#include "mesh.h"

namespace tetstream {

struct IsoSurface {
  std::vector<float> positions;  // 3 per surface vertex
  std::vector<float> normals;    // 3 per surface vertex, unit length (0 for isolated points)
  std::vector<uint32_t> indices; // 3 per triangle

  uint32_t vertexCount() const { return uint32_t(positions.size() / 3); }
  uint32_t triangleCount() const { return uint32_t(indices.size() / 3); }
  void clear() { positions.clear(); normals.clear(); indices.clear(); }
};

// Long-lived scratch state: create once, reuse for every extraction (no reallocation once warm).
struct IsoExtractor {
  EdgeMap vertexOfEdge;  // edge key (lo << 32 | hi), or (v << 32 | v) for a vertex on λ
};

// Extracts the isosurface field == isovalue from all tetrahedra of `mesh`, or only from those
// listed in `tetSubset` when it is non-empty. `field` has one value per mesh vertex.
// Preconditions (asserted): field.size() == mesh.vertexCount(), every tet index is in range.
void extractIsosurface(const TetMesh& mesh, std::span<const float> field, float isovalue,
                       IsoExtractor& scratch, IsoSurface& out,
                       std::span<const uint32_t> tetSubset = {});

// Sum of triangle areas, in double.
double surfaceArea(const IsoSurface& s);

}  // namespace tetstream
