// Chunk files, encode side (FORMAT.md §2-§3). Pack side only; the viewer never links this.
#pragma once
#include <cstdint>
#include <vector>

#include "manifest.h"
#include "mesh.h"
#include "status.h"

namespace tetstream {

// Serialises `mesh` as base-mesh chunk `index` and compresses it with zstd at `level`.
// Fills the size, hash and count fields of `info` (not `file`).
Result encodeBaseChunk(const TetMesh& mesh, uint32_t index, int level, std::vector<uint8_t>& file, ChunkInfo& info);

}  // namespace tetstream
