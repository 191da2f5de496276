// Half-edge-collapse simplification; see simplify.h for the cost and legality rules.
//
// State is flat per-vertex and per-tet arrays. The priority queue holds at most one entry per
// vertex: the last known cost of its cheapest outgoing half-edge. Every half-edge is evaluated
// (both directions), but a vertex whose neighbourhood changed is only re-evaluated when its
// entry reaches the top (lazy update): every pop is evaluated afresh, so a changed vertex keeps
// its entry, and only one that had none (no legal collapse last time) is queued again. Entries
// of removed vertices are dropped when they reach the top; the queue is never rebuilt.
//
// Speculation on two threads: the next few entries of the queue are evaluated at once, then
// processed in queue order on one thread. An evaluation is only used if nothing it read has
// changed since (no collapse of the round touched the vertex or its neighbours) and nothing
// queued meanwhile comes first; otherwise the entry goes back. The result is therefore exactly
// that of the one-thread loop, whatever the timing (tests compare the two).
//
// Before that, a large mesh is simplified in slabs, one thread each, in rounds of rising cost
// (runParts).
#include "simplify.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdlib>
#include <queue>
#include <thread>
#include <atomic>

#include "work_pool.h"

#include "adjacency.h"
#include "tet_quality.h"

namespace tetstream {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr uint32_t kOmega = 0xfffffffeu;   // the virtual vertex the boundary is coned to
constexpr double kFlat = 1e-7;            // |6V| <= kFlat * (longest edge)^3 counts as flat
constexpr float kKappaCap = 1e4f;         // κ of flat tets, capped so averages stay finite

// A symmetric quadric form x^T Q x on N-vectors whose last entry is 1 (homogeneous), stored as
// its upper triangle, with the total weight of what was added. Sums of such forms are the error
// quadrics of Garland & Heckbert (paper eq. 3-4).
template <int N>
struct SymmetricQuadric {
  double q[N * (N + 1) / 2] = {};
  double weight = 0;
  // Adds w·(a·x)² for a plane or hyperplane a.
  void addSquare(const double (&a)[N], double w) {
    int n = 0;
    for (int r = 0; r < N; ++r)
      for (int k = r; k < N; ++k) q[n++] += w * a[r] * a[k];
    weight += w;
  }
  void add(const SymmetricQuadric& o) {
    for (int k = 0; k < N * (N + 1) / 2; ++k) q[k] += o.q[k];
    weight += o.weight;
  }
  double eval(const double (&x)[N]) const {
    double sum = 0;
    int n = 0;
    for (int r = 0; r < N; ++r)
      for (int k = r; k < N; ++k) sum += (r == k ? 1.0 : 2.0) * q[n++] * x[r] * x[k];
    return sum;
  }
};

// Boundary quadric: squared distances to the planes of the boundary faces, area weighted.
using Quadric = SymmetricQuadric<4>;

// Field quadric (Garland & Heckbert's attribute quadrics, applied to the scalar field): each tet
// defines a linear field s(x) = g·x + c; its volume-weighted squared deviation (g·x + c − s)² at a
// point (x, s) of 4D space is a quadric in (x, y, z, s, 1). Summed over the original tets around a
// vertex, and summed again on every collapse, it measures how far a kept vertex and its value
// stray from the original field over the whole region it now stands for.
using FieldQuadric = SymmetricQuadric<5>;

struct Entry {
  float cost;
  uint32_t vertex;
};
struct EntryAfter {  // min-heap by cost, ties by vertex id: deterministic
  bool operator()(const Entry& a, const Entry& b) const {
    return a.cost > b.cost || (a.cost == b.cost && a.vertex > b.vertex);
  }
};


template <typename T>
void sortUnique(std::vector<T>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

template <typename T>
size_t intersectionSize(const std::vector<T>& a, const std::vector<T>& b) {
  size_t n = 0;
  for (size_t x = 0, y = 0; x < a.size() && y < b.size();) {
    if (a[x] < b[y]) ++x;
    else if (b[y] < a[x]) ++y;
    else { ++n; ++x; ++y; }
  }
  return n;
}

struct Tri {
  uint32_t v[3];
  bool operator<(const Tri& o) const { return std::lexicographical_compare(v, v + 3, o.v, o.v + 3); }
  bool operator==(const Tri& o) const { return v[0] == o.v[0] && v[1] == o.v[1] && v[2] == o.v[2]; }
};
Tri makeTri(uint32_t a, uint32_t b, uint32_t c) {
  if (a > b) std::swap(a, b);
  if (b > c) std::swap(b, c);
  if (a > b) std::swap(a, b);
  return {{a, b, c}};
}
uint64_t makeEdge(uint32_t a, uint32_t b) { return a < b ? uint64_t(a) << 32 | b : uint64_t(b) << 32 | a; }

class Simplifier {
 public:
  Simplifier(const TetMesh& m, const SimplifyOptions& o, SimplifyResult& r, FaceAdjacency* adjacency = nullptr,
             std::vector<uint32_t>* takeTets = nullptr)
      : mesh_(m), opt_(o), out_(r), adjacency_(adjacency), takeTets_(takeTets) {}

  CollapseVerdict check(uint32_t i, uint32_t j) {
    init();
    readyLanes();
    Lane& L = *main_.lane;
    neighbours(L, i, L.nbr);
    const size_t slot = size_t(std::find(L.nbr.begin(), L.nbr.end(), j) - L.nbr.begin());
    if (slot == L.nbr.size()) return CollapseVerdict::NotAnEdge;
    CollapseVerdict v = CollapseVerdict::Legal;
    prepareStar(L, i);
    if (legal(L, i, j, bitOf(slot), &v)) {
      Candidate c = boundTerms(L, i, j, bitOf(slot), L.removed, L.removedQuality);
      localTerm(L, i, c);
      finishCost(L, c, &v);
    }
    if (v == CollapseVerdict::Legal && !linkCondition(main_, i, j)) v = CollapseVerdict::LinkCondition;
    return v;
  }

  Result run() {
    init();
    const uint32_t target = std::max<uint32_t>(opt_.targetVertices, 4);
    const uint32_t planned = alive_ > target ? alive_ - target : 0;
    out_.stopReason = "target reached";
    tetsAlive_ = T_;
    Worker& W = main_;
    W.log = &out_.log;
    slack_ = V_ >= opt_.partitionMinVertices ? kLargeMeshSlack : 1.0f;
    if (V_ >= opt_.partitionMinVertices) runParts(planned);
    for (uint32_t v = 0; v < V_; ++v)  // (after the parts: what they left queued)
      if (out_.vertexAlive[v] && queued_[v]) W.heap.push({queueKey(v), v});
    readyLanes();
    const bool parallel = opt_.threads > 1 && V_ >= opt_.parallelMinVertices;
    const uint32_t roundSize = parallel ? kRoundSize : 1;
    trackChanges_ = roundSize > 1;  // (changedThisRound reads changed_ only then)
    if (trackChanges_) changed_.assign(V_, 0);
    WorkPool pool(parallel ? 1 : 0);
    auto evaluateTask = [this](uint32_t k) { evaluateVertex(lanes_[k], round_[k].vertex); };
    auto goOn = [&] { return alive_ - W.collapsed > target && tetsAlive_ - W.tetsRemoved > opt_.targetTets && !W.errorBound; };
    while (goOn()) {
      round_.clear();
      Entry e;
      while (round_.size() < roundSize && peekValid(W.heap, e)) {
        W.heap.pop();
        round_.push_back(e);
      }
      if (round_.empty()) {
        out_.stopReason = "no legal collapse left";
        break;
      }
      pool.run(uint32_t(round_.size()), evaluateTask);
      ++roundStamp_;
      for (size_t k = 0; k < round_.size(); ++k) {
        const Entry& r = round_[k];
        Entry top;
        const bool topValid = peekValid(W.heap, top);
        if (k > 0 && (!goOn() || (topValid && EntryAfter()(r, top)) || changedThisRound(lanes_[k], r.vertex))) {
          for (size_t x = k; x < round_.size(); ++x) W.heap.push(round_[x]);  // evaluated for nothing
          break;
        }
        float next = topValid ? top.cost : float(kInf);
        if (k + 1 < round_.size()) next = std::min(next, round_[k + 1].cost);
        queued_[r.vertex] = 0;
        tryCollapse(W, r.vertex, lanes_[k], next);
        if (opt_.progress && (out_.log.size() & 4095) == 0) opt_.progress(out_.log.size(), planned);
      }
    }
    if (W.errorBound) out_.stopReason = "error bound reached";
    if (opt_.progress) opt_.progress(out_.log.size(), planned);
    auto count = [&](const Worker& w) {
      out_.queuePops += w.pops;
      out_.requeued += w.requeued;
      out_.rejectedByLink += w.rejectedByLink;
      out_.flatTetsRemoved += w.flatTetsRemoved;
      out_.linkMismatches += w.linkMismatches;
    };
    count(main_);
    for (const Worker& w : parts_) count(w);
    alive_ -= W.collapsed;
    tetsAlive_ -= W.tetsRemoved;
    out_.vertices = alive_;
    out_.costEvaluations += mainLane_.evaluations;
    for (const Lane& L : lanes_) out_.costEvaluations += L.evaluations;
    out_.tetCount = 0;
    for (uint32_t t = 0; t < T_; ++t) {
      out_.tetCount += out_.tetAlive[t];
      if (out_.tetAlive[t] && kappa_[t] >= kKappaCap) ++out_.flatTetsLeft;
    }
    out_.log.close(opt_.recordReadSets);
    if (fitOn_ && opt_.refitValues) refitValues();
    if (fitOn_) {
      out_.values.resize(V_);
      for (uint32_t v = 0; v < V_; ++v) out_.values[v] = vert_[v].fit;
      out_.valuesField = opt_.field;
    }
    return Result::success();
  }

 private:
  // ------------------------------------------------------------------ setup
  void init() {
    V_ = mesh_.vertexCount();
    T_ = mesh_.tetCount();
    field_ = mesh_.fields[size_t(opt_.field)].values.data();
    vert_.resize(V_);
    for (uint32_t v = 0; v < V_; ++v) {
      const float* q = &mesh_.positions[3 * size_t(v)];
      vert_[v] = {{q[0], q[1], q[2]}, field_[v]};
    }
    fitOn_ = opt_.fitValues;
    Range r = computeRange(mesh_.fields[size_t(opt_.field)].values);
    range_ = r.max > r.min ? double(r.max) - r.min : 1.0;
    fieldMin_ = r.min;
    fieldMax_ = r.max;
    diag_ = computeBounds(mesh_.positions).diagonal();
    if (!(diag_ > 0)) diag_ = 1;

    assert(!takeTets_ || takeTets_ == &mesh_.tets);
    if (takeTets_) out_.tets = std::move(*takeTets_);  // (mesh_.tets is not read again: T_ counts them)
    else out_.tets = mesh_.tets;
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
    for (uint32_t v = 0; v < V_; ++v)
      if (!star_[v].empty()) { out_.vertexAlive[v] = 1; ++alive_; }

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
    for (uint32_t h = 0; h < 4 * T_; ++h) {
      if (opp_[h] != kNoNeighbor) continue;
      const uint32_t* v = &out_.tets[h & ~3u];
      uint32_t a = v[kFaces[h & 3][0]], b = v[kFaces[h & 3][1]], c = v[kFaces[h & 3][2]];
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
    fieldQuadric_.assign(V_, {});
    // κ of every tet and the per-vertex sums over them (3/κ, field quadrics) on two threads: each
    // adds to the vertices of its own range only, taking the tets in order, so every sum is
    // formed in the same order as on one thread; a tet with vertices in both ranges is computed
    // by both (few, in a mesh numbered coherently).
    uint32_t flat[2] = {0, 0};
    auto sums = [&](int part, uint32_t lo, uint32_t hi) {
      for (uint32_t t = 0; t < T_; ++t) {
        const uint32_t* v = &out_.tets[4 * size_t(t)];
        bool mine[4], any = false;
        for (int k = 0; k < 4; ++k) any |= mine[k] = v[k] >= lo && v[k] < hi;
        if (!any) continue;
        const float kappa = tetKappa(t);
        if (mine[0]) {  // (the owner of its first vertex writes κ)
          kappa_[t] = kappa;
          flat[part] += kappa >= kKappaCap;
        }
        for (int k = 0; k < 4; ++k)
          if (mine[k]) qualitySum_[v[k]] += 3.0 / kappa;
        double hyperplane[5], w;
        if (fieldHyperplane(v, hyperplane, w))
          for (int k = 0; k < 4; ++k)
            if (mine[k]) fieldQuadric_[v[k]].addSquare(hyperplane, w);
      }
    };
    onBoth([&](int part) { sums(part, part ? V_ / 2 : 0, part ? V_ : V_ / 2); });
    flatInput_ += flat[0] + flat[1];
    queued_.assign(V_, 0);
    represented_.assign(V_, 1);
    lastCost_.assign(V_, float(kInf));
    // Every vertex's first cost, on two threads (each with its own scratch lane; the mesh is
    // only read), then queued in vertex order so the result does not depend on the threads.
    main_.lane = &mainLane_;
    lanes_.resize(kRoundSize);
    for (size_t k = 0; k < 2; ++k) lanes_[k].reset(V_);  // (the rest: readyLanes())
    auto work = [this](Lane& L, uint32_t begin, uint32_t end) {
      for (uint32_t v = begin; v < end; ++v)
        if (out_.vertexAlive[v]) lastCost_[v] = bestCost(L, v);
    };
    onBoth([&](int part) { work(lanes_[size_t(part)], part ? V_ / 2 : 0, part ? V_ : V_ / 2); });
    for (uint32_t v = 0; v < V_; ++v) queued_[v] = lastCost_[v] < float(kInf);  // (run() queues them)
  }

  // Runs f(0) and f(1) at once on two threads, or one after the other with threads = 1. Neither
  // may touch what the other writes, so the result is the same either way.
  template <typename F>
  void onBoth(F f) const {
    if (opt_.threads > 1) {
      std::thread second(f, 1);
      f(0);
      second.join();
    } else {
      f(0);
      f(1);
    }
  }

  // Whether j's value is fitted after a collapse that leaves it standing for `count` input
  // vertices: only from kMinFitCount on. Below that the fit gains little while every split that
  // changes j's value costs the viewer an update of all tets around j; this way most splits of
  // the finest levels (the bulk of the stream) leave p_j's value alone.
  bool fitsRegion(uint32_t count) const { return fitOn_ && count >= kMinFitCount; }
  static constexpr uint32_t kMinFitCount = 4;

  // The value s at x that minimises the field quadric (x, s): its derivative in s is zero.
  // (q is the upper triangle of the 5×5 form: q[12] is (s, s), q[3], q[7], q[10] are (x, s),
  // (y, s), (z, s), q[13] is (s, 1).) Kept inside the field's range, which the stream's
  // quantization grid covers.
  double fitted(const FieldQuadric& f, const double* x, double fallback) const {
    const double a = f.q[12], b = f.q[3] * x[0] + f.q[7] * x[1] + f.q[10] * x[2] + f.q[13];
    return a > 0 ? std::clamp(-b / a, fieldMin_, fieldMax_) : fallback;
  }

  static constexpr uint8_t kFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

  // Vertex v's position, from the floats of vert_ (exact in double; a copy in double took 24
  // bytes a vertex of memory and of the caches).
  struct Point {
    double x[3];
    operator const double*() const { return x; }
  };
  Point p(uint32_t v) const {
    const float* q = vert_[v].x;
    return {{q[0], q[1], q[2]}};
  }

  // The linear field s(x) = g·x + c of tet v (its four vertex values) as the hyperplane
  // (g, −1, c) of the field quadric, with a quarter of the volume as weight (one quarter to each
  // vertex). False for a flat tet, which defines no gradient.
  bool fieldHyperplane(const uint32_t* v, double (&hyperplane)[5], double& w) const {
    const Point p0 = p(v[0]), p1 = p(v[1]), p2 = p(v[2]), p3 = p(v[3]);
    double e[3][3], ds[3];
    for (int k = 0; k < 3; ++k) {
      e[0][k] = p1[k] - p0[k];
      e[1][k] = p2[k] - p0[k];
      e[2][k] = p3[k] - p0[k];
    }
    for (int k = 0; k < 3; ++k) ds[k] = double(field_[v[k + 1]]) - field_[v[0]];
    // Gradient g solves e·g = ds (Cramer's rule).
    double det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) - e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                 e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
    if (!(std::abs(det) > 0)) return false;
    double g[3];
    for (int col = 0; col < 3; ++col) {
      double m[3][3];
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) m[r][k] = k == col ? ds[r] : e[r][k];
      g[col] = (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])) / det;
    }
    const double c = field_[v[0]] - (g[0] * p0[0] + g[1] * p0[1] + g[2] * p0[2]);
    w = std::abs(det) / 24.0;
    hyperplane[0] = g[0], hyperplane[1] = g[1], hyperplane[2] = g[2], hyperplane[3] = -1.0, hyperplane[4] = c;
    return true;
  }

  float tetKappa(uint32_t t) const {
    const uint32_t* v = &out_.tets[4 * size_t(t)];
    const TetShape shape = tetShape(p(v[0]), p(v[1]), p(v[2]), p(v[3]));
    if (shape.det <= kFlat * shape.longestEdge * std::sqrt(shape.longestEdge)) return kKappaCap;
    return float(std::min<double>(kKappaCap, shape.kappa()));
  }

  bool tetHas(uint32_t t, uint32_t v) const {
    const uint32_t* x = &out_.tets[4 * size_t(t)];
    return x[0] == v || x[1] == v || x[2] == v || x[3] == v;
  }

  // ------------------------------------------------------------------ costs
  bool isBoundaryEdge(uint32_t i, uint32_t j) const {
    for (uint32_t t : star_[i]) {
      const uint32_t* v = &out_.tets[4 * size_t(t)];
      if (!tetHas(t, j)) continue;
      for (int f = 0; f < 4; ++f)
        if (opp_[4 * t + f] == kNoNeighbor && v[f] != i && v[f] != j) return true;
    }
    return false;
  }

  // Per-tet data of star(i) shared by every candidate target j: with P = p_j in the slot of i,
  // the determinant is g·(P − x0) (newDet), and κ's edge and face terms without P are fixed.
  struct StarTet {
    uint32_t t;
    uint32_t other[3];        // the vertices besides i, in slot order
    uint64_t mask;            // bitOf() their places in Lane::nbr (see removes())
    double g[3];              // det of the new tet with P in the slot of i: g·(P − x[0]) (newDet)
    double detOld;            // det with p_i (numerator for the slot of i)
    double fixedEdges, fixedFace;  // κ's terms of the edges and the face without p_i
    double x[3][3];           // positions of the other vertices
    double sign;              // orientation sign of the slot of i
    float f[3];               // field at the other vertices
    float kappa;              // κ of the tet now
    double quality;           // 3/κ now
  };

  // A candidate's cost is refined in stages while it could still be the cheapest
  // (cheapestCandidate): each stage's cost is a lower bound of the next one's.
  struct Candidate {
    enum Stage : uint8_t { Bound, Local, Exact };
    double cost;     // exact, or a lower bound until stage Exact
    double base;     // the cost without the shape term
    double sj, region, eg, weight, shapeBound;  // parts of the cost (boundTerms)
    uint32_t j;
    uint64_t bit;    // bitOf(j's place in Lane::nbr)
    float fieldErr;  // E_f (from stage Local on)
    Stage stage;
  };

  // Scratch for evaluating one vertex's out-edges; one per thread.
  struct Lane {
    std::vector<StarTet> star;
    uint32_t center = 0;  // the vertex of star
    double flatBound = 0;  // see prepareStar
    double qualityFloor = 0;  // the least 3/κ a changed tet may have (see prepareStar)
    uint64_t boundaryEdges = 0;  // bitOf() the neighbours joined to the vertex by a boundary edge
    double removedQuality = 0;  // of the last legal() candidate: Σ 3/κ of the tets it removes
    int removed = 0;            // ... and their count
    std::vector<uint32_t> nbr;
    struct Passed {  // an out-edge that passed legal(), with what legal() found of it
      uint32_t place;  // in nbr
      int removed;
      double removedQuality;
    };
    std::vector<Passed> passed;
    std::vector<Candidate> candidates;
    std::vector<uint32_t> seen;  // neighbour stamps
    std::vector<uint8_t> place;  // per vertex seen with the last stamp of neighbours(): its place in nbr (≤ 255)
    void reset(uint32_t vertices) {
      seen.assign(vertices, 0);
      place.assign(vertices, 0);
    }
    uint32_t stamp = 0;
    uint64_t evaluations = 0;
  };

  // A small open-addressing table of edge keys with a byte of state, emptied in O(1) by
  // changing its stamp. Link edge sets have tens of entries; it grows if ever needed.
  struct EdgeTable {
    std::vector<uint64_t> keys;
    std::vector<uint32_t> stamps;
    std::vector<uint8_t> values;
    uint32_t stamp = 0, count = 0;
    void beginSet(uint32_t s) {
      if (keys.empty()) { keys.resize(512); stamps.assign(512, 0); values.resize(512); }
      stamp = s;
      count = 0;
    }
    size_t slot(uint64_t key) const {
      uint64_t h = key * 0x9e3779b97f4a7c15ull;
      size_t mask = keys.size() - 1;
      for (size_t k = size_t(h >> 40) & mask;; k = (k + 1) & mask)
        if (stamps[k] != stamp || keys[k] == key) return k;
    }
    uint8_t get(uint64_t key) const {
      size_t k = slot(key);
      return stamps[k] == stamp ? values[k] : 0;
    }
    void mark(uint64_t key, uint8_t value) {
      if (2 * (count + 1) > keys.size()) grow();
      size_t k = slot(key);
      if (stamps[k] != stamp) { stamps[k] = stamp; keys[k] = key; ++count; }
      values[k] = value;
    }
    void grow() {
      EdgeTable bigger;
      bigger.keys.resize(2 * keys.size());
      bigger.stamps.assign(2 * keys.size(), 0);
      bigger.values.resize(2 * keys.size());
      bigger.stamp = stamp;
      for (size_t k = 0; k < keys.size(); ++k)
        if (stamps[k] == stamp) {
          size_t s = bigger.slot(keys[k]);
          bigger.stamps[s] = stamp;
          bigger.keys[s] = keys[k];
          bigger.values[s] = values[k];
          ++bigger.count;
        }
      *this = std::move(bigger);
    }
  };

  using Heap = std::priority_queue<Entry, std::vector<Entry>, EntryAfter>;

  // What the collapse loop works with: the queue of the whole mesh, or of one slab in the
  // parallel phase (runParts), with its own log and scratch.
  struct Worker {
    int part = -1;          // -1: the whole mesh; else the slab
    Heap heap;
    CollapseLog ownLog;     // a slab's collapses in this round (merged into out_.log after it)
    CollapseLog* log = &ownLog;
    std::vector<float> keys;  // a slab's collapses: the queue key each was taken at
    Lane* lane = nullptr;   // link condition and collapse (and a slab's evaluations): its thread's
    std::atomic<uint32_t> collapsed{0};  // (read by the progress report on the other thread)
    uint32_t tetsRemoved = 0;
    uint64_t pops = 0, requeued = 0, rejectedByLink = 0, flatTetsRemoved = 0, linkMismatches = 0;
    bool errorBound = false;
    std::vector<uint32_t> touched, around;
    CollapseTets record;    // the tets of the collapse being made
    std::vector<uint64_t> linkEdges, edgeLink;
    EdgeTable edgeTable;
    uint32_t edgeTableStamp = 0;
  };


  // (After neighbours(L, i, L.nbr).)
  void prepareStar(Lane& L, uint32_t i) {
    const std::vector<uint32_t>& star = star_[i];
    L.star.resize(star.size());
    L.center = i;
    const Point pi = p(i);
    // Every edge of a tet after the collapse lies in the star's bounding box, so the flatness
    // threshold of the longest possible edge bounds every tet's own threshold from above.
    double lo[3] = {pi[0], pi[1], pi[2]}, hi[3] = {pi[0], pi[1], pi[2]};
    float worstKappa = 0;
    L.boundaryEdges = 0;
    for (size_t n = 0; n < star.size(); ++n) {
      const uint32_t t = star[n];
      const uint32_t* v = &out_.tets[4 * size_t(t)];
      if (boundary_[i])  // the boundary faces at i give its boundary edges (see legal())
        for (int f = 0; f < 4; ++f)
          if (v[f] != i && opp_[4 * size_t(t) + f] == kNoNeighbor)
            for (int k = 0; k < 4; ++k)
              if (k != f && v[k] != i) L.boundaryEdges |= bitOf(L.place[v[k]]);
      StarTet& st = L.star[n];
      st.t = t;
      st.mask = 0;
      st.kappa = kappa_[t];
      st.quality = 3.0 / st.kappa;
      worstKappa = std::max(worstKappa, st.kappa);
      int si = 0, m = 0;
      for (int k = 0; k < 4; ++k) {
        if (v[k] == i) { si = k; continue; }
        const Point q = p(v[k]);
        st.other[m] = v[k];
        st.mask |= bitOf(L.place[v[k]]);
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
    for (uint32_t w : L.nbr) {  // (neighbours() listed the star's vertices but i)
      const Point q = p(w);
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], q[a]);
        hi[a] = std::max(hi[a], q[a]);
      }
    }
    const double diam2 = (hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]);
    L.flatBound = kFlat * diam2 * std::sqrt(diam2);
    // A changed tet must reach the minimum quality, or else be no worse than the worst tet of
    // the star now: real meshes (boundary layers of CFD grids) start with tets far below any
    // fixed minimum, and a collapse that does not make their region worse is allowed.
    L.qualityFloor = std::min(opt_.minQuality, 3.0 / double(worstKappa));
  }

  // Whether the new tet (P and the others of st) is flat, judged by its own longest edge.
  static bool isFlat(const StarTet& st, const double* P, double det) {
    double longest = std::max({dist2(st.x[0], st.x[1]), dist2(st.x[0], st.x[2]), dist2(st.x[1], st.x[2])});
    for (int k = 0; k < 3; ++k) longest = std::max(longest, dist2(P, st.x[k]));
    return det <= kFlat * longest * std::sqrt(longest);
  }

  static double dist2(const double* a, const double* b) {
    double d0 = a[0] - b[0], d1 = a[1] - b[1], d2 = a[2] - b[2];
    return d0 * d0 + d1 * d1 + d2 * d2;
  }
  static double dot(const double* u, const double* v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; }
  // A bit for each of the first 64 neighbours (by place in Lane::nbr), 0 for the others.
  static uint64_t bitOf(size_t place) { return place < 64 ? uint64_t(1) << place : 0; }
  // Whether the collapse onto j (bit: bitOf(its place)) removes star tet st: st has j.
  static bool removes(const StarTet& st, uint32_t j, uint64_t bit) {
    return bit ? (st.mask & bit) != 0 : st.other[0] == j || st.other[1] == j || st.other[2] == j;
  }
  // The edges from P to st's other vertices x0, x1, x2.
  static void edgesFrom(const double* P, const StarTet& st, double* a, double* b, double* e) {
    for (int k = 0; k < 3; ++k) {
      a[k] = st.x[0][k] - P[k];
      b[k] = st.x[1][k] - P[k];
      e[k] = st.x[2][k] - P[k];
    }
  }
  // The determinant of st's tet with P in the slot of i (positive: properly oriented), from the
  // move m = P − p_i: g·(P − x0) = detOld + g·m, three products a tet instead of six operations
  // (legal() runs this for every tet around i and every neighbour of i).
  static double newDet(const StarTet& st, const double* m) { return st.detOld + dot(st.g, m); }
  static void moveTo(const double* P, const double* pi, double* m) {
    for (int k = 0; k < 3; ++k) m[k] = P[k] - pi[k];
  }
  static void cross(const double* u, const double* v, double* n) {
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
  }

  // Cost of hec(i → j) given prepareStar(i), in steps so that the expensive terms are only
  // computed for candidates that can still win (cheapestCandidate): legal() checks the boundary
  // rule and that no tet inverts or flattens, boundTerms() a lower bound from the geometric and
  // region terms, localTerm() adds the local field error, finishCost() the exact shape term and
  // the minimum-quality check.
  bool legal(Lane& L, uint32_t i, uint32_t j, uint64_t bit, CollapseVerdict* verdict) {
    ++L.evaluations;
    *verdict = CollapseVerdict::Legal;
    if (boundary_[i] && !(bit ? (L.boundaryEdges & bit) != 0 : isBoundaryEdge(i, j)))
      return *verdict = CollapseVerdict::BoundaryRule, false;
    const Point P = p(j);
    double m[3];
    moveTo(P, p(i), m);
    L.removedQuality = 0;  // Σ 3/κ of the tets the collapse removes, and their count
    L.removed = 0;
    for (const StarTet& st : L.star) {
      if (removes(st, j, bit)) {
        L.removedQuality += st.quality;
        ++L.removed;
        continue;
      }
      const double det = newDet(st, m);
      if (det <= 0) return *verdict = CollapseVerdict::Inverted, false;
      if (det <= L.flatBound && isFlat(st, P, det)) return *verdict = CollapseVerdict::Flat, false;
    }
    return true;
  }

  // Everything of the cost but the local field error and the exact shape term: the geometric
  // error, the region term of the field error and a lower bound of the shape term.
  // (removed, removedQuality: what legal() found of the tets the collapse removes.)
  Candidate boundTerms(Lane& L, uint32_t i, uint32_t j, uint64_t bit, int removed, double removedQuality) {
    const Point P = p(j);
    Candidate c;
    c.j = j;
    c.bit = bit;
    FieldQuadric fq = fieldQuadric_[i];
    fq.add(fieldQuadric_[j]);
    const uint32_t count = represented_[i] + represented_[j];
    c.sj = fitsRegion(count) ? fitted(fq, P, vert_[j].fit) : vert_[j].fit;
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
    // The error terms are weighted by the square root of the number of input vertices i and j
    // stand for together: about the root of the summed squared error at those vertices (paper
    // eq. 5 sums over them), which is what adds to the RMS over the whole mesh, so a collapse
    // that spreads an error over a large region waits behind one that keeps it local. A count,
    // not a volume: graded CFD grids put most vertices in thin boundary layers, where a volume
    // weight made the error 1.8× larger on Blunt Fin. The manifest reports the unweighted E_f.
    c.weight = std::sqrt(double(count));
    // E_s after the collapse with every new tet at the best quality (3/κ = 1), as the tets of
    // p_j's star that stay are known: most candidates lose without finishCost(). Scaled down a
    // little so that round-off (its sums run in another order) never lifts it above E_s.
    const double moved = double(L.star.size()) - removed, after = double(star_[j].size()) - removed + moved;
    c.shapeBound = after > 0 ? std::max(0.0, 1.0 - (qualitySum_[j] - removedQuality + moved) / after) : 0.0;
    setCost(c, 0.0);  // a lower bound: the local error is at least 0 (rounding is monotone)
    c.stage = Candidate::Bound;
    return c;
  }

  // The cost with the local field error `local` and the bound of the shape term.
  void setCost(Candidate& c, double local) const {
    const double ef = local + c.region;
    c.fieldErr = float(ef);
    c.base = c.weight * (opt_.weightGeometry * c.eg + opt_.weightField * ef);
    c.cost = c.base + opt_.weightShape * c.shapeBound * (1 - 1e-9);
  }

  // Adds the paper's local field error (eq. 6) to a candidate of boundTerms():
  // |S(p_i) − S'(p_i)| / range, where S' interpolates the coarse field at p_i among the new tets.
  // The first tet that contains p_i wins; if none does (p_i on the boundary, or round-off), the
  // one it is least outside of. Only signs are needed until the tet is found (det > 0).
  void localTerm(Lane& L, uint32_t i, Candidate& c) {
    const uint32_t j = c.j;
    const Point P = p(j);
    const Point pi = p(i);
    const double d[3] = {pi[0] - P[0], pi[1] - P[1], pi[2] - P[2]};
    double bestInside = -kInf, interp = c.sj;
    for (const StarTet& st : L.star) {
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

  bool finishCost(Lane& L, Candidate& c, CollapseVerdict* verdict) {
    const uint32_t j = c.j;
    const Point P = p(j);
    double m[3];
    moveTo(P, p(L.center), m);
    double qualitySum = qualitySum_[j];
    int64_t count = int64_t(star_[j].size());
    for (const StarTet& st : L.star) {
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
      if (quality < L.qualityFloor) return *verdict = CollapseVerdict::LowQuality, false;
      qualitySum += std::max(quality, 3.0 / kKappaCap);
      ++count;
    }
    // Mean of (κ − 3)/κ = 1 − 3/κ: the paper's κ − 3, mapped onto [0, 1) so that one sliver
    // cannot outweigh the field error (see simplify.h).
    double es = count > 0 ? std::max(0.0, 1.0 - qualitySum / double(count)) : 0.0;
    c.cost = c.base + opt_.weightShape * es;
    c.stage = Candidate::Exact;
    return true;
  }

  // The legal out-edges of i with their lower bounds (prepareStar(i) and neighbours(i) first).
  // What boundTerms() reads of a neighbour is scattered over large arrays (the loads of the field
  // quadrics were half of its time): it is asked for as soon as legal() passes the out-edge, and
  // only then. Asking for every neighbour's while legal() ran, as before session 21, fetched four
  // times what was used (about 3 of 14 out-edges are legal), and the two threads of the slabs
  // share the memory's bandwidth: 3-5% more time in the simplifier on Harmonic 64³.
  void gatherCandidates(Lane& L, uint32_t i) {
    L.candidates.clear();
    L.passed.clear();
    for (size_t n = 0; n < L.nbr.size(); ++n) {
      CollapseVerdict v;
      const uint32_t w = L.nbr[n];
      if (!legal(L, i, w, bitOf(n), &v)) continue;
      L.passed.push_back({uint32_t(n), L.removed, L.removedQuality});
      const char* q = reinterpret_cast<const char*>(&fieldQuadric_[w]);
      __builtin_prefetch(q);
      __builtin_prefetch(q + 64);
      __builtin_prefetch(&star_[w]);
      __builtin_prefetch(&qualitySum_[w]);
      __builtin_prefetch(&represented_[w]);
    }
    for (const Lane::Passed& x : L.passed) {
      L.candidates.push_back(boundTerms(L, i, L.nbr[x.place], bitOf(x.place), x.removed, x.removedQuality));
    }
  }

  // Best-first over the candidates: the cheapest one with an exact cost, finishing bounds only
  // while one could still win. Returns its index, or -1 when none is legal.
  int cheapestCandidate(Lane& L, uint32_t i) {
    for (;;) {
      int best = -1;
      for (int c = 0; c < int(L.candidates.size()); ++c) {
        const Candidate& x = L.candidates[size_t(c)];
        if (best < 0 || x.cost < L.candidates[size_t(best)].cost ||
            (x.cost == L.candidates[size_t(best)].cost && x.j < L.candidates[size_t(best)].j))
          best = c;
      }
      if (best < 0) return -1;
      Candidate& b = L.candidates[size_t(best)];
      if (b.stage == Candidate::Exact) return best;
      CollapseVerdict v;
      if (b.stage == Candidate::Bound) localTerm(L, i, b);
      else if (!finishCost(L, b, &v)) L.candidates.erase(L.candidates.begin() + best);
    }
  }

  // Distinct vertices of the tets around v (v excluded), in first-seen order: a stamp per vertex
  // instead of sorting, as this runs for every queue pop.
  void neighbours(Lane& L, uint32_t v, std::vector<uint32_t>& out) {
    out.clear();
    ++L.stamp;
    L.seen[v] = L.stamp;
    for (uint32_t t : star_[v]) {
      __builtin_prefetch(&kappa_[t]);
      for (int k = 0; k < 4; ++k) {
        uint32_t w = out_.tets[4 * size_t(t) + k];
        if (L.seen[w] != L.stamp) {
          L.seen[w] = L.stamp;
          L.place[w] = uint8_t(std::min<size_t>(out.size(), 255));
          out.push_back(w);
          __builtin_prefetch(&vert_[w]);  // prepareStar and legal() read it next
        }
      }
    }
  }

  // Asks for the tets around v, which neighbours(v) reads first: called for the vertex likely
  // to be evaluated next, while the current one is.
  void prefetchStar(uint32_t v) const {
    for (uint32_t t : star_[v]) __builtin_prefetch(&out_.tets[4 * size_t(t)]);
  }

  // The cost of v's cheapest legal out-edge (infinity when it has none).
  float bestCost(Lane& L, uint32_t v) {
    neighbours(L, v, L.nbr);
    prepareStar(L, v);
    gatherCandidates(L, v);
    int best = cheapestCandidate(L, v);
    return best < 0 ? float(kInf) : float(L.candidates[size_t(best)].cost);
  }

  // Pops are re-evaluated (the neighbourhood of the target may have changed since the push):
  // the candidates of every out-edge of v in lane L, the cheapest one with its exact cost.
  void evaluateVertex(Lane& L, uint32_t v) {
    neighbours(L, v, L.nbr);
    prepareStar(L, v);
    gatherCandidates(L, v);
    cheapestCandidate(L, v);  // finishes the winner here, on the lane's thread
  }

  // The key v is queued under: its last known cost, or 0 when it had no legal collapse then.
  float queueKey(uint32_t v) const { return std::isfinite(lastCost_[v]) ? lastCost_[v] : 0.0f; }

  // The top entry of the queue that is still current (stale ones are dropped on the way).
  bool peekValid(Heap& heap, Entry& e) {
    while (!heap.empty()) {
      e = heap.top();
      if (out_.vertexAlive[e.vertex]) return true;
      heap.pop();
    }
    return false;
  }

  // Whether a collapse of this round changed anything evaluateVertex(L, v) read: v's star and,
  // for the targets, their quadrics, κ sums and star sizes; all of these change only for the
  // vertices a collapse touches.
  bool changedThisRound(const Lane& L, uint32_t v) const {
    if (changed_[v] == roundStamp_) return true;
    for (uint32_t w : L.nbr)
      if (changed_[w] == roundStamp_) return true;
    return false;
  }

  // Collapses i along its cheapest legal out-edge (evaluated in L) unless that costs more than
  // slack_ × `next`, the key of the next entry: then i goes back into the queue under its new
  // cost. Most pops find that the cost went up since a neighbour collapsed. On meshes large
  // enough to be cut in slabs, those within 10% are taken anyway: a quarter fewer pops (each
  // evaluates every out-edge of i), a field error 0.3–1.2% higher on Harmonic 64³ and up to 0.6%
  // on the carotid data, 1.8% fewer bytes. Small meshes pack in moments: they keep the exact
  // order (the 8,750 tets of post.vtk got up to 12% worse with the slack).
  static constexpr float kLargeMeshSlack = 1.1f;
  void tryCollapse(Worker& W, uint32_t i, Lane& L, float next) {
    ++W.pops;
    bool first = true;
    for (int c; (c = cheapestCandidate(L, i)) >= 0;) {
      const Candidate cand = L.candidates[size_t(c)];
      if (first) lastCost_[i] = float(cand.cost);
      first = false;
      if (float(cand.cost) > next * slack_) {
        W.heap.push({float(cand.cost), i});  // something else is cheaper now
        queued_[i] = 1;
        ++W.requeued;
        return;
      }
      if (cand.fieldErr > opt_.maxError) {  // the next collapse in line would exceed the bound
        W.heap.push({float(cand.cost), i});
        queued_[i] = 1;
        W.errorBound = true;
        return;
      }
      if (W.part >= 0 && !inner_[cand.j]) {  // a part leaves it to the whole mesh's queue
        queued_[i] = 1;
        return;
      }
      if (!linkCondition(W, i, cand.j)) {
        ++W.rejectedByLink;
        L.candidates.erase(L.candidates.begin() + c);
        continue;
      }
      collapse(W, i, cand.j, cand.fieldErr, float(cand.cost));
      return;
    }
    if (first) lastCost_[i] = float(kInf);
    // No legal collapse from i until its neighbourhood changes (then it is queued again).
  }

  // ------------------------------------------------------------------ the parallel phase
  // Most collapses happen in slabs of the mesh, one thread each. A slab owns the vertices inside
  // it, and only collapses i → j where i and j are inner: all their neighbours are its own. A
  // collapse changes the tets around i and j (vertices, κ, faces) and the stars, κ sums, quadrics
  // and values of i's neighbours; an evaluation reads those of v, its star and its neighbours.
  // For inner vertices all of that is the slab's own, so slabs touch disjoint data, no slab's
  // collapses depend on another's or on timing (one thread gives the same result), and any
  // interleaving of their sequences is a valid sequence of collapses: each round's are merged by
  // the key each was taken at, close to the order of one queue.
  //
  // Rounds: every slab collapses its entries up to a key τ, then τ grows by kTauGrowth. The
  // rounds alternate between two slabs cut at the median and three cut at the quartiles, so a
  // vertex left waiting along one round's cut is inner in the next and is collapsed within a
  // step of τ of its turn. (With one fixed cut its vertices waited for the whole mesh's queue at
  // the end: they were the last collapses and so the first splits, and the levels around 12% of
  // Harmonic 64³'s vertices spent a quarter of their vertices on a refined slab along the cut.
  // Parallel cuts never cross, so no vertex waits on two; more slabs, for smaller working sets,
  // made the stream up to 10% larger and were no faster.) Growth 2 left the levels up to 3%
  // worse than √2; 2^¼ was no better than √2 and takes twice the rounds (each ~10 ms on
  // Harmonic 64³).
  // The slabs take kPartShare of the planned collapses; the one queue of the whole mesh then
  // evens out what they left along the last round's cuts and takes the rest. Its collapses cost
  // twice as much time as the slabs' (Harmonic 64³: 5% of the collapses took 0.22 s there).
  // Shares from 0.95 to 0.99 gave the same field error within 0.3% at every level of Harmonic
  // 64³; with 1, Harmonic 20³ cut to 2.5% of its vertices got 55% worse (nothing evens out).
  static constexpr double kPartShare = 0.98;
  static constexpr float kTauGrowth = 1.41421356f;
  static constexpr uint32_t kMaxSlabs = 3;

  // The slab of every alive vertex: two cut at the median of `order`'s alive vertices or, on
  // staggered rounds, three cut at the quartiles. Returns the number of slabs.
  uint32_t slabsOf(const std::vector<uint32_t>& order, uint32_t alive, bool staggered, std::vector<uint32_t>& slab) const {
    const uint32_t count = staggered ? 3 : 2;
    uint32_t rank = 0, s = 0;
    for (uint32_t v : order) {
      if (!out_.vertexAlive[v]) continue;
      // Slab s holds the ranks below its upper quantile: 1/2, or 1/4 and 3/4.
      while (s + 1 < count && 4 * uint64_t(rank) >= uint64_t(alive) * (staggered ? 2 * s + 1 : 2)) ++s;
      slab[v] = s;
      ++rank;
    }
    return count;
  }

  void runParts(uint32_t planned) {
    // The order the slabs follow: the vertex numbering (meshes are mostly numbered coherently,
    // and the split stream then compresses best: Harmonic 64³'s grew by 9% with slabs across its
    // numbering) or an axis, whichever crosses fewest vertices when halved.
    std::vector<uint32_t> order, candidate, slab(V_, 0);
    for (uint32_t v = 0; v < V_; ++v)
      if (out_.vertexAlive[v]) candidate.push_back(v);
    size_t fewest = ~size_t(0);
    for (int axis = -1; axis < 3; ++axis) {
      if (axis >= 0)
        std::stable_sort(candidate.begin(), candidate.end(), [&](uint32_t a, uint32_t b) { return p(a)[axis] < p(b)[axis]; });
      slabsOf(candidate, alive_, false, slab);
      markInner(slab);
      size_t border = 0;
      for (uint32_t v : candidate) border += !inner_[v];
      if (border < fewest) {
        fewest = border;
        order = candidate;
      }
    }
    for (uint32_t s = 0; s < kMaxSlabs; ++s) parts_[s].part = int(s);
    // The log sized up front (a log grown by doubling holds up to twice its size): a collapse
    // removes about (T − target tets) / planned tets and moves the rest of a star of 4T/V tets.
    const double removedEach = double(tetsAlive_ - std::min<uint32_t>(tetsAlive_, opt_.targetTets)) / std::max(1u, planned);
    const double movedEach = std::max(0.0, 4.0 * tetsAlive_ / std::max<uint32_t>(alive_, 1) - removedEach);
    const double expected = planned + 1.0;
    forEachArray([&](auto& v) { v.reserve(size_t(expected)); }, out_.log);
    out_.log.tetBytes.reserve(size_t(expected * (CollapseLog::kHeaderBytes + CollapseLog::kMovedBytes * movedEach +
                                                 CollapseLog::kRemovedBytes * removedEach)));
    if (opt_.recordReadSets) out_.log.star.reserve(size_t(expected * 4.0 * tetsAlive_ / std::max<uint32_t>(alive_, 1)));

    const double budgetV = kPartShare * planned;
    const double budgetT = opt_.targetTets > 0 ? kPartShare * (double(tetsAlive_) - opt_.targetTets) : kInf;
    double capV[kMaxSlabs], capT[kMaxSlabs], inner[kMaxSlabs];
    std::vector<uint32_t> thread[2];
    float tau = 0;
    uint32_t collapsedAll = 0, removedAll = 0;
    auto work = [&](int t) {
      for (uint32_t s : thread[t]) {
        Worker& W = parts_[s];
        Entry e, top;
        while (W.collapsed < capV[s] && W.tetsRemoved < capT[s] && !W.errorBound && peekValid(W.heap, e) &&
               e.cost <= tau) {
          W.heap.pop();
          queued_[e.vertex] = 0;
          if (!W.heap.empty()) prefetchStar(W.heap.top().vertex);
          evaluateVertex(*W.lane, e.vertex);
          tryCollapse(W, e.vertex, *W.lane, peekValid(W.heap, top) ? top.cost : float(kInf));
          if (t == 0 && opt_.progress && (W.collapsed & 4095) == 0) {
            uint32_t done = collapsedAll;
            for (const Worker& x : parts_) done += x.collapsed;
            opt_.progress(done, planned);
          }
        }
      }
    };
    // Rounds end when the budget is spent, nothing is queued, or two rounds in a row (one of each
    // kind) collapsed nothing: what is left waits along the cuts for the whole mesh's queue.
    for (int round = 0, idle = 0; idle < 2; ++round) {
      const uint32_t slabs = slabsOf(order, alive_ - collapsedAll, round & 1, slab);
      markInner(slab);
      // The slabs' queues anew: every queued inner vertex under its last known cost.
      std::vector<Entry> entries[kMaxSlabs];
      std::fill(inner, inner + kMaxSlabs, 0.0);
      for (uint32_t v : order) {
        if (!out_.vertexAlive[v] || !inner_[v]) continue;
        inner[slab[v]] += 1;
        if (queued_[v]) entries[slab[v]].push_back({queueKey(v), v});
      }
      float least = float(kInf);
      bool errorBound = false;
      double innerAll = 0;
      for (uint32_t s = 0; s < slabs; ++s) {
        Worker& W = parts_[s];
        W.heap = Heap(EntryAfter(), std::move(entries[s]));
        if (!W.heap.empty()) least = std::min(least, W.heap.top().cost);
        errorBound |= W.errorBound;
        innerAll += inner[s];
      }
      const double leftV = budgetV - collapsedAll, leftT = budgetT - removedAll;
      if (leftV < 1 || leftT < 1 || least == float(kInf) || errorBound) break;
      tau = std::max(kTauGrowth * tau, least);
      // Each slab's collapses this round are capped, in proportion to its inner vertices, by
      // what is left of the budget; the slabs go to the threads by size, largest first.
      uint32_t bySize[kMaxSlabs];
      for (uint32_t s = 0; s < slabs; ++s) bySize[s] = s;
      std::stable_sort(bySize, bySize + slabs, [&](uint32_t a, uint32_t b) { return inner[a] > inner[b]; });
      double load[2] = {0, 0};
      thread[0].clear();
      thread[1].clear();
      for (uint32_t k = 0; k < slabs; ++k) {
        const uint32_t s = bySize[k];
        Worker& W = parts_[s];
        W.collapsed = 0;
        W.tetsRemoved = 0;
        capV[s] = leftV * inner[s] / innerAll;
        capT[s] = leftT * inner[s] / innerAll;
        const int t = load[1] < load[0] ? 1 : 0;
        load[t] += inner[s];
        thread[t].push_back(s);
        W.lane = &lanes_[size_t(t)];
      }
      onBoth(work);
      mergeRound(slabs);
      uint32_t collapsed = 0;
      for (uint32_t s = 0; s < slabs; ++s) {
        collapsed += parts_[s].collapsed;
        removedAll += parts_[s].tetsRemoved;
      }
      collapsedAll += collapsed;
      idle = collapsed ? 0 : idle + 1;
    }
    // What is left in the slabs' queues stays marked queued_ for the whole mesh's queue.
    out_.slabCollapses += collapsedAll;
    alive_ -= collapsedAll;
    tetsAlive_ -= removedAll;
    for (Worker& W : parts_) {
      W.heap = Heap();
      W.ownLog = CollapseLog();
      W.keys = std::vector<float>();
    }
  }

  // Appends the collapses of this round's slabs to the log, merged by the key each was taken at
  // (ties: the lower slab first), and empties the slabs' logs for the next round.
  void mergeRound(uint32_t slabs) {
    uint32_t next[kMaxSlabs] = {};
    for (;;) {
      int best = -1;
      for (uint32_t s = 0; s < slabs; ++s)
        if (next[s] < parts_[s].ownLog.size() &&
            (best < 0 || parts_[s].keys[next[s]] < parts_[size_t(best)].keys[next[size_t(best)]]))
          best = int(s);
      if (best < 0) break;
      appendCollapse(out_.log, parts_[size_t(best)].ownLog, next[size_t(best)]++);
    }
    for (uint32_t s = 0; s < slabs; ++s) {
      forEachArray([](auto& x) { x.clear(); }, parts_[s].ownLog);
      parts_[s].keys.clear();
    }
  }

  // inner_[v]: every alive tet around v lies in v's slab.
  void markInner(const std::vector<uint32_t>& slab) {
    inner_.assign(V_, 1);
    for (uint32_t t = 0; t < T_; ++t) {
      if (!out_.tetAlive[t]) continue;
      const uint32_t* v = &out_.tets[4 * size_t(t)];
      if (slab[v[0]] != slab[v[1]] || slab[v[0]] != slab[v[2]] || slab[v[0]] != slab[v[3]])
        for (int k = 0; k < 4; ++k) inner_[v[k]] = 0;
    }
  }

  // Calls f with the same array of each log, for every array of a CollapseLog.
  template <class F, class... Logs>
  static void forEachArray(F f, Logs&... logs) {
    f(logs.i...), f(logs.j...), f(logs.fieldError...), f(logs.iValue...), f(logs.jValue...);
    f(logs.tetsBegin...), f(logs.tetBytes...), f(logs.starBegin...), f(logs.star...);
  }

  // Appends collapse c of `src` (whose begin arrays have no closing entry yet) to `dst`.
  static void appendCollapse(CollapseLog& dst, const CollapseLog& src, uint32_t c) {
    dst.i.push_back(src.i[c]);
    dst.j.push_back(src.j[c]);
    dst.fieldError.push_back(src.fieldError[c]);
    dst.iValue.push_back(src.iValue[c]);
    dst.jValue.push_back(src.jValue[c]);
    dst.appendTetsOf(src, c);
    if (src.starBegin.empty()) return;  // (no read sets recorded)
    const uint32_t s0 = src.starBegin[c], s1 = c + 1 < src.size() ? src.starBegin[c + 1] : uint32_t(src.star.size());
    dst.starBegin.push_back(uint32_t(dst.star.size()));
    dst.star.insert(dst.star.end(), src.star.begin() + s0, src.star.begin() + s1);
  }

  // ------------------------------------------------------------------ link condition
  // Lk(i) ∩ Lk(j) = Lk(ij) with the boundary coned to kOmega: vertices and edges of the two
  // links meet exactly in the link of the edge, and no triangle is in both.
  void gatherLink(uint32_t v, std::vector<uint32_t>& verts, std::vector<uint64_t>& edges, std::vector<Tri>& tris) {
    verts.clear();
    edges.clear();
    tris.clear();
    for (uint32_t t : star_[v]) {
      const uint32_t* x = &out_.tets[4 * size_t(t)];
      uint32_t o[3];
      int n = 0, sv = 0;
      for (int k = 0; k < 4; ++k) {
        if (x[k] == v) sv = k;
        else o[n++] = x[k];
      }
      verts.insert(verts.end(), o, o + 3);
      edges.push_back(makeEdge(o[0], o[1]));
      edges.push_back(makeEdge(o[0], o[2]));
      edges.push_back(makeEdge(o[1], o[2]));
      tris.push_back(makeTri(o[0], o[1], o[2]));
      for (int f = 0; f < 4; ++f) {
        if (f == sv || opp_[4 * t + f] != kNoNeighbor) continue;
        uint32_t a = 0, b = 0;  // the boundary face f contains v and two others
        int m = 0;
        for (int k = 0; k < 4; ++k)
          if (k != f && x[k] != v) (m++ == 0 ? a : b) = x[k];
        verts.push_back(kOmega);
        edges.push_back(makeEdge(a, kOmega));
        edges.push_back(makeEdge(b, kOmega));
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
  // (SimplifyOptions::verifyLinkCondition) and count disagreements.
  bool linkCondition(Worker& W, uint32_t i, uint32_t j) {
    const bool verify = opt_.verifyLinkCondition;
    const bool reference = verify && linkConditionBySorting(i, j);
#define TS_LINK_RESULT(x)                                              \
  do {                                                                 \
    const bool result_ = (x);                                          \
    if (verify && result_ != reference) ++W.linkMismatches;            \
    return result_;                                                    \
  } while (0)
    Lane& L = *W.lane;
    auto hasBoundaryFace = [&](uint32_t v) {
      bool any = false;
      forBoundaryFaces(v, [&](uint32_t, uint32_t) { any = true; });
      return any;
    };
    const bool bothBoundary = boundary_[i] && boundary_[j] && hasBoundaryFace(i) && hasBoundaryFace(j);
    // Vertices: common neighbours of i and j (and ω when both are on the boundary) against the
    // link of the edge.
    uint32_t stampJ = ++L.stamp;
    for (uint32_t t : star_[j])
      for (int k = 0; k < 4; ++k) L.seen[out_.tets[4 * size_t(t) + k]] = stampJ;
    uint32_t stampI = ++L.stamp;
    size_t common = bothBoundary ? 1 : 0;
    for (uint32_t t : star_[i])
      for (int k = 0; k < 4; ++k) {
        uint32_t w = out_.tets[4 * size_t(t) + k];
        if (w == i || w == j || L.seen[w] == stampI) continue;
        common += L.seen[w] == stampJ;
        L.seen[w] = stampI;
      }
    // Link of the edge: the opposite edges of the tets around it, and the boundary faces at it.
    size_t edgeVerts = 0, edgeEdges = 0;
    bool boundaryEdge = false;
    uint32_t stampE = ++L.stamp;
    W.edgeLink.clear();
    forEdgeLink(i, j, [&](const uint32_t o[2]) {
      for (int k = 0; k < 2; ++k)
        if (L.seen[o[k]] != stampE) { L.seen[o[k]] = stampE; ++edgeVerts; }
      ++edgeEdges;  // each tet around the edge has its own opposite edge
      W.edgeLink.push_back(makeEdge(o[0], o[1]));
    }, [&](uint32_t k) {
      boundaryEdge = true;
      ++edgeEdges;  // (k, ω) for the boundary face (i, j, k): one per face
      W.edgeLink.push_back(makeEdge(k, kOmega));
    });
    if (common != edgeVerts + (boundaryEdge ? 1 : 0)) TS_LINK_RESULT(false);
    // Edges: those of Lk(j) in a table, then the distinct ones of Lk(i) found there. With the
    // vertices equal, an edge in both links has both ends in Lk(ij) (stamped stampE; ω when the
    // edge is on the boundary): only those are looked at.
    W.edgeTable.beginSet(++W.edgeTableStamp);
    auto inEdgeLink = [&](uint32_t x) { return L.seen[x] == stampE; };
    auto linkEdgesOf = [&](uint32_t v, auto&& each) {
      for (uint32_t t : star_[v]) {
        const uint32_t* x = &out_.tets[4 * size_t(t)];
        uint32_t o[3];
        int n = 0;
        for (int k = 0; k < 4; ++k)
          if (x[k] != v) o[n++] = x[k];
        const bool in[3] = {inEdgeLink(o[0]), inEdgeLink(o[1]), inEdgeLink(o[2])};
        if (in[0] && in[1]) each(makeEdge(o[0], o[1]));
        if (in[0] && in[2]) each(makeEdge(o[0], o[2]));
        if (in[1] && in[2]) each(makeEdge(o[1], o[2]));
      }
      if (boundaryEdge)
        forBoundaryFaces(v, [&](uint32_t a, uint32_t b) {
          if (inEdgeLink(a)) each(makeEdge(a, kOmega));
          if (inEdgeLink(b)) each(makeEdge(b, kOmega));
        });
    };
    linkEdgesOf(j, [&](uint64_t e) { W.edgeTable.mark(e, 1); });
    size_t commonEdges = 0;
    linkEdgesOf(i, [&](uint64_t e) {
      if (W.edgeTable.get(e) == 1) {
        W.edgeTable.mark(e, 2);  // count each shared edge once
        ++commonEdges;
      }
    });
    if (commonEdges != edgeEdges) TS_LINK_RESULT(false);
    // Triangles: with vertices and edges equal, a triangle in both links has its three edges in
    // Lk(ij). Most edge links are a cycle of four or more vertices (or a path closed through ω)
    // without a triangle, and then none is shared; otherwise the faces are looked at.
    if (!hasTriangle(W.edgeLink)) TS_LINK_RESULT(true);
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
      W.linkEdges.clear();  // edges (a, b) of the boundary faces at j
      forBoundaryFaces(j, [&](uint32_t a, uint32_t b) { W.linkEdges.push_back(makeEdge(a, b)); });
      bool shared = false;
      forBoundaryFaces(i, [&](uint32_t a, uint32_t b) {
        shared |= std::find(W.linkEdges.begin(), W.linkEdges.end(), makeEdge(a, b)) != W.linkEdges.end();
      });
      if (shared) TS_LINK_RESULT(false);
    }
    TS_LINK_RESULT(true);
#undef TS_LINK_RESULT
  }

  // Whether three of the edges (a few) form a triangle.
  static bool hasTriangle(const std::vector<uint64_t>& edges) {
    auto ends = [](uint64_t e, uint32_t& a, uint32_t& b) { a = uint32_t(e >> 32), b = uint32_t(e); };
    for (size_t x = 0; x < edges.size(); ++x)
      for (size_t y = x + 1; y < edges.size(); ++y) {
        uint32_t a, b, c, d;
        ends(edges[x], a, b);
        ends(edges[y], c, d);
        // Sharing one end, the other two ends must be joined too.
        uint32_t p = ~0u, q = ~0u;
        if (a == c) p = b, q = d;
        else if (a == d) p = b, q = c;
        else if (b == c) p = a, q = d;
        else if (b == d) p = a, q = c;
        if (p == ~0u || p == q) continue;
        const uint64_t third = makeEdge(p, q);
        for (size_t z = 0; z < edges.size(); ++z)
          if (edges[z] == third) return true;
      }
    return false;
  }

  // The link of edge (i, j): calls edge(o) with the opposite edge o[2] of every tet around it,
  // and face(k) for every boundary face (i, j, k).
  template <typename Edge, typename Face>
  void forEdgeLink(uint32_t i, uint32_t j, Edge edge, Face face) const {
    for (uint32_t t : star_[i]) {
      if (!tetHas(t, j)) continue;
      const uint32_t* x = &out_.tets[4 * size_t(t)];
      uint32_t o[2];
      int n = 0;
      for (int k = 0; k < 4; ++k)
        if (x[k] != i && x[k] != j) o[n++] = x[k];
      edge(o);
      for (int f = 0; f < 4; ++f)
        if (opp_[4 * t + f] == kNoNeighbor && x[f] != i && x[f] != j) face(o[0] == x[f] ? o[1] : o[0]);
    }
  }

  // Calls f(a, b) for every boundary face (v, a, b) around v.
  template <typename F>
  void forBoundaryFaces(uint32_t v, F f) const {
    for (uint32_t t : star_[v]) {
      const uint32_t* x = &out_.tets[4 * size_t(t)];
      for (int face = 0; face < 4; ++face) {
        if (x[face] == v || opp_[4 * t + face] != kNoNeighbor) continue;
        uint32_t a = 0, b = 0;
        int m = 0;
        for (int k = 0; k < 4; ++k)
          if (k != face && x[k] != v) (m++ == 0 ? a : b) = x[k];
        f(a, b);
      }
    }
  }

  bool linkConditionBySorting(uint32_t i, uint32_t j) {
    std::vector<uint32_t> lvI, lvJ, lvE;  // (tests only: allocates)
    std::vector<uint64_t> leI, leJ, leE;
    std::vector<Tri> ltI, ltJ;
    gatherLink(i, lvI, leI, ltI);
    gatherLink(j, lvJ, leJ, ltJ);
    if (intersectionSize(ltI, ltJ) != 0) return false;
    // Link of the edge: the opposite edges of the tets around it, and the boundary faces at it.
        forEdgeLink(i, j, [&](const uint32_t o[2]) {
      lvE.insert(lvE.end(), o, o + 2);
      leE.push_back(makeEdge(o[0], o[1]));
    }, [&](uint32_t k) {
      lvE.push_back(kOmega);
      leE.push_back(makeEdge(k, kOmega));
    });
    sortUnique(lvE);
    sortUnique(leE);
    return intersectionSize(lvI, lvJ) == lvE.size() && intersectionSize(leI, leJ) == leE.size();
  }

  // ------------------------------------------------------------------ the last level's values
  // Each collapse fits j's value to the region j then stands for, but later collapses around j
  // change how the coarse field interpolates there. So at the end the values of the vertices
  // that stand for others are fitted again, all together: least squares of the coarse field
  // against the input field at every input vertex (the RMS error the benchmarks measure),
  // solved by conjugate gradients. A split restores the value j had before its collapse (the
  // log keeps it), so the finer levels and the full mesh are unchanged; a vertex that stands
  // only for itself keeps its sample, as no split would give it back.
  void refitValues() {
    const uint32_t none = ~0u;
    std::vector<uint32_t> rep(V_), col(V_, none);
    for (uint32_t v = 0; v < V_; ++v) rep[v] = v;
    const CollapseLog& log = out_.log;
    for (uint32_t c = log.size(); c-- > 0;) rep[log.i[c]] = rep[log.j[c]];
    std::vector<uint32_t> free;  // the unknowns: alive vertices that stand for others
    for (uint32_t v = 0; v < V_; ++v)
      if (out_.vertexAlive[v] && represented_[v] > 1) {
        col[v] = uint32_t(free.size());
        free.push_back(v);
      }
    if (free.empty()) return;
    // The normal equations' matrix, one row per unknown over the unknowns among its neighbours
    // and itself (column = unknown index; col[] grows with the vertex id, so sorted either way).
    const uint32_t n = uint32_t(free.size());
    std::vector<uint32_t> rowStart(n + 1, 0), cols;
    for (uint32_t r = 0; r < n; ++r) {
      Lane& L = mainLane_;
      neighbours(L, free[r], L.nbr);
      L.nbr.push_back(free[r]);
      std::sort(L.nbr.begin(), L.nbr.end());
      for (uint32_t w : L.nbr)
        if (col[w] != none) cols.push_back(col[w]);
      rowStart[r + 1] = uint32_t(cols.size());
    }
    std::vector<double> a(cols.size(), 0.0), rhs(n, 0.0);
    auto at = [&](uint32_t r, uint32_t c) -> double& {
      auto it = std::lower_bound(cols.begin() + rowStart[r], cols.begin() + rowStart[r + 1], c);
      assert(it != cols.begin() + rowStart[r + 1] && *it == c);
      return a[size_t(it - cols.begin())];
    };
    // Every input vertex located in the coarse mesh (two threads, each a range of vertices),
    // then its squared error added to the rows of the unknowns around it (two threads, each its
    // own rows, taking the vertices in order: every sum is formed as on one thread).
    struct Located {
      uint32_t t4[4];
      double w[4];
      bool usable;  // inside the mesh, and a sample and neighbour values that are numbers
    };
    std::vector<Located> located(V_);
    onBoth([&](int part) {
      for (uint32_t v = part ? V_ / 2 : 0, end = part ? V_ : V_ / 2; v < end; ++v) {
        Located& l = located[v];
        l.usable = false;
        if (out_.vertexAlive[v]) {
          l.t4[0] = v;
          l.w[0] = 1;
          for (int k = 1; k < 4; ++k) l.t4[k] = v, l.w[k] = 0;
        } else if (star_[rep[v]].empty() || !locate(v, star_[rep[v]].front(), l.t4, l.w)) {
          continue;  // (a vertex of no tet stands nowhere)
        }
        l.usable = std::isfinite(field_[v]);  // a NaN or infinite sample (or neighbour value) fits nothing
        for (int x = 0; x < 4; ++x) l.usable = l.usable && (l.w[x] == 0 || std::isfinite(vert_[l.t4[x]].fit));
      }
    });
    onBoth([&](int part) {
      const uint32_t lo = part ? n / 2 : 0, hi = part ? n : n / 2;
      for (uint32_t v = 0; v < V_; ++v) {
        const Located& l = located[v];
        if (!l.usable) continue;
        const double f = field_[v];
        for (int x = 0; x < 4; ++x) {
          const uint32_t r = col[l.t4[x]];
          if (r == none || r < lo || r >= hi || l.w[x] == 0) continue;
          rhs[r] += l.w[x] * f;
          for (int y = 0; y < 4; ++y) {
            if (l.w[y] == 0) continue;
            if (col[l.t4[y]] == none) rhs[r] -= l.w[x] * l.w[y] * vert_[l.t4[y]].fit;  // a fixed value
            else at(r, col[l.t4[y]]) += l.w[x] * l.w[y];
          }
        }
      }
    });
    // Conjugate gradients with a Jacobi preconditioner, from the values the collapses fitted.
    // The values must stay inside the field's range (the stream's grid covers just that): one
    // that ends up outside is held at the bound it crossed and the others are solved again.
    std::vector<double> x(n), res(n), z(n), d(n), q(n), inverse(n);
    std::vector<uint8_t> held(n, 0);
    for (uint32_t r = 0; r < n; ++r) {
      x[r] = std::isfinite(vert_[free[r]].fit) ? vert_[free[r]].fit : 0.0;
      const double diagonal = at(r, r);
      inverse[r] = diagonal > 0 ? 1 / diagonal : 0.0;
      if (!(diagonal > 0)) held[r] = 2;  // no usable sample around it: it keeps its value
    }
    auto multiply = [&](const std::vector<double>& in, std::vector<double>& out) {
      for (uint32_t r = 0; r < n; ++r) {
        double sum = 0;
        for (uint32_t k = rowStart[r]; k < rowStart[r + 1]; ++k) sum += a[k] * in[cols[k]];
        out[r] = held[r] ? 0.0 : sum;
      }
    };
    for (int round = 0; round < kRefitRounds; ++round) {
      multiply(x, q);
      double rz = 0, norm = 0;
      for (uint32_t r = 0; r < n; ++r) {
        res[r] = held[r] ? 0.0 : rhs[r] - q[r];
        z[r] = res[r] * inverse[r];
        d[r] = z[r];
        rz += res[r] * z[r];
        norm += held[r] ? 0.0 : rhs[r] * rhs[r];
      }
      for (int iter = 0; iter < kRefitIterations && rz > 1e-24 * norm; ++iter) {
        multiply(d, q);
        double dq = 0;
        for (uint32_t r = 0; r < n; ++r) dq += d[r] * q[r];
        if (!(dq > 0)) break;
        const double alpha = rz / dq;
        double rzNext = 0;
        for (uint32_t r = 0; r < n; ++r) {
          x[r] += alpha * d[r];
          res[r] -= alpha * q[r];
          z[r] = res[r] * inverse[r];
          rzNext += res[r] * z[r];
        }
        const double beta = rzNext / rz;
        rz = rzNext;
        for (uint32_t r = 0; r < n; ++r) d[r] = z[r] + beta * d[r];
      }
      bool crossed = false;
      for (uint32_t r = 0; r < n; ++r) {
        if (held[r] || (x[r] >= fieldMin_ && x[r] <= fieldMax_)) continue;
        x[r] = std::clamp(x[r], fieldMin_, fieldMax_);
        held[r] = 1;
        crossed = true;
      }
      if (!crossed) break;
    }
    for (uint32_t r = 0; r < n; ++r)
      if (held[r] != 2 && std::isfinite(x[r])) vert_[free[r]].fit = float(std::clamp(x[r], fieldMin_, fieldMax_));
  }
  static constexpr int kRefitRounds = 4;
  static constexpr int kRefitIterations = 200;

  // The tet of the current mesh holding input vertex x, by walking from tet `t` across the face with the
  // most negative barycentric coordinate; outside the mesh (the boundary moved inwards), the
  // tet x is least outside of, with its coordinates clamped to the tet. Weights by vertex.
  bool locate(uint32_t x, uint32_t t, uint32_t* vertices, double* w) const {
    const float* P = mesh_.positions.data();
    double best = -kInf;
    bool found = false;
    for (int step = 0; step < 64; ++step) {
      const uint32_t* v = &out_.tets[4 * size_t(t)];
      const float* q[4] = {P + 3 * size_t(v[0]), P + 3 * size_t(v[1]), P + 3 * size_t(v[2]), P + 3 * size_t(v[3])};
      double l[4];
      if (barycentric(q, P + 3 * size_t(x), l) == -kInf) break;  // flat (left from the input): no coordinates
      int worst = 0;
      for (int k = 1; k < 4; ++k)
        if (l[k] < l[worst]) worst = k;
      if (l[worst] > best) {
        best = l[worst];
        found = true;
        double sum = 0;
        for (int k = 0; k < 4; ++k) sum += std::max(0.0, l[k]);
        for (int k = 0; k < 4; ++k) {
          vertices[k] = v[k];
          w[k] = std::max(0.0, l[k]) / sum;
        }
      }
      if (l[worst] >= 0) break;  // inside
      const uint32_t next = opp_[4 * size_t(t) + size_t(worst)];
      if (next == kNoNeighbor) break;
      t = next >> 2;
    }
    return found;
  }

  // ------------------------------------------------------------------ the collapse
  static void eraseFrom(std::vector<uint32_t>& v, uint32_t x) {
    auto it = std::find(v.begin(), v.end(), x);
    assert(it != v.end());
    *it = v.back();
    v.pop_back();
  }

  // The two vertices of tet v besides those in slots si and sj, in the order that makes
  // (v[si], v[sj], a, b) an even permutation of v: a split that recreates the tet as (i, j, a, b)
  // gives it the same orientation.
  static void orientedOthers(const uint32_t* v, int si, int sj, uint32_t* out) {
    int slot[4] = {si, sj, 0, 0}, n = 2;
    for (int k = 0; k < 4; ++k)
      if (k != si && k != sj) slot[n++] = k;
    int inversions = 0;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) inversions += slot[a] > slot[b];
    if (inversions & 1) std::swap(slot[2], slot[3]);
    out[0] = v[slot[2]];
    out[1] = v[slot[3]];
  }

  void collapse(Worker& W, uint32_t i, uint32_t j, float fieldErr, float key) {
    CollapseLog& log = *W.log;
    if (W.part >= 0) W.keys.push_back(key);
    log.i.push_back(i);
    log.j.push_back(j);
    log.iValue.push_back(vert_[i].fit);
    log.jValue.push_back(vert_[j].fit);
    log.fieldError.push_back(float(fieldErr * range_));
    CollapseTets& record = W.record;
    record.clear();

    W.around.assign(star_[i].begin(), star_[i].end());  // star_ lists change below
    const std::vector<uint32_t>& around = W.around;
    for (uint32_t t : around) {
      uint32_t* v = &out_.tets[4 * size_t(t)];
      if (!tetHas(t, j)) continue;
      // Removed tet (i, j, k, l): glue its neighbours across (j, k, l) and (i, k, l).
      record.removed.push_back(t);
      int si = 0, sj = 0;
      for (int k = 0; k < 4; ++k) {
        if (v[k] == i) si = k;
        if (v[k] == j) sj = k;
      }
      uint32_t others[2];
      orientedOthers(v, si, sj, others);
      record.others.insert(record.others.end(), others, others + 2);
      uint32_t hA = opp_[4 * t + si], hB = opp_[4 * t + sj];
      if (hA != kNoNeighbor) opp_[hA] = hB;
      if (hB != kNoNeighbor) opp_[hB] = hA;
      for (int f = 0; f < 4; ++f) opp_[4 * t + f] = kNoNeighbor;
      if (kappa_[t] >= kKappaCap) ++W.flatTetsRemoved;
      out_.tetAlive[t] = 0;
      ++W.tetsRemoved;
      for (int k = 0; k < 4; ++k) qualitySum_[v[k]] -= 3.0 / kappa_[t];
      for (int k = 0; k < 4; ++k)
        if (v[k] != i) eraseFrom(star_[v[k]], t);
    }
    {  // j's star grows by a quarter beyond what it needs, not by doubling (peak memory 197 -> 192 MB on Harmonic 64³)
      std::vector<uint32_t>& sj = star_[j];
      size_t need = sj.size();
      for (uint32_t t : around) need += out_.tetAlive[t];
      if (need > sj.capacity()) sj.reserve(need + need / 4);
    }
    for (uint32_t t : around) {
      if (!out_.tetAlive[t]) continue;
      uint32_t* v = &out_.tets[4 * size_t(t)];
      for (int k = 0; k < 4; ++k)
        if (v[k] == i) v[k] = j;
      record.moved.push_back(t);
      star_[j].push_back(t);
      float before = kappa_[t];
      kappa_[t] = tetKappa(t);
      for (int k = 0; k < 4; ++k) qualitySum_[v[k]] += 3.0 / kappa_[t] - (v[k] == j ? 0.0 : 3.0 / before);
    }
    log.appendTets(record, j);
    if (opt_.recordReadSets) {
      log.starBegin.push_back(uint32_t(log.star.size()));
      log.star.insert(log.star.end(), star_[j].begin(), star_[j].end());
    }
    star_[i].clear();
    star_[i].shrink_to_fit();
    out_.vertexAlive[i] = 0;
    ++W.collapsed;
    if (boundary_[i]) {  // (then j is on the boundary too, and has a quadric: see legal())
      boundary_[j] = 1;
      assert(quadricOf_[j] != kNoQuadric);
      if (quadricOf_[j] != kNoQuadric) quadrics_[quadricOf_[j]].add(quadrics_[quadricOf_[i]]);
    }
    fieldQuadric_[j].add(fieldQuadric_[i]);
    // j now stands for the region of both: its value becomes the one that fits the original
    // field there best (least squares over the region's original tets, at p_j); the split gives
    // the value before back. (The paper keeps the sample; at 5% of Harmonic's tets fitting
    // lowers the RMS field error by a fifth.)
    represented_[j] += represented_[i];
    if (fitsRegion(represented_[j])) vert_[j].fit = float(fitted(fieldQuadric_[j], p(j), vert_[j].fit));

    // Everything around j changed. j and its neighbours are re-evaluated lazily, when they reach
    // the top: those already queued keep their entry; a blocked one (no legal collapse last
    // time) is queued again under its last known cost, as its neighbourhood changed.
    Lane& L = *W.lane;
    W.touched.clear();
    ++L.stamp;
    L.seen[i] = L.stamp;
    for (uint32_t t : around)
      for (int k = 0; k < 4; ++k) {
        uint32_t w = out_.tets[4 * size_t(t) + k];
        if (L.seen[w] != L.stamp) {
          L.seen[w] = L.stamp;
          W.touched.push_back(w);
        }
      }
    if (trackChanges_) {  // (random writes the slabs and a one-thread queue would make for nothing)
      changed_[i] = roundStamp_;
      for (uint32_t v : W.touched) changed_[v] = roundStamp_;
    }
    for (uint32_t v : W.touched) {
      if (queued_[v]) continue;  // its entry stays: it is evaluated afresh when popped
      queued_[v] = 1;
      if (W.part >= 0 && !inner_[v]) continue;  // left to the whole mesh's queue
      W.heap.push({queueKey(v), v});
    }
  }


  const TetMesh& mesh_;
  const SimplifyOptions& opt_;
  SimplifyResult& out_;
  FaceAdjacency* adjacency_;  // the caller's, taken over by init() (or none)
  std::vector<uint32_t>* takeTets_;  // mesh_.tets, taken over by init() (or none: copied)
  uint32_t V_ = 0, T_ = 0, alive_ = 0, tetsAlive_ = 0, flatInput_ = 0;
  const float* field_ = nullptr;
  double range_ = 1, diag_ = 1;
  // Per vertex, what an evaluation reads of each neighbour, in one place (one cache line
  // instead of two): its position and the steering field's value now (fitted, see collapse).
  struct Vertex {
    float x[3];
    float fit;
  };
  std::vector<Vertex> vert_;
  std::vector<uint32_t> represented_;  // per vertex: input vertices it stands for (itself and those collapsed into it)
  bool fitOn_ = false;
  double fieldMin_ = 0, fieldMax_ = 0;
  std::vector<std::vector<uint32_t>> star_;
  std::vector<uint32_t> opp_;
  std::vector<uint8_t> boundary_;
  static constexpr uint32_t kNoQuadric = ~0u;
  std::vector<uint32_t> quadricOf_;  // per vertex: its boundary quadric in quadrics_, or kNoQuadric (interior)
  std::vector<Quadric> quadrics_;
  // The boundary quadric of v: zero for an interior vertex, whose collapse does not move the boundary.
  const Quadric& boundaryQuadric(uint32_t v) const {
    static const Quadric zero;
    return quadricOf_[v] == kNoQuadric ? zero : quadrics_[quadricOf_[v]];
  }
  std::vector<float> kappa_, lastCost_;
  std::vector<FieldQuadric> fieldQuadric_;
  std::vector<double> qualitySum_;  // per vertex: Σ 3/κ over its star
  std::vector<uint8_t> queued_;  // per vertex: has an entry in the queue (or in the current round)
  Lane mainLane_;
  std::vector<Lane> lanes_;  // one per entry of a round (and per thread in init() and runParts())
  // The one queue's lanes (all but the two of the first costs and the slabs) get their
  // per-vertex arrays only now, after the slabs, when less memory is in use (peak memory).
  void readyLanes() {
    if (mainLane_.seen.size() != V_) mainLane_.reset(V_);
    for (Lane& L : lanes_)
      if (L.seen.size() != V_) L.reset(V_);
  }
  static constexpr uint32_t kRoundSize = 4;
  std::vector<Entry> round_;
  std::vector<uint32_t> changed_;  // per vertex: roundStamp_ of the last round that touched it
  bool trackChanges_ = false;      // collapses keep changed_ (the one queue's rounds of several)
  uint32_t roundStamp_ = 0;
  Worker main_;     // the one queue of the whole mesh (its log is out_.log)
  Worker parts_[kMaxSlabs];  // the slabs of the parallel phase
  float slack_ = 1.0f;  // see tryCollapse
  std::vector<uint8_t> inner_;  // per vertex: every neighbour is in its slab (runParts)
};

}  // namespace

const char* collapseVerdictName(CollapseVerdict v) {
  switch (v) {
    case CollapseVerdict::Legal: return "legal";
    case CollapseVerdict::BoundaryRule: return "boundary vertex leaves the boundary";
    case CollapseVerdict::Inverted: return "a tet would invert";
    case CollapseVerdict::Flat: return "a tet would become flat";
    case CollapseVerdict::LowQuality: return "a tet would fall below the minimum quality";
    case CollapseVerdict::LinkCondition: return "link condition violated";
    case CollapseVerdict::NotAnEdge: return "not an edge";
  }
  return "?";
}

CollapseVerdict checkCollapse(const TetMesh& mesh, uint32_t i, uint32_t j, const SimplifyOptions& options) {
  SimplifyResult scratch;
  Simplifier s(mesh, options, scratch);
  return s.check(i, j);
}

Result simplifyMesh(const TetMesh& mesh, const SimplifyOptions& options, SimplifyResult& out, FaceAdjacency* adjacency,
                    std::vector<uint32_t>* takeTets) {
  assert(options.field >= 0 && size_t(options.field) < mesh.fields.size());
  out = SimplifyResult{};
  Simplifier s(mesh, options, out, adjacency, takeTets);
  return s.run();
}

}  // namespace tetstream
