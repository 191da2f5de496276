// How much memory the viewer needs for a level of a dataset, before any of it is fetched, and how
// much it holds now. A browser gives a page's WebAssembly at most 4 GB (wasm32; viewer.cmake sets
// MAXIMUM_MEMORY=4GB) and often less under memory pressure; the viewer stops streaming at the
// last level whose estimate fits the limit instead of running out of memory part way
// (viewer_state.h: openManifest, addChunk).
//
// The estimate uses only the manifest's per-chunk counts (vertices, tets, splits, rawBytes) and
// the viewer's per-element costs: mesh, incidence lists and undo log (progressive.h), the kept split
// payloads (dataset.h), the isosurface with its interval tree (isosurface_incremental.h, ~49
// bytes per tet measured on Harmonic 64), and the hull (viewer_state.h: ~110 bytes per boundary
// triangle, boundary triangles guessed from the tet count as for a cube). It is an estimate:
// a surface far bigger than a smooth field gives (noise) or a very thin domain can need more;
// tests/unit/test_viewer_state.cpp checks it against the measured use on Harmonic grids.
#pragma once
#include <cstdint>

#include "dataset.h"

namespace tetstream::viewer {

// Heap bytes the viewer's data takes at the level made of the first `chunks` chunks (base
// included, clamped to the manifest), with the mesh arrays reserved for that level.
uint64_t estimateLevelBytes(const Manifest& m, uint32_t chunks);

// The most chunks whose level fits in `budgetBytes` (0 when not even the base fits).
uint32_t chunksThatFit(const Manifest& m, uint64_t budgetBytes);

// Bytes the dataset's arrays hold now (vector capacities): mesh, incidence, undo log, payloads.
uint64_t datasetMemoryBytes(const Dataset& ds);

// "12.3 MB", "1.2 GB": for messages.
std::string formatBytes(uint64_t bytes);

}  // namespace tetstream::viewer
