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
// Before that, a large mesh is simplified in a tree of regions, level by level from the leaves,
// two threads at once (runTree, simplify_tree.cpp). simplifier.h lists where the rest of the class lives.
#include "simplify.h"

#include <cassert>

#include "pack/simplifier.h"
#include "work_pool.h"

namespace tetstream {
namespace simplify_detail {

// The verdict the simplifier would reach on hec(i → j) of the input (checkCollapse, tests).
CollapseVerdict Simplifier::check(uint32_t i, uint32_t j) {
  init();
  readyScratches();
  Scratch& sc = *main_.scratch;
  neighbours(sc, i, sc.nbr);
  const size_t slot = size_t(std::find(sc.nbr.begin(), sc.nbr.end(), j) - sc.nbr.begin());
  if (slot == sc.nbr.size()) return CollapseVerdict::NotAnEdge;
  CollapseVerdict v = CollapseVerdict::Legal;
  prepareStar(sc, i);
  if (legal(sc, i, j, bitOf(slot), &v)) {
    Candidate c = boundTerms(sc, i, j, bitOf(slot), sc.removed, sc.removedQuality);
    localTerm(sc, i, c);
    finishCost(sc, c, &v);
  }
  if (v == CollapseVerdict::Legal && !linkCondition(main_, i, j)) v = CollapseVerdict::LinkCondition;
  return v;
}

// The queue of the whole mesh until the target, then the result (simplify.h).
Result Simplifier::run() {
  init();
  const uint32_t target = std::max<uint32_t>(opt_.targetVertices, 4);
  const uint32_t planned = countedAlive() > target ? countedAlive() - target : 0;
  out_.stopReason = "target reached";
  tetsAlive_ = T_;
  Queue& Q = main_;
  Q.log = &out_.log;
  const uint64_t size = opt_.part && opt_.part->inputVertices ? opt_.part->inputVertices : V_;
  slack_ = size >= kSlackMinVertices ? kLargeMeshSlack : 1.0f;
  runTree(target);
  // A part's top collapses only its inner vertices (markTopInner), as one more region of its
  // tree or, with halo vertices left, as the root; a whole mesh's root collapses any.
  const bool topIsRegion = opt_.part && opt_.part->topIsRegion;
  if (topIsRegion || haloAlive_) {
    markTopInner();
    Q.region = true;
  }
  if (!topIsRegion)
    for (uint32_t v = 0; v < V_; ++v)  // (after the regions: what they left queued)
      if (out_.vertexAlive[v] && queued_[v] && (!Q.region || inner_[v])) Q.heap.push({queueKey(v), v});
  readyScratches();
  if (topIsRegion) runTop(Q, target);
  const bool parallel = !topIsRegion && opt_.threads > 1 && V_ >= opt_.parallelMinVertices;
  const uint32_t roundSize = parallel ? kRoundSize : 1;
  trackChanges_ = roundSize > 1;  // (changedThisRound reads changed_ only then)
  if (trackChanges_) changed_.assign(V_, 0);
  WorkPool pool(parallel ? 1 : 0);
  auto evaluateTask = [this](uint32_t k) { evaluateVertex(scratches_[k], round_[k].vertex); };
  auto goOn = [&] {
    return countedAlive() - Q.collapsed > target && tetsAlive_ - Q.tetsRemoved > opt_.targetTets && !Q.errorBound;
  };
  while (!topIsRegion && goOn()) {
    round_.clear();
    Entry e;
    while (round_.size() < roundSize && peekValid(Q.heap, e)) {
      Q.heap.pop();
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
      const bool topValid = peekValid(Q.heap, top);
      if (k > 0 && (!goOn() || (topValid && EntryAfter()(r, top)) || changedThisRound(scratches_[k], r.vertex))) {
        for (size_t x = k; x < round_.size(); ++x) Q.heap.push(round_[x]);  // evaluated for nothing
        break;
      }
      float next = topValid ? top.cost : float(kInf);
      if (k + 1 < round_.size()) next = std::min(next, round_[k + 1].cost);
      queued_[r.vertex] = 0;
      tryCollapse(Q, r.vertex, scratches_[k], next);
      if (opt_.progress && (out_.log.size() & 4095) == 0) opt_.progress(out_.log.size(), planned);
    }
  }
  if (Q.errorBound) out_.stopReason = "error bound reached";
  if (opt_.progress) opt_.progress(out_.log.size(), planned);
  auto count = [&](const Queue& w) {
    out_.queuePops += w.pops;
    out_.requeued += w.requeued;
    out_.rejectedByLink += w.rejectedByLink;
    out_.flatTetsRemoved += w.flatTetsRemoved;
    tune_.linkMismatches += w.linkMismatches;
  };
  count(main_);
  out_.queuePops += regionPops_;
  out_.requeued += regionRequeued_;
  out_.rejectedByLink += regionRejectedByLink_;
  out_.flatTetsRemoved += regionFlatRemoved_;
  tune_.linkMismatches += regionLinkMismatches_;
  alive_ -= Q.collapsed;
  if (out_.log.size() > (out_.tree.sectionEnd.empty() ? 0 : out_.tree.sectionEnd.back())) {
    out_.tree.sectionNode.push_back(1);  // the root's collapses
    out_.tree.sectionEnd.push_back(out_.log.size());
  }
  tetsAlive_ -= Q.tetsRemoved;
  out_.vertices = alive_;
  out_.costEvaluations += mainScratch_.evaluations;
  for (const Scratch& sc : scratches_) out_.costEvaluations += sc.evaluations;
  out_.tetCount = 0;
  for (uint32_t t = 0; t < T_; ++t) {
    out_.tetCount += out_.tetAlive[t];
    if (out_.tetAlive[t] && kappa_[t] >= kKappaCap) ++out_.flatTetsLeft;
  }
  out_.log.close(opt_.recordReadSets);
  // (A part has not the whole input the refit fits against.)
  if (fitOn_ && opt_.refitValues && !opt_.part) refitValues();
  if (fitOn_) {
    out_.values.resize(V_);
    for (uint32_t v = 0; v < V_; ++v) out_.values[v] = vert_[v].fit;
    out_.valuesField = opt_.field;
  }
  if (opt_.part) fillCarried();
  return Result::success();
}

void Simplifier::tryCollapse(Queue& Q, uint32_t i, Scratch& sc, float next) {
  ++Q.pops;
  bool first = true;
  for (int c; (c = cheapestCandidate(sc, i)) >= 0;) {
    const Candidate cand = sc.candidates[size_t(c)];
    if (first) lastCost_[i] = float(cand.cost);
    first = false;
    if (float(cand.cost) > next * slack_) {
      Q.heap.push({float(cand.cost), i});  // something else is cheaper now
      queued_[i] = 1;
      ++Q.requeued;
      return;
    }
    if (cand.fieldErr > opt_.maxError) {  // the next collapse in line would exceed the bound
      Q.heap.push({float(cand.cost), i});
      queued_[i] = 1;
      Q.errorBound = true;
      return;
    }
    if (Q.region && !inner_[cand.j]) {  // a region leaves it to the regions above
      queued_[i] = 1;
      return;
    }
    if (!linkCondition(Q, i, cand.j)) {
      ++Q.rejectedByLink;
      sc.candidates.erase(sc.candidates.begin() + c);
      continue;
    }
    collapse(Q, i, cand.j, cand.fieldErr);
    return;
  }
  if (first) lastCost_[i] = float(kInf);
  // No legal collapse from i until its neighbourhood changes (then it is queued again).
}

}  // namespace simplify_detail

using simplify_detail::Simplifier;

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
  SimplifyTuning tuning;
  Simplifier s(mesh, options, tuning, scratch);
  return s.check(i, j);
}

Result simplifyMesh(const TetMesh& mesh, const SimplifyOptions& options, SimplifyResult& out, FaceAdjacency* adjacency,
                    std::vector<uint32_t>* takeTets) {
  assert(options.field >= 0 && size_t(options.field) < mesh.fields.size());
  out = SimplifyResult{};
  SimplifyTuning tuning;
  Simplifier s(mesh, options, tuning, out, adjacency, takeTets);
  return s.run();
}

Result simplifyMeshTuned(const TetMesh& mesh, const SimplifyOptions& options, SimplifyTuning& tuning,
                         SimplifyResult& out) {
  assert(options.field >= 0 && size_t(options.field) < mesh.fields.size());
  out = SimplifyResult{};
  tuning.linkMismatches = 0;
  Simplifier s(mesh, options, tuning, out);
  return s.run();
}

}  // namespace tetstream
