// A packed dataset as a reader sees it: the manifest, then chunks applied strictly in order
// (FORMAT.md). Used by the viewer (bytes arrive from the network) and natively by the CLI and
// tests (bytes come from files).
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "chunk.h"
#include "manifest.h"
#include "mesh.h"
#include "status.h"

namespace tetstream {

struct Dataset {
  Manifest manifest;
  TetMesh mesh;                 // the level reached so far (empty until the base is applied)
  uint32_t chunksApplied = 0;
  uint64_t bytesApplied = 0;    // compressed bytes of the applied chunks
  ChunkDecoder decoder;
};

// Parses the manifest and resets the dataset. Nothing is applied yet.
Result openDataset(Dataset& ds, std::string_view manifestJson);

// Verifies and applies chunk `index`, which must be the next one (ds.chunksApplied). On any
// failure the dataset is unchanged, so the level already shown stays valid.
Result applyChunk(Dataset& ds, uint32_t index, std::span<const uint8_t> file);

// Native convenience: reads DIR/manifest.json and applies the first `maxChunks` chunks
// (all when negative) from DIR.
Result loadPackedDir(const std::string& dir, Dataset& ds, int maxChunks = -1);

// True when DIR looks like a packed dataset (has a manifest.json).
bool isPackedDir(const std::string& path);

}  // namespace tetstream
