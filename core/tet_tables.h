// The one place that owns tetrahedron numbering. Adjacency, validation, the inversion test and
// marching tetrahedra all use these tables; tests/unit/test_tet_tables.cpp checks them by brute
// force. All tables assume a positively oriented tet (mesh.h): det(v1-v0, v2-v0, v3-v0) > 0.
#pragma once
#include <cstdint>

namespace tetstream {

// Local edges, (a, b) with a < b. Edge e of tet t joins tets[4t+kTetEdges[e][0]] and ...[1].
inline constexpr uint8_t kTetEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

// Local faces: face f is opposite local vertex f, listed so that its normal (right-hand rule)
// points out of a positively oriented tet. Half-face id of face f of tet t is 4t + f.
inline constexpr uint8_t kTetFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

// Marching tetrahedra (paper §4.1). Case index: bit i set when vertex i is strictly above the
// isovalue (s_i > λ); a vertex equal to λ counts as below, so every case is well-defined and
// neighbouring tets agree on every shared edge. Each case lists up to two triangles as local
// edge ids (kTetEdges); the surface vertex of an edge lies on it by linear interpolation
// (paper eq. 7). Triangles are wound so that their normal points toward increasing field
// (toward the vertices above λ) in a positively oriented tet; extraction flips them for a
// negatively oriented one.
struct MarchingCase {
  uint8_t triangleCount;
  int8_t edges[6];
};

inline constexpr MarchingCase kMarchingTets[16] = {
    {0, {-1, -1, -1, -1, -1, -1}},  // ----
    {1, {0, 2, 1, -1, -1, -1}},     // v0 above
    {1, {0, 3, 4, -1, -1, -1}},     // v1
    {2, {1, 3, 4, 1, 4, 2}},        // v0 v1
    {1, {1, 5, 3, -1, -1, -1}},     // v2
    {2, {0, 2, 5, 0, 5, 3}},        // v0 v2
    {2, {0, 1, 5, 0, 5, 4}},        // v1 v2
    {1, {2, 5, 4, -1, -1, -1}},     // v0 v1 v2
    {1, {2, 4, 5, -1, -1, -1}},     // v3
    {2, {0, 4, 5, 0, 5, 1}},        // v0 v3
    {2, {0, 3, 5, 0, 5, 2}},        // v1 v3
    {1, {1, 3, 5, -1, -1, -1}},     // v0 v1 v3
    {2, {1, 2, 4, 1, 4, 3}},        // v2 v3
    {1, {0, 4, 3, -1, -1, -1}},     // v0 v2 v3
    {1, {0, 1, 2, -1, -1, -1}},     // v1 v2 v3
    {0, {-1, -1, -1, -1, -1, -1}},  // all above
};

}  // namespace tetstream
