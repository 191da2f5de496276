// Numbering for memory locality. The simplifier and the encoder walk from a vertex to the tets
// around it and on to their vertices; with a numbering that keeps neighbours close in memory
// those walks stay in the caches. Meshes from grids and most solvers are numbered that way, but
// some are not (meshers that number points as they insert them; a mesh unpacked from a stream
// comes in stream order), and those pack markedly slower.
#pragma once
#include <cstdint>

#include "mesh.h"

namespace tetstream {

// How far apart the vertices of a tet are numbered: the median, over a sample of tets, of
// (largest − smallest vertex id) / vertex count. A grid numbered layer by layer gives about
// one layer's share (0.015–0.03 on the 64³-class datasets); a scattered numbering ~0.3–0.5.
double numberingSpread(const TetMesh& mesh);

// The packer renumbers (renumberForLocality) meshes whose spread is above this and that have at
// least PackOptions::renumberMinTets tets: smaller ones stay in the caches whatever their
// numbering, and renumbering them gains no time and can make the stream larger.
inline constexpr double kScatteredNumbering = 0.2;

// Whether renumberForLocality can take the mesh: every index names a vertex, every coordinate
// is finite (else the validation says what is wrong).
bool renumberable(const TetMesh& mesh);

// Renumbers the vertices along a Morton (Z-order) curve through their positions and the tets
// by their smallest new vertex id (ties: the old order), keeping each tet's slot order (so its
// orientation). Before anything is built on the mesh: the packer renumbers before validating.
void renumberForLocality(TetMesh& mesh);

}  // namespace tetstream
