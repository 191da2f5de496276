// The last level's values, fitted again at the end (simplifier.h).
#include "pack/bounded_cg.h"
#include "pack/simplifier.h"

namespace tetstream::simplify_detail {

// Each collapse fits j's value to the region j then stands for, but later collapses around j
// change how the coarse field interpolates there. So at the end the values of the vertices
// that stand for others are fitted again, all together: least squares of the coarse field
// against the input field at every input vertex (the RMS error the benchmarks measure),
// solved by conjugate gradients. A split restores the value j had before its collapse (the
// log keeps it), so the finer levels and the full mesh are unchanged; a vertex that stands
// only for itself keeps its sample, as no split would give it back.
void Simplifier::refitValues() {
  const uint32_t none = ~0u;
  std::vector<uint32_t> rep(V_), col(V_, none);
  for (uint32_t v = 0; v < V_; ++v) rep[v] = v;
  const CollapseLog& log = out_.log;
  for (uint32_t c = log.size(); c-- > 0;) rep[log.i[c]] = rep[log.j[c]];
  std::vector<uint32_t> free;  // the unknowns: alive vertices that stand for others
  for (uint32_t v = 0; v < V_; ++v)
    if (out_.vertexAlive[v] && represented_[v] > 1) {
      col[v] = uint32_t(free.size());
      free.push_back(v);
    }
  if (free.empty()) return;
  // The normal equations' matrix, one row per unknown over the unknowns among its neighbours
  // and itself (column = unknown index; col[] grows with the vertex id, so sorted either way).
  const uint32_t n = uint32_t(free.size());
  std::vector<uint32_t> rowStart(n + 1, 0), cols;
  for (uint32_t r = 0; r < n; ++r) {
    Scratch& sc = mainScratch_;
    neighbours(sc, free[r], sc.nbr);
    sc.nbr.push_back(free[r]);
    std::sort(sc.nbr.begin(), sc.nbr.end());
    for (uint32_t w : sc.nbr)
      if (col[w] != none) cols.push_back(col[w]);
    rowStart[r + 1] = uint32_t(cols.size());
  }
  // Each value keeps to the range of the region that last collapsed onto it (lastNode_).
  auto lo = [&](uint32_t r) { return nodeLo(lastNode_.empty() ? 1u : lastNode_[free[r]]); };
  auto hi = [&](uint32_t r) { return nodeHi(lastNode_.empty() ? 1u : lastNode_[free[r]]); };
  std::vector<double> a(cols.size(), 0.0), rhs(n, 0.0);
  auto at = [&](uint32_t r, uint32_t c) -> double& {
    auto it = std::lower_bound(cols.begin() + rowStart[r], cols.begin() + rowStart[r + 1], c);
    assert(it != cols.begin() + rowStart[r + 1] && *it == c);
    return a[size_t(it - cols.begin())];
  };
  // Every input vertex located in the coarse mesh (two threads, each a range of vertices),
  // then its squared error added to the rows of the unknowns around it (two threads, each its
  // own rows, taking the vertices in order: every sum is formed as on one thread).
  struct Located {
    uint32_t t4[4];
    double w[4];
    bool usable;  // inside the mesh, and a sample and neighbour values that are numbers
  };
  std::vector<Located> located(V_);
  onBoth([&](int half) {
    for (uint32_t v = half ? V_ / 2 : 0, end = half ? V_ : V_ / 2; v < end; ++v) {
      Located& l = located[v];
      l.usable = false;
      if (out_.vertexAlive[v]) {
        l.t4[0] = v;
        l.w[0] = 1;
        for (int k = 1; k < 4; ++k) l.t4[k] = v, l.w[k] = 0;
      } else if (star_[rep[v]].empty() || !locate(v, star_[rep[v]].front(), l.t4, l.w)) {
        continue;  // (a vertex of no tet stands nowhere)
      }
      l.usable = std::isfinite(field_[v]);  // a NaN or infinite sample (or neighbour value) fits nothing
      for (int x = 0; x < 4; ++x) l.usable = l.usable && (l.w[x] == 0 || std::isfinite(vert_[l.t4[x]].fit));
    }
  });
  onBoth([&](int half) {
    const uint32_t lo = half ? n / 2 : 0, hi = half ? n : n / 2;
    for (uint32_t v = 0; v < V_; ++v) {
      const Located& l = located[v];
      if (!l.usable) continue;
      const double f = field_[v];
      for (int x = 0; x < 4; ++x) {
        const uint32_t r = col[l.t4[x]];
        if (r == none || r < lo || r >= hi || l.w[x] == 0) continue;
        rhs[r] += l.w[x] * f;
        for (int y = 0; y < 4; ++y) {
          if (l.w[y] == 0) continue;
          if (col[l.t4[y]] == none)
            rhs[r] -= l.w[x] * l.w[y] * vert_[l.t4[y]].fit;  // a fixed value
          else
            at(r, col[l.t4[y]]) += l.w[x] * l.w[y];
        }
      }
    }
  });
  // From the values the collapses fitted, each kept to its region's range (bounded_cg.h).
  std::vector<double> x(n), lower(n), upper(n);
  std::vector<uint8_t> held;
  for (uint32_t r = 0; r < n; ++r) {
    x[r] = std::isfinite(vert_[free[r]].fit) ? vert_[free[r]].fit : 0.0;
    lower[r] = lo(r);
    upper[r] = hi(r);
  }
  solveBoundedLeastSquares(rowStart, cols, a, rhs, lower, upper, kRefitRounds, kRefitIterations, x, held);
  for (uint32_t r = 0; r < n; ++r)
    if (held[r] != 2 && std::isfinite(x[r])) vert_[free[r]].fit = float(std::clamp(x[r], lo(r), hi(r)));
}

// The tet of the current mesh holding input vertex x, by walking from tet `t` across the face with the
// most negative barycentric coordinate; outside the mesh (the boundary moved inwards), the
// tet x is least outside of, with its coordinates clamped to the tet. Weights by vertex.
bool Simplifier::locate(uint32_t x, uint32_t t, uint32_t* vertices, double* w) const {
  const float* P = mesh_.positions.data();
  double best = -kInf;
  bool found = false;
  for (int step = 0; step < 64; ++step) {
    const uint32_t* v = &out_.tets[4 * size_t(t)];
    const float* q[4] = {P + 3 * size_t(v[0]), P + 3 * size_t(v[1]), P + 3 * size_t(v[2]), P + 3 * size_t(v[3])};
    double l[4];
    if (barycentric(q, P + 3 * size_t(x), l) == -kInf) break;  // flat (left from the input): no coordinates
    int worst = 0;
    for (int k = 1; k < 4; ++k)
      if (l[k] < l[worst]) worst = k;
    if (l[worst] > best) {
      best = l[worst];
      found = true;
      double sum = 0;
      for (int k = 0; k < 4; ++k) sum += std::max(0.0, l[k]);
      for (int k = 0; k < 4; ++k) {
        vertices[k] = v[k];
        w[k] = std::max(0.0, l[k]) / sum;
      }
    }
    if (l[worst] >= 0) break;  // inside
    const uint32_t next = opp_[4 * size_t(t) + size_t(worst)];
    if (next == kNoNeighbor) break;
    t = next >> 2;
  }
  return found;
}

}  // namespace tetstream::simplify_detail

namespace tetstream {

void solveBoundedLeastSquares(const std::vector<uint32_t>& rowStart, const std::vector<uint32_t>& cols,
                              const std::vector<double>& a, const std::vector<double>& rhs,
                              const std::vector<double>& lo, const std::vector<double>& hi, int rounds, int iterations,
                              std::vector<double>& x, std::vector<uint8_t>& held) {
  const uint32_t n = uint32_t(rhs.size());
  std::vector<double> res(n), z(n), d(n), q(n), inverse(n);
  held.assign(n, 0);
  for (uint32_t r = 0; r < n; ++r) {
    double diagonal = 0;
    for (uint32_t k = rowStart[r]; k < rowStart[r + 1]; ++k)
      if (cols[k] == r) diagonal = a[k];
    inverse[r] = diagonal > 0 ? 1 / diagonal : 0.0;
    if (!(diagonal > 0)) held[r] = 2;  // no usable sample around it: it keeps its value
  }
  auto multiply = [&](const std::vector<double>& in, std::vector<double>& out) {
    for (uint32_t r = 0; r < n; ++r) {
      double sum = 0;
      for (uint32_t k = rowStart[r]; k < rowStart[r + 1]; ++k) sum += a[k] * in[cols[k]];
      out[r] = held[r] ? 0.0 : sum;
    }
  };
  for (int round = 0; round < rounds; ++round) {
    multiply(x, q);
    double rz = 0, norm = 0;
    for (uint32_t r = 0; r < n; ++r) {
      res[r] = held[r] ? 0.0 : rhs[r] - q[r];
      z[r] = res[r] * inverse[r];
      d[r] = z[r];
      rz += res[r] * z[r];
      norm += held[r] ? 0.0 : rhs[r] * rhs[r];
    }
    for (int iter = 0; iter < iterations && rz > 1e-24 * norm; ++iter) {
      multiply(d, q);
      double dq = 0;
      for (uint32_t r = 0; r < n; ++r) dq += d[r] * q[r];
      if (!(dq > 0)) break;
      const double alpha = rz / dq;
      double rzNext = 0;
      for (uint32_t r = 0; r < n; ++r) {
        x[r] += alpha * d[r];
        res[r] -= alpha * q[r];
        z[r] = res[r] * inverse[r];
        rzNext += res[r] * z[r];
      }
      const double beta = rzNext / rz;
      rz = rzNext;
      for (uint32_t r = 0; r < n; ++r) d[r] = z[r] + beta * d[r];
    }
    bool crossed = false;
    for (uint32_t r = 0; r < n; ++r) {
      if (held[r] || (x[r] >= lo[r] && x[r] <= hi[r])) continue;
      x[r] = std::clamp(x[r], lo[r], hi[r]);
      held[r] = 1;
      crossed = true;
    }
    if (!crossed) break;
  }
}

}  // namespace tetstream
