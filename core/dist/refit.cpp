#include "dist/refit.h"

#include <algorithm>
#include <cmath>

#include "dist/tet_grid.h"
#include "pack/bounded_cg.h"

namespace tetstream::dist {
namespace {

// As simplify_refit.cpp: rounds of holding values at a bound, iterations of each solve.
constexpr int kRounds = 4, kIterations = 200;

// The base as rank 0 shares it: the mesh, each vertex's value, count and range.
struct SharedBase {
  TetMesh mesh;
  std::vector<float> fit, lo, hi;
  std::vector<uint32_t> represented;
};

}  // namespace

void refitBase(Comm& comm, Unit* root, const PartMesh& input, int field) {
  Bytes mine;
  std::vector<uint32_t> localOf;  // (rank 0) base vertex -> the root part's vertex
  if (root) {
    const SimplifyResult& s = root->s;
    SharedBase b;
    for (uint32_t v = 0; v < s.vertexAlive.size(); ++v) {
      if (!s.vertexAlive[v]) continue;
      const uint32_t c = uint32_t(localOf.size());  // (s.carried covers the alive vertices, in order)
      localOf.push_back(v);
      b.fit.push_back(s.values.empty() ? root->part.mesh.fields[size_t(field)].values[v] : s.values[v]);
      b.represented.push_back(c < s.carried.represented.size() ? s.carried.represented[c] : 1);
      const Range r = c < s.carried.fitRange.size() ? s.carried.fitRange[c] : Range{b.fit.back(), b.fit.back()};
      b.lo.push_back(r.min);
      b.hi.push_back(r.max);
    }
    Writer w(mine);
    w.putVector(root->handoff.mesh.positions);
    w.putVector(root->handoff.mesh.tets);
    w.putVector(b.fit);
    w.putVector(b.represented);
    w.putVector(b.lo);
    w.putVector(b.hi);
  }
  SharedBase b;
  for (const Bytes& got : comm.allGather(mine)) {
    if (got.empty()) continue;
    Reader in(got);
    b.mesh.positions = in.getVector<float>();
    b.mesh.tets = in.getVector<uint32_t>();
    b.fit = in.getVector<float>();
    b.represented = in.getVector<uint32_t>();
    b.lo = in.getVector<float>();
    b.hi = in.getVector<float>();
  }
  const uint32_t V = b.mesh.vertexCount();
  if (b.mesh.tets.empty() || b.fit.size() != V || b.represented.size() != V) return;  // (the same on every rank)

  // The unknowns (vertices that stand for others) and the pattern of the normal equations: a row
  // per unknown over the unknowns it shares a tet with, and itself.
  const uint32_t none = ~0u;
  std::vector<uint32_t> col(V, none), unknown;
  for (uint32_t v = 0; v < V; ++v)
    if (b.represented[v] > 1) {
      col[v] = uint32_t(unknown.size());
      unknown.push_back(v);
    }
  const uint32_t n = uint32_t(unknown.size());
  if (n == 0) return;
  std::vector<std::vector<uint32_t>> near(n);
  for (size_t t = 0; t < b.mesh.tets.size(); t += 4)
    for (int x = 0; x < 4; ++x)
      if (const uint32_t r = col[b.mesh.tets[t + size_t(x)]]; r != none)
        for (int y = 0; y < 4; ++y)
          if (const uint32_t c = col[b.mesh.tets[t + size_t(y)]]; c != none) near[r].push_back(c);
  std::vector<uint32_t> rowStart(n + 1, 0), cols;
  for (uint32_t r = 0; r < n; ++r) {
    std::sort(near[r].begin(), near[r].end());
    near[r].erase(std::unique(near[r].begin(), near[r].end()), near[r].end());
    cols.insert(cols.end(), near[r].begin(), near[r].end());
    rowStart[r + 1] = uint32_t(cols.size());
    std::vector<uint32_t>().swap(near[r]);
  }
  // This rank's rows: each of its input vertices' squared error, at the base's coordinates there.
  std::vector<double> sums(cols.size() + n, 0.0);  // a, then the right-hand side
  auto at = [&](uint32_t r, uint32_t c) -> double& {
    auto it = std::lower_bound(cols.begin() + rowStart[r], cols.begin() + rowStart[r + 1], c);
    return sums[size_t(it - cols.begin())];
  };
  const TetGrid grid(b.mesh);
  const std::vector<float>& samples = input.mesh.fields[size_t(field)].values;
  for (uint32_t v = 0; v < input.mesh.vertexCount(); ++v) {
    TetGrid::Location l;
    if (!input.owned[v] || !std::isfinite(samples[v]) || !grid.locate(&input.mesh.positions[3 * size_t(v)], l))
      continue;
    bool usable = true;
    for (int x = 0; x < 4; ++x) usable = usable && (l.w[x] == 0 || std::isfinite(b.fit[l.vertex[x]]));
    if (!usable) continue;
    for (int x = 0; x < 4; ++x) {
      const uint32_t r = col[l.vertex[x]];
      if (r == none || l.w[x] == 0) continue;
      sums[cols.size() + r] += l.w[x] * samples[v];
      for (int y = 0; y < 4; ++y) {
        if (l.w[y] == 0) continue;
        if (col[l.vertex[y]] == none)
          sums[cols.size() + r] -= l.w[x] * l.w[y] * b.fit[l.vertex[y]];  // a fixed value
        else
          at(r, col[l.vertex[y]]) += l.w[x] * l.w[y];
      }
    }
  }
  comm.sumInPlace(sums);
  if (!root) return;
  const std::vector<double> a(sums.begin(), sums.begin() + ptrdiff_t(cols.size())),
      rhs(sums.begin() + ptrdiff_t(cols.size()), sums.end());
  std::vector<double> x(n), lo(n), hi(n);
  std::vector<uint8_t> held;
  for (uint32_t r = 0; r < n; ++r) {
    const uint32_t v = unknown[r];
    x[r] = std::isfinite(b.fit[v]) ? b.fit[v] : 0.0;
    lo[r] = b.lo[v];
    hi[r] = b.hi[v];
  }
  solveBoundedLeastSquares(rowStart, cols, a, rhs, lo, hi, kRounds, kIterations, x, held);
  std::vector<float>& values = root->s.values;
  if (values.empty()) return;
  for (uint32_t r = 0; r < n; ++r)
    if (held[r] != 2 && std::isfinite(x[r])) values[localOf[unknown[r]]] = float(std::clamp(x[r], lo[r], hi[r]));
}

}  // namespace tetstream::dist
