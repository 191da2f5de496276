// The link of p_j as a split record is read (FORMAT.md §4): the triangles of the tets around
// p_j, opposite p_j. Two things of a record follow from it and cost few bytes that way:
//
// - The new tets' ring as a walk (split flag bit 5): each ring vertex after the first is one of
//   the link neighbours of the one before, named by its rank among them (a handful) instead of
//   its place among all neighbours of p_j (tens).
//
// - T_moved (split flag bit 4). In a manifold mesh, the link of the edge (p_i, p_j) is the ring
//   of the new tets' (a, b) pairs. After the collapse that ring is a closed path (an open one at
//   the boundary) of edges in the link of p_j, and it cuts that link in two: the triangles of
//   the tets that came from p_i (T_moved) on one side, those of p_j's own tets on the other.
//   Which side is which follows from orientation: the new tet (i, j, a, b) is positive, so
//   (j, a, b, i) is negative, and of the two tets around p_j with the face (j, a, b), the one
//   from p_i is where (j, a, b, x) is negative too. The link vertices off the ring that paths
//   off the ring join to those seeds' are p_i's side, and T_moved is the tets with such a
//   vertex, or with all three on the ring and a seed.
//
// Degenerate input (flat tets stored in either orientation, non-manifold spots) can break the
// second; the packer checks every record with this same code and writes the mask where it
// differs.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "mesh.h"

namespace tetstream {

class VertexLink {
 public:
  static constexpr uint32_t kMaxLink = 64;  // link vertices as bits of a word
  static constexpr uint32_t kNone = ~0u;

  // star: the tets around j, ascending ids; neighbours: the distinct vertices of those tets
  // other than j, ascending (their places are the link's local vertex numbers).
  void build(const TetMesh& mesh, uint32_t j, std::span<const uint32_t> star, std::span<const uint32_t> neighbours);
  // The local number of mesh vertex v, or kNone when v is no neighbour of j. A link of more than
  // kMaxLink vertices has none: no walks (every ring vertex is named on its own) and no T_moved.
  uint32_t localOf(uint32_t v) const;

  // Ring walks. `used`: the local numbers of the ring vertices so far, as bits. The next vertex's
  // choices are the link neighbours of `from` (a local number) not in `used`, in ascending
  // order: choices() counts them, rankOf() gives v's rank (kNone when v is none of them), and
  // choice() the vertex of a rank.
  uint32_t choices(uint32_t from, uint64_t used) const;
  uint32_t rankOf(uint32_t from, uint64_t used, uint32_t v) const;
  uint32_t choice(uint32_t from, uint64_t used, uint32_t rank) const;

  // T_moved for the new tets (i, j, a, b) (each vertex < the mesh's vertex count, or i), ascending
  // tet ids. May leave out tets it cannot place (a link triangle with all three vertices on the
  // ring and no ring edge; none beyond kMaxLink), which the packer's check then finds.
  void moved(std::span<const uint32_t> newTets, std::vector<uint32_t>& out);

 private:
  std::span<const uint32_t> star_, neighbours_;
  bool usable_ = false;
  std::vector<uint8_t> local_;      // per mesh vertex: its place in neighbours (valid for those only)
  std::vector<uint64_t> triangle_;  // per star tet: its link triangle's vertices
  std::vector<uint32_t>
      corners_;  // per star tet: p, q, r (its vertices but j, in stored order), and (j, p, q, r)'s sign bit
  std::vector<uint8_t> side_;    // per star tet: 1 when a ring edge says it came from p_i
  uint64_t adjacent_[kMaxLink];  // per link vertex: its neighbours in the link
  uint64_t ringOut_[kMaxLink];   // per link vertex: where ring edges from it go
};

}  // namespace tetstream
