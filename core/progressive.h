// A tetrahedral mesh that is refined by vertex splits and coarsened again by undoing them
// (paper §3.1, FORMAT.md §4). View side: the viewer and the CLI's reader use it, and so does
// the packer's encoder, so both sides see identical neighbourhoods.
//
// Incidence: corner c = 4t + k is slot k of tet t. Each vertex keeps its corners in one block of
// a shared pool (StarPool below), so walking a star reads one or two cache lines instead of
// chasing a linked list through the whole mesh: a split reads the star of j twice and a linked
// list made that half of the streaming time. No per-vertex allocation.
// Tets are only ever appended (T_new) or have one slot changed (T_moved); undo reverses both.
// A split may also give p_j a value back (fitted values, FORMAT.md §4); undo restores it.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "mesh.h"

namespace tetstream {

// Per-vertex corner lists in one flat array. Block sizes go 8, 12, 16, 24, 32, 48, ... (steps of
// about 1.5); a full block moves to the next size, and freed blocks are kept by size for reuse,
// so the pool holds about 1.3 slots per corner and never needs compacting. Order within a list is not meaningful
// (starOf and neighboursOf sort).
class StarPool {
 public:
  void clear();
  void reserve(size_t vertices, size_t corners);
  // Appends a vertex with room for `capacity` corners; returns its id.
  uint32_t addVertex(uint32_t capacity);
  void popVertex();  // the last one; its block is freed
  uint32_t vertexCount() const { return uint32_t(start_.size()); }
  void add(uint32_t v, uint32_t corner) {
    if (size_[v] == capacityOf(cls_[v])) grow(v);
    pool_[start_[v] + size_[v]++] = corner;
  }
  // Removes every corner for which drop(corner) holds.
  template <typename Pred>
  void removeIf(uint32_t v, Pred drop) {
    uint32_t* c = &pool_[start_[v]];
    uint32_t n = 0;
    for (uint32_t k = 0; k < size_[v]; ++k)
      if (!drop(c[k])) c[n++] = c[k];
    size_[v] = n;
  }
  std::span<const uint32_t> corners(uint32_t v) const { return {pool_.data() + start_[v], size_[v]}; }
  size_t bytes() const;  // memory held

 private:
  static uint32_t capacityOf(uint8_t cls) { return (cls & 1 ? 12u : 8u) << (cls >> 1); }
  static uint8_t classFor(uint32_t capacity);
  uint32_t allocate(uint8_t cls);
  void release(uint32_t start, uint8_t cls);
  void grow(uint32_t v);

  std::vector<uint32_t> pool_;
  std::vector<uint32_t> start_, size_;
  std::vector<uint8_t> cls_;
  std::vector<std::vector<uint32_t>> free_;  // per class: starts of free blocks
};

// One split, decoded: the new vertex i gets id vertexCount(); `moved` lists tets (ids, all in
// star(j)) whose j slot becomes i; `newTets` holds 4 vertex ids per recreated tet (using the
// new id for i); `position` 3 floats; `fields` one value per field; `jFields`, when given, the
// values j takes back for the mesh's kept fields (ProgressiveMesh::keptFirst, keptCount: the
// packer fits j's value to the region it stood for).
struct SplitOp {
  uint32_t j = 0;
  std::span<const uint32_t> moved;
  std::span<const uint32_t> newTets;
  const float* position = nullptr;
  const float* fields = nullptr;
  const float* jFields = nullptr;
};

struct ProgressiveMesh {
  TetMesh mesh;
  StarPool stars;  // the corners around each vertex
  // Undo log, one entry per applied split: the kept vertex and the tet count before the split.
  std::vector<uint32_t> splitJ, splitTetsBefore;
  std::vector<float> splitJValues;  // per applied split, j's kept-field values before it
  // The fields whose value at j a split may give back: [keptFirst, keptFirst + keptCount). The
  // same for every split of a dataset (FORMAT.md §4), so the undo log holds keptCount values a
  // split, not one per field: the isoField's (1), none (packed with --samples) or, in streams
  // of the first packers with fitted values, every field. keptFixed: set by the first split,
  // cleared when the last one is undone.
  uint32_t keptFirst = 0, keptCount = 0;
  bool keptFixed = false;
  uint32_t baseVertices = 0, baseTets = 0;
  // Scratch for de-duplicating vertices without sorting: a stamp per vertex.
  mutable std::vector<uint32_t> seen;
  mutable uint32_t stamp = 0;
  mutable std::vector<uint32_t> cornerIds;  // neighboursOf's scratch: the vertices of a star's tets

  uint32_t vertexCount() const { return mesh.vertexCount(); }
  uint32_t tetCount() const { return mesh.tetCount(); }
  uint32_t splitsApplied() const { return uint32_t(splitJ.size()); }
};

// Takes ownership of the base mesh and builds the incidence lists.
void initProgressive(ProgressiveMesh& pm, TetMesh base);

// Sets aside room for a mesh of `vertices` and `tets` (the full level), so that applying
// splits never moves the arrays (the packer's encoder: growing them by doubling would copy and
// first-touch tens of MB on a large mesh).
void reserveProgressive(ProgressiveMesh& pm, uint32_t vertices, uint32_t tets);

// Tets around v, ascending ids (the canonical order of FORMAT.md §4).
void starOf(const ProgressiveMesh& pm, uint32_t v, std::vector<uint32_t>& tets);

// Distinct vertices of the tets around v, ascending, without v itself.
void neighboursOf(const ProgressiveMesh& pm, uint32_t v, std::vector<uint32_t>& vertices);

// Applies a split. Preconditions (asserted; the decoder validates untrusted data first):
// j exists, every moved tet contains j, new tets reference existing vertices or the new one.
// Appends the ids of every tet whose vertices changed (moved, then new) to `changed`, and when
// j's values change, every other tet around j too (isosurface_incremental.h's contract).
void applySplit(ProgressiveMesh& pm, const SplitOp& op, std::vector<uint32_t>& changed);

// Undoes the last applied split. Appends the moved tet ids to `changed` (and the other tets
// around j when its values change back); the removed tets are those with id >= tetCount() afterwards.
void undoSplit(ProgressiveMesh& pm, std::vector<uint32_t>& changed);

}  // namespace tetstream
