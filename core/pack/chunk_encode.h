// Chunk files, encode side (FORMAT.md §2-§4). Pack side only; the viewer never links this.
#pragma once
#include <cstdint>
#include <vector>

#include "manifest.h"
#include "mesh.h"
#include "status.h"

namespace tetstream {

// Starts a chunk's raw bytes with the 16-byte chunk header.
void beginChunk(std::vector<uint8_t>& raw, ChunkKind kind, uint32_t index);

// The packer's default level, at which finishChunk() tunes zstd's parameters (see there).
inline constexpr int kTunedZstdLevel = 18;

// Compresses the raw chunk with zstd at `level` into `file` and fills the size and hash fields
// of `info` (kind, counts and file name are the caller's).
Result finishChunk(const std::vector<uint8_t>& raw, int level, std::vector<uint8_t>& file, ChunkInfo& info);

// Serialises `mesh` as base-mesh chunk `index` (FORMAT.md §3) and compresses it. Fills the
// size, hash and count fields of `info` (not `file`).
Result encodeBaseChunk(const TetMesh& mesh, uint32_t index, int level, std::vector<uint8_t>& file, ChunkInfo& info);

}  // namespace tetstream
