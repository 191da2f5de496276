// The parallel phase: a large mesh simplified in slabs, one thread each (simplifier.h).
//
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
// step of τ of its turn. (With one fixed cut its vertices would wait for the whole mesh's queue
// at the end: they would be the last collapses and so the first splits, and the coarse levels
// would spend many of their vertices on a refined band along the cut. Parallel cuts never
// cross, so no vertex waits on two; more slabs, for smaller working sets, make the stream
// larger and are no faster.) A larger growth makes the levels worse; a smaller one is no
// better and takes more rounds.
// The slabs take kSlabShare of the planned collapses; the one queue of the whole mesh then
// evens out what they left along the last round's cuts and takes the rest. Its collapses cost
// about twice as much time as the slabs', so the share is high; below 1, so that something is
// left to even out the cuts (with 1 the coarsest levels get much worse). The error hardly
// depends on the share between 0.95 and 0.99. Figures: docs/design-notes.md.
#include "pack/simplifier.h"

namespace tetstream::simplify_detail {

namespace {

// Calls f with the same array of each log, for every array of a CollapseLog.
template <class F, class... Logs>
void forEachArray(F f, Logs&... logs) {
  f(logs.i...), f(logs.j...), f(logs.fieldError...), f(logs.iValue...), f(logs.jValue...);
  f(logs.tetsBegin...), f(logs.tetBytes...), f(logs.starBegin...), f(logs.star...);
}

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

// The slab of every vertex of `order` (the alive ones): two cut at its median or, on staggered
// rounds, three cut at its quartiles. Returns the number of slabs.
uint32_t Simplifier::slabsOf(const std::vector<uint32_t>& order, bool staggered, std::vector<uint8_t>& slab) const {
  const uint32_t count = staggered ? 3 : 2;
  const uint64_t alive = order.size();
  uint32_t rank = 0, s = 0;
  for (uint32_t v : order) {
    // Slab s holds the ranks below its upper quantile: 1/2, or 1/4 and 3/4.
    while (s + 1 < count && 4 * uint64_t(rank) >= alive * (staggered ? 2 * s + 1 : 2)) ++s;
    slab[v] = uint8_t(s);
    ++rank;
  }
  return count;
}

void Simplifier::runSlabs(uint32_t planned) {
  // The order the slabs follow: the vertex numbering (meshes are mostly numbered coherently,
  // and the split stream then compresses best; slabs across the numbering make it larger) or
  // an axis, whichever crosses fewest vertices when halved.
  // (Each axis sorts the order of the one before, stably: ties keep that order.)
  std::vector<uint32_t> order, candidate;  // (alive vertices only: those that die leave each round)
  std::vector<uint8_t> slab(V_, 0);
  std::vector<std::pair<float, uint32_t>> byAxis;
  for (uint32_t v = 0; v < V_; ++v)
    if (out_.vertexAlive[v]) candidate.push_back(v);
  size_t fewest = ~size_t(0);
  for (int axis = -1; axis < 3; ++axis) {
    if (axis >= 0) {
      byAxis.clear();
      for (uint32_t v : candidate) byAxis.push_back({vert_[v].x[axis], v});
      std::stable_sort(byAxis.begin(), byAxis.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      for (size_t k = 0; k < byAxis.size(); ++k) candidate[k] = byAxis[k].second;
    }
    slabsOf(candidate, false, slab);
    markInner(slab);
    size_t border = 0;
    for (uint32_t v : candidate) border += !inner_[v];
    if (border < fewest) {
      fewest = border;
      order = candidate;
    }
  }
  for (uint32_t s = 0; s < kMaxSlabs; ++s) slabs_[s].slab = int(s);
  // The log sized up front (a log grown by doubling holds up to twice its size): a collapse
  // removes about (T − target tets) / planned tets and moves the rest of a star of 4T/V tets.
  const double removedEach =
      double(tetsAlive_ - std::min<uint32_t>(tetsAlive_, opt_.targetTets)) / std::max(1u, planned);
  const double movedEach = std::max(0.0, 4.0 * tetsAlive_ / std::max<uint32_t>(alive_, 1) - removedEach);
  const double expected = planned + 1.0;
  forEachArray([&](auto& v) { v.reserve(size_t(expected)); }, out_.log);
  out_.log.tetBytes.reserve(size_t(expected * (CollapseLog::kHeaderBytes + CollapseLog::kMovedBytes * movedEach +
                                               CollapseLog::kRemovedBytes * removedEach)));
  if (opt_.recordReadSets) out_.log.star.reserve(size_t(expected * 4.0 * tetsAlive_ / std::max<uint32_t>(alive_, 1)));

  const double budgetV = kSlabShare * planned;
  const double budgetT = opt_.targetTets > 0 ? kSlabShare * (double(tetsAlive_) - opt_.targetTets) : kInf;
  double capV[kMaxSlabs], capT[kMaxSlabs], inner[kMaxSlabs];
  std::vector<uint32_t> thread[2];
  float tau = 0;
  uint32_t collapsedAll = 0, removedAll = 0;
  auto work = [&](int t) {
    for (uint32_t s : thread[t]) {
      Queue& Q = slabs_[s];
      Entry e, top;
      while (Q.collapsed < capV[s] && Q.tetsRemoved < capT[s] && !Q.errorBound && peekValid(Q.heap, e) &&
             e.cost <= tau) {
        Q.heap.pop();
        queued_[e.vertex] = 0;
        if (!Q.heap.empty()) prefetchStar(Q.heap.top().vertex);
        evaluateVertex(*Q.scratch, e.vertex);
        tryCollapse(Q, e.vertex, *Q.scratch, peekValid(Q.heap, top) ? top.cost : float(kInf));
        if (t == 0 && opt_.progress && (Q.collapsed & 4095) == 0) {
          uint32_t done = collapsedAll;
          for (const Queue& x : slabs_) done += x.collapsed;
          opt_.progress(done, planned);
        }
      }
    }
  };
  // Rounds end when the budget is spent, nothing is queued, or two rounds in a row (one of each
  // kind) collapsed nothing: what is left waits along the cuts for the whole mesh's queue.
  for (int round = 0, idle = 0; idle < 2; ++round) {
    std::erase_if(order, [&](uint32_t v) { return !out_.vertexAlive[v]; });
    const uint32_t slabs = slabsOf(order, round & 1, slab);
    markInner(slab);
    // The slabs' queues anew: every queued inner vertex under its last known cost.
    std::vector<Entry> entries[kMaxSlabs];
    std::fill(inner, inner + kMaxSlabs, 0.0);
    for (uint32_t v : order) {
      if (!inner_[v]) continue;
      inner[slab[v]] += 1;
      if (queued_[v]) entries[slab[v]].push_back({queueKey(v), v});
    }
    float least = float(kInf);
    bool errorBound = false;
    double innerAll = 0;
    for (uint32_t s = 0; s < slabs; ++s) {
      Queue& Q = slabs_[s];
      Q.heap = Heap(EntryAfter(), std::move(entries[s]));
      if (!Q.heap.empty()) least = std::min(least, Q.heap.top().cost);
      errorBound |= Q.errorBound;
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
      Queue& Q = slabs_[s];
      Q.collapsed = 0;
      Q.tetsRemoved = 0;
      capV[s] = leftV * inner[s] / innerAll;
      capT[s] = leftT * inner[s] / innerAll;
      const int t = load[1] < load[0] ? 1 : 0;
      load[t] += inner[s];
      thread[t].push_back(s);
      Q.scratch = &scratches_[size_t(t)];
    }
    onBoth(work);
    mergeRound(slabs);
    uint32_t collapsed = 0;
    for (uint32_t s = 0; s < slabs; ++s) {
      collapsed += slabs_[s].collapsed;
      removedAll += slabs_[s].tetsRemoved;
    }
    collapsedAll += collapsed;
    idle = collapsed ? 0 : idle + 1;
  }
  // What is left in the slabs' queues stays marked queued_ for the whole mesh's queue.
  out_.slabCollapses += collapsedAll;
  alive_ -= collapsedAll;
  tetsAlive_ -= removedAll;
  for (Queue& Q : slabs_) {
    Q.heap = Heap();
    Q.ownLog = CollapseLog();
    Q.keys = std::vector<float>();
  }
}

// Appends the collapses of this round's slabs to the log, merged by the key each was taken at
// (ties: the lower slab first), and empties the slabs' logs for the next round.
void Simplifier::mergeRound(uint32_t slabs) {
  uint32_t next[kMaxSlabs] = {};
  for (;;) {
    int best = -1;
    for (uint32_t s = 0; s < slabs; ++s)
      if (next[s] < slabs_[s].ownLog.size() &&
          (best < 0 || slabs_[s].keys[next[s]] < slabs_[size_t(best)].keys[next[size_t(best)]]))
        best = int(s);
    if (best < 0) break;
    appendCollapse(out_.log, slabs_[size_t(best)].ownLog, next[size_t(best)]++);
  }
  for (uint32_t s = 0; s < slabs; ++s) {
    forEachArray([](auto& x) { x.clear(); }, slabs_[s].ownLog);
    slabs_[s].keys.clear();
  }
}

// inner_[v]: every alive tet around v lies in v's slab.
// Every round scans all tets: on large meshes (kTwoThreadScan) in two halves at once. Both
// halves only ever write 0, relaxed: the result is the same.
void Simplifier::markInner(const std::vector<uint8_t>& slab) {
  inner_.assign(V_, 1);
  auto scan = [&](uint32_t begin, uint32_t end) {
    for (uint32_t t = begin; t < end; ++t) {
      if (!out_.tetAlive[t]) continue;
      const uint32_t* v = &out_.tets[4 * size_t(t)];
      if (slab[v[0]] != slab[v[1]] || slab[v[0]] != slab[v[2]] || slab[v[0]] != slab[v[3]])
        for (int k = 0; k < 4; ++k) std::atomic_ref<uint8_t>(inner_[v[k]]).store(0, std::memory_order_relaxed);
    }
  };
  if (T_ < kTwoThreadScan) return scan(0, T_);
  onBoth([&](int half) { scan(half ? T_ / 2 : 0, half ? T_ : T_ / 2); });
}

}  // namespace tetstream::simplify_detail
