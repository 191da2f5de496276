#include "isosurface.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>

#include "tet_tables.h"

namespace tetstream {
namespace {

struct Extraction {
  const float* pos;
  const float* field;
  float iso;
  IsoExtractor* scratch;
  IsoSurface* out;

  // Surface vertex on the edge (a, b), one endpoint above λ and one at or below.
  uint32_t edgeVertex(uint32_t a, uint32_t b) {
    const CutEdge c = cutEdge(field, iso, a, b);
    bool inserted;
    uint32_t id = scratch->vertexOfEdge.findOrInsert(c.key, out->vertexCount(), &inserted);
    if (!inserted) return id;
    const float w1 = c.weightHi(iso);
    const float w0 = 1.0f - w1;
    const float* p0 = pos + 3 * size_t(c.lo);
    const float* p1 = pos + 3 * size_t(c.hi);
    for (int k = 0; k < 3; ++k) out->positions.push_back(cutValue(c, w0, w1, p0[k], p1[k]));
    for (int k = 0; k < 3; ++k) out->normals.push_back(0.0f);
    return id;
  }

  void tet(const uint32_t* v) {
    float s[4] = {field[v[0]], field[v[1]], field[v[2]], field[v[3]]};
    unsigned mask = (s[0] > iso) | (s[1] > iso) << 1 | (s[2] > iso) << 2 | (s[3] > iso) << 3;
    const MarchingCase& mc = kMarchingTets[mask];
    if (mc.triangleCount == 0) return;
    bool flip =
        tetVolume(pos + 3 * size_t(v[0]), pos + 3 * size_t(v[1]), pos + 3 * size_t(v[2]), pos + 3 * size_t(v[3])) < 0;
    for (int t = 0; t < mc.triangleCount; ++t) {
      uint32_t tri[3];
      for (int k = 0; k < 3; ++k) {
        const uint8_t* e = kTetEdges[mc.edges[3 * t + k]];
        tri[k] = edgeVertex(v[e[0]], v[e[1]]);
      }
      if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) continue;
      if (flip) std::swap(tri[1], tri[2]);
      out->indices.insert(out->indices.end(), tri, tri + 3);
    }
  }
};

void computeVertexNormals(IsoSurface& s) {
  float* n = s.normals.data();
  const float* p = s.positions.data();
  for (size_t i = 0; i < s.indices.size(); i += 3) {
    const uint32_t a = s.indices[i], b = s.indices[i + 1], c = s.indices[i + 2];
    float u[3], v[3];
    for (int k = 0; k < 3; ++k) {
      u[k] = p[3 * b + k] - p[3 * a + k];
      v[k] = p[3 * c + k] - p[3 * a + k];
    }
    // Unnormalised cross product = area-weighted normal.
    float fn[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    for (uint32_t id : {a, b, c})
      for (int k = 0; k < 3; ++k) n[3 * id + k] += fn[k];
  }
  for (size_t i = 0; i < s.normals.size(); i += 3) {
    float len = std::sqrt(n[i] * n[i] + n[i + 1] * n[i + 1] + n[i + 2] * n[i + 2]);
    if (len > 0)
      for (int k = 0; k < 3; ++k) n[i + k] /= len;
  }
}

}  // namespace

void extractIsosurface(const TetMesh& mesh, std::span<const float> field, float isovalue, IsoExtractor& scratch,
                       IsoSurface& out, std::span<const uint32_t> tetSubset) {
  assert(field.size() == mesh.vertexCount());
  out.clear();
  scratch.vertexOfEdge.clear();
  Extraction x{mesh.positions.data(), field.data(), isovalue, &scratch, &out};
  const uint32_t* tets = mesh.tets.data();
  if (tetSubset.empty()) {
    for (size_t t = 0, n = mesh.tetCount(); t < n; ++t) x.tet(tets + 4 * t);
  } else {
    for (uint32_t t : tetSubset) x.tet(tets + 4 * size_t(t));
  }
  computeVertexNormals(out);
}

double surfaceArea(const IsoSurface& s) {
  double area = 0;
  const float* p = s.positions.data();
  for (size_t i = 0; i < s.indices.size(); i += 3) {
    const float* a = p + 3 * size_t(s.indices[i]);
    const float* b = p + 3 * size_t(s.indices[i + 1]);
    const float* c = p + 3 * size_t(s.indices[i + 2]);
    double u[3], v[3];
    for (int k = 0; k < 3; ++k) {
      u[k] = double(b[k]) - a[k];
      v[k] = double(c[k]) - a[k];
    }
    double cx = u[1] * v[2] - u[2] * v[1], cy = u[2] * v[0] - u[0] * v[2], cz = u[0] * v[1] - u[1] * v[0];
    area += 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
  }
  return area;
}

}  // namespace tetstream

namespace tetstream {
namespace {

using Corners = std::array<float, 9>;

std::vector<Corners> canonicalTriangles(const IsoSurface& s) {
  std::vector<Corners> out(s.triangleCount());
  for (uint32_t t = 0; t < s.triangleCount(); ++t) {
    std::array<std::array<float, 3>, 3> c;
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) c[size_t(k)][size_t(a)] = s.positions[3 * size_t(s.indices[3 * t + k]) + a];
    const size_t first = size_t(std::min_element(c.begin(), c.end()) - c.begin());
    for (size_t k = 0; k < 3; ++k)
      for (size_t a = 0; a < 3; ++a) out[t][3 * k + a] = c[(first + k) % 3][a];
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

bool sameTriangles(const IsoSurface& a, const IsoSurface& b) {
  return a.triangleCount() == b.triangleCount() && canonicalTriangles(a) == canonicalTriangles(b);
}

}  // namespace tetstream
