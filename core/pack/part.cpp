// Parts of a mesh packed on several processes (part.h): the part a simplification leaves, two
// parts merged, and their bytes between ranks.
#include "pack/part.h"

#include <cassert>
#include <cstring>
#include <type_traits>

namespace tetstream {

namespace {

bool hasCarried(const CarriedVertexState& c) { return !c.fit.empty(); }

// Vertex `from` of `src` appended to `dst` (whose fields are laid out as src's): position,
// every field's sample, input id, and its carried state when src has one.
void appendVertex(PartMesh& dst, const PartMesh& src, uint32_t from) {
  const float* x = &src.mesh.positions[3 * size_t(from)];
  dst.mesh.positions.insert(dst.mesh.positions.end(), x, x + 3);
  for (size_t f = 0; f < src.mesh.fields.size(); ++f)
    dst.mesh.fields[f].values.push_back(src.mesh.fields[f].values[from]);
  dst.vertexId.push_back(src.vertexId[from]);
  if (!hasCarried(src.carried)) return;
  CarriedVertexState& d = dst.carried;
  const CarriedVertexState& s = src.carried;
  d.fit.push_back(s.fit[from]);
  d.represented.push_back(s.represented[from]);
  d.boundary.push_back(s.boundary[from]);
  d.boundaryQuadric.push_back(s.boundaryQuadric[from]);
  d.fieldQuadric.push_back(s.fieldQuadric[from]);
  d.fitRange.push_back(s.fitRange[from]);
}

// The fields' names, without values.
void copyFieldNames(const TetMesh& from, TetMesh& to) {
  to.fields.resize(from.fields.size());
  for (size_t f = 0; f < from.fields.size(); ++f) to.fields[f].name = from.fields[f].name;
}

}  // namespace

PartMesh partAfter(const PartMesh& in, const SimplifyResult& s) {
  // (The tets are s's: in.mesh.tets may have been taken over by the simplification.)
  const uint32_t V = in.mesh.vertexCount(), T = uint32_t(s.tetAlive.size());
  assert(s.vertexAlive.size() == V && in.vertexId.size() == V && in.tetId.size() == T && in.owned.size() == V);
  PartMesh out;
  out.mesh.name = in.mesh.name;
  copyFieldNames(in.mesh, out.mesh);
  // The state at the end (SimplifyResult::carried covers the alive vertices, in order).
  uint32_t alive = 0;
  for (uint32_t v = 0; v < V; ++v) alive += s.vertexAlive[v];
  const bool carried = alive > 0 && s.carried.fit.size() == alive;
  std::vector<uint32_t> local(V, ~0u);
  for (uint32_t v = 0; v < V; ++v) {
    if (!s.vertexAlive[v]) continue;
    const uint32_t c = uint32_t(out.vertexId.size());  // (its index among the alive ones)
    local[v] = c;
    const float* x = &in.mesh.positions[3 * size_t(v)];
    out.mesh.positions.insert(out.mesh.positions.end(), x, x + 3);
    for (size_t f = 0; f < in.mesh.fields.size(); ++f) out.mesh.fields[f].values.push_back(in.mesh.fields[f].values[v]);
    out.vertexId.push_back(in.vertexId[v]);
    out.owned.push_back(in.owned[v]);
    if (!carried) continue;
    CarriedVertexState& d = out.carried;
    d.fit.push_back(s.carried.fit[c]);
    d.represented.push_back(s.carried.represented[c]);
    d.boundary.push_back(s.carried.boundary[c]);
    d.boundaryQuadric.push_back(s.carried.boundaryQuadric[c]);
    d.fieldQuadric.push_back(s.carried.fieldQuadric[c]);
    d.fitRange.push_back(s.carried.fitRange[c]);
  }
  for (uint32_t t = 0; t < T; ++t) {
    if (!s.tetAlive[t]) continue;
    for (int k = 0; k < 4; ++k) out.mesh.tets.push_back(local[s.tets[4 * size_t(t) + k]]);
    out.tetId.push_back(in.tetId[t]);
  }
  return out;
}

PartMesh mergeParts(const PartMesh& a, const PartMesh& b) {
  assert(a.mesh.fields.size() == b.mesh.fields.size());
  assert(hasCarried(a.carried) == hasCarried(b.carried));  // (both after a level, or neither)
  PartMesh out;
  out.mesh.name = a.mesh.name;
  copyFieldNames(a.mesh, out.mesh);
  const uint32_t Va = a.mesh.vertexCount(), Vb = b.mesh.vertexCount();
  std::vector<uint32_t> fromA(Va), fromB(Vb);
  // Vertices by input id, both lists ascending: each from the part that owns it, else from a.
  for (uint32_t x = 0, y = 0; x < Va || y < Vb;) {
    const bool inA = x < Va && (y >= Vb || a.vertexId[x] <= b.vertexId[y]);
    const bool inB = y < Vb && (x >= Va || b.vertexId[y] <= a.vertexId[x]);
    const bool ownedA = inA && a.owned[x], ownedB = inB && b.owned[y];
    const uint32_t id = uint32_t(out.vertexId.size());
    if ((ownedB && !ownedA) || !inA)
      appendVertex(out, b, y);
    else
      appendVertex(out, a, x);
    out.owned.push_back(ownedA || ownedB);
    if (inA) fromA[x++] = id;
    if (inB) fromB[y++] = id;
  }
  // Tets by input id; one in both parts is the same tet (no collapse changes a tet that has
  // vertices of two parts), kept once.
  const uint32_t Ta = a.mesh.tetCount(), Tb = b.mesh.tetCount();
  for (uint32_t x = 0, y = 0; x < Ta || y < Tb;) {
    const bool inA = x < Ta && (y >= Tb || a.tetId[x] <= b.tetId[y]);
    const bool inB = y < Tb && (x >= Ta || b.tetId[y] <= a.tetId[x]);
    const uint32_t* v = inA ? &a.mesh.tets[4 * size_t(x)] : &b.mesh.tets[4 * size_t(y)];
    const std::vector<uint32_t>& map = inA ? fromA : fromB;
    for (int k = 0; k < 4; ++k) out.mesh.tets.push_back(map[v[k]]);
    out.tetId.push_back(inA ? a.tetId[x] : b.tetId[y]);
    x += inA;
    y += inB;
  }
  return out;
}

// ------------------------------------------------------------------ bytes
// The layout, in native byte order: "TSP1", then u32 vertices V, tets T, fields F, carried
// (0 or 1), the mesh's name (u32 length, bytes); positions (3V f32), tets (4T u32), per field
// its name (u32 length, bytes) and V f32; vertexId (V u64), tetId (T u64), owned (V u8); with
// carried: fit (V f32), represented (V u32), boundary (V u8), boundary quadrics (V × 11 f64),
// field quadrics (V × 16 f64).

namespace {

constexpr char kMagic[4] = {'T', 'S', 'P', '1'};

static_assert(std::is_trivially_copyable_v<Quadric> && std::is_trivially_copyable_v<FieldQuadric>);

struct Writer {
  std::vector<uint8_t>& out;
  void bytes(const void* p, size_t n) {
    if (n == 0) return;
    const size_t at = out.size();
    out.resize(at + n);
    std::memcpy(out.data() + at, p, n);
  }
  void u32(uint32_t x) { bytes(&x, 4); }
  template <typename T>
  void array(const std::vector<T>& v) {
    bytes(v.data(), v.size() * sizeof(T));
  }
  void string(const std::string& s) {
    u32(uint32_t(s.size()));
    bytes(s.data(), s.size());
  }
};

// Every read checks its size against the bytes left (in 64 bits: no count overflows).
struct Reader {
  const std::vector<uint8_t>& in;
  size_t at = 0;
  bool bytes(void* p, uint64_t n) {
    if (n > in.size() - at) return false;
    if (n) std::memcpy(p, in.data() + at, size_t(n));
    at += size_t(n);
    return true;
  }
  bool u32(uint32_t& x) { return bytes(&x, 4); }
  template <typename T>
  bool array(std::vector<T>& v, uint64_t count) {
    if (count > (in.size() - at) / sizeof(T)) return false;
    v.resize(size_t(count));
    return bytes(v.data(), count * sizeof(T));
  }
  bool string(std::string& s) {
    uint32_t n;
    if (!u32(n) || n > in.size() - at) return false;
    s.assign(reinterpret_cast<const char*>(in.data() + at), n);
    at += n;
    return true;
  }
};

template <typename T>
bool ascending(const std::vector<T>& v) {
  for (size_t k = 1; k < v.size(); ++k)
    if (!(v[k - 1] < v[k])) return false;
  return true;
}

bool zeroOrOne(const std::vector<uint8_t>& v) {
  for (uint8_t x : v)
    if (x > 1) return false;
  return true;
}

}  // namespace

void writePart(const PartMesh& p, std::vector<uint8_t>& out) {
  const uint32_t V = p.mesh.vertexCount(), T = p.mesh.tetCount();
  const bool carried = hasCarried(p.carried);
  assert(p.vertexId.size() == V && p.tetId.size() == T && p.owned.size() == V);
  assert(!carried || (p.carried.fit.size() == V && p.carried.represented.size() == V &&
                      p.carried.boundary.size() == V && p.carried.boundaryQuadric.size() == V &&
                      p.carried.fieldQuadric.size() == V && p.carried.fitRange.size() == V));
  out.clear();
  Writer w{out};
  w.bytes(kMagic, 4);
  w.u32(V);
  w.u32(T);
  w.u32(uint32_t(p.mesh.fields.size()));
  w.u32(carried);
  w.string(p.mesh.name);
  w.array(p.mesh.positions);
  w.array(p.mesh.tets);
  for (const ScalarField& f : p.mesh.fields) {
    assert(f.values.size() == V);
    w.string(f.name);
    w.array(f.values);
  }
  w.array(p.vertexId);
  w.array(p.tetId);
  w.array(p.owned);
  if (!carried) return;
  w.array(p.carried.fit);
  w.array(p.carried.represented);
  w.array(p.carried.boundary);
  w.array(p.carried.boundaryQuadric);
  w.array(p.carried.fieldQuadric);
  w.array(p.carried.fitRange);
}

bool readPart(const std::vector<uint8_t>& in, PartMesh& p) {
  p = PartMesh{};
  Reader r{in};
  char magic[4];
  uint32_t V, T, F, carried;
  if (!r.bytes(magic, 4) || std::memcmp(magic, kMagic, 4) != 0) return false;
  if (!r.u32(V) || !r.u32(T) || !r.u32(F) || !r.u32(carried) || carried > 1) return false;
  if (!r.string(p.mesh.name) || !r.array(p.mesh.positions, 3 * uint64_t(V)) || !r.array(p.mesh.tets, 4 * uint64_t(T)))
    return false;
  // Each field takes at least its name's length: F cannot exceed what is left.
  if (F > (in.size() - r.at) / 4) return false;
  p.mesh.fields.resize(F);
  for (ScalarField& f : p.mesh.fields)
    if (!r.string(f.name) || !r.array(f.values, V)) return false;
  if (!r.array(p.vertexId, V) || !r.array(p.tetId, T) || !r.array(p.owned, V)) return false;
  if (carried) {
    CarriedVertexState& c = p.carried;
    if (!r.array(c.fit, V) || !r.array(c.represented, V) || !r.array(c.boundary, V) || !r.array(c.boundaryQuadric, V) ||
        !r.array(c.fieldQuadric, V) || !r.array(c.fitRange, V) || !zeroOrOne(c.boundary))
      return false;
  }
  if (r.at != in.size()) return false;
  for (uint32_t v : p.mesh.tets)
    if (v >= V) return false;
  return ascending(p.vertexId) && ascending(p.tetId) && zeroOrOne(p.owned);
}

}  // namespace tetstream
