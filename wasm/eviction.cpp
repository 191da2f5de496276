#include "eviction.h"

#include <algorithm>
#include <limits>

#include "viewer_state.h"

namespace tetstream::viewer {
namespace {

bool fits(const ViewerState& s, const LevelCounts& counts) {
  return s.memory.baseBytes + estimateBytes(s.dataset.manifest, counts) <= s.memory.limitBytes;
}

// What node k's received chunks brought.
LevelCounts receivedCounts(const Dataset& ds, uint32_t k) {
  LevelCounts c;
  const NodeInfo& n = ds.manifest.nodes[k];
  for (uint32_t i = n.firstChunk; i < n.firstChunk + ds.nodeChunksReceived[k]; ++i)
    addCounts(c, chunkCounts(ds.manifest, i));
  return c;
}

}  // namespace

LevelCounts keptCounts(const ViewerState& s) {
  LevelCounts c = s.memory.received;
  for (uint32_t k : s.evict.nodes) subtractCounts(c, receivedCounts(s.dataset, k));
  return c;
}

bool budgetedByRegions(const ViewerState& s) { return !s.dataset.manifest.nodes.empty() && s.memory.limitBytes > 0; }

uint32_t levelCap(const ViewerState& s) {
  return std::min({s.level.targetSplits, s.dataset.splitsReceived(), s.evict.cap});
}

std::vector<uint32_t> chunksToFetch(const ViewerState& s) {
  const Dataset& ds = s.dataset;
  if (!budgetedByRegions(s)) {
    const uint32_t room = s.memory.chunksAllowed > ds.chunksReceived ? s.memory.chunksAllowed - ds.chunksReceived : 0;
    return plannedChunks(s, room);
  }
  std::vector<uint32_t> out = plannedChunks(s, std::numeric_limits<uint32_t>::max());
  LevelCounts have = keptCounts(s);
  size_t n = 0;
  for (; n < out.size(); ++n) {
    addCounts(have, chunkCounts(ds.manifest, out[n]));
    if (!fits(s, have)) break;
  }
  out.resize(n);
  return out;
}

void planEviction(ViewerState& s) {
  Eviction& e = s.evict;
  e.nodes.clear();
  e.cap = ~0u;
  e.memoryFull = false;
  const Dataset& ds = s.dataset;
  const Manifest& m = ds.manifest;
  const FetchPlan& p = s.fetch;
  if (!budgetedByRegions(s) || ds.chunksReceived == 0 || p.needed.size() != m.nodes.size()) return;
  // What the view needs, in hand or not.
  LevelCounts want = s.memory.received;
  for (uint32_t k = 0; k < m.nodes.size(); ++k)
    if (p.needed[k] && !p.broken[k])
      for (uint32_t i = m.nodes[k].firstChunk + ds.nodeChunksReceived[k];
           i < m.nodes[k].firstChunk + m.nodes[k].chunkCount; ++i)
        addCounts(want, chunkCounts(m, i));
  if (fits(s, want)) return;
  // Nodes the view does not need, latest first (a child comes after its parent, so children
  // are considered before their parents), each once nothing received hangs below it.
  std::vector<uint32_t> first(m.nodes.size(), ~0u), childrenIn(m.nodes.size(), 0), in;
  for (uint32_t place = 1; place < ds.received.size(); ++place)
    if (const int32_t k = ds.nodeOfChunk(ds.received[place]); k >= 0 && first[size_t(k)] == ~0u) {
      first[size_t(k)] = ds.chunkFirstSplit[place];
      in.push_back(uint32_t(k));
      if (m.nodes[size_t(k)].parent >= 0) ++childrenIn[size_t(m.nodes[size_t(k)].parent)];
    }
  std::sort(in.begin(), in.end(), [&](uint32_t a, uint32_t b) { return first[a] > first[b]; });
  for (uint32_t k : in) {
    if (fits(s, want)) break;
    if (p.needed[k] || childrenIn[k] > 0) continue;
    e.nodes.push_back(k);
    e.cap = std::min(e.cap, first[k]);
    subtractCounts(want, receivedCounts(ds, k));
    if (m.nodes[k].parent >= 0) --childrenIn[size_t(m.nodes[k].parent)];
  }
  e.memoryFull = p.missing > 0 && chunksToFetch(s).empty();
}

bool forgetEvicted(ViewerState& s) {
  Eviction& e = s.evict;
  Dataset& ds = s.dataset;
  if (e.nodes.empty() || ds.splitsApplied() > e.cap) return false;
  const Manifest& m = ds.manifest;
  for (uint32_t k : e.nodes) {
    const LevelCounts counts = receivedCounts(ds, k);
    const uint32_t chunks = ds.nodeChunksReceived[k];
    if (!forgetNode(ds, k)) break;  // (cannot happen: chosen leaves first, undone to the cap)
    subtractCounts(s.memory.received, counts);
    for (uint32_t i = m.nodes[k].firstChunk; i < m.nodes[k].firstChunk + chunks; ++i) e.forgottenChunks.push_back(i);
    ++e.nodesForgotten;
  }
  // Chunks that were waiting for a node now gone are given back too (the page fetches them
  // again if the view comes back to them).
  for (auto it = s.pendingChunks.begin(); it != s.pendingChunks.end();) {
    const int32_t k = ds.nodeOfChunk(it->first);
    const int32_t parent = k >= 0 ? m.nodes[size_t(k)].parent : -1;
    if (parent >= 0 && ds.nodeChunksReceived[size_t(parent)] == 0 && ds.nodeChunksReceived[size_t(k)] == 0) {
      e.forgottenChunks.push_back(it->first);
      it = s.pendingChunks.erase(it);
    } else {
      ++it;
    }
  }
  e.nodes.clear();
  e.cap = ~0u;
  if (s.level.live) s.level.targetSplits = ds.splitsReceived();
  s.level.targetSplits = std::min(s.level.targetSplits, ds.splitsReceived());
  replan(s);  // (the plan may now fit more: the page asks for it again)
  return true;
}

}  // namespace tetstream::viewer
