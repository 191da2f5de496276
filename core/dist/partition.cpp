#include "dist/partition.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>

namespace tetstream::dist {
namespace {

// A float as an unsigned key in the same order (−0 as +0), so a cut can be bisected over keys.
uint32_t orderKey(float x) {
  if (x == 0) x = 0;  // (−0 → +0)
  uint32_t u;
  std::memcpy(&u, &x, 4);
  return (u & 0x80000000u) ? ~u : u | 0x80000000u;
}

// A point's identity across ranks: its coordinates' bits.
struct PointKey {
  uint32_t k[3];
  bool operator<(const PointKey& o) const { return std::lexicographical_compare(k, k + 3, o.k, o.k + 3); }
  bool operator==(const PointKey& o) const { return k[0] == o.k[0] && k[1] == o.k[1] && k[2] == o.k[2]; }
};
PointKey keyOf(const float* p) { return {{orderKey(p[0]), orderKey(p[1]), orderKey(p[2])}}; }

std::vector<uint8_t> usedVertices(const TetMesh& mesh) {
  std::vector<uint8_t> used(mesh.vertexCount(), 0);
  for (uint32_t v : mesh.tets)
    if (v < used.size()) used[v] = 1;
  return used;
}

bool sameValue(float a, float b) { return a == b || (std::isnan(a) && std::isnan(b)); }

}  // namespace

int RankTree::ownerOf(const float* p) const {
  int g = 0;
  while (groups[size_t(g)].low >= 0) {
    const Group& x = groups[size_t(g)];
    g = orderKey(p[x.axis]) < x.cutKey ? x.low : x.high;
  }
  return groups[size_t(g)].first;
}

int RankTree::leafOf(int r) const {
  for (size_t g = 0; g < groups.size(); ++g)
    if (groups[g].low < 0 && groups[g].first == r) return int(g);
  return -1;
}

std::vector<int> RankTree::preorder() const {
  std::vector<int> order, stack{0};
  while (!stack.empty()) {
    const int g = stack.back();
    stack.pop_back();
    order.push_back(g);
    if (groups[size_t(g)].low >= 0) {
      stack.push_back(groups[size_t(g)].high);
      stack.push_back(groups[size_t(g)].low);
    }
  }
  return order;
}

RankTree cutRegions(Comm& comm, const TetMesh& mesh) {
  RankTree tree;
  tree.groups.push_back({0, comm.size()});
  const std::vector<uint8_t> used = usedVertices(mesh);
  std::vector<uint32_t> points;
  for (uint32_t v = 0; v < used.size(); ++v)
    if (used[v]) points.push_back(v);
  std::vector<int> groupOf(points.size(), 0);
  std::vector<int> active;
  if (comm.size() > 1) active.push_back(0);
  while (!active.empty()) {
    const size_t G = active.size();
    std::vector<int> slot(tree.groups.size(), -1);
    for (size_t a = 0; a < G; ++a) slot[size_t(active[a])] = int(a);
    // Each group's bounding box and point count.
    std::vector<double> lo(3 * G, INFINITY), hi(3 * G, -INFINITY);
    std::vector<uint64_t> total(G, 0);
    for (size_t k = 0; k < points.size(); ++k) {
      const int a = slot[size_t(groupOf[k])];
      if (a < 0) continue;
      const float* p = &mesh.positions[3 * size_t(points[k])];
      for (int d = 0; d < 3; ++d) {
        lo[3 * size_t(a) + size_t(d)] = std::min<double>(lo[3 * size_t(a) + size_t(d)], p[d]);
        hi[3 * size_t(a) + size_t(d)] = std::max<double>(hi[3 * size_t(a) + size_t(d)], p[d]);
      }
      ++total[size_t(a)];
    }
    comm.minInPlace(lo);
    comm.maxInPlace(hi);
    comm.sumInPlace(total);
    std::vector<int> axis(G, 0);
    std::vector<uint64_t> want(G), below(G), from(G, 0), to(G, uint64_t(1) << 32);
    for (size_t a = 0; a < G; ++a) {
      for (int d = 1; d < 3; ++d)
        if (hi[3 * a + size_t(d)] - lo[3 * a + size_t(d)] > hi[3 * a + size_t(axis[a])] - lo[3 * a + size_t(axis[a])])
          axis[a] = d;
      const RankTree::Group& g = tree.groups[size_t(active[a])];
      want[a] = total[a] * uint64_t(g.count / 2) / uint64_t(g.count);
    }
    // The least key K with at least `want` points below it, bisected for all groups at once.
    for (int round = 0; round < 33; ++round) {
      std::vector<uint64_t> mid(G);
      for (size_t a = 0; a < G; ++a) mid[a] = (from[a] + to[a]) / 2;
      std::fill(below.begin(), below.end(), 0);
      for (size_t k = 0; k < points.size(); ++k) {
        const int a = slot[size_t(groupOf[k])];
        if (a >= 0 && orderKey(mesh.positions[3 * size_t(points[k]) + size_t(axis[size_t(a)])]) < mid[size_t(a)])
          ++below[size_t(a)];
      }
      comm.sumInPlace(below);
      for (size_t a = 0; a < G; ++a) (below[a] >= want[a] ? to[a] : from[a]) = mid[a];
    }
    std::vector<int> next;
    for (size_t a = 0; a < G; ++a) {
      const int gi = active[a];
      RankTree::Group g = tree.groups[size_t(gi)];
      g.axis = axis[a];
      g.cutKey = to[a];
      g.low = int(tree.groups.size());
      g.high = g.low + 1;
      const int lowRanks = g.count / 2;
      tree.groups.push_back({g.first, lowRanks});
      tree.groups.push_back({g.first + lowRanks, g.count - lowRanks});
      tree.groups[size_t(g.low)].parent = tree.groups[size_t(g.high)].parent = gi;
      tree.groups[size_t(gi)] = g;
      for (int c : {g.low, g.high})
        if (tree.groups[size_t(c)].count > 1) next.push_back(c);
    }
    for (size_t k = 0; k < points.size(); ++k) {
      const RankTree::Group& g = tree.groups[size_t(groupOf[k])];
      if (g.low >= 0 && slot[size_t(groupOf[k])] >= 0)
        groupOf[k] = orderKey(mesh.positions[3 * size_t(points[k]) + size_t(g.axis)]) < g.cutKey ? g.low : g.high;
    }
    active = std::move(next);
  }
  return tree;
}

Result distribute(Comm& comm, TetMesh&& mesh, uint64_t firstTetId, const RankTree& tree,
                  const std::vector<std::vector<double>>& cellWeight, PartMesh& part, DistributionReport& report) {
  const int N = comm.size(), me = comm.rank();
  const size_t F = mesh.fields.size();
  // The fields that are cell data on any rank (a rank that read no cells of its own sends zero
  // weights, which count only where no copy has any).
  std::vector<uint64_t> anyCell(F, 0);
  for (size_t f = 0; f < F; ++f) anyCell[f] = f < cellWeight.size() && cellWeight[f].size() == mesh.vertexCount();
  comm.sumInPlace(anyCell);
  std::vector<size_t> cellFields;
  std::vector<uint8_t> isCell(F, 0);
  for (size_t f = 0; f < F; ++f)
    if (anyCell[f]) cellFields.push_back(f), isCell[f] = 1;
  auto weightOf = [&](size_t f, uint32_t v) {
    return f < cellWeight.size() && v < cellWeight[f].size() ? cellWeight[f][v] : 0.0;
  };
  const size_t C = cellFields.size();
  const uint32_t V = mesh.vertexCount(), T = mesh.tetCount();
  std::vector<int> owner(V, -1);
  for (uint32_t v : mesh.tets) {
    if (v >= V)
      return fail(Status::OutOfRange, "a tetrahedron names vertex " + std::to_string(v) + " of " + std::to_string(V));
    if (owner[v] < 0) owner[v] = tree.ownerOf(&mesh.positions[3 * size_t(v)]);
  }
  // (destination, tet) pairs, by destination.
  std::vector<std::vector<uint32_t>> tetsTo(static_cast<size_t>(N));
  for (uint32_t t = 0; t < T; ++t) {
    int seen[4];
    int n = 0;
    for (int k = 0; k < 4; ++k) {
      const int d = owner[mesh.tets[4 * size_t(t) + size_t(k)]];
      if (std::find(seen, seen + n, d) == seen + n) seen[n++] = d;
    }
    for (int k = 0; k < n; ++k) tetsTo[size_t(seen[k])].push_back(t);
  }
  std::vector<Bytes> out(static_cast<size_t>(N));
  std::vector<uint32_t> stamp(V, 0), index(V, 0);
  for (int d = 0; d < N; ++d) {
    std::vector<uint32_t> table;
    for (uint32_t t : tetsTo[size_t(d)])
      for (int k = 0; k < 4; ++k) {
        const uint32_t v = mesh.tets[4 * size_t(t) + size_t(k)];
        if (stamp[v] == uint32_t(d) + 1) continue;
        stamp[v] = uint32_t(d) + 1;
        index[v] = uint32_t(table.size());
        table.push_back(v);
      }
    Writer w(out[size_t(d)]);
    w.put<uint64_t>(table.size());
    for (uint32_t v : table) {
      for (int k = 0; k < 3; ++k) w.put(mesh.positions[3 * size_t(v) + size_t(k)]);
      for (size_t f = 0; f < F; ++f) w.put(mesh.fields[f].values[v]);
      for (size_t f : cellFields) w.put(weightOf(f, v));
    }
    w.put<uint64_t>(tetsTo[size_t(d)].size());
    for (uint32_t t : tetsTo[size_t(d)]) {
      w.put<uint64_t>(firstTetId + t);
      for (int k = 0; k < 4; ++k) w.put(index[mesh.tets[4 * size_t(t) + size_t(k)]]);
    }
    tetsTo[size_t(d)] = {};
  }
  part = PartMesh{};
  part.mesh.name = mesh.name;
  for (const ScalarField& f : mesh.fields) part.mesh.fields.push_back({f.name, {}});
  mesh = TetMesh{};
  std::vector<Bytes> in = comm.allToAll(out);
  out = {};

  // Every vertex received, by key and then by the sender's rank (the lowest rank's copy wins).
  struct Copy {
    PointKey key;
    uint32_t source, index;  // sender, place in its table
    uint64_t at;             // the copy's values: float offset into `values`
  };
  std::vector<Copy> copies;
  std::vector<float> values;    // 3 + F per copy
  std::vector<double> weights;  // C per copy: the volume behind each cell field's average
  std::vector<std::vector<uint64_t>> tetIds(static_cast<size_t>(N));
  std::vector<std::vector<uint32_t>> tetCorners(static_cast<size_t>(N));
  std::vector<uint64_t> tableSize(static_cast<size_t>(N), 0);
  for (int s = 0; s < N; ++s) {
    Reader r(in[size_t(s)]);
    const uint64_t nv = r.get<uint64_t>();
    tableSize[size_t(s)] = nv;
    if (!r.ok() || nv > in[size_t(s)].size())
      return fail(Status::Corrupt, "a message from rank " + std::to_string(s) + " is damaged");
    for (uint64_t k = 0; k < nv; ++k) {
      const uint64_t at = values.size();
      for (size_t x = 0; x < 3 + F; ++x) values.push_back(r.get<float>());
      for (size_t c = 0; c < C; ++c) weights.push_back(r.get<double>());
      copies.push_back({keyOf(&values[at]), uint32_t(s), uint32_t(k), at});
    }
    const uint64_t nt = r.get<uint64_t>();
    if (!r.ok() || nt > in[size_t(s)].size())
      return fail(Status::Corrupt, "a message from rank " + std::to_string(s) + " is damaged");
    for (uint64_t k = 0; k < nt; ++k) {
      tetIds[size_t(s)].push_back(r.get<uint64_t>());
      for (int c = 0; c < 4; ++c) tetCorners[size_t(s)].push_back(r.get<uint32_t>());
    }
    if (!r.atEnd()) return fail(Status::Corrupt, "a message from rank " + std::to_string(s) + " is damaged");
    in[size_t(s)] = {};
  }
  std::sort(copies.begin(), copies.end(),
            [](const Copy& a, const Copy& b) { return a.key < b.key || (a.key == b.key && a.source < b.source); });
  // Unique points (in key order) and where each sender's table entries went.
  std::vector<std::vector<uint32_t>> localOf(static_cast<size_t>(N));
  for (int s = 0; s < N; ++s) localOf[size_t(s)].assign(tableSize[size_t(s)], 0);
  std::vector<uint32_t> firstCopy;
  std::vector<float> joined;  // C per unique point: its cell fields joined over the copies here
  report.disagreements.assign(F, 0);
  std::vector<uint8_t> differs(F);
  for (size_t c = 0; c < copies.size();) {
    size_t e = c + 1;
    while (e < copies.size() && copies[e].key == copies[c].key) ++e;
    const uint32_t local = uint32_t(firstCopy.size());
    firstCopy.push_back(uint32_t(c));
    for (size_t k = 0; k < C; ++k) {
      double num = 0, den = 0;
      for (size_t x = c; x < e; ++x) {
        const double w = weights[(copies[x].at / (3 + F)) * C + k], v = values[copies[x].at + 3 + cellFields[k]];
        if (w > 0 && std::isfinite(v)) num += w * v, den += w;
      }
      joined.push_back(den > 0 ? float(num / den) : values[copies[c].at + 3 + cellFields[k]]);
    }
    if (e - c > 1) {
      ++report.joinedPoints;
      std::fill(differs.begin(), differs.end(), 0);
      for (size_t x = c + 1; x < e; ++x)
        for (size_t f = 0; f < F; ++f)
          differs[f] |= !isCell[f] && !sameValue(values[copies[x].at + 3 + f], values[copies[c].at + 3 + f]);
      for (size_t f = 0; f < F; ++f) report.disagreements[f] += differs[f];
    }
    for (size_t x = c; x < e; ++x) localOf[copies[x].source][copies[x].index] = local;
    c = e;
  }
  const uint32_t nLocal = uint32_t(firstCopy.size());
  std::vector<PointKey> keys(nLocal);
  std::vector<uint8_t> owned(nLocal);
  for (uint32_t v = 0; v < nLocal; ++v) {
    const Copy& c = copies[firstCopy[v]];
    keys[v] = c.key;
    owned[v] = tree.ownerOf(&values[c.at]) == me;
  }

  // Input ids: the owners number their points in key order, one rank after the other.
  std::vector<uint64_t> ownedCount(static_cast<size_t>(N), 0);
  ownedCount[size_t(me)] = uint64_t(std::count(owned.begin(), owned.end(), 1));
  comm.sumInPlace(ownedCount);
  uint64_t offset = 0;
  for (int r = 0; r < me; ++r) offset += ownedCount[size_t(r)];
  std::vector<uint64_t> id(nLocal, ~uint64_t(0));
  std::vector<uint32_t> ownedList;  // local ids of owned points, in key order
  for (uint32_t v = 0; v < nLocal; ++v)
    if (owned[v]) {
      id[v] = offset + ownedList.size();
      ownedList.push_back(v);
    }
  // The halo's ids, asked of their owners.
  std::vector<std::vector<uint32_t>> asked(static_cast<size_t>(N));
  std::vector<Bytes> question(static_cast<size_t>(N));
  for (uint32_t v = 0; v < nLocal; ++v)
    if (!owned[v]) {
      const int o = tree.ownerOf(&values[copies[firstCopy[v]].at]);
      asked[size_t(o)].push_back(v);
      Writer(question[size_t(o)]).put(keys[v]);
    }
  std::vector<Bytes> questions = comm.allToAll(question);
  std::vector<Bytes> answer(static_cast<size_t>(N));
  bool unknown = false;
  for (int s = 0; s < N; ++s) {
    Reader r(questions[size_t(s)]);
    Writer w(answer[size_t(s)]);
    for (size_t n = questions[size_t(s)].size() / sizeof(PointKey); n-- > 0;) {
      const PointKey k = r.get<PointKey>();
      auto it = std::lower_bound(ownedList.begin(), ownedList.end(), k,
                                 [&](uint32_t v, const PointKey& x) { return keys[v] < x; });
      const bool found = it != ownedList.end() && keys[*it] == k;
      unknown |= !found;
      w.put<uint64_t>(found ? offset + uint64_t(it - ownedList.begin()) : ~uint64_t(0));
      for (size_t k = 0; k < C; ++k) w.put(found ? joined[size_t(*it) * C + k] : 0.0f);
    }
  }
  std::vector<Bytes> answers = comm.allToAll(answer);
  for (int o = 0; o < N; ++o) {
    Reader r(answers[size_t(o)]);
    for (uint32_t v : asked[size_t(o)]) {
      id[v] = r.get<uint64_t>();
      for (size_t k = 0; k < C; ++k) joined[size_t(v) * C + k] = r.get<float>();  // (the owner's, everywhere)
    }
    unknown |= !r.atEnd();
  }
  for (uint64_t x : id) unknown |= x == ~uint64_t(0);
  if (unknown) return fail(Status::Corrupt, "a point's owner does not hold it (internal error)");

  // The part, vertices by input id, tets by input id.
  std::vector<uint32_t> byId(nLocal);
  std::iota(byId.begin(), byId.end(), 0u);
  std::sort(byId.begin(), byId.end(), [&](uint32_t a, uint32_t b) { return id[a] < id[b]; });
  std::vector<uint32_t> newOf(nLocal);
  part.vertexId.resize(nLocal);
  part.owned.resize(nLocal);
  part.mesh.positions.resize(3 * size_t(nLocal));
  for (ScalarField& f : part.mesh.fields) f.values.resize(nLocal);
  for (uint32_t n = 0; n < nLocal; ++n) {
    const uint32_t v = byId[n];
    newOf[v] = n;
    part.vertexId[n] = id[v];
    part.owned[n] = owned[v];
    const float* x = &values[copies[firstCopy[v]].at];
    for (int k = 0; k < 3; ++k) part.mesh.positions[3 * size_t(n) + size_t(k)] = x[k];
    for (size_t f = 0; f < F; ++f) part.mesh.fields[f].values[n] = x[3 + f];
    for (size_t k = 0; k < C; ++k) part.mesh.fields[cellFields[k]].values[n] = joined[size_t(v) * C + k];
  }
  struct Tet {
    uint64_t id;
    uint32_t v[4];
  };
  std::vector<Tet> tets;
  for (int s = 0; s < N; ++s)
    for (size_t k = 0; k < tetIds[size_t(s)].size(); ++k) {
      Tet t{tetIds[size_t(s)][k], {}};
      for (int c = 0; c < 4; ++c) {
        const uint32_t x = tetCorners[size_t(s)][4 * k + size_t(c)];
        if (x >= localOf[size_t(s)].size())
          return fail(Status::Corrupt, "a message from rank " + std::to_string(s) + " is damaged");
        t.v[c] = newOf[localOf[size_t(s)][x]];
      }
      tets.push_back(t);
    }
  std::sort(tets.begin(), tets.end(), [](const Tet& a, const Tet& b) { return a.id < b.id; });
  part.tetId.resize(tets.size());
  part.mesh.tets.resize(4 * tets.size());
  for (size_t k = 0; k < tets.size(); ++k) {
    part.tetId[k] = tets[k].id;
    std::copy(tets[k].v, tets[k].v + 4, &part.mesh.tets[4 * k]);
  }
  return Result::success();
}

}  // namespace tetstream::dist
