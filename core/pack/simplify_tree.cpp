// The tree of regions below the root (simplify.h): the vertices bisected recursively, then
// simplified level by level from the leaves up, the regions of a level on two threads.
//
// A region owns its vertices, and a tet lies in the region of its vertices that comes first (the
// lowest number at that level), so a tet across a cut belongs to one side. A vertex is inner
// when every tet around it lies in its own region: along a cut the first side's vertices stay
// inner, and only the second side's vertices on the cut (those with a tet across it) are left to
// the level above. A region collapses i → j only when both are inner: the collapse changes the
// tets around i and j (its own) and the stars, quadrics and values of their vertices, and an
// evaluation reads no more. The vertices on a cut are the one thing two regions share: their
// stars lose the tets either side removes, and their quality sums change. Those are left as they
// are while the level runs (neither region evaluates them, and they stay put) and settled after
// it (settleCuts), in an order that does not depend on the threads. So the regions of a level
// may run on any thread in any order (one thread gives the same result), and a region's
// collapses need only what the levels above leave in place: its splits depend on its ancestors'
// alone (FORMAT.md §1.1). What a region leaves on its cuts is inner one level up, where the cut
// between two children runs through the middle of their parent; the root, the queue of the
// whole mesh, has no cut at all. (With a vertex inner only when its tets have all four vertices
// in its region, both sides of every cut were left to the level above: the upper levels, which
// every view needs, held about twice the vertices.)
//
// The cut: at the median along the longest side of the region's bounding box, ties by vertex id,
// so the tree is perfect (every leaf at the same depth) and each leaf holds at most leafVertices.
//
// How far a level goes: its regions collapse every queued inner vertex up to one cost τ, the
// cost at which the one queue of the whole mesh would stop at the target (estimated from the
// costs queued now, at most kLevelShareCap of the way). So the regions coarsen as far as the base will be coarse
// wherever their cuts allow, and each level above mostly coarsens its own cut: the bytes of the stream sit in the
// smallest regions that can hold them, and a viewer that needs a few regions fetches little. (Levels that stopped
// earlier, at quantiles of the cost shared out between them, kept the stream's order closer to one queue's but left a
// third of the splits to the root, which every view needs: docs/design-notes.md.) One τ for all the regions of a level
// keeps a region of smooth field coarsening further than one of detail, as one queue would.
#include <algorithm>
#include <cmath>

#include "pack/simplifier.h"

namespace tetstream::simplify_detail {

namespace {

// A level takes at most this share of its queued vertices' costs: the last tenth, where the
// estimate of the one queue's last cost is least sure, is left to the levels above and the
// root. Without the cap the coarsest bases (a few tens of vertices) lost the input's boundary
// where the one queue keeps it, and the base's field error grew by a tenth.
constexpr double kLevelShareCap = 0.9;

// Appends collapse c of `src` (whose begin arrays have no closing entry yet) to `dst`.
void appendCollapse(CollapseLog& dst, const CollapseLog& src, uint32_t c) {
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

}  // namespace

void Simplifier::buildTree() {
  RegionTree& tree = out_.tree;
  tree = RegionTree{};
  // A part's tree cuts its owned vertices alone (countedAlive()); its halo is in no region.
  const uint32_t count = countedAlive();
  if (opt_.leafVertices == 0 || count < 2 * uint64_t(opt_.leafVertices)) return;
  while ((uint64_t(count) >> tree.depth) > opt_.leafVertices) ++tree.depth;
  std::vector<uint32_t> order;
  order.reserve(count);
  for (uint32_t v = 0; v < V_; ++v)
    if (out_.vertexAlive[v] && owned(v)) order.push_back(v);
  tree.leafOf.assign(V_, ~0u);  // (vertices of no tet, and halo vertices: in no region)
  struct Part {
    uint32_t begin, end, level, index;
  };
  std::vector<Part> stack{{0, uint32_t(order.size()), 0, 0}};
  while (!stack.empty()) {
    const Part part = stack.back();
    stack.pop_back();
    if (part.level == tree.depth) {
      for (uint32_t k = part.begin; k < part.end; ++k) tree.leafOf[order[k]] = part.index;
      continue;
    }
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t k = part.begin; k < part.end; ++k)
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], vert_[order[k]].x[a]);
        hi[a] = std::max(hi[a], vert_[order[k]].x[a]);
      }
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
    const uint32_t mid = part.begin + (part.end - part.begin) / 2;
    std::nth_element(order.begin() + part.begin, order.begin() + mid, order.begin() + part.end,
                     [&](uint32_t a, uint32_t b) {
                       const float xa = vert_[a].x[axis], xb = vert_[b].x[axis];
                       return xa < xb || (xa == xb && a < b);
                     });
    stack.push_back({part.begin, mid, part.level + 1, 2 * part.index});
    stack.push_back({mid, part.end, part.level + 1, 2 * part.index + 1});
  }
  // The vertices a leaf's tets reach in later leaves (a tet lies in its first leaf). A vertex
  // is reached by several tets of the same leaf, one after another in a grid's order: the leaf
  // last recorded for each vertex (in a scratch's per-vertex array, cleared after) keeps the list
  // near its final size (at Harmonic 256³, tens of MB instead of hundreds).
  std::vector<uint32_t>& recorded = scratches_[0].seen;
  std::fill(recorded.begin(), recorded.end(), ~0u);
  for (uint32_t t = 0; t < T_; ++t) {
    if (!out_.tetAlive[t]) continue;
    const uint32_t* v = &out_.tets[4 * size_t(t)];
    const uint32_t l[4] = {tree.leafOf[v[0]], tree.leafOf[v[1]], tree.leafOf[v[2]], tree.leafOf[v[3]]};
    const uint32_t first = std::min({l[0], l[1], l[2], l[3]}), last = std::max({l[0], l[1], l[2], l[3]});
    if (first == last || last == ~0u) continue;  // (a tet with a halo vertex lies in no region)
    for (int k = 0; k < 4; ++k)
      if (l[k] != first && recorded[v[k]] != first) {
        recorded[v[k]] = first;
        tree.rim.push_back({first, v[k]});
      }
  }
  std::fill(recorded.begin(), recorded.end(), 0u);  // (stamps start again: nothing seen)
  std::sort(tree.rim.begin(), tree.rim.end());
  tree.rim.erase(std::unique(tree.rim.begin(), tree.rim.end()), tree.rim.end());
  tree.rim.shrink_to_fit();
  // Each region's range of the steering field (fitted values keep to it), from the leaves up:
  // the values of its tets' vertices.
  nodeRange_.assign(tree.nodes(), Range{INFINITY, -INFINITY});
  const uint32_t firstLeaf = 1u << tree.depth;
  auto include = [&](uint32_t leaf, uint32_t v) {
    if (!std::isfinite(field_[v])) return;
    Range& r = nodeRange_[firstLeaf + leaf];
    r.min = std::min(r.min, field_[v]);
    r.max = std::max(r.max, field_[v]);
  };
  for (uint32_t v : order) include(tree.leafOf[v], v);
  for (const auto& [leaf, v] : tree.rim) include(leaf, v);
  for (uint32_t n = firstLeaf; n-- > 1;) {
    if (n < firstLeaf)
      nodeRange_[n] = {std::min(nodeRange_[2 * n].min, nodeRange_[2 * n + 1].min),
                       std::max(nodeRange_[2 * n].max, nodeRange_[2 * n + 1].max)};
  }
  for (Range& r : nodeRange_)
    if (!(r.min <= r.max)) r = {float(topLo_), float(topHi_)};  // (no finite value: any)
  // A part's top keeps to the range its caller gives (that of the input over the part's region,
  // which holds every owned sample here).
  if (opt_.part) nodeRange_[1] = {float(opt_.part->topMin), float(opt_.part->topMax)};
  lastNode_.assign(V_, 1);
}

void Simplifier::runTree(uint32_t target) {
  buildTree();
  RegionTree& tree = out_.tree;
  if (tree.depth == 0) return;
  std::vector<uint32_t> region(V_, 0);
  std::vector<CollapseLog> logs;
  std::vector<uint32_t> thread[2];
  uint32_t collapsedAll = 0;
  for (uint32_t level = 0; level < tree.depth; ++level) {
    const uint32_t regions = 1u << (tree.depth - level);
    // (A halo vertex's ~0u >> level lies above every region's index, 2^(depth − level) − 1 at
    // most, as depth < 32: the halo is a region of its own, so no owned vertex next to it is inner.)
    for (uint32_t v = 0; v < V_; ++v)
      if (out_.vertexAlive[v]) region[v] = tree.leafOf[v] >> level;
    markInner(region, ~0u >> level);
    std::vector<std::vector<Entry>> entries(regions);
    std::vector<float> keys;
    for (uint32_t v = 0; v < V_; ++v) {
      if (!out_.vertexAlive[v] || !queued_[v] || !owned(v)) continue;
      keys.push_back(queueKey(v));
      if (inner_[v]) entries[region[v]].push_back({queueKey(v), v});
    }
    float tau;
    if (!levelTau(keys, target, tau)) continue;
    // Regions go to the threads largest first, to the one with less work so far.
    std::vector<uint32_t> bySize(regions);
    for (uint32_t k = 0; k < regions; ++k) bySize[k] = k;
    std::stable_sort(bySize.begin(), bySize.end(),
                     [&](uint32_t a, uint32_t b) { return entries[a].size() > entries[b].size(); });
    thread[0].clear();
    thread[1].clear();
    size_t load[2] = {0, 0};
    for (uint32_t k : bySize) {
      const int t = load[1] < load[0] ? 1 : 0;
      load[t] += entries[k].size();
      thread[t].push_back(k);
    }
    logs.assign(regions, CollapseLog());
    struct Counts {
      uint64_t pops = 0, requeued = 0, rejectedByLink = 0, flatTetsRemoved = 0, linkMismatches = 0;
      uint32_t collapsed = 0, tetsRemoved = 0;
    } counts[2];
    onBoth([&](int t) {
      Scratch& sc = scratches_[size_t(t)];
      for (uint32_t k : thread[t]) {
        Queue Q;
        Q.node = (1u << (tree.depth - level)) + k;
        Q.region = true;
        Q.sharedCuts = true;
        Q.scratch = &sc;
        Q.heap = Heap(EntryAfter(), std::move(entries[k]));
        sc.fitLo = nodeLo(Q.node);
        sc.fitHi = nodeHi(Q.node);
        runRegion(Q, tau);
        Counts& c = counts[t];
        c.pops += Q.pops, c.requeued += Q.requeued, c.rejectedByLink += Q.rejectedByLink;
        c.flatTetsRemoved += Q.flatTetsRemoved, c.linkMismatches += Q.linkMismatches;
        c.collapsed += Q.collapsed, c.tetsRemoved += Q.tetsRemoved;
        logs[k] = std::move(Q.ownLog);
        if (t == 0 && opt_.progress) opt_.progress(collapsedAll + c.collapsed, alive_ + collapsedAll - target);
      }
    });
    for (Scratch& sc : scratches_) sc.fitLo = topLo_, sc.fitHi = topHi_;
    settleCuts();
    // The regions' collapses, region after region, each a section of the log.
    for (uint32_t k = 0; k < regions; ++k) {
      if (logs[k].size() == 0) continue;
      for (uint32_t c = 0; c < logs[k].size(); ++c) appendCollapse(out_.log, logs[k], c);
      tree.sectionNode.push_back((1u << (tree.depth - level)) + k);
      tree.sectionEnd.push_back(out_.log.size());
    }
    logs.clear();
    for (const Counts& c : counts) {
      regionPops_ += c.pops, regionRequeued_ += c.requeued, regionRejectedByLink_ += c.rejectedByLink;
      regionFlatRemoved_ += c.flatTetsRemoved, regionLinkMismatches_ += c.linkMismatches;
      alive_ -= c.collapsed;
      tetsAlive_ -= c.tetsRemoved;
      collapsedAll += c.collapsed;
    }
  }
  out_.regionCollapses = collapsedAll;
}

// The cost τ up to which a level collapses (this file's head), from the keys of the queued
// vertices (reordered); false when the level has nothing to do: no key, or the target reached.
bool Simplifier::levelTau(std::vector<float>& keys, uint32_t target, float& tau) const {
  // The one queue of the whole mesh would stop, at the target, at about the cost that many of
  // the queued vertices have now (an underestimate: costs rise as neighbours collapse).
  const uint32_t alive = countedAlive();
  const double goal =
      std::max<double>(target, opt_.targetTets && tetsAlive_ ? double(alive) * opt_.targetTets / tetsAlive_ : 0.0);
  if (keys.empty() || alive <= goal + 1) return false;
  const double share = std::min((double(alive) - goal) / keys.size(), kLevelShareCap);
  const size_t at = size_t(std::min<double>(double(keys.size() - 1), share * keys.size()));
  std::nth_element(keys.begin(), keys.begin() + ptrdiff_t(at), keys.end());
  tau = keys[at];
  return true;
}

// inner_ for node 1 of a part (SimplifyPart): its region is every owned vertex, so an owned
// vertex is inner when every alive tet around it has four owned vertices. No collapse changes
// this: a tet with a halo vertex is around no inner vertex, so none ever moves or goes.
void Simplifier::markTopInner() {
  std::vector<uint32_t> region(V_);
  for (uint32_t v = 0; v < V_; ++v) region[v] = owned(v) ? 0 : 1;
  markInner(region, 1);
  for (uint32_t v = 0; v < V_; ++v) inner_[v] &= uint8_t(owned(v));
}

// A part's top node as one more level of its tree (SimplifyPart::topIsRegion): its inner
// vertices up to the level's τ, in Q (the one queue, region = true; its log is out_.log).
void Simplifier::runTop(Queue& Q, uint32_t target) {
  std::vector<Entry> entries;
  std::vector<float> keys;
  for (uint32_t v = 0; v < V_; ++v) {
    if (!out_.vertexAlive[v] || !queued_[v] || !owned(v)) continue;
    keys.push_back(queueKey(v));
    if (inner_[v]) entries.push_back({queueKey(v), v});
  }
  float tau;
  if (!levelTau(keys, target, tau)) {
    out_.stopReason = keys.empty() ? "no legal collapse left" : "target reached";
    return;
  }
  // The top goes no further than its share of the base plus what it cannot collapse (the owned
  // vertices next to the halo, which the parts above collapse): the root, not a part, decides
  // what the base keeps, and a part that went below its share would leave the cuts to the base.
  uint32_t fixed = 0;
  for (uint32_t v = 0; v < V_; ++v) fixed += out_.vertexAlive[v] && owned(v) && !inner_[v];
  const uint32_t alive = countedAlive(), keep = target + fixed;
  Q.heap = Heap(EntryAfter(), std::move(entries));
  runRegion(Q, tau, alive > keep ? alive - keep : 0);
  Entry e;
  out_.stopReason = peekValid(Q.heap, e) ? "level cost reached" : "no legal collapse left";
}

// Collapses the region's queued inner vertices up to cost tau (this file's head).
void Simplifier::runRegion(Queue& Q, float tau, uint32_t maxCollapses) {
  Entry e, top;
  while (!Q.errorBound && Q.collapsed < maxCollapses && peekValid(Q.heap, e) && e.cost <= tau) {
    Q.heap.pop();
    queued_[e.vertex] = 0;
    if (!Q.heap.empty()) prefetchStar(Q.heap.top().vertex);
    evaluateVertex(*Q.scratch, e.vertex);
    tryCollapse(Q, e.vertex, *Q.scratch, peekValid(Q.heap, top) ? top.cost : float(kInf));
  }
}

// inner_[v]: every alive tet around v lies in v's region (this file's head): a tet lies in the
// first region of its vertices', one with a vertex in `halo` (a part's halo) in none.
// Every level scans all tets: on large meshes (kTwoThreadScan) in two halves at once. Both
// halves only ever write 0, relaxed: the result is the same.
void Simplifier::markInner(const std::vector<uint32_t>& region, uint32_t halo) {
  inner_.assign(V_, 1);
  auto scan = [&](uint32_t begin, uint32_t end) {
    for (uint32_t t = begin; t < end; ++t) {
      if (!out_.tetAlive[t]) continue;
      const uint32_t* v = &out_.tets[4 * size_t(t)];
      const uint32_t r[4] = {region[v[0]], region[v[1]], region[v[2]], region[v[3]]};
      const uint32_t first = std::min({r[0], r[1], r[2], r[3]}), last = std::max({r[0], r[1], r[2], r[3]});
      if (first == last) continue;
      for (int k = 0; k < 4; ++k)
        if (r[k] != first || last == halo) std::atomic_ref<uint8_t>(inner_[v[k]]).store(0, std::memory_order_relaxed);
    }
  };
  if (T_ < kTwoThreadScan) return scan(0, T_);
  onBoth([&](int half) { scan(half ? T_ / 2 : 0, half ? T_ : T_ / 2); });
}

// After a level: the vertices on the cuts lose the tets their regions removed (their stars keep
// the order of the others: whichever thread removed what, the result is the same), and their
// quality sums are counted again from their stars.
void Simplifier::settleCuts() {
  std::vector<std::pair<uint32_t, uint32_t>> erasures;
  for (Scratch& sc : scratches_) {
    erasures.insert(erasures.end(), sc.cutErasures.begin(), sc.cutErasures.end());
    sc.cutErasures.clear();
  }
  std::sort(erasures.begin(), erasures.end());
  for (size_t a = 0; a < erasures.size();) {
    const uint32_t v = erasures[a].first;
    size_t b = a;
    while (b < erasures.size() && erasures[b].first == v) ++b;
    auto gone = [&](uint32_t t) {
      return std::binary_search(erasures.begin() + ptrdiff_t(a), erasures.begin() + ptrdiff_t(b), std::pair{v, t});
    };
    std::vector<uint32_t>& star = star_[v];
    star.erase(std::remove_if(star.begin(), star.end(), gone), star.end());
    a = b;
  }
  for (uint32_t v = 0; v < V_; ++v) {
    if (!out_.vertexAlive[v] || inner_[v]) continue;
    double sum = 0;
    for (uint32_t t : star_[v]) sum += 3.0 / kappa_[t];
    qualitySum_[v] = sum;
  }
}

}  // namespace tetstream::simplify_detail
