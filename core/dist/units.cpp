#include "dist/units.h"

#include <algorithm>
#include <cmath>

namespace tetstream::dist {

Bounds RegionFigures::groupBounds(const RankTree::Group& g) const {
  Bounds b = bounds[size_t(g.first)];
  for (int r = g.first + 1; r < g.first + g.count; ++r)
    for (int k = 0; k < 3; ++k) {
      b.min[k] = std::min(b.min[k], bounds[size_t(r)].min[k]);
      b.max[k] = std::max(b.max[k], bounds[size_t(r)].max[k]);
    }
  return b;
}

Range RegionFigures::groupRange(const RankTree::Group& g, size_t field) const {
  Range x = ranges[size_t(g.first)][field];
  for (int r = g.first + 1; r < g.first + g.count; ++r) {
    x.min = std::min(x.min, ranges[size_t(r)][field].min);
    x.max = std::max(x.max, ranges[size_t(r)][field].max);
  }
  return x;
}

uint64_t ownedCount(const PartMesh& p) { return uint64_t(std::count(p.owned.begin(), p.owned.end(), 1)); }

void ownedExtent(const PartMesh& p, std::vector<double>& lo, std::vector<double>& hi) {
  const size_t F = p.mesh.fields.size();
  lo.assign(3 + F, INFINITY);
  hi.assign(3 + F, -INFINITY);
  for (uint32_t v = 0; v < p.mesh.vertexCount(); ++v) {
    if (!p.owned[v]) continue;
    for (int k = 0; k < 3; ++k) {
      lo[size_t(k)] = std::min<double>(lo[size_t(k)], p.mesh.positions[3 * size_t(v) + size_t(k)]);
      hi[size_t(k)] = std::max<double>(hi[size_t(k)], p.mesh.positions[3 * size_t(v) + size_t(k)]);
    }
    for (size_t f = 0; f < F; ++f) {
      const float x = p.mesh.fields[f].values[v];
      if (!std::isfinite(x)) continue;
      lo[3 + f] = std::min<double>(lo[3 + f], x);
      hi[3 + f] = std::max<double>(hi[3 + f], x);
    }
  }
}

RegionFigures regionFigures(Comm& comm, const PartMesh& part, const Manifest& m) {
  const size_t F = m.fields.size();
  std::vector<double> lo, hi;
  ownedExtent(part, lo, hi);
  Bytes mine;
  Writer w(mine);
  w.putVector(lo);
  w.putVector(hi);
  const std::vector<Bytes> all = comm.allGather(mine);
  RegionFigures out;
  for (const Bytes& b : all) {
    Reader in(b);
    std::vector<double> l = in.getVector<double>(), h = in.getVector<double>();
    l.resize(3 + F, INFINITY);
    h.resize(3 + F, -INFINITY);
    Bounds bounds = m.bounds;  // (a rank without points: the whole box)
    if (l[0] <= h[0])
      for (int k = 0; k < 3; ++k)
        bounds.min[k] = std::max(float(l[size_t(k)]), m.bounds.min[k]),
        bounds.max[k] = std::min(float(h[size_t(k)]), m.bounds.max[k]);
    out.bounds.push_back(bounds);
    std::vector<Range> ranges(F);
    for (size_t f = 0; f < F; ++f) {
      const Range whole = m.fields[f].range;
      ranges[f] = l[3 + f] <= h[3 + f]
                      ? Range{std::max(float(l[3 + f]), whole.min), std::min(float(h[3 + f]), whole.max)}
                      : Range{whole.min, whole.min};
      if (!(ranges[f].min <= ranges[f].max)) ranges[f] = {whole.min, whole.min};
    }
    out.ranges.push_back(std::move(ranges));
  }
  return out;
}

UnitLayout planUnits(Comm& comm, const RankTree& tree, const std::vector<Unit>& units) {
  const size_t G = tree.groups.size();
  std::vector<uint64_t> counts(2 * G + 2, 0);
  for (const Unit& u : units) {
    counts[2 * size_t(u.group)] = u.part.mesh.vertexCount() - u.handoff.mesh.vertexCount();
    counts[2 * size_t(u.group) + 1] = u.s.tetAlive.size() - u.handoff.mesh.tetCount();
    if (u.group == 0) {
      counts[2 * G] = u.handoff.mesh.vertexCount();
      counts[2 * G + 1] = u.handoff.mesh.tetCount();
    }
  }
  comm.sumInPlace(counts);
  UnitLayout l;
  l.baseVertices = counts[2 * G];
  l.baseTets = counts[2 * G + 1];
  l.vertexBegin.assign(G, 0);
  l.tetBegin.assign(G, 0);
  l.newVertices.assign(G, 0);
  l.newTets.assign(G, 0);
  uint64_t v = l.baseVertices, t = l.baseTets;
  for (int g : tree.preorder()) {
    l.vertexBegin[size_t(g)] = v;
    l.tetBegin[size_t(g)] = t;
    l.newVertices[size_t(g)] = counts[2 * size_t(g)];
    l.newTets[size_t(g)] = counts[2 * size_t(g) + 1];
    v += l.newVertices[size_t(g)];
    t += l.newTets[size_t(g)];
  }
  return l;
}

Result encodeOne(Unit& u, const StableIds& hand, const Manifest& m, UnitEncodeOptions& options) {
  const std::vector<uint64_t>& handVertex = hand.vertices;
  const std::vector<uint64_t>& handTet = hand.tets;
  SimplifyResult& s = u.s;
  if (!hand.values.empty()) {  // (the values the unit above leaves: its values at the end)
    if (hand.values.size() != handVertex.size() || s.values.size() != s.vertexAlive.size())
      return fail(Status::Corrupt, "a handoff's values do not match (internal error)");
    size_t k = 0;
    for (uint32_t v = 0; v < s.vertexAlive.size(); ++v)
      if (s.vertexAlive[v]) s.values[v] = hand.values[k++];
  }
  options.stableVertex.assign(u.part.mesh.vertexCount(), ~uint64_t(0));
  options.stableTet.assign(s.tetAlive.size(), ~uint64_t(0));
  size_t k = 0;
  for (uint32_t v = 0; v < s.vertexAlive.size(); ++v)
    if (s.vertexAlive[v]) {
      if (k >= handVertex.size()) return fail(Status::Corrupt, "a handoff's vertices do not match (internal error)");
      options.stableVertex[v] = handVertex[k++];
    }
  if (k != handVertex.size()) return fail(Status::Corrupt, "a handoff's vertices do not match (internal error)");
  k = 0;
  for (uint32_t t = 0; t < s.tetAlive.size(); ++t)
    if (s.tetAlive[t]) {
      if (k >= handTet.size()) return fail(Status::Corrupt, "a handoff's tets do not match (internal error)");
      options.stableTet[t] = handTet[k++];
    }
  if (k != handTet.size()) return fail(Status::Corrupt, "a handoff's tets do not match (internal error)");
  return encodeUnit(u.part.mesh, u.s, m, options, u.encoded);
}

StableIds stableIdsOf(const Unit& u, int side) {
  StableIds out;
  auto look = [](const std::vector<uint64_t>& ids, const std::vector<uint64_t>& idsOfPart,
                 const std::vector<uint64_t>& stable, std::vector<uint64_t>& into) {
    into.reserve(ids.size());
    for (uint64_t id : ids) {
      auto it = std::lower_bound(idsOfPart.begin(), idsOfPart.end(), id);
      const size_t at = size_t(it - idsOfPart.begin());
      into.push_back(it != idsOfPart.end() && *it == id && at < stable.size() ? stable[at] : ~uint64_t(0));
    }
  };
  look(u.childVertexIds[side], u.part.vertexId, u.encoded.startVertex, out.vertices);
  look(u.childTetIds[side], u.part.tetId, u.encoded.startTet, out.tets);
  if (!u.encoded.startValue.empty()) {
    out.values.reserve(u.childVertexIds[side].size());
    for (uint64_t id : u.childVertexIds[side]) {
      auto it = std::lower_bound(u.part.vertexId.begin(), u.part.vertexId.end(), id);
      const size_t at = size_t(it - u.part.vertexId.begin());
      out.values.push_back(at < u.encoded.startValue.size() ? u.encoded.startValue[at] : NAN);
    }
  }
  return out;
}

}  // namespace tetstream::dist
