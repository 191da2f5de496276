// manifest.json of a packed dataset (FORMAT.md §1): parsing with full validation of untrusted
// input, and writing.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "mesh.h"
#include "status.h"

namespace tetstream {

// Manifests are written as version 2 (a hierarchy of nodes, FORMAT.md §1.1); version 1 (one
// sequence of chunks, no nodes) is still read. Chunk files did not change: their header keeps
// its own version, kChunkVersion.
inline constexpr uint32_t kFormatVersion = 2;
inline constexpr uint32_t kChunkVersion = 1;
// The largest manifest a reader takes (FORMAT.md §5), in bytes and in chunks. The packer keeps
// its manifests within both (PackOptions::maxLeaves) and refuses to write one that is not.
inline constexpr uint64_t kManifestLimitBytes = 64ull << 20;
inline constexpr size_t kManifestMaxChunks = size_t(1) << 18;
inline constexpr const char* kLibraryVersion = "0.3.0";

// The most a chunk of `bytes` compressed bytes may declare after decompression: zstd on mesh
// data gives 2-5x, so 64x (+1 MiB for tiny chunks), and never more than 1 GiB. Guards the
// decompression buffer against a hostile manifest or frame.
inline constexpr uint64_t kMaxChunkRawBytes = 1ull << 30;
inline constexpr uint64_t maxRawBytesFor(uint64_t bytes) {
  const uint64_t byRatio = 64 * bytes + (1u << 20);
  return byRatio < kMaxChunkRawBytes ? byRatio : kMaxChunkRawBytes;
}

enum class ChunkKind : uint8_t { Base = 1, Splits = 2 };

struct FieldInfo {
  std::string name;
  Range range;
};

struct ChunkInfo {
  std::string file;  // relative to the manifest's folder
  ChunkKind kind = ChunkKind::Base;
  uint64_t bytes = 0;     // compressed file size
  uint64_t rawBytes = 0;  // decompressed size
  uint64_t hash = 0;      // XXH3-64 of the file
  uint32_t vertices = 0;  // counts after applying this chunk
  uint32_t tets = 0;
  uint32_t splits = 0;
  double fieldError = 0;
  // Measured at the input's vertices (level_error.h), in units of isoField; -1 when not given.
  double fieldRms = -1, fieldMax = -1;
};

// A node of the patch hierarchy (FORMAT.md §1.1): a region of the mesh and the splits that
// refine it. Its splits need those of its ancestors and of nothing else, so any set of nodes
// that holds every selected node's parent, applied parents first, is a valid mesh.
struct NodeInfo {
  int32_t parent = -1;                      // index in Manifest::nodes, below this node's; -1: the base
  uint32_t firstChunk = 0, chunkCount = 0;  // its chunks: Manifest::chunks[firstChunk, +chunkCount)
  // Stable ids its splits create, whatever other nodes are loaded: vertices [vertexBegin,
  // vertexEnd) (one a split) and tets [tetBegin, tetEnd), in the numbering of the whole stream.
  uint32_t vertexBegin = 0, vertexEnd = 0, tetBegin = 0, tetEnd = 0;
  Bounds bounds;              // of its region's input vertices
  std::vector<Range> ranges;  // per field (manifest order): min and max over its region at full resolution
  double fieldError = 0;      // estimated (simplifier) field error in its region before its splits, isoField units
  double fieldRms = -1, fieldMax = -1;  // measured there at the input's vertices; -1 when not given
};

struct Manifest {
  uint32_t formatVersion = kFormatVersion;
  std::string generator;
  std::string name;
  Bounds bounds;
  uint32_t vertices = 0, tets = 0;  // full mesh
  std::vector<FieldInfo> fields;
  std::string isoField;
  bool lossless = false;
  int positionBits = 16, fieldBits = 16;
  std::vector<ChunkInfo> chunks;
  std::vector<NodeInfo> nodes;  // version 2; empty for version 1 (one sequence)

  uint64_t totalBytes() const;
  int findField(std::string_view name) const;
};

// Parses and validates; on failure `out` is unspecified and the message names the bad key.
Result parseManifest(std::string_view json, Manifest& out);
std::string writeManifest(const Manifest& m);

}  // namespace tetstream
