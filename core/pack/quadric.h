// Error quadrics (Garland & Heckbert; paper eq. 3-4): the boundary quadric of each vertex and
// the field quadric over the original tets it stands for, summed on every collapse (simplify.h).
#pragma once

namespace tetstream {

// A symmetric quadric form x^T Q x on N-vectors whose last entry is 1 (homogeneous), stored as
// its upper triangle, with the total weight of what was added. Sums of such forms are the error
// quadrics of Garland & Heckbert (paper eq. 3-4).
template <int N>
struct SymmetricQuadric {
  double q[N * (N + 1) / 2] = {};
  double weight = 0;
  // Adds w·(a·x)² for a plane or hyperplane a.
  void addSquare(const double (&a)[N], double w) {
    int n = 0;
    for (int r = 0; r < N; ++r)
      for (int k = r; k < N; ++k) q[n++] += w * a[r] * a[k];
    weight += w;
  }
  void add(const SymmetricQuadric& o) {
    for (int k = 0; k < N * (N + 1) / 2; ++k) q[k] += o.q[k];
    weight += o.weight;
  }
  double eval(const double (&x)[N]) const {
    double sum = 0;
    int n = 0;
    for (int r = 0; r < N; ++r)
      for (int k = r; k < N; ++k) sum += (r == k ? 1.0 : 2.0) * q[n++] * x[r] * x[k];
    return sum;
  }
};

// Boundary quadric: squared distances to the planes of the boundary faces, area weighted.
using Quadric = SymmetricQuadric<4>;

// Field quadric (Garland & Heckbert's attribute quadrics, applied to the scalar field): each tet
// defines a linear field s(x) = g·x + c; its volume-weighted squared deviation (g·x + c − s)² at a
// point (x, s) of 4D space is a quadric in (x, y, z, s, 1). Summed over the original tets around a
// vertex, and summed again on every collapse, it measures how far a kept vertex and its value
// stray from the original field over the whole region it now stands for.
using FieldQuadric = SymmetricQuadric<5>;

}  // namespace tetstream
