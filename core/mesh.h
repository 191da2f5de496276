// The tetrahedral mesh as flat arrays (structure of arrays).
//   positions: 3 floats per vertex (x, y, z), any unit.
//   tets:      4 uint32 vertex ids per tetrahedron; tetrahedron t is tets[4t .. 4t+3].
//   fields:    named point scalar fields, one float per vertex each.
// Positive orientation means det(b-a, c-a, d-a) > 0 for tet (a, b, c, d) (paper eq. 1).
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace tetstream {

struct ScalarField {
  std::string name;
  std::vector<float> values;  // one per vertex
};

struct TetMesh {
  std::string name;
  std::vector<float> positions;  // 3 * vertexCount
  std::vector<uint32_t> tets;    // 4 * tetCount
  std::vector<ScalarField> fields;

  uint32_t vertexCount() const { return uint32_t(positions.size() / 3); }
  uint32_t tetCount() const { return uint32_t(tets.size() / 4); }
  // Index into fields, or -1.
  int findField(std::string_view fieldName) const;
};

struct Bounds {
  float min[3] = {0, 0, 0};
  float max[3] = {0, 0, 0};
  float diagonal() const;
};

struct Range {
  float min = 0, max = 0;
};

Bounds computeBounds(std::span<const float> positions);
// Range of the finite values; {0,0} when there are none.
Range computeRange(std::span<const float> values);

// The key of the undirected edge (a, b): the smaller id in the high 32 bits, the larger in the low.
inline uint64_t edgeKey(uint32_t a, uint32_t b) { return a < b ? uint64_t(a) << 32 | b : uint64_t(b) << 32 | a; }

// Signed volume of tet (a, b, c, d), paper eq. (1), computed in double.
double tetVolume(const float* a, const float* b, const float* c, const float* d);
inline double tetVolume(const TetMesh& m, uint32_t t) {
  const uint32_t* v = &m.tets[4 * size_t(t)];
  const float* p = m.positions.data();
  return tetVolume(p + 3 * size_t(v[0]), p + 3 * size_t(v[1]), p + 3 * size_t(v[2]), p + 3 * size_t(v[3]));
}
// Barycentric coordinates of point x in tet q (by volumes); returns the smallest of them
// (negative: outside), or -infinity for a flat tet.
double barycentric(const float* const q[4], const float* x, double l[4]);

}  // namespace tetstream
