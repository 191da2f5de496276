// A packed dataset as a reader sees it (FORMAT.md): the manifest, chunks received and verified
// strictly in order, and a level of detail that can move back and forth over the splits
// received so far. Used by the viewer (bytes arrive from the network, splits are applied a
// few per frame, the user moves a level slider) and natively by the CLI and tests.
//
// Receiving and applying are separate: receiveChunk() verifies a chunk completely (size, hash,
// zstd, header) and keeps its decoded payload; stepTowards() then applies or undoes splits one
// at a time toward a target level. Undo needs nothing stored (the mesh holds it, progressive.h);
// redo re-reads the kept payload at the record's remembered offset.
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
  ProgressiveMesh pm;  // the current level (empty until the base is received)
  ChunkDecoder decoder;
  uint32_t chunksReceived = 0;                 // verified chunks, base included
  uint64_t bytesReceived = 0;                  // compressed bytes of the verified chunks
  std::vector<std::vector<uint8_t>> payloads;  // per received chunk: split records (empty for the base)
  std::vector<uint32_t> chunkFirstSplit;       // per received chunk, plus one past the last
  std::vector<uint32_t> recordStart;  // per split decoded so far, plus the next: where its record starts in each column
                                      // (SplitReader::tell)
  uint32_t splitsDecoded = 0;         // splits read at least once (the frontier)
  SplitReader reader;                 // scratch

  uint32_t splitsReceived() const { return chunkFirstSplit.empty() ? 0 : chunkFirstSplit.back(); }
  uint32_t splitsApplied() const { return pm.splitsApplied(); }
  // Chunks whose every split is applied (the base counts once received).
  uint32_t chunksApplied() const;
  // Splits needed to reach the end of chunk `index` (0 for the base).
  uint32_t splitsThroughChunk(uint32_t index) const;
};

// Parses the manifest and resets the dataset. Nothing is received yet.
Result openDataset(Dataset& ds, std::string_view manifestJson);

// Verifies chunk `index`, which must be the next one (ds.chunksReceived). The base chunk is
// applied at once; a split chunk is kept for stepTowards. On failure nothing changes.
// hashChecked: as openChunk's.
Result receiveChunk(Dataset& ds, uint32_t index, std::span<const uint8_t> file, bool hashChecked = false);

// Applies (or undoes) up to `maxSteps` splits toward `targetSplits` (clamped to the splits
// received). Appends the ids of changed tets (see progressive.h; removed tets are those with
// id >= tetCount() afterwards) to `changed`. *reached tells whether the target was reached.
// A record that fails to decode (a hostile but correctly hashed chunk) undoes its whole chunk,
// drops it and everything after it, and returns the error: the level stays a valid prefix.
Result stepTowards(Dataset& ds, uint32_t targetSplits, uint32_t maxSteps, std::vector<uint32_t>& changed,
                   bool* reached);

// Receives and fully applies a chunk. On any failure the dataset stays at its last valid level.
Result applyChunk(Dataset& ds, uint32_t index, std::span<const uint8_t> file);

// Native convenience: reads DIR/manifest.json and applies the first `maxChunks` chunks (all
// when negative) from DIR, stopping inside a chunk once the mesh has `maxVertices` vertices.
Result loadPackedDir(const std::string& dir, Dataset& ds, int maxChunks = -1, uint32_t maxVertices = ~0u);

// True when DIR looks like a packed dataset (has a manifest.json).
bool isPackedDir(const std::string& path);

}  // namespace tetstream
