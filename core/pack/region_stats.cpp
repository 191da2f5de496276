#include "pack/region_stats.h"

#include <algorithm>
#include <cmath>

namespace tetstream {
namespace {

Bounds unite(const Bounds& a, const Bounds& b) {
  Bounds u;
  for (int k = 0; k < 3; ++k) {
    u.min[k] = std::min(a.min[k], b.min[k]);
    u.max[k] = std::max(a.max[k], b.max[k]);
  }
  return u;
}

}  // namespace

RegionStats regionStats(const TetMesh& mesh, const SimplifyResult& s, const Manifest& m) {
  const RegionTree& tree = s.tree;
  const uint32_t nodes = tree.nodes(), F = uint32_t(mesh.fields.size());
  RegionStats out;
  Bounds empty;
  for (int k = 0; k < 3; ++k) empty.min[k] = INFINITY, empty.max[k] = -INFINITY;
  out.bounds.assign(nodes, empty);
  out.ranges.assign(nodes, std::vector<Range>(F, Range{INFINITY, -INFINITY}));
  out.fieldError.assign(nodes, 0.0f);
  // The vertices of the stream: those of the base and those a collapse removed.
  std::vector<uint8_t> used(s.vertexAlive.begin(), s.vertexAlive.end());
  for (uint32_t i : s.log.i) used[i] = 1;
  const uint32_t firstLeaf = 1u << tree.depth;
  // A leaf's own vertices, and those of its tets in later leaves (RegionTree::rim).
  auto include = [&](uint32_t n, uint32_t v) {
    const float* p = &mesh.positions[3 * size_t(v)];
    for (int k = 0; k < 3; ++k) {
      out.bounds[n].min[k] = std::min(out.bounds[n].min[k], p[k]);
      out.bounds[n].max[k] = std::max(out.bounds[n].max[k], p[k]);
    }
    for (uint32_t f = 0; f < F; ++f) {
      const float x = mesh.fields[f].values[v];
      if (!std::isfinite(x)) continue;  // (NaN: no value, no surface)
      out.ranges[n][f].min = std::min(out.ranges[n][f].min, x);
      out.ranges[n][f].max = std::max(out.ranges[n][f].max, x);
    }
  };
  for (uint32_t v = 0; v < mesh.vertexCount(); ++v)
    if (used[v]) include(tree.depth ? firstLeaf + tree.leafOf[v] : 1, v);
  for (const auto& [leaf, v] : tree.rim) include(firstLeaf + leaf, v);
  for (size_t sec = 0, begin = 0; sec < tree.sectionNode.size(); begin = tree.sectionEnd[sec++]) {
    float& e = out.fieldError[tree.sectionNode[sec]];
    for (size_t c = begin; c < tree.sectionEnd[sec]; ++c) e = std::max(e, s.log.fieldError[c]);
  }
  for (uint32_t n = firstLeaf; n-- > 1;) {
    if (n >= firstLeaf) continue;
    out.bounds[n] = unite(out.bounds[2 * n], out.bounds[2 * n + 1]);
    for (uint32_t f = 0; f < F; ++f)
      out.ranges[n][f] = {std::min(out.ranges[2 * n][f].min, out.ranges[2 * n + 1][f].min),
                          std::max(out.ranges[2 * n][f].max, out.ranges[2 * n + 1][f].max)};
    out.fieldError[n] = std::max({out.fieldError[n], out.fieldError[2 * n], out.fieldError[2 * n + 1]});
  }
  // A field with no finite value in a region (no surface there at any isovalue) takes its
  // parent's range, so ranges still nest; at the root, the field's (the manifest's).
  for (uint32_t n = 1; n < nodes; ++n)
    for (uint32_t f = 0; f < F; ++f)
      if (!(out.ranges[n][f].min <= out.ranges[n][f].max))
        out.ranges[n][f] = n > 1 ? out.ranges[n / 2][f] : m.fields[f].range;
  for (uint32_t n = 1; n < nodes; ++n) {
    for (uint32_t f = 0; f < F; ++f) {
      Range& r = out.ranges[n][f];
      r = {std::clamp(r.min, m.fields[f].range.min, m.fields[f].range.max),
           std::clamp(r.max, m.fields[f].range.min, m.fields[f].range.max)};
    }
    for (int k = 0; k < 3; ++k) {
      Bounds& b = out.bounds[n];
      b.min[k] = std::clamp(b.min[k], m.bounds.min[k], m.bounds.max[k]);
      b.max[k] = std::clamp(b.max[k], m.bounds.min[k], m.bounds.max[k]);
    }
  }
  return out;
}

}  // namespace tetstream
