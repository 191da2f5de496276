// A tetrahedral mesh that is refined by vertex splits and coarsened again by undoing them
// (paper §3.1, FORMAT.md §4). View side: the viewer and the CLI's reader use it, and so does
// the packer's encoder, so both sides see identical neighbourhoods.
//
// Incidence is kept as flat corner lists: corner c = 4t + k is slot k of tet t; cornerNext[c]
// links the corners of one vertex, vertexHead[v] starts the list. No per-vertex allocation.
// Tets are only ever appended (T_new) or have one slot changed (T_moved); undo reverses both.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "mesh.h"

namespace tetstream {

inline constexpr uint32_t kNoCorner = ~uint32_t(0);

// One split, decoded: the new vertex i gets id vertexCount(); `moved` lists tets (ids, all in
// star(j)) whose j slot becomes i; `newTets` holds 4 vertex ids per recreated tet (using the
// new id for i); `position` 3 floats; `fields` one value per field.
struct SplitOp {
  uint32_t j = 0;
  std::span<const uint32_t> moved;
  std::span<const uint32_t> newTets;
  const float* position = nullptr;
  const float* fields = nullptr;
};

struct ProgressiveMesh {
  TetMesh mesh;
  std::vector<uint32_t> cornerNext;  // 4 per tet
  std::vector<uint32_t> vertexHead;  // 1 per vertex
  // Undo log, one entry per applied split: the kept vertex and the tet count before the split.
  std::vector<uint32_t> splitJ, splitTetsBefore;
  uint32_t baseVertices = 0, baseTets = 0;
  // Scratch for de-duplicating vertices without sorting: a stamp per vertex.
  mutable std::vector<uint32_t> seen;
  mutable uint32_t stamp = 0;

  uint32_t vertexCount() const { return mesh.vertexCount(); }
  uint32_t tetCount() const { return mesh.tetCount(); }
  uint32_t splitsApplied() const { return uint32_t(splitJ.size()); }
};

// Takes ownership of the base mesh and builds the incidence lists.
void initProgressive(ProgressiveMesh& pm, TetMesh base);

// Tets around v, ascending ids (the canonical order of FORMAT.md §4).
void starOf(const ProgressiveMesh& pm, uint32_t v, std::vector<uint32_t>& tets);

// Distinct vertices of the tets around v, ascending, without v itself.
void neighboursOf(const ProgressiveMesh& pm, uint32_t v, std::vector<uint32_t>& vertices);

// Applies a split. Preconditions (asserted; the decoder validates untrusted data first):
// j exists, every moved tet contains j, new tets reference existing vertices or the new one.
// Appends the ids of every tet whose vertices changed (moved, then new) to `changed`.
void applySplit(ProgressiveMesh& pm, const SplitOp& op, std::vector<uint32_t>& changed);

// Undoes the last applied split. Appends the moved tet ids to `changed`; the removed tets are
// those with id >= tetCount() afterwards.
void undoSplit(ProgressiveMesh& pm, std::vector<uint32_t>& changed);

}  // namespace tetstream
