// A packed dataset as a reader sees it: the manifest, then chunks applied strictly in order
// (FORMAT.md). Used by the viewer (bytes arrive from the network, splits are applied a few per
// frame) and natively by the CLI and tests (bytes come from files).
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "chunk.h"
#include "manifest.h"
#include "progressive.h"
#include "quantize.h"
#include "split_stream.h"
#include "status.h"

namespace tetstream {

struct Dataset {
  Manifest manifest;
  Quantizer quant;
  ProgressiveMesh pm;            // the level reached so far (empty until the base is applied)
  uint32_t chunksApplied = 0;    // complete chunks
  uint64_t bytesApplied = 0;     // compressed bytes of the complete chunks
  ChunkDecoder decoder;
  // A split chunk being applied step by step (beginChunk / stepChunk).
  SplitReader splits;
  bool chunkOpen = false;
  uint32_t openSplitsApplied = 0;
};

// Parses the manifest and resets the dataset. Nothing is applied yet.
Result openDataset(Dataset& ds, std::string_view manifestJson);

// Verifies chunk `index` (the next one) and starts applying it. A base chunk is applied at once;
// a split chunk is then applied by stepChunk. The decoded chunk lives in ds.decoder, so `file`
// need not outlive the call.
Result beginChunk(Dataset& ds, uint32_t index, std::span<const uint8_t> file);

// Applies up to `maxSplits` splits of the open chunk, appending changed tet ids to `changed`.
// *done becomes true when the chunk is complete. On a bad record every split of this chunk is
// undone (the changed tets are reported), so the level reached by complete chunks stays.
Result stepChunk(Dataset& ds, uint32_t maxSplits, std::vector<uint32_t>& changed, bool* done);

// Verifies and applies a whole chunk. On any failure the dataset is as before.
Result applyChunk(Dataset& ds, uint32_t index, std::span<const uint8_t> file);

// Native convenience: reads DIR/manifest.json and applies the first `maxChunks` chunks (all
// when negative) from DIR, stopping inside a chunk once the mesh has `maxVertices` vertices.
Result loadPackedDir(const std::string& dir, Dataset& ds, int maxChunks = -1, uint32_t maxVertices = ~0u);

// True when DIR looks like a packed dataset (has a manifest.json).
bool isPackedDir(const std::string& path);

}  // namespace tetstream
