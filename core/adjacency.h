// Face adjacency and boundary of a tetrahedral mesh.
// Half-face id h = 4t + f names face f (tet_tables.h kTetFaces) of tet t.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

namespace tetstream {

inline constexpr uint32_t kNoNeighbor = ~uint32_t(0);

struct FaceAdjacency {
  std::vector<uint32_t> opposite;  // 4 per tet: the matching half-face, or kNoNeighbor (boundary)
  uint64_t nonManifoldFaces = 0;   // faces shared by more than two tets (left unmatched)
};

// O(n) pairing of half-faces by their vertex triple. Preconditions (asserted): every index is
// < vertexCount. Tets with a repeated vertex take part with their (degenerate) faces.
void buildFaceAdjacency(std::span<const uint32_t> tets, uint32_t vertexCount, FaceAdjacency& out);

// Boundary triangles, 3 vertex ids each, wound outward for positively oriented tets.
void extractBoundary(std::span<const uint32_t> tets, const FaceAdjacency& adj, std::vector<uint32_t>& triangles);

// Number of boundary edges not shared by exactly two boundary triangles (0 for a closed,
// manifold boundary).
uint64_t countNonManifoldBoundaryEdges(std::span<const uint32_t> triangles);

}  // namespace tetstream
