// T_moved of a vertex split, found from T_new (FORMAT.md §4, split flag bit 4), so that most
// split records need no mask of the tets around p_j.
//
// In a manifold mesh, the link of the edge (p_i, p_j) is the ring of the new tets' (a, b)
// pairs. After the collapse that ring is a closed path (an open one at the boundary) of edges in
// the link of p_j, and it cuts that link in two: the triangles of the tets that came from p_i
// (T_moved) on one side, those of p_j's own tets on the other. Which side is which follows from
// orientation: the new tet (i, j, a, b) is positive, so (j, a, b, i) is negative, and of the two
// tets around p_j with the face (j, a, b), the one from p_i is where (j, a, b, x) is negative too.
// The link vertices off the ring that paths off the ring join to those seeds' are p_i's side,
// and T_moved is the tets with such a vertex, or with all three on the ring and a seed.
//
// Degenerate input (flat tets stored in either orientation, non-manifold spots) can break this;
// the packer checks every record with this same function and writes the mask where it differs.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "mesh.h"

namespace tetstream {

class MovedTetsFinder {
 public:
  // star: the tets around j, ascending ids; neighbours: the distinct vertices of those tets
  // other than j (any order); newTets: (i, j, a, b) per recreated tet, each vertex < the mesh's
  // vertex count or i. Writes T_moved, ascending, to `moved`; may leave out tets it cannot place
  // (j with more than kMaxLink neighbours: none; a link triangle with all three vertices on the
  // ring and no ring edge), which the packer's check then finds.
  void find(const TetMesh& mesh, uint32_t j, std::span<const uint32_t> star, std::span<const uint32_t> neighbours,
            std::span<const uint32_t> newTets, std::vector<uint32_t>& moved);
  static constexpr uint32_t kMaxLink = 64;  // link vertices as bits of a word

 private:
  std::vector<uint8_t> local_;     // per mesh vertex: its place in neighbours (valid for those only)
  std::vector<uint64_t> triangle_;  // per star tet: its link triangle's vertices
  std::vector<uint8_t> side_;      // per star tet: 1 when a ring edge says it came from p_i
  uint64_t ringOut_[kMaxLink];     // per link vertex: where ring edges from it go
  uint64_t adjacent_[kMaxLink];    // per link vertex: its neighbours in the link
};

}  // namespace tetstream
