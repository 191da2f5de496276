// The link condition of a collapse (simplifier.h).
#include "pack/simplifier.h"

namespace tetstream::simplify_detail {

namespace {

// Whether three of the edges (a few) form a triangle.
bool hasTriangle(const std::vector<uint64_t>& edges) {
  auto ends = [](uint64_t e, uint32_t& a, uint32_t& b) { a = uint32_t(e >> 32), b = uint32_t(e); };
  for (size_t x = 0; x < edges.size(); ++x)
    for (size_t y = x + 1; y < edges.size(); ++y) {
      uint32_t a, b, c, d;
      ends(edges[x], a, b);
      ends(edges[y], c, d);
      // Sharing one end, the other two ends must be joined too.
      uint32_t p = ~0u, q = ~0u;
      if (a == c)
        p = b, q = d;
      else if (a == d)
        p = b, q = c;
      else if (b == c)
        p = a, q = d;
      else if (b == d)
        p = a, q = c;
      if (p == ~0u || p == q) continue;
      const uint64_t third = edgeKey(p, q);
      for (size_t z = 0; z < edges.size(); ++z)
        if (edges[z] == third) return true;
    }
  return false;
}

}  // namespace

// Lk(i) ∩ Lk(j) = Lk(ij) with the boundary coned to kOmega: vertices and edges of the two
// links meet exactly in the link of the edge, and no triangle is in both.
void Simplifier::gatherLink(uint32_t v, std::vector<uint32_t>& verts, std::vector<uint64_t>& edges,
                            std::vector<Tri>& tris) {
  verts.clear();
  edges.clear();
  tris.clear();
  for (uint32_t t : star_[v]) {
    const uint32_t* x = &out_.tets[4 * size_t(t)];
    uint32_t o[3];
    int n = 0, sv = 0;
    for (int k = 0; k < 4; ++k) {
      if (x[k] == v)
        sv = k;
      else
        o[n++] = x[k];
    }
    verts.insert(verts.end(), o, o + 3);
    edges.push_back(edgeKey(o[0], o[1]));
    edges.push_back(edgeKey(o[0], o[2]));
    edges.push_back(edgeKey(o[1], o[2]));
    tris.push_back(makeTri(o[0], o[1], o[2]));
    for (int f = 0; f < 4; ++f) {
      if (f == sv || opp_[4 * t + f] != kNoNeighbor) continue;
      uint32_t a = 0, b = 0;  // the boundary face f contains v and two others
      int m = 0;
      for (int k = 0; k < 4; ++k)
        if (k != f && x[k] != v) (m++ == 0 ? a : b) = x[k];
      verts.push_back(kOmega);
      edges.push_back(edgeKey(a, kOmega));
      edges.push_back(edgeKey(b, kOmega));
      tris.push_back(makeTri(a, b, kOmega));
    }
  }
  sortUnique(verts);
  sortUnique(edges);
  sortUnique(tris);
}

// The same condition without sorting (this runs once per collapse attempt): vertex sets by
// stamps, edge sets in a small stamped hash table, shared tet triangles through the face
// adjacency. linkConditionBySorting() is the plain reference; tests run both
// (SimplifyTuning::verifyLinkCondition) and count disagreements.
bool Simplifier::linkCondition(Queue& Q, uint32_t i, uint32_t j) {
  const bool verify = tune_.verifyLinkCondition;
  const bool reference = verify && linkConditionBySorting(i, j);
#define TS_LINK_RESULT(x)                                   \
  do {                                                      \
    const bool result_ = (x);                               \
    if (verify && result_ != reference) ++Q.linkMismatches; \
    return result_;                                         \
  } while (0)
  Scratch& sc = *Q.scratch;
  auto hasBoundaryFace = [&](uint32_t v) {
    bool any = false;
    forBoundaryFaces(v, [&](uint32_t, uint32_t) { any = true; });
    return any;
  };
  const bool bothBoundary = boundary_[i] && boundary_[j] && hasBoundaryFace(i) && hasBoundaryFace(j);
  // Vertices: common neighbours of i and j (and ω when both are on the boundary) against the
  // link of the edge.
  uint32_t stampJ = ++sc.stamp;
  for (uint32_t t : star_[j])
    for (int k = 0; k < 4; ++k) sc.seen[out_.tets[4 * size_t(t) + k]] = stampJ;
  uint32_t stampI = ++sc.stamp;
  size_t common = bothBoundary ? 1 : 0;
  for (uint32_t t : star_[i])
    for (int k = 0; k < 4; ++k) {
      uint32_t w = out_.tets[4 * size_t(t) + k];
      if (w == i || w == j || sc.seen[w] == stampI) continue;
      common += sc.seen[w] == stampJ;
      sc.seen[w] = stampI;
    }
  // Link of the edge: the opposite edges of the tets around it, and the boundary faces at it.
  size_t edgeVerts = 0, edgeEdges = 0;
  bool boundaryEdge = false;
  uint32_t stampE = ++sc.stamp;
  Q.edgeLink.clear();
  forEdgeLink(
      i, j,
      [&](const uint32_t o[2]) {
        for (int k = 0; k < 2; ++k)
          if (sc.seen[o[k]] != stampE) {
            sc.seen[o[k]] = stampE;
            ++edgeVerts;
          }
        ++edgeEdges;  // each tet around the edge has its own opposite edge
        Q.edgeLink.push_back(edgeKey(o[0], o[1]));
      },
      [&](uint32_t k) {
        boundaryEdge = true;
        ++edgeEdges;  // (k, ω) for the boundary face (i, j, k): one per face
        Q.edgeLink.push_back(edgeKey(k, kOmega));
      });
  if (common != edgeVerts + (boundaryEdge ? 1 : 0)) TS_LINK_RESULT(false);
  // Edges: those of Lk(j) in a table, then the distinct ones of Lk(i) found there. With the
  // vertices equal, an edge in both links has both ends in Lk(ij) (stamped stampE; ω when the
  // edge is on the boundary): only those are looked at.
  Q.edgeTable.beginSet(++Q.edgeTableStamp);
  auto inEdgeLink = [&](uint32_t x) { return sc.seen[x] == stampE; };
  auto linkEdgesOf = [&](uint32_t v, auto&& each) {
    for (uint32_t t : star_[v]) {
      const uint32_t* x = &out_.tets[4 * size_t(t)];
      uint32_t o[3];
      int n = 0;
      for (int k = 0; k < 4; ++k)
        if (x[k] != v) o[n++] = x[k];
      const bool in[3] = {inEdgeLink(o[0]), inEdgeLink(o[1]), inEdgeLink(o[2])};
      if (in[0] && in[1]) each(edgeKey(o[0], o[1]));
      if (in[0] && in[2]) each(edgeKey(o[0], o[2]));
      if (in[1] && in[2]) each(edgeKey(o[1], o[2]));
    }
    if (boundaryEdge)
      forBoundaryFaces(v, [&](uint32_t a, uint32_t b) {
        if (inEdgeLink(a)) each(edgeKey(a, kOmega));
        if (inEdgeLink(b)) each(edgeKey(b, kOmega));
      });
  };
  linkEdgesOf(j, [&](uint64_t e) { Q.edgeTable.mark(e, 1); });
  size_t commonEdges = 0;
  linkEdgesOf(i, [&](uint64_t e) {
    if (Q.edgeTable.get(e) == 1) {
      Q.edgeTable.mark(e, 2);  // count each shared edge once
      ++commonEdges;
    }
  });
  if (commonEdges != edgeEdges) TS_LINK_RESULT(false);
  // Triangles: with vertices and edges equal, a triangle in both links has its three edges in
  // Lk(ij). Most edge links are a cycle of four or more vertices (or a path closed through ω)
  // without a triangle, and then none is shared; otherwise the faces are looked at.
  if (!hasTriangle(Q.edgeLink)) TS_LINK_RESULT(true);
  // Triangles (a, b, c) in both links: tets (i, a, b, c) and (j, a, b, c) share that face.
  for (uint32_t t : star_[i]) {
    if (tetHas(t, j)) continue;
    const uint32_t* x = &out_.tets[4 * size_t(t)];
    int si = 0;
    while (x[si] != i) ++si;
    uint32_t h = opp_[4 * t + si];
    if (h != kNoNeighbor && tetHas(h >> 2, j)) TS_LINK_RESULT(false);
  }
  // Boundary triangles (a, b, ω) in both links: boundary faces (i, a, b) and (j, a, b).
  if (bothBoundary) {
    Q.linkEdges.clear();  // edges (a, b) of the boundary faces at j
    forBoundaryFaces(j, [&](uint32_t a, uint32_t b) { Q.linkEdges.push_back(edgeKey(a, b)); });
    bool shared = false;
    forBoundaryFaces(i, [&](uint32_t a, uint32_t b) {
      shared |= std::find(Q.linkEdges.begin(), Q.linkEdges.end(), edgeKey(a, b)) != Q.linkEdges.end();
    });
    if (shared) TS_LINK_RESULT(false);
  }
  TS_LINK_RESULT(true);
#undef TS_LINK_RESULT
}

// The plain reference for linkCondition(): the three links as sorted sets (tests only).
bool Simplifier::linkConditionBySorting(uint32_t i, uint32_t j) {
  std::vector<uint32_t> lvI, lvJ, lvE;  // (tests only: allocates)
  std::vector<uint64_t> leI, leJ, leE;
  std::vector<Tri> ltI, ltJ;
  gatherLink(i, lvI, leI, ltI);
  gatherLink(j, lvJ, leJ, ltJ);
  if (intersectionSize(ltI, ltJ) != 0) return false;
  // Link of the edge: the opposite edges of the tets around it, and the boundary faces at it.
  forEdgeLink(
      i, j,
      [&](const uint32_t o[2]) {
        lvE.insert(lvE.end(), o, o + 2);
        leE.push_back(edgeKey(o[0], o[1]));
      },
      [&](uint32_t k) {
        lvE.push_back(kOmega);
        leE.push_back(edgeKey(k, kOmega));
      });
  sortUnique(lvE);
  sortUnique(leE);
  return intersectionSize(lvI, lvJ) == lvE.size() && intersectionSize(leI, leJ) == leE.size();
}

}  // namespace tetstream::simplify_detail
