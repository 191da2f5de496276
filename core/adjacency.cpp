#include "adjacency.h"

#include <algorithm>
#include <cassert>

#include "tet_tables.h"

namespace tetstream {

void buildFaceAdjacency(std::span<const uint32_t> tets, uint32_t vertexCount, FaceAdjacency& out) {
  const size_t halfFaces = tets.size();
  out.opposite.assign(halfFaces, kNoNeighbor);
  out.nonManifoldFaces = 0;

  // Bucket half-faces by their smallest vertex (counting sort), then match inside each bucket
  // by the other two vertices. Buckets are small (the faces around one vertex).
  std::vector<uint32_t> start(size_t(vertexCount) + 1, 0);
  auto sortedFace = [&](size_t h, uint32_t s[3]) {
    const uint32_t* v = &tets[h & ~size_t(3)];
    const uint8_t* f = kTetFaces[h & 3];
    s[0] = v[f[0]]; s[1] = v[f[1]]; s[2] = v[f[2]];
    if (s[0] > s[1]) std::swap(s[0], s[1]);
    if (s[1] > s[2]) std::swap(s[1], s[2]);
    if (s[0] > s[1]) std::swap(s[0], s[1]);
  };
  for (size_t h = 0; h < halfFaces; ++h) {
    uint32_t s[3];
    sortedFace(h, s);
    assert(s[2] < vertexCount);
    ++start[s[0] + 1];
  }
  for (size_t v = 0; v < vertexCount; ++v) start[v + 1] += start[v];
  struct Entry { uint64_t key; uint32_t halfFace; };
  std::vector<Entry> entries(halfFaces);
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  for (size_t h = 0; h < halfFaces; ++h) {
    uint32_t s[3];
    sortedFace(h, s);
    entries[fill[s[0]]++] = {uint64_t(s[1]) << 32 | s[2], uint32_t(h)};
  }
  for (size_t v = 0; v < vertexCount; ++v) {
    Entry* b = entries.data() + start[v];
    Entry* e = entries.data() + start[v + 1];
    std::sort(b, e, [](const Entry& x, const Entry& y) { return x.key < y.key || (x.key == y.key && x.halfFace < y.halfFace); });
    for (Entry* run = b; run < e;) {
      Entry* end = run + 1;
      while (end < e && end->key == run->key) ++end;
      if (end - run == 2) {
        out.opposite[run[0].halfFace] = run[1].halfFace;
        out.opposite[run[1].halfFace] = run[0].halfFace;
      } else if (end - run > 2) {
        ++out.nonManifoldFaces;
      }
      run = end;
    }
  }
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
  std::vector<uint64_t> edges;
  edges.reserve(triangles.size());
  for (size_t i = 0; i + 2 < triangles.size(); i += 3)
    for (int k = 0; k < 3; ++k) {
      uint32_t a = triangles[i + k], b = triangles[i + (k + 1) % 3];
      edges.push_back(a < b ? uint64_t(a) << 32 | b : uint64_t(b) << 32 | a);
    }
  std::sort(edges.begin(), edges.end());
  uint64_t bad = 0;
  for (size_t i = 0; i < edges.size();) {
    size_t j = i + 1;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i != 2) ++bad;
    i = j;
  }
  return bad;
}

}  // namespace tetstream
