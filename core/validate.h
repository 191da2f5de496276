// Mesh validation: what is wrong with a mesh, counted, with one human-readable line per kind
// of finding. Used by `tetstream info` and before packing.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "adjacency.h"
#include "mesh.h"

namespace tetstream {

struct ValidationReport {
  // Fatal: the mesh cannot be used as it is.
  uint64_t outOfRangeIndices = 0;   // tets referencing a vertex id >= vertexCount
  uint64_t repeatedVertexTets = 0;  // tets using one vertex twice
  uint64_t nonFinitePositions = 0;  // vertices with a NaN or infinite coordinate
  bool noTets = false;
  // Flaws a robust tool copes with.
  uint64_t positiveTets = 0, negativeTets = 0;
  uint64_t invertedTets = 0;    // oriented against the mesh's majority orientation
  uint64_t zeroVolumeTets = 0;  // |6V| <= 1e-9 * (longest edge)^3
  uint64_t duplicateTets = 0;   // same four vertices as an earlier tet
  uint64_t unusedVertices = 0;
  uint64_t nonFiniteFieldValues = 0;
  uint64_t nonManifoldFaces = 0;  // faces shared by more than two tets
  uint64_t boundaryFaces = 0;
  uint64_t nonManifoldBoundaryEdges = 0;
  std::vector<std::string> findings;  // one line per non-zero count, in plain words

  bool fatal() const { return noTets || outOfRangeIndices || repeatedVertexTets || nonFinitePositions; }
};

// With `adjacency`, the face adjacency it builds is handed over (empty when the indices are bad).
ValidationReport validateMesh(const TetMesh& mesh, FaceAdjacency* adjacency = nullptr);

}  // namespace tetstream
