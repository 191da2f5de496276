#include "adjacency.h"

#include <algorithm>
#include <cassert>
#if !defined(__EMSCRIPTEN__)
#include <thread>
#endif

#include "mesh.h"
#include "tet_tables.h"

namespace tetstream {

[[maybe_unused]] constexpr size_t kParallelHalfFaces = 400000;  // 100,000 tets (native only)

namespace {

// The vertices of half-face h (face h % 4 of tet h / 4, kTetFaces), ascending.
void sortedFace(std::span<const uint32_t> tets, size_t h, uint32_t s[3]) {
  const uint32_t* v = &tets[h & ~size_t(3)];
  const uint8_t* f = kTetFaces[h & 3];
  s[0] = v[f[0]];
  s[1] = v[f[1]];
  s[2] = v[f[2]];
  if (s[0] > s[1]) std::swap(s[0], s[1]);
  if (s[1] > s[2]) std::swap(s[1], s[2]);
  if (s[0] > s[1]) std::swap(s[0], s[1]);
}

// Pairs the half-faces whose smallest vertex lies in [lo, hi): bucketed by that vertex (a
// counting sort), matched inside each bucket by the other two. Buckets are small (the faces
// around one vertex). Writes only those half-faces' entries; returns the non-manifold faces.
uint64_t pairFaces(std::span<const uint32_t> tets, uint32_t lo, uint32_t hi, std::vector<uint32_t>& opposite) {
  const size_t halfFaces = tets.size();
  std::vector<uint32_t> start(size_t(hi - lo) + 1, 0);
  for (size_t h = 0; h < halfFaces; ++h) {
    uint32_t s[3];
    sortedFace(tets, h, s);
    if (s[0] >= lo && s[0] < hi) ++start[s[0] - lo + 1];
  }
  for (size_t v = 0; v < hi - lo; ++v) start[v + 1] += start[v];
  struct Entry {
    uint64_t key;
    uint32_t halfFace;
  };
  std::vector<Entry> entries(start.back());
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  for (size_t h = 0; h < halfFaces; ++h) {
    uint32_t s[3];
    sortedFace(tets, h, s);
    if (s[0] >= lo && s[0] < hi) entries[fill[s[0] - lo]++] = {edgeKey(s[1], s[2]), uint32_t(h)};
  }
  uint64_t nonManifold = 0;
  for (size_t v = 0; v < hi - lo; ++v) {
    Entry* b = entries.data() + start[v];
    Entry* e = entries.data() + start[v + 1];
    std::sort(b, e, [](const Entry& x, const Entry& y) {
      return x.key < y.key || (x.key == y.key && x.halfFace < y.halfFace);
    });
    for (Entry* run = b; run < e;) {
      Entry* end = run + 1;
      while (end < e && end->key == run->key) ++end;
      if (end - run == 2) {
        opposite[run[0].halfFace] = run[1].halfFace;
        opposite[run[1].halfFace] = run[0].halfFace;
      } else if (end - run > 2) {
        ++nonManifold;
      }
      run = end;
    }
  }
  return nonManifold;
}

}  // namespace

void buildFaceAdjacency(std::span<const uint32_t> tets, uint32_t vertexCount, FaceAdjacency& out) {
  out.opposite.assign(tets.size(), kNoNeighbor);
  for ([[maybe_unused]] uint32_t v : tets) assert(v < vertexCount);
#if !defined(__EMSCRIPTEN__)
  // Natively, a large mesh's vertices in two halves on two threads (each scans every face and
  // pairs those of its half: the pairs never cross, so the writes don't either).
  if (tets.size() >= kParallelHalfFaces) {
    uint64_t upper = 0;
    std::jthread other([&] { upper = pairFaces(tets, vertexCount / 2, vertexCount, out.opposite); });
    const uint64_t lower = pairFaces(tets, 0, vertexCount / 2, out.opposite);
    other.join();
    out.nonManifoldFaces = lower + upper;
    return;
  }
#endif
  out.nonManifoldFaces = pairFaces(tets, 0, vertexCount, out.opposite);
}

void extractBoundary(std::span<const uint32_t> tets, const FaceAdjacency& adj, std::vector<uint32_t>& triangles) {
  triangles.clear();
  for (size_t h = 0; h < adj.opposite.size(); ++h) {
    if (adj.opposite[h] != kNoNeighbor) continue;
    const uint32_t* v = &tets[h & ~size_t(3)];
    const uint8_t* f = kTetFaces[h & 3];
    triangles.insert(triangles.end(), {v[f[0]], v[f[1]], v[f[2]]});
  }
}

uint64_t countNonManifoldBoundaryEdges(std::span<const uint32_t> triangles) {
  // Each edge under its smaller vertex (a counting sort: a bucket holds the few boundary edges
  // at one vertex), matched inside its bucket by the other. A quarter of the time of sorting
  // them all as 64-bit keys.
  const size_t edges = triangles.size() / 3 * 3;
  uint32_t vertices = 0;
  for (size_t i = 0; i < edges; ++i) vertices = std::max(vertices, triangles[i] + 1);
  auto edge = [&](size_t e, uint32_t& lo, uint32_t& hi) {
    const size_t tri = e - e % 3;
    const uint32_t a = triangles[e], b = triangles[tri + (e + 1) % 3];
    lo = std::min(a, b), hi = std::max(a, b);
  };
  std::vector<uint32_t> start(size_t(vertices) + 1, 0), other(edges);
  uint32_t lo, hi;
  for (size_t e = 0; e < edges; ++e) edge(e, lo, hi), ++start[lo + 1];
  for (uint32_t v = 0; v < vertices; ++v) start[v + 1] += start[v];
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  for (size_t e = 0; e < edges; ++e) edge(e, lo, hi), other[fill[lo]++] = hi;
  uint64_t bad = 0;
  for (uint32_t v = 0; v < vertices; ++v) {
    uint32_t* b = other.data() + start[v];
    uint32_t* e = other.data() + start[v + 1];
    std::sort(b, e);
    for (uint32_t* run = b; run < e;) {
      uint32_t* end = run + 1;
      while (end < e && *end == *run) ++end;
      bad += end - run != 2;
      run = end;
    }
  }
  return bad;
}

}  // namespace tetstream
