// Simplifier set-up: stars, face adjacency, boundary and field quadrics, κ, first costs (simplifier.h).
#include "pack/simplifier.h"

namespace tetstream::simplify_detail {

namespace {

// The determinant of the 3×3 matrix m (rows).
double det3(const double (&m)[3][3]) {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

// The edges from p0 to p1, p2, p3 (rows), from the floats of `positions`, in double.
void edgesOf(const float* positions, const uint32_t* v, double (&e)[3][3]) {
  const float* p0 = positions + 3 * size_t(v[0]);
  for (int r = 0; r < 3; ++r) {
    const float* q = positions + 3 * size_t(v[r + 1]);
    for (int k = 0; k < 3; ++k) e[r][k] = double(q[k]) - double(p0[k]);
  }
}

}  // namespace

void Simplifier::init() {
  V_ = mesh_.vertexCount();
  T_ = mesh_.tetCount();
  // A part (SimplifyPart) brings the whole mesh's normalisers and, after its first level, the
  // state its vertices' collapses left (CarriedVertexState) instead of what the input gives.
  const SimplifyPart* part = opt_.part;
  const CarriedVertexState* carried = part ? part->carried : nullptr;
  ownedMask_ = part ? part->owned : nullptr;
  assert(!ownedMask_ || ownedMask_->size() == V_);
  assert(!carried ||
         (carried->fit.size() == V_ && carried->represented.size() == V_ && carried->boundary.size() == V_ &&
          carried->boundaryQuadric.size() == V_ && carried->fieldQuadric.size() == V_));
  field_ = mesh_.fields[size_t(opt_.field)].values.data();
  vert_.resize(V_);
  for (uint32_t v = 0; v < V_; ++v) {
    const float* q = &mesh_.positions[3 * size_t(v)];
    vert_[v] = {{q[0], q[1], q[2]}, carried ? carried->fit[v] : field_[v]};
  }
  fitOn_ = opt_.fitValues;
  if (part) {
    fieldMin_ = part->fieldMin;
    fieldMax_ = part->fieldMax;
    range_ = fieldMax_ > fieldMin_ ? fieldMax_ - fieldMin_ : 1.0;
    diag_ = part->diagonal;
    topLo_ = part->topMin;
    topHi_ = part->topMax;
  } else {
    Range r = computeRange(mesh_.fields[size_t(opt_.field)].values);
    range_ = r.max > r.min ? double(r.max) - r.min : 1.0;
    fieldMin_ = r.min;
    fieldMax_ = r.max;
    diag_ = computeBounds(mesh_.positions).diagonal();
    topLo_ = fieldMin_;
    topHi_ = fieldMax_;
  }
  if (!(diag_ > 0)) diag_ = 1;

  assert(!takeTets_ || takeTets_ == &mesh_.tets);
  if (takeTets_)
    out_.tets = std::move(*takeTets_);  // (mesh_.tets is not read again: T_ counts them)
  else
    out_.tets = mesh_.tets;
  out_.tetAlive.assign(T_, 1);
  out_.vertexAlive.assign(V_, 0);
  star_.assign(V_, {});
  {
    std::vector<uint32_t> size(V_, 0);  // each star reserved at its size (no regrowth)
    for (uint32_t v : out_.tets) ++size[v];
    for (uint32_t v = 0; v < V_; ++v) star_[v].reserve(size[v]);
  }
  for (uint32_t t = 0; t < T_; ++t)
    for (int k = 0; k < 4; ++k) star_[out_.tets[4 * size_t(t) + k]].push_back(t);
  alive_ = 0;
  haloAlive_ = 0;
  for (uint32_t v = 0; v < V_; ++v)
    if (!star_[v].empty()) {
      out_.vertexAlive[v] = 1;
      ++alive_;
      haloAlive_ += !owned(v);
    }

  if (adjacency_ && adjacency_->opposite.size() == out_.tets.size()) {
    opp_ = std::move(adjacency_->opposite);
  } else {
    FaceAdjacency adj;
    buildFaceAdjacency(out_.tets, V_, adj);
    opp_ = std::move(adj.opposite);
  }
  boundary_.assign(V_, 0);
  // Only boundary vertices have a quadric (a tenth of a grid's vertices, fewer in a real mesh):
  // 88 bytes each, stored for those alone.
  quadricOf_.assign(V_, kNoQuadric);
  quadrics_.clear();
  if (part) fitRange_.assign(V_, Range{float(fieldMin_), float(fieldMax_)});  // (until a collapse fits it)
  if (carried)
    takeCarried(*carried);
  else
    for (uint32_t h = 0; h < 4 * T_; ++h) {
      if (opp_[h] != kNoNeighbor) continue;
      const uint32_t* v = &out_.tets[h & ~3u];
      uint32_t a = v[kTetFaces[h & 3][0]], b = v[kTetFaces[h & 3][1]], c = v[kTetFaces[h & 3][2]];
      const Point pa = p(a), pb = p(b), pc = p(c);
      double u[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]}, w[3] = {pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2]};
      double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
      double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (uint32_t x : {a, b, c}) {
        boundary_[x] = 1;
        if (quadricOf_[x] == kNoQuadric) {
          quadricOf_[x] = uint32_t(quadrics_.size());
          quadrics_.emplace_back();
        }
      }
      if (len == 0) continue;
      for (double& x : n) x /= len;
      double d = -(n[0] * pa[0] + n[1] * pa[1] + n[2] * pa[2]);
      const double plane[4] = {n[0], n[1], n[2], d};
      for (uint32_t x : {a, b, c}) quadrics_[quadricOf_[x]].addSquare(plane, 0.5 * len);
    }
  kappa_.resize(T_);
  qualitySum_.assign(V_, 0.0);
  if (!carried) fieldQuadric_.assign(V_, {});  // (else takeCarried's)
  // κ of every tet and the per-vertex sums over them (3/κ, field quadrics) on two threads: each
  // adds to the vertices of its own range only, taking the tets in order, so every sum is
  // formed in the same order as on one thread; a tet with vertices in both ranges is computed
  // by both (few, in a mesh numbered coherently).
  uint32_t flat[2] = {0, 0};
  auto sums = [&](int half, uint32_t lo, uint32_t hi) {
    for (uint32_t t = 0; t < T_; ++t) {
      const uint32_t* v = &out_.tets[4 * size_t(t)];
      bool mine[4], any = false;
      for (int k = 0; k < 4; ++k) any |= mine[k] = v[k] >= lo && v[k] < hi;
      if (!any) continue;
      const float kappa = tetKappa(t);
      if (mine[0]) {  // (the owner of its first vertex writes κ)
        kappa_[t] = kappa;
        flat[half] += kappa >= kKappaCap;
      }
      for (int k = 0; k < 4; ++k)
        if (mine[k]) qualitySum_[v[k]] += 3.0 / kappa;
      double hyperplane[5], w;
      if (!carried && fieldHyperplane(v, hyperplane, w))
        for (int k = 0; k < 4; ++k)
          if (mine[k]) fieldQuadric_[v[k]].addSquare(hyperplane, w);
    }
  };
  onBoth([&](int half) { sums(half, half ? V_ / 2 : 0, half ? V_ : V_ / 2); });
  flatInput_ += flat[0] + flat[1];
  // The unit of volume (boundTerms): the mean of the interior vertices', which on an even grid is
  // every interior vertex's own (boundary vertices stand for half a star or less); of all
  // vertices when none is inside (a slab one tet thick). With no volume at all (every tet flat)
  // the count alone remains.
  double volume[2] = {0, 0};
  uint32_t count[2] = {0, 0};
  for (uint32_t v = 0; v < V_; ++v)
    if (out_.vertexAlive[v]) {
      volume[boundary_[v]] += fieldQuadric_[v].weight;
      ++count[boundary_[v]];
    }
  const double inside = count[0] ? volume[0] / count[0] : 0;
  const double all = alive_ ? (volume[0] + volume[1]) / alive_ : 0;
  meanVertexVolume_ = inside > 0 ? inside : all > 0 ? all : kInf;
  if (part) meanVertexVolume_ = part->meanVertexVolume > 0 ? part->meanVertexVolume : kInf;
  queued_.assign(V_, 0);
  if (!carried) represented_.assign(V_, 1);  // (else takeCarried's)
  lastCost_.assign(V_, float(kInf));
  // Every vertex's first cost, on two threads (each with its own scratch; the mesh is
  // only read), then queued in vertex order so the result does not depend on the threads.
  main_.scratch = &mainScratch_;
  scratches_.resize(kRoundSize);
  for (Scratch& sc : scratches_) sc.fitLo = topLo_, sc.fitHi = topHi_;
  mainScratch_.fitLo = topLo_, mainScratch_.fitHi = topHi_;
  for (size_t k = 0; k < 2; ++k) scratches_[k].reset(V_);  // (the rest: readyScratches())
  auto work = [this](Scratch& sc, uint32_t begin, uint32_t end) {
    for (uint32_t v = begin; v < end; ++v)
      if (out_.vertexAlive[v]) lastCost_[v] = bestCost(sc, v);
  };
  onBoth([&](int half) { work(scratches_[size_t(half)], half ? V_ / 2 : 0, half ? V_ : V_ / 2); });
  for (uint32_t v = 0; v < V_; ++v) queued_[v] = lastCost_[v] < float(kInf);  // (run() queues them)
}

// The linear field s(x) = g·x + c of tet v (its four vertex values) as the hyperplane
// (g, −1, c) of the field quadric, with a quarter of the volume as weight (one quarter to each
// vertex). False for a flat tet, which defines no gradient.
bool Simplifier::fieldHyperplane(const uint32_t* v, double (&hyperplane)[5], double& w) const {
  const Point p0 = p(v[0]), p1 = p(v[1]), p2 = p(v[2]), p3 = p(v[3]);
  double e[3][3], ds[3];
  for (int k = 0; k < 3; ++k) {
    e[0][k] = p1[k] - p0[k];
    e[1][k] = p2[k] - p0[k];
    e[2][k] = p3[k] - p0[k];
  }
  for (int k = 0; k < 3; ++k) ds[k] = double(field_[v[k + 1]]) - field_[v[0]];
  // Gradient g solves e·g = ds (Cramer's rule).
  const double det = det3(e);
  if (!(std::abs(det) > 0)) return false;
  double g[3];
  for (int col = 0; col < 3; ++col) {
    double m[3][3];
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) m[r][k] = k == col ? ds[r] : e[r][k];
    g[col] = det3(m) / det;
  }
  const double c = field_[v[0]] - (g[0] * p0[0] + g[1] * p0[1] + g[2] * p0[2]);
  w = std::abs(det) / 24.0;
  hyperplane[0] = g[0], hyperplane[1] = g[1], hyperplane[2] = g[2], hyperplane[3] = -1.0, hyperplane[4] = c;
  return true;
}

float Simplifier::tetKappa(uint32_t t) const {
  const uint32_t* v = &out_.tets[4 * size_t(t)];
  const TetShape shape = tetShape(p(v[0]), p(v[1]), p(v[2]), p(v[3]));
  if (shape.det <= kFlat * shape.longestEdge * std::sqrt(shape.longestEdge)) return kKappaCap;
  return float(std::min<double>(kKappaCap, shape.kappa()));
}

// A part's state from the level below (SimplifyPart::carried): boundary flags and quadrics,
// field quadrics, counts and values as that level's collapses left them. (The boundary of the
// part's tets is not the input's: a halo tet's outer faces may lie inside the input.)
void Simplifier::takeCarried(const CarriedVertexState& c) {
  boundary_ = c.boundary;
  for (uint32_t v = 0; v < V_; ++v)
    if (boundary_[v]) {
      quadricOf_[v] = uint32_t(quadrics_.size());
      quadrics_.push_back(c.boundaryQuadric[v]);
    }
  fieldQuadric_ = c.fieldQuadric;
  represented_ = c.represented;
  if (c.fitRange.size() == V_) fitRange_ = c.fitRange;
}

// out_.carried: the state at the end of the vertices left alive, in vertex order (what the next
// level gets; at the peak of a part's simplification, a copy for every vertex was a fifth of
// its memory, 230 bytes a vertex).
void Simplifier::fillCarried() {
  CarriedVertexState& c = out_.carried;
  c = CarriedVertexState{};
  uint32_t alive = 0;
  for (uint32_t v = 0; v < V_; ++v) alive += out_.vertexAlive[v];
  c.fit.reserve(alive);
  c.represented.reserve(alive);
  c.boundary.reserve(alive);
  c.boundaryQuadric.reserve(alive);
  c.fieldQuadric.reserve(alive);
  c.fitRange.reserve(fitRange_.empty() ? 0 : alive);
  for (uint32_t v = 0; v < V_; ++v) {
    if (!out_.vertexAlive[v]) continue;
    c.fit.push_back(vert_[v].fit);
    c.represented.push_back(represented_[v]);
    c.boundary.push_back(boundary_[v]);
    c.boundaryQuadric.push_back(boundaryQuadric(v));
    c.fieldQuadric.push_back(fieldQuadric_[v]);
    if (!fitRange_.empty()) c.fitRange.push_back(fitRange_[v]);
  }
}

}  // namespace tetstream::simplify_detail

namespace tetstream {

using simplify_detail::det3;
using simplify_detail::edgesOf;

// As Simplifier::init() computes them for the whole mesh, in the same order of operations.
SimplifyPart wholeMeshPart(const TetMesh& mesh, int field) {
  SimplifyPart part;
  const Range r = computeRange(mesh.fields[size_t(field)].values);
  part.fieldMin = part.topMin = r.min;
  part.fieldMax = part.topMax = r.max;
  part.diagonal = computeBounds(mesh.positions).diagonal();
  if (!(part.diagonal > 0)) part.diagonal = 1;
  part.inputVertices = mesh.vertexCount();
  const uint32_t V = mesh.vertexCount(), T = mesh.tetCount();
  FaceAdjacency adj;
  buildFaceAdjacency(mesh.tets, V, adj);
  std::vector<uint8_t> boundary(V, 0), used(V, 0);
  for (uint32_t h = 0; h < 4 * T; ++h)
    if (adj.opposite[h] == kNoNeighbor)
      for (int k = 0; k < 3; ++k) boundary[mesh.tets[(h & ~3u) + kTetFaces[h & 3][k]]] = 1;
  // Each vertex's volume: a quarter of every tet around it that has one (the field quadric's
  // weight), summed in tet order.
  std::vector<double> weight(V, 0.0);
  for (uint32_t t = 0; t < T; ++t) {
    const uint32_t* v = &mesh.tets[4 * size_t(t)];
    for (int k = 0; k < 4; ++k) used[v[k]] = 1;
    double e[3][3];
    edgesOf(mesh.positions.data(), v, e);
    const double det = det3(e);
    if (!(std::abs(det) > 0)) continue;
    for (int k = 0; k < 4; ++k) weight[v[k]] += std::abs(det) / 24.0;
  }
  double volume[2] = {0, 0};
  uint32_t count[2] = {0, 0}, alive = 0;
  for (uint32_t v = 0; v < V; ++v)
    if (used[v]) {
      volume[boundary[v]] += weight[v];
      ++count[boundary[v]];
      ++alive;
    }
  const double inside = count[0] ? volume[0] / count[0] : 0;
  const double all = alive ? (volume[0] + volume[1]) / alive : 0;
  part.meanVertexVolume = inside > 0 ? inside : all > 0 ? all : simplify_detail::kInf;
  return part;
}

}  // namespace tetstream
