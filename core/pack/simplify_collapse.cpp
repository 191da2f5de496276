// A half-edge collapse: the mesh, stars, quadrics and queue around it, and its log entry (simplifier.h).
#include "pack/simplifier.h"

namespace tetstream::simplify_detail {

namespace {

void eraseFrom(std::vector<uint32_t>& v, uint32_t x) {
  auto it = std::find(v.begin(), v.end(), x);
  assert(it != v.end());
  *it = v.back();
  v.pop_back();
}

// The two vertices of tet v besides those in slots si and sj, in the order that makes
// (v[si], v[sj], a, b) an even permutation of v: a split that recreates the tet as (i, j, a, b)
// gives it the same orientation.
void orientedOthers(const uint32_t* v, int si, int sj, uint32_t* out) {
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

}  // namespace

void Simplifier::collapse(Queue& Q, uint32_t i, uint32_t j, float fieldErr) {
  CollapseLog& log = *Q.log;
  log.i.push_back(i);
  log.j.push_back(j);
  log.iValue.push_back(vert_[i].fit);
  log.jValue.push_back(vert_[j].fit);
  log.fieldError.push_back(float(fieldErr * range_));
  CollapseTets& record = Q.record;
  record.clear();

  Q.around.assign(star_[i].begin(), star_[i].end());  // star_ lists change below
  const std::vector<uint32_t>& around = Q.around;
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
    if (kappa_[t] >= kKappaCap) ++Q.flatTetsRemoved;
    out_.tetAlive[t] = 0;
    ++Q.tetsRemoved;
    for (int k = 0; k < 4; ++k)
      if (!onSharedCut(Q, v[k])) qualitySum_[v[k]] -= 3.0 / kappa_[t];
    for (int k = 0; k < 4; ++k) {
      if (v[k] == i) continue;
      if (onSharedCut(Q, v[k]))
        Q.scratch->cutErasures.push_back({v[k], t});
      else
        eraseFrom(star_[v[k]], t);
    }
  }
  {  // j's star grows by a quarter beyond what it needs, not by doubling (a lower peak memory)
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
    for (int k = 0; k < 4; ++k)
      if (!onSharedCut(Q, v[k])) qualitySum_[v[k]] += 3.0 / kappa_[t] - (v[k] == j ? 0.0 : 3.0 / before);
  }
  log.appendTets(record, j);
  if (opt_.recordReadSets) {
    log.starBegin.push_back(uint32_t(log.star.size()));
    log.star.insert(log.star.end(), star_[j].begin(), star_[j].end());
  }
  star_[i].clear();
  star_[i].shrink_to_fit();
  out_.vertexAlive[i] = 0;
  ++Q.collapsed;
  if (boundary_[i]) {  // (then j is on the boundary too, and has a quadric: see legal())
    boundary_[j] = 1;
    assert(quadricOf_[j] != kNoQuadric);
    if (quadricOf_[j] != kNoQuadric) quadrics_[quadricOf_[j]].add(quadrics_[quadricOf_[i]]);
  }
  fieldQuadric_[j].add(fieldQuadric_[i]);
  // j now stands for the region of both: its value becomes the one that fits the original
  // field there best (least squares over the region's original tets, at p_j); the split gives
  // the value before back. (The paper keeps the sample; fitting lowers the coarse levels' RMS
  // field error.)
  represented_[j] += represented_[i];
  if (fitsRegion(represented_[j]))
    vert_[j].fit = float(fitted(fieldQuadric_[j], p(j), vert_[j].fit, nodeLo(Q.node), nodeHi(Q.node)));
  if (!lastNode_.empty()) lastNode_[j] = Q.node;
  if (!fitRange_.empty()) fitRange_[j] = {float(nodeLo(Q.node)), float(nodeHi(Q.node))};

  // Everything around j changed. j and its neighbours are re-evaluated lazily, when they reach
  // the top: those already queued keep their entry; a blocked one (no legal collapse last
  // time) is queued again under its last known cost, as its neighbourhood changed.
  Scratch& sc = *Q.scratch;
  Q.touched.clear();
  ++sc.stamp;
  sc.seen[i] = sc.stamp;
  for (uint32_t t : around)
    for (int k = 0; k < 4; ++k) {
      uint32_t w = out_.tets[4 * size_t(t) + k];
      if (sc.seen[w] != sc.stamp) {
        sc.seen[w] = sc.stamp;
        Q.touched.push_back(w);
      }
    }
  if (trackChanges_) {  // (random writes the regions and a one-thread queue would make for nothing)
    changed_[i] = roundStamp_;
    for (uint32_t v : Q.touched) changed_[v] = roundStamp_;
  }
  for (uint32_t v : Q.touched) {
    if (onSharedCut(Q, v)) {  // left to the regions above; a neighbouring region may mark it too
      std::atomic_ref<uint8_t>(queued_[v]).store(1, std::memory_order_relaxed);
      continue;
    }
    if (queued_[v]) continue;  // its entry stays: it is evaluated afresh when popped
    queued_[v] = 1;
    if (Q.region && !inner_[v]) continue;  // left to the regions above
    Q.heap.push({queueKey(v), v});
  }
}

}  // namespace tetstream::simplify_detail
