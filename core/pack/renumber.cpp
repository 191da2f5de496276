#include "pack/renumber.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace tetstream {
namespace {

// The low 21 bits of x spread to every third bit.
uint64_t spreadBits(uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffull;
  x = (x | x << 16) & 0x1f0000ff0000ffull;
  x = (x | x << 8) & 0x100f00f00f00f00full;
  x = (x | x << 4) & 0x10c30c30c30c30c3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

}  // namespace

double numberingSpread(const TetMesh& mesh) {
  const uint32_t T = mesh.tetCount(), V = mesh.vertexCount();
  if (T == 0 || V == 0) return 0;
  const uint32_t step = std::max<uint32_t>(1, T / 4096);
  std::vector<uint32_t> spans;
  spans.reserve(T / step + 1);
  for (uint32_t t = 0; t < T; t += step) {
    const uint32_t* v = &mesh.tets[4 * size_t(t)];
    spans.push_back(std::max({v[0], v[1], v[2], v[3]}) - std::min({v[0], v[1], v[2], v[3]}));
  }
  std::nth_element(spans.begin(), spans.begin() + spans.size() / 2, spans.end());
  return double(spans[spans.size() / 2]) / V;
}

bool renumberable(const TetMesh& mesh) {
  const uint32_t V = mesh.vertexCount();
  for (uint32_t v : mesh.tets)
    if (v >= V) return false;
  for (float x : mesh.positions)
    if (!std::isfinite(x)) return false;
  return true;
}

void renumberForLocality(TetMesh& mesh) {
  const uint32_t V = mesh.vertexCount(), T = mesh.tetCount();
  const Bounds b = computeBounds(mesh.positions);
  std::vector<std::pair<uint64_t, uint32_t>> order(V);
  for (uint32_t v = 0; v < V; ++v) {
    uint64_t code = 0;
    for (int k = 0; k < 3; ++k) {
      const double extent = double(b.max[k]) - b.min[k];
      const double x = extent > 0 ? (mesh.positions[3 * size_t(v) + k] - b.min[k]) / extent : 0.0;
      code |= spreadBits(uint64_t(std::clamp(x, 0.0, 1.0) * 0x1fffff)) << k;
    }
    order[v] = {code, v};
  }
  std::sort(order.begin(), order.end());
  std::vector<uint32_t> newVertex(V);
  for (uint32_t r = 0; r < V; ++r) newVertex[order[r].second] = r;

  std::vector<float> positions(mesh.positions.size());
  for (uint32_t r = 0; r < V; ++r)
    for (int k = 0; k < 3; ++k) positions[3 * size_t(r) + k] = mesh.positions[3 * size_t(order[r].second) + k];
  mesh.positions = std::move(positions);
  for (ScalarField& f : mesh.fields) {
    std::vector<float> values(V);
    for (uint32_t r = 0; r < V; ++r) values[r] = f.values[order[r].second];
    f.values = std::move(values);
  }
  order = {};

  // Tets by smallest new vertex id, a counting sort (stable: ties keep the old order).
  std::vector<uint32_t> start(size_t(V) + 1, 0), newTet(T);
  for (uint32_t t = 0; t < T; ++t) {
    uint32_t* v = &mesh.tets[4 * size_t(t)];
    for (int k = 0; k < 4; ++k) v[k] = newVertex[v[k]];
    ++start[std::min({v[0], v[1], v[2], v[3]}) + 1];
  }
  for (uint32_t v = 0; v < V; ++v) start[v + 1] += start[v];
  for (uint32_t t = 0; t < T; ++t) {
    const uint32_t* v = &mesh.tets[4 * size_t(t)];
    newTet[t] = start[std::min({v[0], v[1], v[2], v[3]})]++;
  }
  std::vector<uint32_t> tets(mesh.tets.size());
  for (uint32_t t = 0; t < T; ++t)
    for (int k = 0; k < 4; ++k) tets[4 * size_t(newTet[t]) + k] = mesh.tets[4 * size_t(t) + k];
  mesh.tets = std::move(tets);
}

}  // namespace tetstream
