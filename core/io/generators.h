// Built-in datasets: structured grids split into tetrahedra, with analytic fields. Used by
// `tetstream gen`, the demo and the tests (no test depends on outside data).
#pragma once
#include <cstdint>

#include "mesh.h"

namespace tetstream {

// n × n × n vertices evenly spaced over [-1, 1]³; every cube split into the 6 tetrahedra
// around its main diagonal (Kuhn split: conforming, all positively oriented).
// (n-1)³ · 6 tets; n = 64 gives 1,500,282. Precondition: n >= 2.
TetMesh makeGridMesh(uint32_t n);

// The paper's Harmonic dataset (§5): a spherical harmonic with exponentially decreasing
// radial dependency, here the d_z² orbital shape
//   harmonic(p) = (9/8)·e²·(2z² − x² − y²)·exp(−3|p|),
// scaled so that its maximum (at z = ±2/3 on the axis) is 1. Adds the field "harmonic".
void addHarmonicField(TetMesh& mesh);

// Distance from the origin, field "distance": its isosurfaces are spheres (tests).
void addDistanceField(TetMesh& mesh);

}  // namespace tetstream
