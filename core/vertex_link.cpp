#include "vertex_link.h"

#include <algorithm>
#include <bit>

namespace tetstream {
namespace {

uint64_t bit(uint32_t x) { return uint64_t(1) << x; }

}  // namespace

void VertexLink::build(const TetMesh& mesh, uint32_t j, std::span<const uint32_t> star,
                       std::span<const uint32_t> neighbours) {
  star_ = star;
  neighbours_ = neighbours;
  const uint32_t L = uint32_t(neighbours.size());
  usable_ = L <= kMaxLink;
  if (!usable_) return;
  if (local_.size() < mesh.vertexCount()) local_.resize(mesh.vertexCount());
  for (uint32_t x = 0; x < L; ++x) local_[neighbours[x]] = uint8_t(x);
  // Each tet's link triangle (its vertices other than j) and the link's edges. (Branch-free:
  // these branches go either way at random, and mispredicting them cost more than the rest.)
  const size_t n = star.size();
  triangle_.resize(n);
  corners_.resize(n);
  std::fill(adjacent_, adjacent_ + L, 0);
  for (size_t s = 0; s < n; ++s) {
    const uint32_t* v = &mesh.tets[4 * size_t(star[s])];
    const int at = (v[1] == j) + 2 * (v[2] == j) + 3 * (v[3] == j);  // j's slot
    // (Every vertex of a tet around j is a neighbour: its local_ entry is from this call.)
    const uint32_t p = local_[v[at == 0 ? 1 : 0]], q = local_[v[at <= 1 ? 2 : 1]], r = local_[v[at <= 2 ? 3 : 2]];
    // (j, p, q, r) takes `at` swaps from the stored order: odd `at`, it is negative.
    corners_[s] = p | q << 8 | r << 16 | uint32_t(at & 1) << 24;
    triangle_[s] = bit(p) | bit(q) | bit(r);
    adjacent_[p] |= bit(q) | bit(r);
    adjacent_[q] |= bit(p) | bit(r);
    adjacent_[r] |= bit(p) | bit(q);
  }
}

uint32_t VertexLink::localOf(uint32_t v) const {
  if (!usable_ || v >= local_.size()) return kNone;
  const uint32_t x = local_[v];
  return x < neighbours_.size() && neighbours_[x] == v ? x : kNone;
}

uint32_t VertexLink::choices(uint32_t from, uint64_t used) const {
  return uint32_t(std::popcount(adjacent_[from] & ~used));
}

uint32_t VertexLink::rankOf(uint32_t from, uint64_t used, uint32_t v) const {
  const uint64_t c = adjacent_[from] & ~used;
  const uint32_t x = localOf(v);
  if (x == kNone || !(c >> x & 1)) return kNone;
  return uint32_t(std::popcount(c & (bit(x) - 1)));
}

uint32_t VertexLink::choice(uint32_t from, uint64_t used, uint32_t rank) const {
  uint64_t c = adjacent_[from] & ~used;
  for (uint32_t k = 0; k < rank; ++k) c &= c - 1;  // (the caller keeps rank < choices())
  return neighbours_[size_t(std::countr_zero(c))];
}

void VertexLink::moved(std::span<const uint32_t> newTets, std::vector<uint32_t>& out) {
  out.clear();
  if (!usable_) return;  // (the packer then writes the mask)
  const size_t n = star_.size();
  const uint32_t L = uint32_t(neighbours_.size());
  // The ring: its vertices, and its edges directed as in the new tets (i, j, a, b).
  uint64_t ringVertices = 0;
  std::fill(ringOut_, ringOut_ + L, 0);
  for (size_t t = 0; t + 3 < newTets.size(); t += 4) {
    const uint32_t a = localOf(newTets[t + 2]), b = localOf(newTets[t + 3]);
    if (a == kNone || b == kNone) continue;  // no edge of j's link: (i, a, b) was a boundary face
    ringOut_[a] |= bit(b);
    ringVertices |= bit(a) | bit(b);
  }
  // The seeds: a tet with a ring edge (a, b) came from p_i exactly when (j, a, b, x) is negative.
  // With (j, p, q, r) the tet in stored order (its sign from corners_), (j, a, b, x) has the same
  // sign when (a, b) runs along p → q → r → p, the other sign when against it.
  uint64_t sideI = 0, sideJ = 0;  // link vertices off the ring known to be on either side
  side_.resize(n);
  for (size_t s = 0; s < n; ++s) {
    const uint32_t c = corners_[s], p = c & 0xff, q = c >> 8 & 0xff, r = c >> 16 & 0xff;
    const uint64_t along = (ringOut_[p] >> q | ringOut_[q] >> r | ringOut_[r] >> p) & 1;
    const uint64_t against = (ringOut_[q] >> p | ringOut_[r] >> q | ringOut_[p] >> r) & 1;
    const uint64_t negative = c >> 24;  // (j, p, q, r) is negative
    const uint64_t fromI = negative ? along : against, fromJ = negative ? against : along;
    side_[s] = uint8_t(fromI);
    const uint64_t off = triangle_[s] & ~ringVertices;
    sideI |= off & (0 - fromI);
    sideJ |= off & (0 - fromJ);
  }
  // p_i's side: every link vertex off the ring that a path off the ring joins to a seed's.
  for (uint64_t frontier = sideI; frontier;) {
    const uint32_t x = uint32_t(std::countr_zero(frontier));
    frontier &= frontier - 1;
    const uint64_t fresh = adjacent_[x] & ~ringVertices & ~sideI;
    sideI |= fresh;
    frontier |= fresh;
  }
  if (sideI & sideJ) return;  // the ring does not cut the link in two: no manifold spot
  for (size_t s = 0; s < n; ++s) {
    // A tet with a vertex off the ring is on that vertex's side; one with all three on the ring
    // only if its ring edge made it a seed (one without a ring edge: no guess, mask written).
    const bool fromI = (triangle_[s] & ~ringVertices) ? (triangle_[s] & sideI) != 0 : side_[s];
    if (fromI) out.push_back(star_[s]);
  }
}

}  // namespace tetstream
