// `tetstream pack`: turns a mesh into a packed dataset folder (FORMAT.md): validate, orient,
// quantize, simplify by half-edge collapses down to a small base mesh (simplify.h), encode the
// reversed collapses as vertex-split chunks (split_encode.h), write chunks and manifest.
#pragma once
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "manifest.h"
#include "mesh.h"
#include "status.h"

namespace tetstream {

struct PackOptions {
  std::string field;                        // field that steers simplification and is shown first; "" = first field
  std::string name;                         // dataset name; "" = mesh.name
  int zstdLevel = 18;                       // higher levels take much longer for hardly fewer bytes
  double weights[3] = {100.0, 1.0, 0.005};  // geometry, field, shape (simplify.h)
  double baseFraction = 0.01;               // base mesh size as a fraction of the vertices...
  uint32_t baseVertices = 0;                // ...or as a vertex count (wins when non-zero)
  uint32_t minBaseVertices = 256;           // floor for the fraction rule on small meshes
  uint32_t maxBaseVertices = 65536;         // cap of the fraction rule on huge meshes (see packer.cpp)
  uint32_t baseTets = 0;                    // stop earlier once the base has this many tets
  double maxError = std::numeric_limits<double>::infinity();  // stop at this field error (SimplifyOptions)
  bool lossless = false;                                      // keep float32 values in split records
  bool fitValues = true;         // coarse levels get fitted values (SimplifyOptions::fitValues)
  uint32_t chunkKb = 256;        // largest split chunk, compressed
  bool ringWalk = true;          // rings as walks in p_j's link (StreamOptions::ringWalk)
  bool orderSplits = false;      // splits by kept vertex inside each chunk (pack --compact)
  double maxMemoryBytes = 0;     // refuse meshes that need more (0: 90% of physical memory)
  int threads = 2;               // threads that evaluate collapse costs and measure levels (1 or 2; same output)
  uint32_t leafVertices = 2048;  // largest region of the patch hierarchy (SimplifyOptions)
  // At most this many leaves (leafVerticesFor): every node is a manifest entry, which a viewer
  // fetches and reads before the first picture (about 90 bytes gzipped and 40 µs in wasm each).
  uint32_t maxLeaves = 16384;
  uint32_t renumberMinTets = 50000;  // renumber scattered meshes from this size (pack/renumber.h)
  // Progress for displays: phase ("validate", "simplify", "encode", "write"), items done and
  // planned in that phase (collapses, splits; 0 planned when not countable).
  std::function<void(const char* phase, uint64_t done, uint64_t planned)> progress;
};

struct PackSummary {
  Manifest manifest;
  uint64_t flippedTets = 0;  // negatively oriented tets re-oriented (FORMAT.md §3)
  uint32_t baseVertices = 0, baseTets = 0, splits = 0;
  uint32_t flatTetsRemoved = 0, flatTetsLeft = 0;
  uint32_t movedMasks = 0;  // splits that carry a mask of T_moved (it does not follow from T_new)
  uint64_t queuePops = 0, requeued = 0, costEvaluations = 0;  // simplifier work, for benchmarks
  uint32_t regionCollapses = 0;  // of the collapses, those made below the root (two threads at once)
  std::string stopReason;        // why simplification stopped
  double prepareMs = 0, simplifyMs = 0, encodeMs = 0, writeMs = 0;  // prepare: checks, orientation, grid
  std::vector<std::string> notes;                                   // what the packer changed or found, in plain words
};

// The leaf size for a mesh cut into `parts` trees (one a process; MPI ranks: one a rank), the
// largest of `largestPart` vertices: options.leafVertices, or larger when that would make more
// than options.maxLeaves leaves in all (a note saying so is added to `notes`).
uint32_t leafVerticesFor(uint64_t largestPart, uint32_t parts, const PackOptions& options,
                         std::vector<std::string>& notes);

// Validates and packs `mesh` into `outDir` (created if missing). The manifest is written last
// and atomically, so a reader never sees a manifest without its chunks; stale chunk files of an
// earlier pack in the folder are removed.
Result packMesh(TetMesh mesh, const std::string& outDir, const PackOptions& options, PackSummary& summary);

}  // namespace tetstream
