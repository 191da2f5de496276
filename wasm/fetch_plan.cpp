#include "fetch_plan.h"

#include <algorithm>
#include <cmath>
#include <queue>
#include <utility>

#include "viewer_state.h"

namespace tetstream::viewer {
namespace {

// A node's broken flag as seen from below: broken itself or under a broken ancestor (parents
// come first, so one pass in index order settles it).
std::vector<uint8_t> brokenBelow(const FetchPlan& p, const Manifest& m) {
  std::vector<uint8_t> out(p.broken);
  for (size_t k = 0; k < m.nodes.size(); ++k)
    if (m.nodes[k].parent >= 0 && out[size_t(m.nodes[k].parent)]) out[k] = 1;
  return out;
}

// Whether the plane n·p = offset crosses the box.
bool planeCrosses(const Bounds& b, const std::array<float, 3>& n, float offset) {
  double lo = 0, hi = 0;
  for (int k = 0; k < 3; ++k) {
    const double a = n[size_t(k)] * double(b.min[k]), c = n[size_t(k)] * double(b.max[k]);
    lo += std::min(a, c);
    hi += std::max(a, c);
  }
  return lo <= offset && offset <= hi;
}

bool holds(const Range& r, float v) { return r.min <= v && v <= r.max; }

}  // namespace

void resetPlan(ViewerState& s) {
  const Manifest& m = s.dataset.manifest;
  FetchPlan& p = s.fetch;
  p.needed.assign(m.nodes.size(), 0);
  p.broken.assign(m.nodes.size(), 0);
  p.children.assign(m.nodes.size(), {});
  for (uint32_t k = 0; k < m.nodes.size(); ++k)
    if (m.nodes[k].parent >= 0) p.children[size_t(m.nodes[k].parent)].push_back(k);
  replan(s);
}

void replan(ViewerState& s) {
  const Dataset& ds = s.dataset;
  const Manifest& m = ds.manifest;
  FetchPlan& p = s.fetch;
  ++p.version;
  if (m.nodes.empty()) {
    p.missing = uint32_t(m.chunks.size()) - ds.chunksReceived;
    return;
  }
  const size_t f = size_t(std::max(s.field, 0));
  const bool everything = p.mode == FetchMode::Everything || f >= m.fields.size();
  std::fill(p.needed.begin(), p.needed.end(), 0);
  for (size_t k = 0; k < m.nodes.size(); ++k) {
    const NodeInfo& n = m.nodes[k];
    p.needed[k] = everything || holds(n.ranges[f], s.isovalue) ||
                  (s.sliceOn && planeCrosses(n.bounds, s.slice.normal(), s.slice.offset()));
  }
  for (size_t k = m.nodes.size(); k-- > 0;)  // (parents come first: one pass from the end)
    if (p.needed[k] && m.nodes[k].parent >= 0) p.needed[size_t(m.nodes[k].parent)] = 1;
  const std::vector<uint8_t> broken = brokenBelow(p, m);
  p.missing = ds.chunksReceived == 0 ? 1 : 0;
  for (size_t k = 0; k < m.nodes.size(); ++k)
    if (p.needed[k] && !broken[k]) p.missing += m.nodes[k].chunkCount - ds.nodeChunksReceived[k];
  planEviction(s);
}

void notePlannedChunk(ViewerState& s, uint32_t index) {
  FetchPlan& p = s.fetch;
  const int32_t k = s.dataset.nodeOfChunk(index);
  const bool counted = k < 0 || (p.needed[size_t(k)] && !p.broken[size_t(k)]);
  if (counted && p.missing > 0) --p.missing;
}

std::vector<uint32_t> plannedChunks(const ViewerState& s, uint32_t limit) {
  const Dataset& ds = s.dataset;
  const Manifest& m = ds.manifest;
  const FetchPlan& p = s.fetch;
  std::vector<uint32_t> out;
  if (m.nodes.empty()) {
    for (uint32_t c = ds.chunksReceived; c < m.chunks.size() && out.size() < limit; ++c) out.push_back(c);
    return out;
  }
  if (ds.chunksReceived == 0 && limit > 0) out.push_back(0);
  // Most important first, each node after its parent: a queue of the nodes whose parent is in
  // (or planned), by priority; nodes already in go first (their children become ready).
  const std::vector<uint8_t> broken = brokenBelow(p, m);
  auto priority = [&](uint32_t k) {
    const NodeInfo& n = m.nodes[k];
    if (ds.nodeComplete(k)) return INFINITY;
    const double error = n.fieldMax >= 0 ? n.fieldMax : n.fieldError;
    const double seen = p.screenWeight ? p.screenWeight(n.bounds) : 1.0;
    return float((error + 1e-30) * (seen > 0 ? seen : 1e-9));  // (out of view: after everything in view)
  };
  std::priority_queue<std::pair<float, uint32_t>> ready;
  auto offer = [&](uint32_t k) {
    if (p.needed[k] && !broken[k]) ready.push({priority(k), k});
  };
  for (uint32_t k = 0; k < m.nodes.size(); ++k)
    if (m.nodes[k].parent < 0) offer(k);
  while (!ready.empty() && out.size() < limit) {
    const uint32_t k = ready.top().second;
    ready.pop();
    const NodeInfo& n = m.nodes[k];
    for (uint32_t c = n.firstChunk + ds.nodeChunksReceived[k]; c < n.firstChunk + n.chunkCount && out.size() < limit;
         ++c)
      out.push_back(c);
    for (uint32_t child : p.children[k]) offer(child);
  }
  return out;
}

void giveUpChunk(ViewerState& s, uint32_t index) {
  const int32_t k = s.dataset.nodeOfChunk(index);
  if (k < 0) return;
  s.fetch.broken[size_t(k)] = 1;
  replan(s);
}

bool exactSurface(const ViewerState& s) {
  const Dataset& ds = s.dataset;
  const Manifest& m = ds.manifest;
  if (ds.chunksReceived == 0 || !s.level.live || ds.splitsApplied() != ds.splitsReceived() || s.field < 0) return false;
  if (m.nodes.empty()) return ds.chunksReceived == m.chunks.size();
  for (uint32_t k = 0; k < m.nodes.size(); ++k)
    if (holds(m.nodes[k].ranges[size_t(s.field)], s.isovalue) && !ds.nodeComplete(k)) return false;
  return true;
}

uint32_t nodesLoaded(const ViewerState& s) {
  uint32_t n = 0;
  for (uint32_t k = 0; k < s.dataset.manifest.nodes.size(); ++k) n += s.dataset.nodeComplete(k);
  return n;
}

uint64_t neededBytes(const ViewerState& s) {
  const Manifest& m = s.dataset.manifest;
  if (m.nodes.empty()) return m.totalBytes();
  uint64_t bytes = m.chunks.empty() ? 0 : m.chunks[0].bytes;
  const std::vector<uint8_t> broken = brokenBelow(s.fetch, m);
  for (size_t k = 0; k < m.nodes.size(); ++k)
    if (s.fetch.needed[k] && !broken[k])
      for (uint32_t c = m.nodes[k].firstChunk; c < m.nodes[k].firstChunk + m.nodes[k].chunkCount; ++c)
        bytes += m.chunks[c].bytes;
  return bytes;
}

std::pair<uint32_t, uint32_t> neededCounts(const ViewerState& s) {
  const Manifest& m = s.dataset.manifest;
  if (m.chunks.empty()) return {0, 0};
  uint64_t vertices = m.chunks[0].vertices, tets = m.chunks[0].tets;
  const std::vector<uint8_t> broken = brokenBelow(s.fetch, m);
  for (size_t k = 0; k < m.nodes.size(); ++k)
    if (m.nodes.size() == s.fetch.needed.size() && s.fetch.needed[k] && !broken[k]) {
      vertices += m.nodes[k].vertexEnd - m.nodes[k].vertexBegin;
      tets += m.nodes[k].tetEnd - m.nodes[k].tetBegin;
    }
  return {uint32_t(std::min<uint64_t>(vertices, m.vertices)), uint32_t(std::min<uint64_t>(tets, m.tets))};
}

}  // namespace tetstream::viewer
