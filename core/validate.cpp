#include "validate.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <thread>

#include "adjacency.h"
#include "tet_tables.h"

namespace tetstream {
namespace {

double longestEdgeSquared(const float* p, const uint32_t* v) {
  double best = 0;
  for (const auto& e : kTetEdges) {
    const float* a = p + 3 * size_t(v[e[0]]);
    const float* b = p + 3 * size_t(v[e[1]]);
    double d = 0;
    for (int k = 0; k < 3; ++k) d += (double(a[k]) - b[k]) * (double(a[k]) - b[k]);
    best = std::max(best, d);
  }
  return best;
}

[[maybe_unused]] constexpr uint32_t kSecondThreadTets = 10000;

void note(std::vector<std::string>& out, uint64_t count, const std::string& what) {
  if (count) out.push_back(std::to_string(count) + " " + what);
}

}  // namespace

ValidationReport validateMesh(const TetMesh& m, FaceAdjacency* adjacency) {
  ValidationReport r;
  const uint32_t V = m.vertexCount(), T = m.tetCount();
  r.noTets = T == 0;
  for (uint32_t i = 0; i < V; ++i)
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(m.positions[3 * size_t(i) + k])) {
        ++r.nonFinitePositions;
        break;
      }
  for (const ScalarField& f : m.fields)
    for (float x : f.values) r.nonFiniteFieldValues += !std::isfinite(x);

  // The indices first: everything after reads the vertices of every tet.
  std::vector<uint8_t> used(V, 0);
  for (uint32_t t = 0; t < T; ++t) {
    const uint32_t* v = &m.tets[4 * size_t(t)];
    if (!(v[0] < V && v[1] < V && v[2] < V && v[3] < V)) {
      ++r.outOfRangeIndices;
      continue;
    }
    for (int k = 0; k < 4; ++k) used[v[k]] = 1;
  }
  for (uint8_t u : used) r.unusedVertices += !u;
  const bool indicesOk = r.outOfRangeIndices == 0, geometryOk = r.nonFinitePositions == 0;

  // Each tet's orientation (or flatness) and repeated vertices.
  auto shapes = [&m, &r, T, V, geometryOk] {
    for (uint32_t t = 0; t < T; ++t) {
      const uint32_t* v = &m.tets[4 * size_t(t)];
      if (!(v[0] < V && v[1] < V && v[2] < V && v[3] < V)) continue;
      if (v[0] == v[1] || v[0] == v[2] || v[0] == v[3] || v[1] == v[2] || v[1] == v[3] || v[2] == v[3]) {
        ++r.repeatedVertexTets;
        continue;
      }
      if (!geometryOk) continue;
      double vol6 = 6.0 * tetVolume(m, t);
      double l2 = longestEdgeSquared(m.positions.data(), v);
      if (std::abs(vol6) <= 1e-9 * l2 * std::sqrt(l2))
        ++r.zeroVolumeTets;
      else if (vol6 > 0)
        ++r.positiveTets;
      else
        ++r.negativeTets;
    }
    r.invertedTets = std::min(r.positiveTets, r.negativeTets);
  };
  // Duplicates: the sorted vertex quadruples, bucketed by their smallest vertex (a counting
  // sort; duplicates share a bucket), sorted within each small bucket.
  auto countDuplicates = [&m, &r, T, V] {
    std::vector<std::array<uint32_t, 4>> quads(T);
    std::vector<uint32_t> start(size_t(V) + 1, 0);
    for (uint32_t t = 0; t < T; ++t) {
      const uint32_t* v = &m.tets[4 * size_t(t)];
      ++start[std::min({v[0], v[1], v[2], v[3]}) + 1];
    }
    for (uint32_t v = 0; v < V; ++v) start[v + 1] += start[v];
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (uint32_t t = 0; t < T; ++t) {
      std::array<uint32_t, 4> q;
      std::copy_n(&m.tets[4 * size_t(t)], 4, q.begin());
      std::sort(q.begin(), q.end());
      quads[fill[q[0]]++] = q;
    }
    for (uint32_t v = 0; v < V; ++v) {
      auto b = quads.begin() + start[v], e = quads.begin() + start[v + 1];
      std::sort(b, e);
      for (auto it = b; it != e && it + 1 != e; ++it) r.duplicateTets += *it == *(it + 1);
    }
  };
  auto faces = [&m, &r, V, adjacency] {
    FaceAdjacency adj;
    buildFaceAdjacency(m.tets, V, adj);
    r.nonManifoldFaces = adj.nonManifoldFaces;
    std::vector<uint32_t> boundary;
    extractBoundary(m.tets, adj, boundary);
    r.boundaryFaces = boundary.size() / 3;
    r.nonManifoldBoundaryEdges = countNonManifoldBoundaryEdges(boundary);
    if (adjacency) *adjacency = std::move(adj);
  };
  // The faces take about as long as the rest together (each fills its own counts): natively, a
  // mesh of some size has the shapes and duplicates done on a second thread meanwhile, which
  // nearly halves the time. The web build has no threads.
  if (!indicesOk || T == 0) {
    shapes();
  } else {
    auto besideFaces = [&] {
      shapes();
      countDuplicates();
    };
#if !defined(__EMSCRIPTEN__)
    std::jthread side;  // (joins on the way out, an exception included)
    if (T >= kSecondThreadTets)
      side = std::jthread(besideFaces);
    else
      besideFaces();
#else
    besideFaces();
#endif
    faces();
  }

  if (r.noTets) r.findings.push_back("the mesh has no tetrahedra");
  note(r.findings, r.outOfRangeIndices, "tetrahedra reference a vertex that does not exist");
  note(r.findings, r.repeatedVertexTets, "tetrahedra use the same vertex twice");
  note(r.findings, r.nonFinitePositions, "vertices have NaN or infinite coordinates");
  note(r.findings, r.invertedTets,
       std::string("tetrahedra are inverted (oriented against the other ") +
           std::to_string(std::max(r.positiveTets, r.negativeTets)) + ")");
  note(r.findings, r.zeroVolumeTets, "tetrahedra have zero volume (flat)");
  note(r.findings, r.duplicateTets, "tetrahedra duplicate another one");
  note(r.findings, r.unusedVertices, "vertices are not used by any tetrahedron");
  note(r.findings, r.nonFiniteFieldValues, "field values are NaN or infinite");
  note(r.findings, r.nonManifoldFaces, "faces are shared by more than two tetrahedra (non-manifold)");
  note(r.findings, r.nonManifoldBoundaryEdges,
       "boundary edges are not shared by exactly two boundary faces (non-manifold boundary)");
  return r;
}

}  // namespace tetstream
