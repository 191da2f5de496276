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

#include "flat_map.h"
#include "mesh.h"

namespace tetstream {

struct IsoSurface {
  std::vector<float> positions;   // 3 per surface vertex
  std::vector<float> normals;     // 3 per surface vertex, unit length (0 for isolated points)
  std::vector<uint32_t> indices;  // 3 per triangle

  uint32_t vertexCount() const { return uint32_t(positions.size() / 3); }
  uint32_t triangleCount() const { return uint32_t(indices.size() / 3); }
  void clear() {
    positions.clear();
    normals.clear();
    indices.clear();
  }
};

// The surface vertex on mesh edge (a, b), one end above λ and one at or below. Both extractors
// (this one and IncrementalIsosurface) build their vertices with cutEdge() and cutValue(), so
// they agree on every key and every position bit.
struct CutEdge {
  uint32_t lo, hi;  // the end at or below λ, the end above
  float s0, s1;     // their values: s1 > λ >= s0
  bool onVertex;    // s0 == λ: the surface vertex is mesh vertex lo itself
  uint64_t key;     // edgeKey(a, b), or lo << 32 | lo when onVertex (one vertex for all its edges)

  // Paper eq. (7) with p0 = lo, p1 = hi: the denominator is positive, the weights lie in [0, 1].
  float weightHi(float isovalue) const { return (isovalue - s0) / (s1 - s0); }
};

inline CutEdge cutEdge(const float* field, float isovalue, uint32_t a, uint32_t b) {
  CutEdge c;
  c.lo = field[a] > isovalue ? b : a;
  c.hi = c.lo == a ? b : a;
  c.s0 = field[c.lo];
  c.s1 = field[c.hi];
  c.onVertex = c.s0 == isovalue;
  c.key = c.onVertex ? (uint64_t(c.lo) << 32 | c.lo) : edgeKey(a, b);
  return c;
}

// A per-vertex quantity (a coordinate, a colour) at the surface vertex of c, from its values at
// lo and hi and the weights w0 = 1 - w1, w1 = c.weightHi(λ).
inline float cutValue(const CutEdge& c, float w0, float w1, float atLo, float atHi) {
  return c.onVertex ? atLo : w0 * atLo + w1 * atHi;
}

// Long-lived scratch state: create once, reuse for every extraction (no reallocation once warm).
struct IsoExtractor {
  FlatMap vertexOfEdge;  // CutEdge::key -> surface vertex
};

// Extracts the isosurface field == isovalue from all tetrahedra of `mesh`, or only from those
// listed in `tetSubset` when it is non-empty. `field` has one value per mesh vertex.
// Preconditions (asserted): field.size() == mesh.vertexCount(), every tet index is in range.
void extractIsosurface(const TetMesh& mesh, std::span<const float> field, float isovalue, IsoExtractor& scratch,
                       IsoSurface& out, std::span<const uint32_t> tetSubset = {});

// Sum of triangle areas, in double.
double surfaceArea(const IsoSurface& s);

}  // namespace tetstream

namespace tetstream {

// Whether two surfaces have the same triangles, bit for bit, whatever their vertex and triangle
// order: each triangle as its three corner positions, turned to start at its smallest corner
// (its orientation kept). Surfaces of two meshes that share the tets cut, with the same values
// at their vertices, compare equal however the meshes number them (cutEdge() orders each edge
// by value, not by id).
bool sameTriangles(const IsoSurface& a, const IsoSurface& b);

}  // namespace tetstream
