// `tetstream pack`: turns a mesh into a packed dataset folder (FORMAT.md).
// Version 0.1 writes the base chunk only (the whole mesh); the progressive packer of the next
// version adds simplification and vertex-split chunks behind the same entry point.
#pragma once
#include <string>
#include <vector>

#include "manifest.h"
#include "mesh.h"
#include "status.h"

namespace tetstream {

struct PackOptions {
  std::string field;     // field that steers simplification and is shown first; "" = first field
  std::string name;      // dataset name; "" = mesh.name
  int zstdLevel = 9;
};

struct PackSummary {
  Manifest manifest;
  uint64_t flippedTets = 0;         // negatively oriented tets re-oriented (FORMAT.md §3)
  std::vector<std::string> notes;   // what the packer changed or found, in plain words
};

// Validates, orients and writes `mesh` to `outDir` (created if missing). The manifest is
// written last and atomically, so a reader never sees a manifest without its chunks; stale
// chunk files of an earlier pack in the folder are removed.
Result packMesh(TetMesh mesh, const std::string& outDir, const PackOptions& options, PackSummary& summary);

}  // namespace tetstream
