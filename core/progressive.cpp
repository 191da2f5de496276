#include "progressive.h"

#include <algorithm>
#include <cassert>

namespace tetstream {
namespace {

void linkCorner(ProgressiveMesh& pm, uint32_t corner, uint32_t v) {
  pm.cornerNext[corner] = pm.vertexHead[v];
  pm.vertexHead[v] = corner;
}

// Removes from v's list every corner for which drop(corner) holds, keeping the others' order.
template <typename Pred>
void unlinkCorners(ProgressiveMesh& pm, uint32_t v, Pred drop) {
  uint32_t* link = &pm.vertexHead[v];
  while (*link != kNoCorner) {
    uint32_t c = *link;
    if (drop(c)) *link = pm.cornerNext[c];
    else link = &pm.cornerNext[c];
  }
}

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
  pm.seen.resize(pm.vertexHead.size(), 0);
  if (++pm.stamp == 0) {  // wrapped: clear once every 4 billion calls
    std::fill(pm.seen.begin(), pm.seen.end(), 0);
    pm.stamp = 1;
  }
  return pm.stamp;
}

}  // namespace

void initProgressive(ProgressiveMesh& pm, TetMesh base) {
  pm.mesh = std::move(base);
  pm.vertexHead.assign(pm.mesh.vertexCount(), kNoCorner);
  pm.cornerNext.assign(pm.mesh.tets.size(), kNoCorner);
  // Link in reverse so each list runs in ascending corner order (cheaper sorting later).
  for (size_t c = pm.mesh.tets.size(); c-- > 0;) linkCorner(pm, uint32_t(c), pm.mesh.tets[c]);
  pm.splitJ.clear();
  pm.splitTetsBefore.clear();
  pm.baseVertices = pm.mesh.vertexCount();
  pm.baseTets = pm.mesh.tetCount();
}

void starOf(const ProgressiveMesh& pm, uint32_t v, std::vector<uint32_t>& tets) {
  tets.clear();
  for (uint32_t c = pm.vertexHead[v]; c != kNoCorner; c = pm.cornerNext[c]) tets.push_back(c >> 2);
  sortSmall(tets);
}

void neighboursOf(const ProgressiveMesh& pm, uint32_t v, std::vector<uint32_t>& vertices) {
  vertices.clear();
  const uint32_t stamp = nextStamp(pm);
  pm.seen[v] = stamp;
  for (uint32_t c = pm.vertexHead[v]; c != kNoCorner; c = pm.cornerNext[c]) {
    const uint32_t* t = &pm.mesh.tets[c & ~3u];
    for (int k = 0; k < 4; ++k)
      if (pm.seen[t[k]] != stamp) {
        pm.seen[t[k]] = stamp;
        vertices.push_back(t[k]);
      }
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
  pm.vertexHead.push_back(kNoCorner);

  // T_moved: the j corner of each listed tet becomes an i corner.
  for (uint32_t t : op.moved) {
    uint32_t* v = &m.tets[4 * size_t(t)];
    int k = 0;
    while (k < 4 && v[k] != op.j) ++k;
    assert(k < 4);
    v[k] = i;
    changed.push_back(t);
  }
  if (!op.moved.empty()) {
    unlinkCorners(pm, op.j, [&](uint32_t c) { return m.tets[c] == i; });
    for (uint32_t t : op.moved)
      for (uint32_t k = 0; k < 4; ++k)
        if (m.tets[4 * t + k] == i) linkCorner(pm, 4 * t + k, i);
  }
  // T_new: appended tets around the edge (i, j).
  for (size_t n = 0; n + 3 < op.newTets.size(); n += 4) {
    uint32_t t = m.tetCount();
    m.tets.insert(m.tets.end(), op.newTets.begin() + n, op.newTets.begin() + n + 4);
    pm.cornerNext.insert(pm.cornerNext.end(), 4, kNoCorner);
    for (uint32_t k = 0; k < 4; ++k) linkCorner(pm, 4 * t + k, m.tets[4 * t + k]);
    changed.push_back(t);
  }
}

void undoSplit(ProgressiveMesh& pm, std::vector<uint32_t>& changed) {
  assert(!pm.splitJ.empty());
  TetMesh& m = pm.mesh;
  const uint32_t j = pm.splitJ.back(), tetsBefore = pm.splitTetsBefore.back();
  const uint32_t i = m.vertexCount() - 1;
  pm.splitJ.pop_back();
  pm.splitTetsBefore.pop_back();

  // Unlink the new tets' corners from their vertices (one walk per vertex), drop the tets.
  const uint32_t firstDead = 4 * tetsBefore;
  const uint32_t stamp = nextStamp(pm);
  for (uint32_t c = firstDead; c < m.tets.size(); ++c) {
    uint32_t v = m.tets[c];
    if (v == i || pm.seen[v] == stamp) continue;
    pm.seen[v] = stamp;
    unlinkCorners(pm, v, [&](uint32_t x) { return x >= firstDead; });
  }
  m.tets.resize(firstDead);
  pm.cornerNext.resize(firstDead);
  // The remaining corners of i are the moved tets: give them back to j.
  for (uint32_t c = pm.vertexHead[i]; c != kNoCorner;) {
    uint32_t next = pm.cornerNext[c];
    if (c < firstDead) {
      m.tets[c] = j;
      linkCorner(pm, c, j);
      changed.push_back(c >> 2);
    }
    c = next;
  }
  pm.vertexHead.pop_back();
  m.positions.resize(m.positions.size() - 3);
  for (ScalarField& f : m.fields) f.values.pop_back();
}

}  // namespace tetstream
