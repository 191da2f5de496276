// Chunk files (FORMAT.md §2-§3), decode side: integrity checks, zstd decompression, header and
// base-mesh payload parsing. Everything here treats its input as hostile: any inconsistency
// gives a Result, never an assert, a crash or a partly filled mesh.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "manifest.h"
#include "mesh.h"
#include "status.h"

struct ZSTD_DCtx_s;

namespace tetstream {

inline constexpr uint8_t kChunkMagic[4] = {'T', 'S', 'C', '1'};
inline constexpr size_t kChunkHeaderBytes = 16;
inline constexpr size_t kBaseHeaderBytes = 16;  // V, T, F, flags

// Long-lived decode context: create once, reuse for every chunk (the zstd context and the
// output buffer keep their memory).
struct ChunkDecoder {
  ZSTD_DCtx_s* dctx = nullptr;
  std::vector<uint8_t> raw;  // decompressed chunk, header included
  ChunkDecoder() = default;
  ChunkDecoder(const ChunkDecoder&) = delete;
  ChunkDecoder& operator=(const ChunkDecoder&) = delete;
  ~ChunkDecoder();
};

// Checks size and hash against `info`, decompresses, checks the chunk header (magic, version,
// kind, index). On success `payload` views the bytes after the header inside `dec.raw`.
// hashChecked: the caller has compared these bytes' content hash already (hashing is the
// costliest check, and the viewer checks a chunk as it arrives).
Result openChunk(ChunkDecoder& dec, const ChunkInfo& info, uint32_t index, std::span<const uint8_t> file,
                 std::span<const uint8_t>& payload, bool hashChecked = false);

// Parses a base-mesh payload into `out` (replacing its contents) and checks every rule of
// FORMAT.md §3 against the manifest. On failure `out` is left empty.
Result decodeBaseMesh(std::span<const uint8_t> payload, const Manifest& manifest, TetMesh& out);

}  // namespace tetstream
