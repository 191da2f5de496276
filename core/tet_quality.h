// Tetrahedron shape measure of paper §3.3: the condition number κ(S) of the matrix S = A·W⁻¹
// that maps an equilateral tetrahedron onto the tet (Freitag & Knupp). κ = 3 for an equilateral
// tet and grows without bound as it flattens; the paper's shape measure is M(T) = κ(S) − 3.
// Closed form used here (checked against the matrix definition in tests):
//   κ = sqrt(Σ edge lengths²) · sqrt(Σ face areas²) / (6 |V|)
#pragma once
#include <cmath>
#include <limits>

#include "tet_tables.h"

namespace tetstream {

// Everything the simplifier's tests need about one tet, from shared edge vectors:
// det = 6·signed volume, the sum of squared edge lengths, the longest squared edge and the sum
// of squared face areas. κ = sqrt(edgeSum · areaSum) / |det|.
struct TetShape {
  double det, edgeSum, longestEdge, areaSum;
  double kappa() const {
    return det == 0 ? std::numeric_limits<double>::infinity() : std::sqrt(edgeSum * areaSum) / std::abs(det);
  }
};

inline TetShape tetShape(const double* a, const double* b, const double* c, const double* d) {
  double e1[3], e2[3], e3[3], e4[3], e5[3], e6[3];  // ab ac ad bc bd cd
  for (int k = 0; k < 3; ++k) {
    e1[k] = b[k] - a[k];
    e2[k] = c[k] - a[k];
    e3[k] = d[k] - a[k];
    e4[k] = c[k] - b[k];
    e5[k] = d[k] - b[k];
    e6[k] = d[k] - c[k];
  }
  auto dot = [](const double* u, const double* v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; };
  auto crossNorm2 = [](const double* u, const double* v, double* n) {
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
    return n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
  };
  double l[6] = {dot(e1, e1), dot(e2, e2), dot(e3, e3), dot(e4, e4), dot(e5, e5), dot(e6, e6)};
  TetShape s;
  s.edgeSum = l[0] + l[1] + l[2] + l[3] + l[4] + l[5];
  s.longestEdge = l[0];
  for (double x : l) s.longestEdge = x > s.longestEdge ? x : s.longestEdge;
  double n[3], scratch[3];
  // Twice the face areas, squared: faces abc, abd, acd (at a) and bcd.
  double f0 = crossNorm2(e2, e3, n);  // acd; n = ac × ad also gives the determinant
  s.det = dot(e1, n);
  s.areaSum = 0.25 * (f0 + crossNorm2(e1, e2, scratch) + crossNorm2(e1, e3, scratch) + crossNorm2(e4, e5, scratch));
  return s;
}

// κ(S) of tet (a, b, c, d) in double; +infinity for a flat tet.
inline double tetConditionNumber(const double* a, const double* b, const double* c, const double* d) {
  const double* p[4] = {a, b, c, d};
  double l2 = 0;
  for (const auto& e : kTetEdges)
    for (int k = 0; k < 3; ++k) {
      double x = p[e[1]][k] - p[e[0]][k];
      l2 += x * x;
    }
  double a2 = 0;
  for (const auto& f : kTetFaces) {
    double u[3], v[3];
    for (int k = 0; k < 3; ++k) {
      u[k] = p[f[1]][k] - p[f[0]][k];
      v[k] = p[f[2]][k] - p[f[0]][k];
    }
    double cx = u[1] * v[2] - u[2] * v[1], cy = u[2] * v[0] - u[0] * v[2], cz = u[0] * v[1] - u[1] * v[0];
    a2 += 0.25 * (cx * cx + cy * cy + cz * cz);
  }
  double u[3], v[3], w[3];
  for (int k = 0; k < 3; ++k) {
    u[k] = b[k] - a[k];
    v[k] = c[k] - a[k];
    w[k] = d[k] - a[k];
  }
  double det =
      u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
  if (det == 0) return std::numeric_limits<double>::infinity();
  return std::sqrt(l2) * std::sqrt(a2) / std::abs(det);
}

}  // namespace tetstream
