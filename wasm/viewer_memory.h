// How much memory the viewer needs for a level of a dataset, before any of it is fetched, and how
// much it holds now. A browser gives a page's WebAssembly at most 4 GB (wasm32; viewer.cmake sets
// MAXIMUM_MEMORY=4GB) and often less under memory pressure; the viewer stops streaming at the
// last level whose estimate fits the limit instead of running out of memory part way
// (viewer_state.h: openManifest, addChunk).
//
// The estimate uses only the manifest's per-chunk counts (vertices, tets, splits, rawBytes) and
// the viewer's per-element costs: mesh, incidence lists and undo log (progressive.h), the kept split
// payloads (dataset.h), the isosurface with its interval tree (isosurface_incremental.h, ~49
// bytes per tet measured on Harmonic 64), and the hull (core/hull.h: ~110 bytes per boundary
// triangle, boundary triangles guessed from the tet count as for a cube). It is an estimate:
// a surface far bigger than a smooth field gives (noise) or a very thin domain can need more;
// tests/unit/test_viewer_state.cpp checks it against the measured use on Harmonic grids.
#pragma once
#include <cstdint>
#include <string>

#include "dataset.h"

namespace tetstream::viewer {

// What a set of chunks brings, from the manifest's counts: the estimate's inputs.
struct LevelCounts {
  double vertices = 0, tets = 0, splits = 0;
  double payloadBytes = 0;  // decompressed split records, kept for redo
  double largestRaw = 0;    // the decoder's buffer: the largest chunk
};
// What chunk `index` adds (the base: its mesh). A chunk's vertices and tets are the difference
// of the manifest's counts after it and after the chunk before it, so they hold in whatever order
// the chunks of a patch hierarchy arrive.
LevelCounts chunkCounts(const Manifest& m, uint32_t index);
void addCounts(LevelCounts& total, const LevelCounts& more);
void subtractCounts(LevelCounts& total, const LevelCounts& less);

// The memory budget (bytes). The platform sets the limit (the browser's wasm maximum, or the
// page's ?maxMemoryMB=; 0 = none), the heap in use before any dataset (code, stack, UI), the heap
// size and the GPU buffers, and may install reserveHeap. openManifest sets the rest.
struct MemoryBudget {
  uint64_t limitBytes = 0, baseBytes = 0;
  uint64_t heapBytes = 0, gpuBytes = 0;
  uint64_t allocatedBytes = 0;  // what malloc has handed out and not taken back (the heap less its free space)
  uint64_t neededBytes = 0;     // estimate for the whole dataset
  LevelCounts received;         // what the chunks received so far bring
  uint32_t chunksAllowed = 0;   // chunks whose level fits the limit (all of them without one)
  bool limited = false;         // stopped short of the full dataset for lack of memory
  // Grows the heap to at least `bytes` now; false when the browser refuses.
  bool (*reserveHeap)(uint64_t bytes) = nullptr;
};

// Heap bytes the viewer's data takes for those counts, with the mesh arrays reserved for them.
uint64_t estimateBytes(const Manifest& m, const LevelCounts& counts);

// The same for the level made of the first `chunks` chunks (base included, clamped to the
// manifest).
uint64_t estimateLevelBytes(const Manifest& m, uint32_t chunks);

// The most chunks whose level fits in `budgetBytes` (0 when not even the base fits).
uint32_t chunksThatFit(const Manifest& m, uint64_t budgetBytes);

// Bytes the dataset's arrays hold now (vector capacities): mesh, incidence, undo log, payloads.
uint64_t datasetMemoryBytes(const Dataset& ds);

// "512 KB", "1.5 MB", "12 MB", "1.2 GB": the one byte formatter of the viewer (messages, panel).
std::string formatBytes(uint64_t bytes);

}  // namespace tetstream::viewer
