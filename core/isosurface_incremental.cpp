#include "isosurface_incremental.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>

#include "tet_tables.h"

namespace tetstream {
namespace {

constexpr uint32_t kTouched = 1;  // in touched_ (normal to renormalise)
constexpr uint32_t kChanged = 2;  // in changedVertices_

// The triangle's unnormalised normal exactly as isosurface.cpp computes it (float, corner a
// first), so that the sums add the same terms as a from-scratch extraction.
void crossFloat(const float* p, uint32_t a, uint32_t b, uint32_t c, float fn[3]) {
  float u[3], v[3];
  for (int k = 0; k < 3; ++k) {
    u[k] = p[3 * size_t(b) + k] - p[3 * size_t(a) + k];
    v[k] = p[3 * size_t(c) + k] - p[3 * size_t(a) + k];
  }
  fn[0] = u[1] * v[2] - u[2] * v[1];
  fn[1] = u[2] * v[0] - u[0] * v[2];
  fn[2] = u[0] * v[1] - u[1] * v[0];
}

// Area as surfaceArea() computes it (double).
double triangleArea(const float* p, uint32_t ia, uint32_t ib, uint32_t ic) {
  const float* a = p + 3 * size_t(ia);
  const float* b = p + 3 * size_t(ib);
  const float* c = p + 3 * size_t(ic);
  double u[3], v[3];
  for (int k = 0; k < 3; ++k) {
    u[k] = double(b[k]) - a[k];
    v[k] = double(c[k]) - a[k];
  }
  double cx = u[1] * v[2] - u[2] * v[1], cy = u[2] * v[0] - u[0] * v[2], cz = u[0] * v[1] - u[1] * v[0];
  return 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
}

}  // namespace

// ------------------------------------------------------------------ IncrementalIsosurface

struct IncrementalIsosurface::Context {
  const float* pos;
  const float* field;
  const uint32_t* tets;
  float iso;
  const float* colour;  // the colour field, or nullptr (colours 0)
};

void IncrementalIsosurface::reset() {
  clearSurface();
  tetRecord_.clear();
  tree_.clear();
  treeBuilt_ = false;
  coverage_ = 0;
  fullUpload_ = false;
}

void IncrementalIsosurface::setTreeDeferred(bool deferred) { deferred_ = deferred; }

void IncrementalIsosurface::reserveTets(uint32_t tets) {
  tetRecord_.reserve(tets);
  tree_.reserve(tets);
}

bool IncrementalIsosurface::extendTree(const TetMesh& mesh, std::span<const float> field, uint32_t maxTets) {
  assert(field.size() == mesh.vertexCount());
  const uint32_t n = mesh.tetCount();
  if (coverage_ >= n) return true;
  if (coverage_ == 0 && maxTets >= n) {
    tree_.build(mesh, field);  // in one go: faster than inserting one by one
    coverage_ = n;
  } else {
    const uint32_t end = n - coverage_ > maxTets ? coverage_ + maxTets : n;
    for (uint32_t t = coverage_; t < end; ++t) tree_.insert(t, tetInterval(mesh, field, t));
    coverage_ = end;
  }
  return coverage_ == n;
}

void IncrementalIsosurface::clearSurface() {
  // O(records), not O(tets): only tets with a record have to be reset.
  for (const Record& r : records_)
    if (r.tet != kNone) tetRecord_[r.tet] = kNone;
  records_.clear();
  freeRecords_.clear();
  indices_.clear();
  triangleOwner_.clear();
  triangleChanged_.clear();
  triangleCount_ = 0;
  positions_.clear();
  normals_.clear();
  colours_.clear();
  vertices_.clear();
  freeVertices_.clear();
  map_.clear();
  area_ = 0;
  touched_.clear();
  changedVertices_.clear();
  changedTriangles_.clear();
}

void IncrementalIsosurface::rebuild(const TetMesh& mesh, std::span<const float> field, float isovalue,
                                    std::span<const float> colour) {
  assert(field.size() == mesh.vertexCount());
  assert(colour.empty() || colour.size() == mesh.vertexCount());
  clearSurface();
  isovalue_ = isovalue;
  const uint32_t n = mesh.tetCount();
  // Not deferred, a tree of another tet count means the mesh changed behind updateTets' back;
  // building it again is the safe answer (the field cannot be checked that cheaply: see reset()).
  if (!treeBuilt_ || (!deferred_ && (coverage_ != n || tree_.idCount() != n))) {
    if (deferred_) {
      tree_.clear();
      coverage_ = 0;
    } else {
      tree_.build(mesh, field);
      coverage_ = n;
    }
    treeBuilt_ = true;
  }
  tetRecord_.resize(n, kNone);

  // The tree's tets, then every tet past its coverage tested on its own.
  cutTets_.clear();
  if (coverage_ > 0) tree_.query(isovalue, cutTets_);
  for (uint32_t t = coverage_; t < n; ++t)
    if (stabs(tetInterval(mesh, field, t), isovalue)) cutTets_.push_back(t);
  const Context c{mesh.positions.data(), field.data(), mesh.tets.data(), isovalue,
                  colour.empty() ? nullptr : colour.data()};
  bulk_ = true;
  // The query returns tets in interval order, which is random in space; visiting them in id
  // order instead keeps neighbouring tets and their shared surface vertices close in memory.
  // A bitmap over the tets orders them in O(k + tets/64), cheaper than sorting k ids.
  cutBits_.resize((size_t(mesh.tetCount()) + 63) / 64, 0);
  for (uint32_t t : cutTets_) cutBits_[t >> 6] |= uint64_t(1) << (t & 63);
  for (size_t w = 0; w < cutBits_.size(); ++w) {
    for (uint64_t bits = cutBits_[w]; bits; bits &= bits - 1)
      addTet(c, uint32_t(64 * w + size_t(std::countr_zero(bits))));
    cutBits_[w] = 0;
  }
  bulk_ = false;
  for (uint32_t t = 0; t < triangleCount_; ++t) accumulate(&indices_[3 * size_t(t)]);
  for (uint32_t v = 0; v < vertexSlotCount(); ++v) finishNormal(v);
  fullUpload_ = true;
}

void IncrementalIsosurface::updateTets(const TetMesh& mesh, std::span<const float> field,
                                       std::span<const uint32_t> changedTets, std::span<const float> colour) {
  assert(treeBuilt_ && "rebuild() first");
  assert(field.size() == mesh.vertexCount());
  assert(colour.empty() || colour.size() == mesh.vertexCount());
  const Context c{mesh.positions.data(), field.data(), mesh.tets.data(), isovalue_,
                  colour.empty() ? nullptr : colour.data()};
  const uint32_t n = mesh.tetCount();
  const uint32_t old = uint32_t(tetRecord_.size());

  // Every old triangle of a changed or removed tet goes before any new one is made, so a surface
  // vertex whose edge changed is released completely and made again (see the contract).
  if (n < old) {
    for (uint32_t t = n; t < old; ++t) removeTet(t);
    tetRecord_.resize(n);
    tree_.truncate(n);
    coverage_ = std::min(coverage_, n);
  }
  for (uint32_t t : changedTets)
    if (t < std::min(n, old)) removeTet(t);
  if (n > old) tetRecord_.resize(n, kNone);

  // T_new into the tree, T_moved updated in it (paper §4.3), and their triangles made again.
  // Deferred, only tets the tree covers (new tets come after it: coverage_ <= old).
  const uint32_t tracked = deferred_ ? coverage_ : n;
  auto refresh = [&](uint32_t t) {
    Interval iv = tetInterval(mesh, field, t);
    if (t >= tracked)
      ;
    else if (tree_.contains(t))
      tree_.update(t, iv);
    else
      tree_.insert(t, iv);
    if (tetRecord_[t] == kNone && stabs(iv, isovalue_)) addTet(c, t);
  };
  for (uint32_t t : changedTets)
    if (t < n) refresh(t);
  for (uint32_t t = old; t < n; ++t) refresh(t);

  for (uint32_t v : touched_) {
    vertices_[v].flags &= ~kTouched;
    finishNormal(v);
  }
  touched_.clear();
  if (!deferred_) coverage_ = n;
}

void IncrementalIsosurface::addTet(const Context& c, uint32_t t) {
  const uint32_t* v = c.tets + 4 * size_t(t);
  const float s[4] = {c.field[v[0]], c.field[v[1]], c.field[v[2]], c.field[v[3]]};
  const unsigned mask = (s[0] > c.iso) | (s[1] > c.iso) << 1 | (s[2] > c.iso) << 2 | (s[3] > c.iso) << 3;
  const MarchingCase& mc = kMarchingTets[mask];
  if (mc.triangleCount == 0) return;
  const float* p = c.pos;
  const bool flip =
      tetVolume(p + 3 * size_t(v[0]), p + 3 * size_t(v[1]), p + 3 * size_t(v[2]), p + 3 * size_t(v[3])) < 0;

  uint32_t r;
  if (!freeRecords_.empty()) {
    r = freeRecords_.back();
    freeRecords_.pop_back();
  } else {
    r = uint32_t(records_.size());
    records_.push_back({});
  }
  tetRecord_[t] = r;
  // One lookup per cut edge (3 or 4), not per triangle corner (3 or 6): same vertices as
  // extractIsosurface, which asks again for the two edges its triangles share.
  uint32_t edgeVertex[6];
  uint32_t rv[4] = {kNone, kNone, kNone, kNone};
  int nv = 0;
  for (int i = 0; i < 3 * mc.triangleCount; ++i) {
    const int edge = mc.edges[i];
    if (i >= 3 && (edge == mc.edges[0] || edge == mc.edges[1] || edge == mc.edges[2])) continue;
    const uint8_t* e = kTetEdges[edge];
    const uint32_t id = acquireVertex(c, v[e[0]], v[e[1]]);
    edgeVertex[edge] = id;
    // Each vertex the tet asks for is counted once, whether or not a triangle keeps it:
    // extractIsosurface creates the vertices of dropped (degenerate) triangles too.
    if (std::find(rv, rv + nv, id) == rv + nv) {
      rv[nv++] = id;
      ++vertices_[id].refs;
    }
  }
  Record& rec = records_[r];
  std::copy(rv, rv + 4, rec.vertices);
  rec.triangles[0] = rec.triangles[1] = kNone;
  rec.tet = t;
  for (int k = 0; k < mc.triangleCount; ++k) {
    uint32_t tri[3];
    for (int j = 0; j < 3; ++j) tri[j] = edgeVertex[mc.edges[3 * k + j]];
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) continue;
    if (flip) std::swap(tri[1], tri[2]);
    addTriangle(r, k, tri);
  }
}

void IncrementalIsosurface::removeTet(uint32_t t) {
  const uint32_t r = tetRecord_[t];
  if (r == kNone) return;
  Record& rec = records_[r];
  for (int k = 0; k < 2; ++k) {
    // Read after the previous removal: it may have moved this record's other triangle.
    const uint32_t slot = rec.triangles[k];
    if (slot == kNone) continue;
    rec.triangles[k] = kNone;
    removeTriangle(slot);
  }
  for (int i = 0; i < 4 && rec.vertices[i] != kNone; ++i) releaseVertex(rec.vertices[i]);
  rec.tet = kNone;
  freeRecords_.push_back(r);
  tetRecord_[t] = kNone;
}

// The surface vertex on mesh edge (a, b), one end above λ: the same key and position bits as
// extractIsosurface's (both use cutEdge and cutValue, isosurface.h).
uint32_t IncrementalIsosurface::acquireVertex(const Context& c, uint32_t a, uint32_t b) {
  const CutEdge e = cutEdge(c.field, c.iso, a, b);
  const uint32_t lo = e.lo, hi = e.hi;
  const uint64_t key = e.key;
  uint32_t v = freeVertices_.empty() ? vertexSlotCount() : freeVertices_.back();
  bool inserted;
  const uint32_t found = map_.findOrInsert(key, v, &inserted);
  if (!inserted) return found;

  const float w1 = e.weightHi(c.iso);
  const float w0 = 1.0f - w1;
  const float* p0 = c.pos + 3 * size_t(lo);
  const float* p1 = c.pos + 3 * size_t(hi);
  if (freeVertices_.empty()) {
    positions_.resize(positions_.size() + 3);
    normals_.resize(normals_.size() + 3);
    colours_.push_back(0.f);
    vertices_.emplace_back();
  } else {
    freeVertices_.pop_back();
  }
  float* q = &positions_[3 * size_t(v)];
  for (int k = 0; k < 3; ++k) {
    q[k] = cutValue(e, w0, w1, p0[k], p1[k]);
    normals_[3 * size_t(v) + k] = 0;
  }
  // The weight of the key's second vertex (the larger id), so recolour() can interpolate again.
  const float tHigh = e.onVertex ? 0.f : (hi == uint32_t(key) ? w1 : w0);
  colours_[v] = !c.colour ? 0.f : cutValue(e, w0, w1, c.colour[lo], c.colour[hi]);
  vertices_[v] = Vertex{{0, 0, 0}, key, 0, 0, 0, tHigh};
  touchVertex(v);
  return v;
}

void IncrementalIsosurface::releaseVertex(uint32_t v) {
  Vertex& x = vertices_[v];
  assert(x.refs > 0);
  if (--x.refs != 0) return;
  assert(x.triangles == 0);
  map_.erase(x.key);
  freeVertices_.push_back(v);
}

void IncrementalIsosurface::addTriangle(uint32_t record, int which, const uint32_t tri[3]) {
  const uint32_t slot = triangleCount_++;
  if (slot == triangleOwner_.size()) {
    indices_.insert(indices_.end(), tri, tri + 3);
    triangleOwner_.push_back(0);
    triangleChanged_.push_back(0);
  } else {
    std::copy(tri, tri + 3, &indices_[3 * size_t(slot)]);
  }
  triangleOwner_[slot] = record << 1 | uint32_t(which);
  records_[record].triangles[which] = slot;
  for (int j = 0; j < 3; ++j) ++vertices_[tri[j]].triangles;
  if (bulk_) return;  // rebuild() sums normals and area in one pass at the end
  accumulate(tri);
  for (int j = 0; j < 3; ++j) touchVertex(tri[j]);
  touchTriangle(slot);
}

// Adds the triangle's cross product to its corners' normal sums and its area to the total.
void IncrementalIsosurface::accumulate(const uint32_t tri[3]) {
  float fn[3];
  crossFloat(positions_.data(), tri[0], tri[1], tri[2], fn);
  for (int j = 0; j < 3; ++j) {
    double* sum = vertices_[tri[j]].normalSum;
    for (int k = 0; k < 3; ++k) sum[k] += fn[k];
  }
  area_ += triangleArea(positions_.data(), tri[0], tri[1], tri[2]);
}

void IncrementalIsosurface::removeTriangle(uint32_t slot) {
  assert(slot < triangleCount_);
  const uint32_t* tri = &indices_[3 * size_t(slot)];
  // Vertex positions never change while the vertex lives, so these are the very terms added.
  float fn[3];
  crossFloat(positions_.data(), tri[0], tri[1], tri[2], fn);
  for (int j = 0; j < 3; ++j) {
    Vertex& x = vertices_[tri[j]];
    // Exact zero when the last triangle goes, so rounding left in the sum cannot turn into a
    // made-up unit normal for a vertex extractIsosurface gives a zero normal.
    if (--x.triangles == 0)
      x.normalSum[0] = x.normalSum[1] = x.normalSum[2] = 0;
    else
      for (int k = 0; k < 3; ++k) x.normalSum[k] -= fn[k];
    touchVertex(tri[j]);
  }
  area_ -= triangleArea(positions_.data(), tri[0], tri[1], tri[2]);
  if (triangleCount_ == 1) area_ = 0;  // drop accumulated rounding when the surface empties

  const uint32_t last = triangleCount_ - 1;
  if (slot != last) {
    std::copy_n(&indices_[3 * size_t(last)], 3, &indices_[3 * size_t(slot)]);
    const uint32_t owner = triangleOwner_[last];
    triangleOwner_[slot] = owner;
    records_[owner >> 1].triangles[owner & 1] = slot;
    touchTriangle(slot);
  }
  --triangleCount_;
}

void IncrementalIsosurface::touchVertex(uint32_t v) {
  if (bulk_) return;
  uint32_t& f = vertices_[v].flags;
  if (!(f & kTouched)) {
    f |= kTouched;
    touched_.push_back(v);
  }
  if (fullUpload_ || (f & kChanged)) return;
  f |= kChanged;
  if (changedVertices_.empty()) vBegin_ = v, vEnd_ = v + 1;
  vBegin_ = std::min(vBegin_, v);
  vEnd_ = std::max(vEnd_, v + 1);
  changedVertices_.push_back(v);
}

void IncrementalIsosurface::touchTriangle(uint32_t slot) {
  if (bulk_ || fullUpload_ || triangleChanged_[slot]) return;
  triangleChanged_[slot] = 1;
  if (changedTriangles_.empty()) tBegin_ = slot, tEnd_ = slot + 1;
  tBegin_ = std::min(tBegin_, slot);
  tEnd_ = std::max(tEnd_, slot + 1);
  changedTriangles_.push_back(slot);
}

void IncrementalIsosurface::finishNormal(uint32_t v) {
  const Vertex& x = vertices_[v];
  if (x.refs == 0) return;  // free slot
  const double* s = x.normalSum;
  float* n = &normals_[3 * size_t(v)];
  const double len = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
  for (int k = 0; k < 3; ++k) n[k] = len > 0 ? float(s[k] / len) : 0.0f;
}

void IncrementalIsosurface::clearChanges() {
  for (uint32_t v : changedVertices_)
    if (v < vertices_.size()) vertices_[v].flags &= ~kChanged;
  for (uint32_t t : changedTriangles_)
    if (t < triangleChanged_.size()) triangleChanged_[t] = 0;
  changedVertices_.clear();
  changedTriangles_.clear();
  fullUpload_ = false;
}

void IncrementalIsosurface::compact() {
  const uint32_t slots = vertexSlotCount();
  std::vector<uint32_t> remap(slots, kNone);
  uint32_t w = 0;
  for (uint32_t v = 0; v < slots; ++v) {
    if (vertices_[v].refs == 0) continue;
    remap[v] = w;
    if (w != v) {
      std::copy_n(&positions_[3 * size_t(v)], 3, &positions_[3 * size_t(w)]);
      std::copy_n(&normals_[3 * size_t(v)], 3, &normals_[3 * size_t(w)]);
      colours_[w] = colours_[v];
      vertices_[w] = vertices_[v];
    }
    vertices_[w].flags = 0;
    ++w;
  }
  positions_.resize(3 * size_t(w));
  normals_.resize(3 * size_t(w));
  colours_.resize(w);
  vertices_.resize(w);
  freeVertices_.clear();
  map_.remapValues(remap);
  for (Record& r : records_)
    for (uint32_t& v : r.vertices)
      if (v != kNone) v = remap[v];
  indices_.resize(3 * size_t(triangleCount_));
  triangleOwner_.resize(triangleCount_);
  triangleChanged_.assign(triangleCount_, 0);
  for (uint32_t& v : indices_) v = remap[v];
  changedVertices_.clear();
  changedTriangles_.clear();
  fullUpload_ = true;
}

void IncrementalIsosurface::recolour(std::span<const float> colour) {
  for (uint32_t v = 0; v < vertexSlotCount(); ++v) {
    const Vertex& x = vertices_[v];
    if (x.refs == 0) continue;
    const uint32_t a = uint32_t(x.key >> 32), b = uint32_t(x.key);
    if (colour.empty() || std::max(a, b) >= colour.size())
      colours_[v] = 0.f;
    else
      colours_[v] = a == b ? colour[a] : (1.f - x.tHigh) * colour[a] + x.tHigh * colour[b];
  }
  fullUpload_ = true;
}

void IncrementalIsosurface::toIsoSurface(IsoSurface& out) const {
  out.clear();
  std::vector<uint32_t> remap(vertexSlotCount(), kNone);
  out.positions.reserve(3 * size_t(vertexCount()));
  out.normals.reserve(3 * size_t(vertexCount()));
  for (uint32_t v = 0; v < vertexSlotCount(); ++v) {
    if (vertices_[v].refs == 0) continue;
    remap[v] = out.vertexCount();
    out.positions.insert(out.positions.end(), &positions_[3 * size_t(v)], &positions_[3 * size_t(v)] + 3);
    out.normals.insert(out.normals.end(), &normals_[3 * size_t(v)], &normals_[3 * size_t(v)] + 3);
  }
  out.indices.resize(3 * size_t(triangleCount_));
  for (size_t i = 0; i < out.indices.size(); ++i) out.indices[i] = remap[indices_[i]];
}

size_t IncrementalIsosurface::memoryBytes() const {
  auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  return tree_.memoryBytes() + map_.memoryBytes() + bytes(tetRecord_) + bytes(records_) + bytes(freeRecords_) +
         bytes(indices_) + bytes(triangleOwner_) + bytes(triangleChanged_) + bytes(positions_) + bytes(normals_) +
         bytes(colours_) + bytes(vertices_) + bytes(freeVertices_) + bytes(touched_) + bytes(changedVertices_) +
         bytes(changedTriangles_) + bytes(cutTets_) + bytes(cutBits_);
}

bool IncrementalIsosurface::validate() const {
  const uint32_t slots = vertexSlotCount();
  std::vector<uint32_t> refs(slots, 0), tris(slots, 0);
  // Records and tets point at each other.
  size_t liveRecords = 0;
  for (uint32_t r = 0; r < records_.size(); ++r) {
    const Record& rec = records_[r];
    if (rec.tet == kNone) continue;
    ++liveRecords;
    if (rec.tet >= tetRecord_.size() || tetRecord_[rec.tet] != r) return false;
    for (int i = 0; i < 4 && rec.vertices[i] != kNone; ++i) {
      if (rec.vertices[i] >= slots) return false;
      ++refs[rec.vertices[i]];
    }
    for (int k = 0; k < 2; ++k) {
      uint32_t s = rec.triangles[k];
      if (s != kNone && (s >= triangleCount_ || triangleOwner_[s] != (r << 1 | uint32_t(k)))) return false;
    }
  }
  size_t withRecord = 0;
  for (uint32_t t = 0; t < tetRecord_.size(); ++t) {
    uint32_t r = tetRecord_[t];
    if (r == kNone) continue;
    ++withRecord;
    if (r >= records_.size() || records_[r].tet != t) return false;
  }
  if (withRecord != liveRecords || liveRecords + freeRecords_.size() != records_.size()) return false;
  // Triangles: owners, vertices alive, distinct.
  double area = 0;
  for (uint32_t s = 0; s < triangleCount_; ++s) {
    const uint32_t* tri = &indices_[3 * size_t(s)];
    const uint32_t owner = triangleOwner_[s];
    if ((owner >> 1) >= records_.size() || records_[owner >> 1].tet == kNone) return false;
    if (records_[owner >> 1].triangles[owner & 1] != s) return false;
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) return false;
    for (int j = 0; j < 3; ++j) {
      if (tri[j] >= slots || vertices_[tri[j]].refs == 0) return false;
      ++tris[tri[j]];
    }
    area += triangleArea(positions_.data(), tri[0], tri[1], tri[2]);
  }
  if (std::abs(area - area_) > 1e-9 * std::max(1.0, area)) return false;
  // Vertices: counts, map, free list.
  size_t live = 0;
  for (uint32_t v = 0; v < slots; ++v) {
    const Vertex& x = vertices_[v];
    if (refs[v] != x.refs || tris[v] != x.triangles) return false;
    if (x.refs == 0) continue;
    ++live;
    if (map_.find(x.key) != v) return false;
  }
  if (live != map_.size() || live + freeVertices_.size() != slots) return false;
  // The tree holds exactly the covered tets; not deferred, that is every tet.
  return tree_.validate() && tree_.idCount() == coverage_ &&
         (deferred_ ? coverage_ <= tetRecord_.size() : coverage_ == tetRecord_.size());
}

}  // namespace tetstream
