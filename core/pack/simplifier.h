// The simplifier behind simplifyMesh() (simplify.h, where the cost and the legality rules are):
// one class, its state in flat per-vertex and per-tet arrays, its methods in a file per concern:
//   simplify.cpp           the queue of the whole mesh (lazy updates, two-thread speculation)
//   simplify_setup.cpp     stars, face adjacency, quadrics, κ and every vertex's first cost
//   simplify_cost.cpp      one vertex's out-edges: legality, then the cost in refining stages
//   simplify_link.cpp      the link condition
//   simplify_collapse.cpp  a collapse and its log entry
//   simplify_tree.cpp      the tree of regions below the root, two threads at once
//   simplify_refit.cpp     the last level's values, fitted again at the end
// Internal to the packer: nothing outside these files includes it but the tests (SimplifyTuning).
#pragma once
#include <algorithm>
#include <atomic>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <limits>
#include <queue>
#include <thread>
#include <vector>

#include "adjacency.h"
#include "pack/quadric.h"
#include "simplify.h"
#include "tet_quality.h"
#include "tet_tables.h"

namespace tetstream {

// Not product options: knobs that exist so tests can compare the cost with the simpler ones it
// replaced, and a self-check of the link condition. simplifyMesh always uses the defaults.
struct SimplifyTuning {
  // How much of the input a collapse stands for, the weight of its error terms (simplify.h,
  // boundTerms()): the larger of its input vertices and its volume (in units of an interior
  // vertex's mean volume), or (false) the vertices alone.
  bool weighByVolume = true;
  // Each cost is divided by (tets the collapse removes)^this (simplify.h); 0: not at all.
  double removedTetsExponent = 0.5;
  // Also runs the plain reference link check (linkConditionBySorting) at every collapse attempt
  // and counts in linkMismatches where it disagrees with the fast one.
  bool verifyLinkCondition = false;
  uint64_t linkMismatches = 0;  // written by simplifyMeshTuned
};

// simplifyMesh (simplify.h) with other tuning than the defaults.
Result simplifyMeshTuned(const TetMesh& mesh, const SimplifyOptions& options, SimplifyTuning& tuning,
                         SimplifyResult& out);

}  // namespace tetstream

namespace tetstream::simplify_detail {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr uint32_t kOmega = 0xfffffffeu;  // the virtual vertex the boundary is coned to
constexpr double kFlat = 1e-7;            // |6V| <= kFlat * (longest edge)^3 counts as flat
constexpr float kKappaCap = 1e4f;         // κ of flat tets, capped so averages stay finite

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
    if (a[x] < b[y])
      ++x;
    else if (b[y] < a[x])
      ++y;
    else {
      ++n;
      ++x;
      ++y;
    }
  }
  return n;
}

struct Tri {
  uint32_t v[3];
  bool operator<(const Tri& o) const { return std::lexicographical_compare(v, v + 3, o.v, o.v + 3); }
  bool operator==(const Tri& o) const { return v[0] == o.v[0] && v[1] == o.v[1] && v[2] == o.v[2]; }
};
inline Tri makeTri(uint32_t a, uint32_t b, uint32_t c) {
  if (a > b) std::swap(a, b);
  if (b > c) std::swap(b, c);
  if (a > b) std::swap(a, b);
  return {{a, b, c}};
}

class Simplifier {
 public:
  Simplifier(const TetMesh& m, const SimplifyOptions& o, SimplifyTuning& tuning, SimplifyResult& r,
             FaceAdjacency* adjacency = nullptr, std::vector<uint32_t>* takeTets = nullptr)
      : mesh_(m), opt_(o), tune_(tuning), out_(r), adjacency_(adjacency), takeTets_(takeTets) {}

  CollapseVerdict check(uint32_t i, uint32_t j);
  Result run();

 private:
  // ------------------------------------------------------------------ setup
  void init();

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
  // (y, s), (z, s), q[13] is (s, 1).) Kept inside [lo, hi]: the input field's range over the
  // region collapsing (simplify.h), within the field's range, which the quantization grid covers.
  static double fitted(const FieldQuadric& f, const double* x, double fallback, double lo, double hi) {
    const double a = f.q[12], b = f.q[3] * x[0] + f.q[7] * x[1] + f.q[10] * x[2] + f.q[13];
    return a > 0 ? std::clamp(-b / a, lo, hi) : fallback;
  }

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

  bool fieldHyperplane(const uint32_t* v, double (&hyperplane)[5], double& w) const;
  float tetKappa(uint32_t t) const;

  bool tetHas(uint32_t t, uint32_t v) const {
    const uint32_t* x = &out_.tets[4 * size_t(t)];
    return x[0] == v || x[1] == v || x[2] == v || x[3] == v;
  }

  // ------------------------------------------------------------------ costs
  bool isBoundaryEdge(uint32_t i, uint32_t j) const;

  // Per-tet data of star(i) shared by every candidate target j: with P = p_j in the slot of i,
  // the determinant is g·(P − x0) (newDet), and κ's edge and face terms without P are fixed.
  struct StarTet {
    uint32_t t;
    uint32_t other[3];             // the vertices besides i, in slot order
    uint64_t mask;                 // bitOf() their places in Scratch::nbr (see removes())
    double g[3];                   // det of the new tet with P in the slot of i: g·(P − x[0]) (newDet)
    double detOld;                 // det with p_i (numerator for the slot of i)
    double fixedEdges, fixedFace;  // κ's terms of the edges and the face without p_i
    double x[3][3];                // positions of the other vertices
    double sign;                   // orientation sign of the slot of i
    float f[3];                    // field at the other vertices
    float kappa;                   // κ of the tet now
    double quality;                // 3/κ now
  };

  // A candidate's cost is refined in stages while it could still be the cheapest
  // (cheapestCandidate): each stage's cost is a lower bound of the next one's.
  struct Candidate {
    enum Stage : uint8_t { Bound, Local, Exact };
    double cost;                                // exact, or a lower bound until stage Exact
    double base;                                // the cost without the shape term
    double sj, region, eg, weight, shapeBound;  // parts of the cost (boundTerms)
    double perTets;  // the factor for the tets it removes (SimplifyTuning::removedTetsExponent)
    uint32_t j;
    uint64_t bit;    // bitOf(j's place in Scratch::nbr)
    float fieldErr;  // E_f (from stage Local on)
    Stage stage;
  };

  // Scratch for evaluating one vertex's out-edges; one per thread.
  struct Scratch {
    std::vector<StarTet> star;
    uint32_t center = 0;         // the vertex of star
    double flatBound = 0;        // see prepareStar
    double qualityFloor = 0;     // the least 3/κ a changed tet may have (see prepareStar)
    uint64_t boundaryEdges = 0;  // bitOf() the neighbours joined to the vertex by a boundary edge
    double removedQuality = 0;   // of the last legal() candidate: Σ 3/κ of the tets it removes
    int removed = 0;             // ... and their count
    std::vector<uint32_t> nbr;
    struct Passed {    // an out-edge that passed legal(), with what legal() found of it
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
    double fitLo = 0, fitHi = 0;                             // the range fitted values keep to: the region's (fitted())
    std::vector<std::pair<uint32_t, uint32_t>> cutErasures;  // (vertex, tet) left to settleCuts
  };

  // A small open-addressing table of edge keys with a byte of state, emptied in O(1) by
  // changing its stamp. Link edge sets have tens of entries; it grows if ever needed. (Not
  // FlatMap: that one is emptied by a pass over its slots, and this is emptied at every link
  // check.)
  struct EdgeTable {
    std::vector<uint64_t> keys;
    std::vector<uint32_t> stamps;
    std::vector<uint8_t> values;
    uint32_t stamp = 0, count = 0;
    void beginSet(uint32_t s) {
      if (keys.empty()) {
        keys.resize(512);
        stamps.assign(512, 0);
        values.resize(512);
      }
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
      if (stamps[k] != stamp) {
        stamps[k] = stamp;
        keys[k] = key;
        ++count;
      }
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

  // What the collapse loop works with (a queue and its log, not a thread): the queue of the whole
  // mesh, or of one region of the tree (runTree), with its own log and scratch.
  struct Queue {
    uint32_t node = 1;    // the region (RegionTree numbering); 1: the whole mesh
    bool region = false;  // a region below the root: collapses only inner_ vertices
    // A region of a level whose regions run at once (runTree): the vertices on its cuts (not
    // inner_) have tets in other regions too, so their stars and quality sums are left as they are
    // during the level and settled after it (settleCuts).
    bool sharedCuts = false;
    Heap heap;
    CollapseLog ownLog;  // a region's collapses (appended to out_.log after its level)
    CollapseLog* log = &ownLog;
    Scratch* scratch = nullptr;          // link condition and collapse (and a region's evaluations): its thread's
    std::atomic<uint32_t> collapsed{0};  // (read by the progress report on the other thread)
    uint32_t tetsRemoved = 0;
    uint64_t pops = 0, requeued = 0, rejectedByLink = 0, flatTetsRemoved = 0, linkMismatches = 0;
    bool errorBound = false;
    std::vector<uint32_t> touched, around;
    CollapseTets record;  // the tets of the collapse being made
    std::vector<uint64_t> linkEdges, edgeLink;
    EdgeTable edgeTable;
    uint32_t edgeTableStamp = 0;
  };

  void prepareStar(Scratch& sc, uint32_t i);
  // Vertex v lies on a cut that Q's region shares with regions running at the same time.
  bool onSharedCut(const Queue& Q, uint32_t v) const { return Q.sharedCuts && !inner_[v]; }

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
  // A bit for each of the first 64 neighbours (by place in Scratch::nbr), 0 for the others.
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

  bool legal(Scratch& sc, uint32_t i, uint32_t j, uint64_t bit, CollapseVerdict* verdict);
  Candidate boundTerms(Scratch& sc, uint32_t i, uint32_t j, uint64_t bit, int removed, double removedQuality);
  void setCost(Candidate& c, double local) const;
  void localTerm(Scratch& sc, uint32_t i, Candidate& c);
  bool finishCost(Scratch& sc, Candidate& c, CollapseVerdict* verdict);
  void gatherCandidates(Scratch& sc, uint32_t i);
  int cheapestCandidate(Scratch& sc, uint32_t i);
  void neighbours(Scratch& sc, uint32_t v, std::vector<uint32_t>& out);

  // Asks for the tets around v, which neighbours(v) reads first: called for the vertex likely
  // to be evaluated next, while the current one is.
  void prefetchStar(uint32_t v) const {
    for (uint32_t t : star_[v]) __builtin_prefetch(&out_.tets[4 * size_t(t)]);
  }

  float bestCost(Scratch& sc, uint32_t v);
  void evaluateVertex(Scratch& sc, uint32_t v);

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

  // Whether a collapse of this round changed anything evaluateVertex(sc, v) read: v's star and,
  // for the targets, their quadrics, κ sums and star sizes; all of these change only for the
  // vertices a collapse touches.
  bool changedThisRound(const Scratch& sc, uint32_t v) const {
    if (changed_[v] == roundStamp_) return true;
    for (uint32_t w : sc.nbr)
      if (changed_[w] == roundStamp_) return true;
    return false;
  }

  // Collapses i along its cheapest legal out-edge (evaluated in sc) unless that costs more than
  // slack_ × `next`, the key of the next entry: then i goes back into the queue under its new
  // cost. Most pops find that the cost went up since a neighbour collapsed. On meshes large
  // enough for the tree of regions, those within 10% are taken anyway: far fewer pops (each
  // evaluates every out-edge of i) for a slightly higher field error and a slightly smaller
  // stream. Small meshes pack in moments: they keep the exact order, where the slack would cost
  // relatively more error.
  static constexpr float kLargeMeshSlack = 1.1f;
  static constexpr uint32_t kSlackMinVertices = 10000;
  void tryCollapse(Queue& Q, uint32_t i, Scratch& sc, float next);

  // ------------------------------------------------------------------ the tree of regions
  // How the tree is cut and how far each level goes: simplify_tree.cpp.
  void buildTree();
  void runTree(uint32_t target);
  // (At most maxCollapses of them: a part's top keeps its share of the base, runTop.)
  void runRegion(Queue& Q, float tau, uint32_t maxCollapses = ~0u);
  void markInner(const std::vector<uint32_t>& region, uint32_t halo);
  void settleCuts();
  bool levelTau(std::vector<float>& keys, uint32_t target, float& tau) const;
  void markTopInner();
  void runTop(Queue& Q, uint32_t target);
  // The range fitted values keep to in `node` (fitted()); the top's range (topLo_, topHi_) when
  // there is no tree.
  double nodeLo(uint32_t node) const { return nodeRange_.empty() ? topLo_ : nodeRange_[node].min; }
  double nodeHi(uint32_t node) const { return nodeRange_.empty() ? topHi_ : nodeRange_[node].max; }
  std::vector<Range> nodeRange_;  // per node (RegionTree numbering): the steering field's input range
  // Per vertex: the node of the last collapse onto it (1: the root, or none). The refit keeps its
  // value in that node's range: while the node's splits are not applied, its region shows
  // that value, and the node's range must bound it (simplify.h).
  std::vector<uint32_t> lastNode_;
  static constexpr uint32_t kTwoThreadScan = 200000;  // tets: markInner() on two threads from here

  // ------------------------------------------------------------------ a part (SimplifyPart)
  // Whether v is the part's own (every vertex of a whole mesh is): only those are ever
  // collapsed or collapse targets, and only they count towards the target.
  bool owned(uint32_t v) const { return !ownedMask_ || (*ownedMask_)[v]; }
  // The alive vertices the target and the levels' cost τ go by: the owned ones (halo vertices
  // are never collapsed here; their owners count them).
  uint32_t countedAlive() const { return alive_ - haloAlive_; }
  void takeCarried(const CarriedVertexState& c);
  void fillCarried();
  const std::vector<uint8_t>* ownedMask_ = nullptr;  // opt_.part's owned, or null (all owned)
  uint32_t haloAlive_ = 0;                           // alive vertices not owned (constant)
  // The range fitted values of node 1 keep to: the field's range of the whole mesh, or the
  // part's top range (SimplifyPart::topMin/topMax).
  double topLo_ = 0, topHi_ = 0;

  // ------------------------------------------------------------------ link condition
  void gatherLink(uint32_t v, std::vector<uint32_t>& verts, std::vector<uint64_t>& edges, std::vector<Tri>& tris);
  bool linkCondition(Queue& Q, uint32_t i, uint32_t j);

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

  // The plain reference for linkCondition(), for SimplifyTuning::verifyLinkCondition only.
  bool linkConditionBySorting(uint32_t i, uint32_t j);

  // ------------------------------------------------------------------ the last level's values
  void refitValues();
  static constexpr int kRefitRounds = 4;
  static constexpr int kRefitIterations = 200;

  bool locate(uint32_t x, uint32_t t, uint32_t* vertices, double* w) const;

  // ------------------------------------------------------------------ the collapse
  void collapse(Queue& Q, uint32_t i, uint32_t j, float fieldErr);

  const TetMesh& mesh_;
  const SimplifyOptions& opt_;
  SimplifyTuning& tune_;
  SimplifyResult& out_;
  FaceAdjacency* adjacency_;         // the caller's, taken over by init() (or none)
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
  std::vector<Range> fitRange_;             // with SimplifyOptions::part: CarriedVertexState::fitRange
  std::vector<FieldQuadric> fieldQuadric_;  // (its weight: the input volume a vertex stands for, a quarter of each tet)
  double meanVertexVolume_ = 1;             // the unit of the volume measure (init(), boundTerms())
  std::vector<double> qualitySum_;          // per vertex: Σ 3/κ over its star
  std::vector<uint8_t> queued_;             // per vertex: has an entry in the queue (or in the current round)
  Scratch mainScratch_;
  std::vector<Scratch> scratches_;  // one per entry of a round (and per thread in init() and runTree())
  // The one queue's scratches (all but the two of the first costs and the regions') get their
  // per-vertex arrays only now, after the regions, when less memory is in use (peak memory).
  void readyScratches() {
    if (mainScratch_.seen.size() != V_) mainScratch_.reset(V_);
    for (Scratch& sc : scratches_)
      if (sc.seen.size() != V_) sc.reset(V_);
  }
  static constexpr uint32_t kRoundSize = 4;
  std::vector<Entry> round_;
  std::vector<uint32_t> changed_;  // per vertex: roundStamp_ of the last round that touched it
  bool trackChanges_ = false;      // collapses keep changed_ (the one queue's rounds of several)
  uint32_t roundStamp_ = 0;
  Queue main_;                  // the one queue of the whole mesh (its log is out_.log)
  float slack_ = 1.0f;          // see tryCollapse
  std::vector<uint8_t> inner_;  // per vertex: every tet around it lies in its region (runTree)
  uint64_t regionPops_ = 0, regionRequeued_ = 0, regionRejectedByLink_ = 0, regionFlatRemoved_ = 0,
           regionLinkMismatches_ = 0;  // the regions' queues' counts (Queue's), summed
};

}  // namespace tetstream::simplify_detail
