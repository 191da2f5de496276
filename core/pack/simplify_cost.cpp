// The cost of a vertex's out-edges (simplify.h has the terms, simplifier.h the class).
#include "pack/simplifier.h"

namespace tetstream::simplify_detail {

bool Simplifier::isBoundaryEdge(uint32_t i, uint32_t j) const {
  for (uint32_t t : star_[i]) {
    const uint32_t* v = &out_.tets[4 * size_t(t)];
    if (!tetHas(t, j)) continue;
    for (int f = 0; f < 4; ++f)
      if (opp_[4 * t + f] == kNoNeighbor && v[f] != i && v[f] != j) return true;
  }
  return false;
}

// (After neighbours(sc, i, sc.nbr).)
void Simplifier::prepareStar(Scratch& sc, uint32_t i) {
  const std::vector<uint32_t>& star = star_[i];
  sc.star.resize(star.size());
  sc.center = i;
  const Point pi = p(i);
  // Every edge of a tet after the collapse lies in the star's bounding box, so the flatness
  // threshold of the longest possible edge bounds every tet's own threshold from above.
  double lo[3] = {pi[0], pi[1], pi[2]}, hi[3] = {pi[0], pi[1], pi[2]};
  float worstKappa = 0;
  sc.boundaryEdges = 0;
  for (size_t n = 0; n < star.size(); ++n) {
    const uint32_t t = star[n];
    const uint32_t* v = &out_.tets[4 * size_t(t)];
    if (boundary_[i])  // the boundary faces at i give its boundary edges (see legal())
      for (int f = 0; f < 4; ++f)
        if (v[f] != i && opp_[4 * size_t(t) + f] == kNoNeighbor)
          for (int k = 0; k < 4; ++k)
            if (k != f && v[k] != i) sc.boundaryEdges |= bitOf(sc.place[v[k]]);
    StarTet& st = sc.star[n];
    st.t = t;
    st.mask = 0;
    st.kappa = kappa_[t];
    st.quality = 3.0 / st.kappa;
    worstKappa = std::max(worstKappa, st.kappa);
    int si = 0, m = 0;
    for (int k = 0; k < 4; ++k) {
      if (v[k] == i) {
        si = k;
        continue;
      }
      const Point q = p(v[k]);
      st.other[m] = v[k];
      st.mask |= bitOf(sc.place[v[k]]);
      st.f[m] = vert_[v[k]].fit;
      for (int a = 0; a < 3; ++a) st.x[m][a] = q[a];
      ++m;
    }
    // Moving the vertex at slot si to the front takes si adjacent swaps. With u, w the edges
    // from x0, det(P) = sign·(x0 − P)·((x1 − P) × (x2 − P)) = g·(P − x0), g = −sign·(u × w):
    // relative to x0, so no large terms cancel.
    st.sign = (si & 1) ? -1.0 : 1.0;
    double u[3], w[3];
    for (int k = 0; k < 3; ++k) {
      u[k] = st.x[1][k] - st.x[0][k];
      w[k] = st.x[2][k] - st.x[0][k];
    }
    cross(u, w, st.g);
    for (double& x : st.g) x *= -st.sign;
    st.detOld = st.g[0] * (pi[0] - st.x[0][0]) + st.g[1] * (pi[1] - st.x[0][1]) + st.g[2] * (pi[2] - st.x[0][2]);
    // κ's terms without p_i: the face of the others (|u × w|²) and its edges.
    st.fixedFace = dot(st.g, st.g);
    st.fixedEdges = dot(u, u) + dot(w, w) + dist2(st.x[1], st.x[2]);
  }
  for (uint32_t w : sc.nbr) {  // (neighbours() listed the star's vertices but i)
    const Point q = p(w);
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], q[a]);
      hi[a] = std::max(hi[a], q[a]);
    }
  }
  const double diam2 =
      (hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]);
  sc.flatBound = kFlat * diam2 * std::sqrt(diam2);
  // A changed tet must reach the minimum quality, or else be no worse than the worst tet of
  // the star now: real meshes (boundary layers of CFD grids) start with tets far below any
  // fixed minimum, and a collapse that does not make their region worse is allowed.
  sc.qualityFloor = std::min(opt_.minQuality, 3.0 / double(worstKappa));
}

// Cost of hec(i → j) given prepareStar(i), in steps so that the expensive terms are only
// computed for candidates that can still win (cheapestCandidate): legal() checks the boundary
// rule and that no tet inverts or flattens, boundTerms() a lower bound from the geometric and
// region terms, localTerm() adds the local field error, finishCost() the exact shape term and
// the minimum-quality check.
bool Simplifier::legal(Scratch& sc, uint32_t i, uint32_t j, uint64_t bit, CollapseVerdict* verdict) {
  ++sc.evaluations;
  *verdict = CollapseVerdict::Legal;
  if (boundary_[i] && !(bit ? (sc.boundaryEdges & bit) != 0 : isBoundaryEdge(i, j)))
    return *verdict = CollapseVerdict::BoundaryRule, false;
  const Point P = p(j);
  double m[3];
  moveTo(P, p(i), m);
  sc.removedQuality = 0;  // Σ 3/κ of the tets the collapse removes, and their count
  sc.removed = 0;
  for (const StarTet& st : sc.star) {
    if (removes(st, j, bit)) {
      sc.removedQuality += st.quality;
      ++sc.removed;
      continue;
    }
    const double det = newDet(st, m);
    if (det <= 0) return *verdict = CollapseVerdict::Inverted, false;
    if (det <= sc.flatBound && isFlat(st, P, det)) return *verdict = CollapseVerdict::Flat, false;
  }
  return true;
}

// Everything of the cost but the local field error and the exact shape term: the geometric
// error, the region term of the field error and a lower bound of the shape term.
// (removed, removedQuality: what legal() found of the tets the collapse removes.)
Simplifier::Candidate Simplifier::boundTerms(Scratch& sc, uint32_t i, uint32_t j, uint64_t bit, int removed,
                                             double removedQuality) {
  const Point P = p(j);
  Candidate c;
  c.j = j;
  c.bit = bit;
  FieldQuadric fq = fieldQuadric_[i];
  fq.add(fieldQuadric_[j]);
  const uint32_t count = represented_[i] + represented_[j];
  c.sj = fitsRegion(count) ? fitted(fq, P, vert_[j].fit, sc.fitLo, sc.fitHi) : vert_[j].fit;
  // The field quadric over everything i and j stand for (our stand-in for eq. 5's sum over
  // the region).
  const double x5[5] = {P[0], P[1], P[2], c.sj, 1.0};
  c.region = fq.weight > 0 ? std::sqrt(std::max(0.0, fq.eval(x5)) / fq.weight) / range_ : 0.0;
  c.eg = 0;
  if (boundary_[i]) {
    Quadric q = quadrics_[quadricOf_[i]];
    q.add(boundaryQuadric(j));  // (j is on the boundary too: legal() checked the boundary rule)
    const double x4[4] = {P[0], P[1], P[2], 1.0};
    if (q.weight > 0) c.eg = std::sqrt(std::max(0.0, q.eval(x4)) / q.weight) / diag_;
  }
  // The error terms are weighted by the square root of how much of the input i and j stand for
  // together: about the root of the summed squared error there (paper eq. 5 sums over the
  // region), so a collapse that spreads an error over a large region waits behind one that
  // keeps it local. "How much" is the larger of two measures, which agree on an even mesh:
  // - their input vertices: the RMS at the input's vertices is what the benchmarks compare
  //   with VTK. A volume alone lets it grow on meshes whose vertices crowd into thin boundary
  //   layers;
  // - their input volume (the field quadrics' weights) in units of an interior vertex's mean
  //   volume: averaged over all isovalues, an isosurface moves by the volume integral of the
  //   field error, so an error over a large coarse region shows on every isosurface through it.
  //   With the count alone a graded mesh's coarse far field goes early, and the isosurfaces
  //   through it move far from the input's (figures: docs/design-notes.md).
  // The manifest reports the unweighted E_f.
  const double volume = fq.weight / meanVertexVolume_;  // (fq: i's and j's field quadrics, summed above)
  c.weight = std::sqrt(tune_.weighByVolume ? std::max(double(count), volume) : double(count));
  // E_s after the collapse with every new tet at the best quality (3/κ = 1), as the tets of
  // p_j's star that stay are known: most candidates lose without finishCost(). Scaled down a
  // little so that round-off (its sums run in another order) never lifts it above E_s.
  const double moved = double(sc.star.size()) - removed, after = double(star_[j].size()) - removed + moved;
  c.shapeBound = after > 0 ? std::max(0.0, 1.0 - (qualitySum_[j] - removedQuality + moved) / after) : 0.0;
  // Per tet removed (simplify.h); legal() counted them (at least the one tet of the edge).
  c.perTets = tune_.removedTetsExponent == 0.5 ? 1.0 / std::sqrt(double(std::max(removed, 1)))
                                               : std::pow(double(std::max(removed, 1)), -tune_.removedTetsExponent);
  setCost(c, 0.0);  // a lower bound: the local error is at least 0 (rounding is monotone)
  c.stage = Candidate::Bound;
  return c;
}

// The cost with the local field error `local` and the bound of the shape term.
void Simplifier::setCost(Candidate& c, double local) const {
  const double ef = local + c.region;
  c.fieldErr = float(ef);
  c.base = c.weight * (opt_.weightGeometry * c.eg + opt_.weightField * ef);
  c.cost = c.perTets * (c.base + opt_.weightShape * c.shapeBound * (1 - 1e-9));
}

// Adds the paper's local field error (eq. 6) to a candidate of boundTerms():
// |S(p_i) − S'(p_i)| / range, where S' interpolates the coarse field at p_i among the new tets.
// The first tet that contains p_i wins; if none does (p_i on the boundary, or round-off), the
// one it is least outside of. Only signs are needed until the tet is found (det > 0).
void Simplifier::localTerm(Scratch& sc, uint32_t i, Candidate& c) {
  const uint32_t j = c.j;
  const Point P = p(j);
  const Point pi = p(i);
  const double d[3] = {pi[0] - P[0], pi[1] - P[1], pi[2] - P[2]};
  double bestInside = -kInf, interp = c.sj;
  for (const StarTet& st : sc.star) {
    if (removes(st, j, c.bit)) continue;
    // The new tet is P and the others x0, x1, x2 with det = sign·(x0 − P)·((x1 − P) × (x2 − P)).
    // p_i's barycentric numerators: that det with p_i in place of the vertex (detOld for P).
    double a[3], b[3], e[3], be[3], de[3], bd[3];
    edgesFrom(P, st, a, b, e);
    cross(b, e, be);
    cross(d, e, de);
    cross(b, d, bd);
    const double num[4] = {st.detOld, st.sign * dot(d, be), st.sign * dot(a, de), st.sign * dot(a, bd)};
    const double lo = std::min({num[0], num[1], num[2], num[3]});
    const double det = st.detOld - dot(st.g, d);  // newDet() with the move −d
    if (lo < 0 && lo / det <= bestInside) continue;
    bestInside = lo / det;
    interp = (num[0] / det) * c.sj + ((num[1] / det) * st.f[0] + (num[2] / det) * st.f[1] + (num[3] / det) * st.f[2]);
    if (bestInside >= 0) break;
  }
  setCost(c, std::abs(double(field_[i]) - interp) / range_);
  c.stage = Candidate::Local;
}

bool Simplifier::finishCost(Scratch& sc, Candidate& c, CollapseVerdict* verdict) {
  const uint32_t j = c.j;
  const Point P = p(j);
  double m[3];
  moveTo(P, p(sc.center), m);
  double qualitySum = qualitySum_[j];
  int64_t count = int64_t(star_[j].size());
  for (const StarTet& st : sc.star) {
    if (removes(st, j, c.bit)) {
      qualitySum -= st.quality;
      --count;
      continue;
    }
    const double det = newDet(st, m);
    // The edges and faces at P.
    double a[3], b[3], e[3], ab[3], be[3], ae[3];
    edgesFrom(P, st, a, b, e);
    cross(a, b, ab);
    cross(b, e, be);
    cross(a, e, ae);
    const double edges = st.fixedEdges + dot(a, a) + dot(b, b) + dot(e, e);
    const double faces = st.fixedFace + dot(ab, ab) + dot(be, be) + dot(ae, ae);
    // 3/κ = 3·det / sqrt(edges · faces / 4): one root and one division.
    const double quality = 6.0 * det / std::sqrt(edges * faces);
    if (quality < sc.qualityFloor) return *verdict = CollapseVerdict::LowQuality, false;
    qualitySum += std::max(quality, 3.0 / kKappaCap);
    ++count;
  }
  // Mean of (κ − 3)/κ = 1 − 3/κ: the paper's κ − 3, mapped onto [0, 1) so that one sliver
  // cannot outweigh the field error (see simplify.h).
  double es = count > 0 ? std::max(0.0, 1.0 - qualitySum / double(count)) : 0.0;
  c.cost = c.perTets * (c.base + opt_.weightShape * es);
  c.stage = Candidate::Exact;
  return true;
}

// The legal out-edges of i with their lower bounds (prepareStar(i) and neighbours(i) first).
// What boundTerms() reads of a neighbour is scattered over large arrays (the loads of the field
// quadrics were half of its time): it is asked for as soon as legal() passes the out-edge, and
// only then. Asking for every neighbour's while legal() runs would fetch about four times what
// is used (most out-edges are not legal), and the two threads of the regions share the memory's
// bandwidth.
void Simplifier::gatherCandidates(Scratch& sc, uint32_t i) {
  sc.candidates.clear();
  sc.passed.clear();
  for (size_t n = 0; n < sc.nbr.size(); ++n) {
    CollapseVerdict v;
    const uint32_t w = sc.nbr[n];
    if (!legal(sc, i, w, bitOf(n), &v)) continue;
    sc.passed.push_back({uint32_t(n), sc.removed, sc.removedQuality});
    const char* q = reinterpret_cast<const char*>(&fieldQuadric_[w]);
    __builtin_prefetch(q);
    __builtin_prefetch(q + 64);
    __builtin_prefetch(&star_[w]);
    __builtin_prefetch(&qualitySum_[w]);
    __builtin_prefetch(&represented_[w]);
  }
  for (const Scratch::Passed& x : sc.passed) {
    sc.candidates.push_back(boundTerms(sc, i, sc.nbr[x.place], bitOf(x.place), x.removed, x.removedQuality));
  }
}

// Best-first over the candidates: the cheapest one with an exact cost, finishing bounds only
// while one could still win. Returns its index, or -1 when none is legal.
int Simplifier::cheapestCandidate(Scratch& sc, uint32_t i) {
  for (;;) {
    int best = -1;
    for (int c = 0; c < int(sc.candidates.size()); ++c) {
      const Candidate& x = sc.candidates[size_t(c)];
      if (best < 0 || x.cost < sc.candidates[size_t(best)].cost ||
          (x.cost == sc.candidates[size_t(best)].cost && x.j < sc.candidates[size_t(best)].j))
        best = c;
    }
    if (best < 0) return -1;
    Candidate& b = sc.candidates[size_t(best)];
    if (b.stage == Candidate::Exact) return best;
    CollapseVerdict v;
    if (b.stage == Candidate::Bound)
      localTerm(sc, i, b);
    else if (!finishCost(sc, b, &v))
      sc.candidates.erase(sc.candidates.begin() + best);
  }
}

// Distinct vertices of the tets around v (v excluded), in first-seen order: a stamp per vertex
// instead of sorting, as this runs for every queue pop.
void Simplifier::neighbours(Scratch& sc, uint32_t v, std::vector<uint32_t>& out) {
  out.clear();
  ++sc.stamp;
  sc.seen[v] = sc.stamp;
  const bool onBoundary = boundary_[v];
  for (uint32_t t : star_[v]) {
    __builtin_prefetch(&kappa_[t]);
    // prepareStar reads a boundary vertex's face neighbours next: on meshes whose vertices are
    // mostly on the boundary, waiting on those loads would be a large share of its time.
    if (onBoundary) __builtin_prefetch(&opp_[4 * size_t(t)]);
    for (int k = 0; k < 4; ++k) {
      uint32_t w = out_.tets[4 * size_t(t) + k];
      if (sc.seen[w] != sc.stamp) {
        sc.seen[w] = sc.stamp;
        sc.place[w] = uint8_t(std::min<size_t>(out.size(), 255));
        out.push_back(w);
        __builtin_prefetch(&vert_[w]);  // prepareStar and legal() read it next
      }
    }
  }
}

// The cost of v's cheapest legal out-edge (infinity when it has none).
float Simplifier::bestCost(Scratch& sc, uint32_t v) {
  neighbours(sc, v, sc.nbr);
  prepareStar(sc, v);
  gatherCandidates(sc, v);
  int best = cheapestCandidate(sc, v);
  return best < 0 ? float(kInf) : float(sc.candidates[size_t(best)].cost);
}

// Pops are re-evaluated (the neighbourhood of the target may have changed since the push):
// the candidates of every out-edge of v in scratch sc, the cheapest one with its exact cost.
void Simplifier::evaluateVertex(Scratch& sc, uint32_t v) {
  neighbours(sc, v, sc.nbr);
  prepareStar(sc, v);
  gatherCandidates(sc, v);
  cheapestCandidate(sc, v);  // finishes the winner here, on the thread that owns sc
}

}  // namespace tetstream::simplify_detail
