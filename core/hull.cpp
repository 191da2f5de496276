#include "hull.h"

#include <algorithm>
#include <cmath>

#include "adjacency.h"
#include "hash.h"
#include "mesh.h"
#include "tet_tables.h"

namespace tetstream {

void triangleNormal(const float* p, const uint32_t tri[3], float n[3]) {
  const float* a = p + 3 * size_t(tri[0]);
  const float* b = p + 3 * size_t(tri[1]);
  const float* c = p + 3 * size_t(tri[2]);
  float u[3], v[3];
  for (int k = 0; k < 3; ++k) u[k] = b[k] - a[k], v[k] = c[k] - a[k];
  n[0] = u[1] * v[2] - u[2] * v[1];
  n[1] = u[2] * v[0] - u[0] * v[2];
  n[2] = u[0] * v[1] - u[1] * v[0];
  float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (int k = 0; k < 3; ++k) n[k] = len > 0 ? n[k] / len : 0.f;
}

// ------------------------------------------------------------------ the hull, kept up to date

void HullTracker::clear() {
  faces_.clear();
  positions_.clear();
  normals_.clear();
  head_.clear();
  next_.clear();
  prev_.clear();
  lines_.clear();
  lineKeys_.clear();
  lineOfEdge_.clear();
  dirtyEdges_.clear();
  changedTriangles_.clear();
  changedLines_.clear();
  fullUpload_ = true;
}

size_t HullTracker::memoryBytes() const {
  auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  return bytes(faces_) + bytes(positions_) + bytes(normals_) + bytes(head_) + bytes(next_) + bytes(prev_) +
         bytes(lines_) + bytes(lineKeys_) + lineOfEdge_.memoryBytes() + bytes(dirtyEdges_) + bytes(entries_) +
         bytes(vertexScratch_) + bytes(dropScratch_) + bytes(changedTriangles_) + bytes(changedLines_);
}

void HullTracker::clearChanges() {
  changedTriangles_.clear();
  changedLines_.clear();
  fullUpload_ = false;
}

void HullTracker::rebuild(const ProgressiveMesh& pm) {
  clear();
  const TetMesh& mesh = pm.mesh;
  head_.assign(mesh.vertexCount(), kNone);
  if (mesh.tetCount() == 0) return;
  FaceAdjacency adj;
  buildFaceAdjacency(mesh.tets, mesh.vertexCount(), adj);
  std::vector<uint32_t> tris;
  extractBoundary(mesh.tets, adj, tris);
  for (size_t t = 0; t + 2 < tris.size(); t += 3) addFace(mesh.positions.data(), &tris[t]);
  std::sort(dirtyEdges_.begin(), dirtyEdges_.end());
  dirtyEdges_.erase(std::unique(dirtyEdges_.begin(), dirtyEdges_.end()), dirtyEdges_.end());
  for (uint64_t e : dirtyEdges_) updateEdge(mesh.positions.data(), e);
  dirtyEdges_.clear();
  fullUpload_ = true;
}

void HullTracker::update(const ProgressiveMesh& pm, std::span<const uint32_t> vertices) {
  const uint32_t nv = pm.vertexCount();
  // A split or undo of (i, j) with neither on the hull changes no hull face: the tets it changes
  // fill star(i) ∪ star(j), whose faces through i or j are then all interior, before and after
  // (the region's outer faces contain neither). About nine in ten splits of a volume mesh are
  // such, and recounting their stars was a quarter of the refinement time. A vertex that an
  // earlier split of the batch did touch may have changed sides: those are recounted.
  const uint32_t known = uint32_t(head_.size());  // vertices the hull has seen
  if (head_.size() < nv) head_.resize(nv, kNone);
  vertexScratch_.clear();
  touched_.clear();
  auto onHull = [&](uint32_t v) { return v < known && head_[v] != kNone; };
  auto touched = [&](uint32_t v) { return std::find(touched_.begin(), touched_.end(), v) != touched_.end(); };
  for (size_t k = 0; k + 1 < vertices.size(); k += 2) {
    const uint32_t i = vertices[k], j = vertices[k + 1];
    if (!onHull(i) && !onHull(j) && !touched(i) && !touched(j)) continue;
    touched_.insert(touched_.end(), {i, j});
    vertexScratch_.insert(vertexScratch_.end(), {i, j});
  }
  std::sort(vertexScratch_.begin(), vertexScratch_.end());
  vertexScratch_.erase(std::unique(vertexScratch_.begin(), vertexScratch_.end()), vertexScratch_.end());
  // Removed vertices first (their faces go), then a recount around each remaining one. Every
  // face whose set of tets changed contains a split's i or j, so nothing else can change.
  std::vector<uint32_t>& drop = dropScratch_;
  for (uint32_t v : vertexScratch_) {
    if (v < nv || v >= head_.size()) continue;
    drop.clear();
    for (uint32_t c = head_[v]; c != kNone; c = next_[c]) drop.push_back(c / 3);
    std::sort(drop.begin(), drop.end(), std::greater<>());
    for (uint32_t slot : drop) removeFace(slot);
  }
  for (uint32_t v : vertexScratch_)
    if (v < nv) recount(pm, v);
  std::sort(dirtyEdges_.begin(), dirtyEdges_.end());
  dirtyEdges_.erase(std::unique(dirtyEdges_.begin(), dirtyEdges_.end()), dirtyEdges_.end());
  for (uint64_t e : dirtyEdges_) updateEdge(pm.mesh.positions.data(), e);
  dirtyEdges_.clear();
}

// The faces containing v: a face with one tet is on the boundary, with two it is inside.
// Keyed by the two other vertices. Most split vertices are inside the domain: an XOR of the
// faces' hashes, where every face seen twice cancels, tells so without sorting (a boundary face
// would have to hash to exactly the XOR of the others to go unnoticed: p ~ 2^-64).
void HullTracker::recount(const ProgressiveMesh& pm, uint32_t v) {
  const uint32_t* tets = pm.mesh.tets.data();
  entries_.clear();
  uint64_t parity = 0;
  for (uint32_t c : pm.stars.corners(v)) {
    const uint32_t t = c >> 2, k = c & 3;
    for (uint32_t f = 0; f < 4; ++f) {
      if (f == k) continue;  // face f is opposite local vertex f: the others contain v
      uint32_t other[2], n = 0;
      for (int i = 0; i < 3; ++i)
        if (kTetFaces[f][i] != k) other[n++] = tets[4 * t + kTetFaces[f][i]];
      const uint64_t key = edgeKey(other[0], other[1]);
      parity ^= hash64(key);
      entries_.push_back({key, t << 2 | f});
    }
  }
  if (parity == 0 && head_[v] == kNone) return;
  std::sort(entries_.begin(), entries_.end(), [](const FaceEntry& x, const FaceEntry& y) { return x.key < y.key; });
  auto countOf = [&](uint64_t key) {
    auto lo = std::lower_bound(entries_.begin(), entries_.end(), key,
                               [](const FaceEntry& e, uint64_t k) { return e.key < k; });
    size_t n = 0;
    for (; lo != entries_.end() && lo->key == key; ++lo) ++n;
    return n;
  };
  auto keyWithout = [&](uint32_t slot) {
    const uint32_t* f = &faces_[3 * size_t(slot)];
    return f[0] == v ? edgeKey(f[1], f[2]) : f[1] == v ? edgeKey(f[0], f[2]) : edgeKey(f[0], f[1]);
  };

  std::vector<uint32_t>& drop = dropScratch_;
  drop.clear();
  for (uint32_t c = head_[v]; c != kNone; c = next_[c])
    if (countOf(keyWithout(c / 3)) != 1) drop.push_back(c / 3);
  std::sort(drop.begin(), drop.end(), std::greater<>());
  for (uint32_t slot : drop) removeFace(slot);

  for (size_t i = 0; i < entries_.size();) {
    size_t j = i + 1;
    while (j < entries_.size() && entries_[j].key == entries_[i].key) ++j;
    if (j - i == 1) {
      bool present = false;
      for (uint32_t c = head_[v]; c != kNone && !present; c = next_[c]) present = keyWithout(c / 3) == entries_[i].key;
      if (!present) {
        const uint32_t t = entries_[i].tetFace >> 2, f = entries_[i].tetFace & 3;
        const uint32_t tri[3] = {tets[4 * t + kTetFaces[f][0]], tets[4 * t + kTetFaces[f][1]],
                                 tets[4 * t + kTetFaces[f][2]]};
        addFace(pm.mesh.positions.data(), tri);
      }
    }
    i = j;
  }
}

void HullTracker::link(uint32_t corner, uint32_t v) {
  next_[corner] = head_[v];
  prev_[corner] = kNone;
  if (head_[v] != kNone) prev_[head_[v]] = corner;
  head_[v] = corner;
}

void HullTracker::unlink(uint32_t corner) {
  const uint32_t v = faces_[corner];
  if (prev_[corner] != kNone)
    next_[prev_[corner]] = next_[corner];
  else
    head_[v] = next_[corner];
  if (next_[corner] != kNone) prev_[next_[corner]] = prev_[corner];
}

void HullTracker::markEdges(const uint32_t tri[3]) {
  for (int k = 0; k < 3; ++k) dirtyEdges_.push_back(edgeKey(tri[k], tri[(k + 1) % 3]));
}

void HullTracker::addFace(const float* p, const uint32_t tri[3]) {
  const uint32_t slot = triangleCount();
  faces_.insert(faces_.end(), tri, tri + 3);
  float n[3];
  triangleNormal(p, tri, n);
  for (int k = 0; k < 3; ++k) {
    const float* q = p + 3 * size_t(tri[k]);
    positions_.insert(positions_.end(), q, q + 3);
    normals_.insert(normals_.end(), n, n + 3);
  }
  next_.resize(faces_.size());
  prev_.resize(faces_.size());
  for (uint32_t k = 0; k < 3; ++k) link(3 * slot + k, tri[k]);
  markEdges(tri);
  if (!fullUpload_) changedTriangles_.push_back(slot);
}

void HullTracker::removeFace(uint32_t slot) {
  markEdges(&faces_[3 * size_t(slot)]);
  for (uint32_t k = 0; k < 3; ++k) unlink(3 * slot + k);
  const uint32_t last = triangleCount() - 1;
  if (slot != last) {
    for (uint32_t k = 0; k < 3; ++k) unlink(3 * last + k);
    std::copy_n(&faces_[3 * size_t(last)], 3, &faces_[3 * size_t(slot)]);
    std::copy_n(&positions_[9 * size_t(last)], 9, &positions_[9 * size_t(slot)]);
    std::copy_n(&normals_[9 * size_t(last)], 9, &normals_[9 * size_t(slot)]);
    for (uint32_t k = 0; k < 3; ++k) link(3 * slot + k, faces_[3 * slot + k]);
    if (!fullUpload_) changedTriangles_.push_back(slot);
  }
  faces_.resize(3 * size_t(last));
  positions_.resize(9 * size_t(last));
  normals_.resize(9 * size_t(last));
  next_.resize(faces_.size());
  prev_.resize(faces_.size());
}

void HullTracker::updateEdge(const float* p, uint64_t key) {
  const uint32_t a = uint32_t(key >> 32), b = uint32_t(key);
  uint32_t count = 0, slots[2] = {kNone, kNone};
  if (a < head_.size())
    for (uint32_t c = head_[a]; c != kNone; c = next_[c]) {
      const uint32_t* f = &faces_[3 * size_t(c / 3)];
      if (f[0] != b && f[1] != b && f[2] != b) continue;
      if (count < 2) slots[count] = c / 3;
      ++count;
    }
  bool draw = count == 1 || count > 2;
  if (count == 2) {
    const float* n0 = &normals_[9 * size_t(slots[0])];
    const float* n1 = &normals_[9 * size_t(slots[1])];
    draw = n0[0] * n1[0] + n0[1] * n1[1] + n0[2] * n1[2] < kCreaseCos;
  }
  const uint32_t line = lineOfEdge_.find(key);
  if (draw && line == FlatMap::kNone) {
    const uint32_t slot = lineCount();
    lines_.insert(lines_.end(), p + 3 * size_t(a), p + 3 * size_t(a) + 3);
    lines_.insert(lines_.end(), p + 3 * size_t(b), p + 3 * size_t(b) + 3);
    lineKeys_.push_back(key);
    bool inserted;
    lineOfEdge_.findOrInsert(key, slot, &inserted);
    if (!fullUpload_) changedLines_.push_back(slot);
  } else if (!draw && line != FlatMap::kNone) {
    removeLine(line);
  }
}

void HullTracker::removeLine(uint32_t slot) {
  lineOfEdge_.erase(lineKeys_[slot]);
  const uint32_t last = lineCount() - 1;
  if (slot != last) {
    const uint64_t moved = lineKeys_[last];
    lineOfEdge_.erase(moved);
    bool inserted;
    lineOfEdge_.findOrInsert(moved, slot, &inserted);
    lineKeys_[slot] = moved;
    std::copy_n(&lines_[6 * size_t(last)], 6, &lines_[6 * size_t(slot)]);
    if (!fullUpload_) changedLines_.push_back(slot);
  }
  lineKeys_.pop_back();
  lines_.resize(6 * size_t(last));
}

}  // namespace tetstream
