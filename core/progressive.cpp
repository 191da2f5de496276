#include "progressive.h"

#include <algorithm>
#include <cassert>
#include <cstring>

namespace tetstream {
namespace {

// Small arrays (a vertex's star: tens of entries): insertion sort beats introsort's overhead.
void sortSmall(std::vector<uint32_t>& v) {
  for (size_t i = 1; i < v.size(); ++i) {
    uint32_t x = v[i];
    size_t k = i;
    for (; k > 0 && v[k - 1] > x; --k) v[k] = v[k - 1];
    v[k] = x;
  }
}

uint32_t nextStamp(const ProgressiveMesh& pm) {
  pm.seen.resize(pm.vertexCount(), 0);
  if (++pm.stamp == 0) {  // wrapped: clear once every 4 billion calls
    std::fill(pm.seen.begin(), pm.seen.end(), 0);
    pm.stamp = 1;
  }
  return pm.stamp;
}

// Bitwise, so that a NaN value (kept in lossless streams) compares equal to itself.
bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Appends the tets around v with ids below `end` (those a split did not create).
void listOldTetsAround(const ProgressiveMesh& pm, uint32_t v, uint32_t end, std::vector<uint32_t>& out) {
  for (uint32_t c : pm.stars.corners(v))
    if ((c >> 2) < end) out.push_back(c >> 2);
}

}  // namespace

void StarPool::clear() {
  pool_.clear();
  start_.clear();
  size_.clear();
  cls_.clear();
  free_.clear();
}

void StarPool::reserve(size_t vertices, size_t corners) {
  start_.reserve(vertices);
  size_.reserve(vertices);
  cls_.reserve(vertices);
  pool_.reserve(corners + corners * 2 / 5);  // ~1.3 slots per corner (see StarPool), and a margin
}

uint8_t StarPool::classFor(uint32_t capacity) {
  uint8_t cls = 0;
  while (capacityOf(cls) < capacity) ++cls;
  return cls;
}

uint32_t StarPool::allocate(uint8_t cls) {
  if (free_.size() > cls && !free_[cls].empty()) {
    uint32_t s = free_[cls].back();
    free_[cls].pop_back();
    return s;
  }
  const uint32_t s = uint32_t(pool_.size());
  pool_.resize(pool_.size() + capacityOf(cls));
  return s;
}

uint32_t StarPool::addVertex(uint32_t capacity) {
  const uint8_t cls = classFor(std::max<uint32_t>(capacity, 8));
  start_.push_back(allocate(cls));
  size_.push_back(0);
  cls_.push_back(cls);
  return uint32_t(start_.size() - 1);
}

void StarPool::release(uint32_t start, uint8_t cls) {
  if (free_.size() <= cls) free_.resize(cls + 1);
  free_[cls].push_back(start);
}

void StarPool::popVertex() {
  release(start_.back(), cls_.back());
  start_.pop_back();
  size_.pop_back();
  cls_.pop_back();
}

void StarPool::grow(uint32_t v) {
  const uint8_t cls = cls_[v];
  const uint32_t to = allocate(uint8_t(cls + 1));  // may move pool_: copy by index
  std::copy_n(pool_.begin() + start_[v], size_[v], pool_.begin() + to);
  release(start_[v], cls);
  start_[v] = to;
  cls_[v] = uint8_t(cls + 1);
}

size_t StarPool::bytes() const {
  size_t n = pool_.capacity() * 4 + start_.capacity() * 4 + size_.capacity() * 4 + cls_.capacity();
  for (const auto& f : free_) n += f.capacity() * 4;
  return n;
}

void initProgressive(ProgressiveMesh& pm, TetMesh base) {
  pm.mesh = std::move(base);
  const uint32_t V = pm.mesh.vertexCount();
  std::vector<uint32_t> degree(V, 0);
  for (uint32_t v : pm.mesh.tets) ++degree[v];
  pm.stars.clear();
  pm.stars.reserve(V, pm.mesh.tets.size());
  for (uint32_t v = 0; v < V; ++v) pm.stars.addVertex(degree[v] + degree[v] / 4);  // room to grow
  for (size_t c = 0; c < pm.mesh.tets.size(); ++c) pm.stars.add(pm.mesh.tets[c], uint32_t(c));
  pm.splitJ.clear();
  pm.splitTetsBefore.clear();
  pm.splitJValues.clear();
  pm.keptFirst = pm.keptCount = 0;
  pm.keptFixed = false;
  pm.baseVertices = pm.mesh.vertexCount();
  pm.baseTets = pm.mesh.tetCount();
}

void reserveProgressive(ProgressiveMesh& pm, uint32_t vertices, uint32_t tets) {
  TetMesh& m = pm.mesh;
  m.positions.reserve(3 * size_t(vertices));
  for (ScalarField& f : m.fields) f.values.reserve(vertices);
  m.tets.reserve(4 * size_t(tets));
  pm.stars.reserve(vertices, 4 * size_t(tets));
  pm.seen.reserve(vertices);
  const size_t splits = vertices > m.vertexCount() ? vertices - m.vertexCount() : 0;
  pm.splitJ.reserve(splits);
  pm.splitTetsBefore.reserve(splits);
  pm.splitJValues.reserve(splits * pm.keptCount);
}

void starOf(const ProgressiveMesh& pm, uint32_t v, std::vector<uint32_t>& tets) {
  tets.clear();
  for (uint32_t c : pm.stars.corners(v)) tets.push_back(c >> 2);
  sortSmall(tets);
}

void neighboursOf(const ProgressiveMesh& pm, uint32_t v, std::vector<uint32_t>& vertices) {
  // The star's tets lie anywhere in the tet array, and this is the first look at them in a
  // split: their vertices are copied out in a pass without branches, so that the cache misses
  // overlap, and only then de-duplicated.
  const std::span<const uint32_t> corners = pm.stars.corners(v);
  std::vector<uint32_t>& ids = pm.cornerIds;
  if (ids.size() < 4 * corners.size()) ids.resize(4 * corners.size());  // grows rarely: no zeroing per call
  uint32_t* out = ids.data();
  for (uint32_t c : corners) {
    std::memcpy(out, &pm.mesh.tets[c & ~3u], 4 * sizeof(uint32_t));
    out += 4;
  }
  vertices.clear();
  const uint32_t stamp = nextStamp(pm);
  pm.seen[v] = stamp;
  for (const uint32_t* w = ids.data(); w != out; ++w)
    if (pm.seen[*w] != stamp) {
      pm.seen[*w] = stamp;
      vertices.push_back(*w);
    }
  sortSmall(vertices);
}

void applySplit(ProgressiveMesh& pm, const SplitOp& op, std::vector<uint32_t>& changed) {
  TetMesh& m = pm.mesh;
  const uint32_t i = m.vertexCount();
  assert(op.j < i);
  pm.splitJ.push_back(op.j);
  pm.splitTetsBefore.push_back(m.tetCount());

  m.positions.insert(m.positions.end(), op.position, op.position + 3);
  for (size_t f = 0; f < m.fields.size(); ++f) m.fields[f].values.push_back(op.fields[f]);
  bool jValuesChange = false;
  assert(pm.keptFirst + pm.keptCount <= m.fields.size());
  for (uint32_t k = 0; k < pm.keptCount; ++k) {
    float& value = m.fields[pm.keptFirst + k].values[op.j];
    pm.splitJValues.push_back(value);
    if (op.jFields && !sameBits(value, op.jFields[k])) {
      value = op.jFields[k];
      jValuesChange = true;
    }
  }
  pm.stars.addVertex(uint32_t(op.moved.size() + op.newTets.size() / 4));

  // T_moved: the j corner of each listed tet becomes an i corner.
  for (uint32_t t : op.moved) {
    uint32_t* v = &m.tets[4 * size_t(t)];
    int k = 0;
    while (k < 4 && v[k] != op.j) ++k;
    assert(k < 4);
    v[k] = i;
    pm.stars.add(i, 4 * t + uint32_t(k));
    changed.push_back(t);
  }
  if (!op.moved.empty()) pm.stars.removeIf(op.j, [&](uint32_t c) { return m.tets[c] == i; });
  // T_new: appended tets around the edge (i, j).
  for (size_t n = 0; n + 3 < op.newTets.size(); n += 4) {
    uint32_t t = m.tetCount();
    m.tets.insert(m.tets.end(), op.newTets.begin() + n, op.newTets.begin() + n + 4);
    for (uint32_t k = 0; k < 4; ++k) pm.stars.add(m.tets[4 * t + k], 4 * t + k);
    changed.push_back(t);
  }
  if (jValuesChange) listOldTetsAround(pm, op.j, pm.splitTetsBefore.back(), changed);
}

void undoSplit(ProgressiveMesh& pm, std::vector<uint32_t>& changed) {
  assert(!pm.splitJ.empty());
  TetMesh& m = pm.mesh;
  const uint32_t j = pm.splitJ.back(), tetsBefore = pm.splitTetsBefore.back();
  const uint32_t i = m.vertexCount() - 1;
  pm.splitJ.pop_back();
  pm.splitTetsBefore.pop_back();
  const size_t K = pm.keptCount;
  bool jValuesChange = false;
  for (size_t k = 0; k < K; ++k) {
    float& value = m.fields[pm.keptFirst + k].values[j];
    const float before = pm.splitJValues[pm.splitJValues.size() - K + k];
    jValuesChange |= !sameBits(value, before);
    value = before;
  }
  pm.splitJValues.resize(pm.splitJValues.size() - K);
  if (pm.splitJ.empty()) pm.keptFixed = false;  // back at the base: the next split sets the kind again

  // Drop the new tets' corners from their vertices (once per vertex), then the tets.
  const uint32_t firstDead = 4 * tetsBefore;
  const uint32_t stamp = nextStamp(pm);
  for (uint32_t c = firstDead; c < m.tets.size(); ++c) {
    uint32_t v = m.tets[c];
    if (v == i || pm.seen[v] == stamp) continue;
    pm.seen[v] = stamp;
    pm.stars.removeIf(v, [&](uint32_t x) { return x >= firstDead; });
  }
  m.tets.resize(firstDead);
  // j's own tets (before the moved ones come back) when its values changed back.
  if (jValuesChange) listOldTetsAround(pm, j, tetsBefore, changed);
  // The remaining corners of i are the moved tets: give them back to j.
  for (uint32_t k = 0; k < pm.stars.corners(i).size(); ++k) {  // add() may move the pool: no span kept
    const uint32_t c = pm.stars.corners(i)[k];
    if (c >= firstDead) continue;
    m.tets[c] = j;
    pm.stars.add(j, c);
    changed.push_back(c >> 2);
  }
  pm.stars.popVertex();
  m.positions.resize(m.positions.size() - 3);
  for (ScalarField& f : m.fields) f.values.pop_back();
}

}  // namespace tetstream
