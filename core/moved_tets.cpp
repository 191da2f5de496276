#include "moved_tets.h"

#include <bit>

namespace tetstream {
namespace {

// Whether the stored tet v, read as (j, a, b, x), is an odd permutation of its stored order:
// stored tets are positive, so (j, a, b, x) is then negative.
bool oddAs(const uint32_t* v, uint32_t j, uint32_t a, uint32_t b) {
  int pos[4] = {0, 0, 0, 0}, n = 0;
  for (uint32_t want : {j, a, b})
    for (int k = 0; k < 4; ++k)
      if (v[k] == want && n < 3) pos[n++] = k;
  pos[3] = 6 - pos[0] - pos[1] - pos[2];  // (the caller's tets hold j, a and b)
  int inversions = 0;
  for (int x = 0; x < 4; ++x)
    for (int y = x + 1; y < 4; ++y) inversions += pos[x] > pos[y];
  return inversions & 1;
}

}  // namespace

void MovedTetsFinder::find(const TetMesh& mesh, uint32_t j, std::span<const uint32_t> star,
                           std::span<const uint32_t> neighbours, std::span<const uint32_t> newTets,
                           std::vector<uint32_t>& moved) {
  const size_t n = star.size();
  const uint32_t L = uint32_t(neighbours.size());
  moved.clear();
  if (L > kMaxLink) return;  // (the packer then writes the mask)
  // Link vertices by their place in `neighbours`, sets of them as bit masks.
  if (local_.size() < mesh.vertexCount()) local_.resize(mesh.vertexCount());
  for (uint32_t x = 0; x < L; ++x) local_[neighbours[x]] = uint8_t(x);
  auto localOf = [&](uint32_t v) -> uint32_t {  // L for a vertex that is no neighbour of j
    const uint32_t x = local_[v];
    return x < L && neighbours[x] == v ? x : L;
  };

  // The ring: its vertices, and its edges directed as in the new tets (i, j, a, b).
  uint64_t ringVertices = 0;
  std::fill(ringOut_, ringOut_ + L, 0);
  for (size_t t = 0; t + 3 < newTets.size(); t += 4) {
    const uint32_t a = localOf(newTets[t + 2]), b = localOf(newTets[t + 3]);
    if (a == L || b == L) continue;  // no edge of j's link: (i, a, b) was a boundary face
    ringOut_[a] |= uint64_t(1) << b;
    ringVertices |= uint64_t(1) << a | uint64_t(1) << b;
  }

  // Each tet's link triangle (the tet's vertices other than j) and the link's edges. A tet with
  // a ring edge (a, b) is on p_i's side exactly when (j, a, b, x) is negative: the seeds.
  triangle_.resize(n);
  std::fill(adjacent_, adjacent_ + L, 0);
  uint64_t sideI = 0, sideJ = 0;  // link vertices off the ring known to be on either side
  side_.assign(n, 0);
  for (size_t s = 0; s < n; ++s) {
    const uint32_t* v = &mesh.tets[4 * size_t(star[s])];
    const int at = (v[1] == j) + 2 * (v[2] == j) + 3 * (v[3] == j);  // j's slot
    // (Every vertex of a tet around j is a neighbour: its local_ entry is from this call.)
    const uint32_t p = local_[v[at == 0 ? 1 : 0]], q = local_[v[at <= 1 ? 2 : 1]], r = local_[v[at <= 2 ? 3 : 2]];
    const uint64_t P = uint64_t(1) << p, Q = uint64_t(1) << q, R = uint64_t(1) << r;
    triangle_[s] = P | Q | R;
    adjacent_[p] |= Q | R;
    adjacent_[q] |= P | R;
    adjacent_[r] |= P | Q;
    // The ring edges (a, b) among the triangle's: each says from which side the tet is.
    bool fromI = false, fromJ = false;
    for (auto [x, y] : {std::pair{p, q}, std::pair{q, r}, std::pair{r, p}})
      for (auto [a, b] : {std::pair{x, y}, std::pair{y, x}})
        if (ringOut_[a] >> b & 1) (oddAs(v, j, neighbours[a], neighbours[b]) ? fromI : fromJ) = true;
    side_[s] = fromI;
    if (fromI) sideI |= triangle_[s] & ~ringVertices;
    if (fromJ) sideJ |= triangle_[s] & ~ringVertices;
  }
  // p_i's side: every link vertex off the ring that a path off the ring joins to a seed's.
  for (uint64_t frontier = sideI; frontier;) {
    const int x = std::countr_zero(frontier);
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
    if (fromI) moved.push_back(star[s]);
  }
}

}  // namespace tetstream
