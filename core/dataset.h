// A packed dataset as a reader sees it (FORMAT.md): the manifest, chunks received and verified
// in an order that puts every node's parent first (FORMAT.md §1.1; manifest order without
// nodes), and a level of detail that can move back and forth over the splits received so far,
// in the order received. Used by the viewer (bytes arrive from the network, splits are applied a
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
  uint32_t chunksReceived = 0;  // verified chunks, base included
  uint64_t bytesReceived = 0;   // compressed bytes of the verified chunks
  // Per received chunk, in the order received (its place): its index in the manifest.
  std::vector<uint32_t> received;
  std::vector<std::vector<uint8_t>> payloads;  // per place: split records (empty for the base)
  std::vector<uint32_t> chunkFirstSplit;       // per place, plus one past the last
  std::vector<uint32_t> tetsAfter;             // per place: the mesh's tets once its splits are applied
  // Per node (FORMAT.md §1.1): the stable ids its records may name, mapped to the mesh's; set
  // when its first chunk is received. Empty maps while every chunk came in manifest order
  // (stable ids are the mesh's own then: no lookups).
  std::vector<VertexIdMap> nodeIds;
  std::vector<uint32_t> nodeChunksReceived;  // per node
  bool inManifestOrder = true;
  std::vector<uint32_t> recordStart;  // per split decoded so far, plus the next: where its record starts in each column
                                      // (SplitReader::tell)
  std::vector<uint32_t>
      stableJ;  // per split decoded so far: its kept vertex's stable id (the next record's delta is from it)
  uint32_t splitsDecoded = 0;  // splits read at least once (the frontier)
  SplitReader reader;          // scratch

  uint32_t splitsReceived() const { return chunkFirstSplit.empty() ? 0 : chunkFirstSplit.back(); }
  // Whether chunk `index` can be received next: the base first, then (without nodes) the next in
  // manifest order, or the next chunk of a node whose parent has every chunk in.
  bool canReceive(uint32_t index) const;
  // The node of chunk `index` (-1: the base, or a dataset without nodes).
  int32_t nodeOfChunk(uint32_t index) const;
  bool nodeComplete(uint32_t node) const { return nodeChunksReceived[node] == manifest.nodes[node].chunkCount; }
  // Whether chunk `index` is received.
  bool hasChunk(uint32_t index) const {
    if (chunksReceived == 0 || index >= manifest.chunks.size()) return false;
    const int32_t k = nodeOfChunk(index);
    if (index == 0 || k < 0) return index < chunksReceived;
    return index < manifest.nodes[size_t(k)].firstChunk + nodeChunksReceived[size_t(k)];
  }
  uint32_t splitsApplied() const { return pm.splitsApplied(); }
  // Chunks whose every split is applied (the base counts once received), in places.
  uint32_t chunksApplied() const;
  // The place of the chunk that holds split g (g < splitsReceived(); at splitsReceived(), the
  // number of places).
  uint32_t placeOfSplit(uint32_t g) const;
  // Splits needed to reach the end of the chunk in place `place` (0 for the base); for places not
  // received yet, counted as if the next chunks came in manifest order.
  uint32_t splitsThroughChunk(uint32_t place) const;
};

// Parses the manifest and resets the dataset. Nothing is received yet.
Result openDataset(Dataset& ds, std::string_view manifestJson);

// Verifies chunk `index`, which must be one that canReceive() allows. The base chunk is
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

// Where node `node`'s splits start in the order received: the first split of its first chunk
// received (splitsReceived() when it has none).
uint32_t nodeFirstSplit(const Dataset& ds, uint32_t node);

// Gives back every received chunk of `node`, as if it had never come: the viewer forgets a region
// the view no longer needs when memory is tight. The node must have no received child and none
// of its splits applied (stepTowards to nodeFirstSplit first), so the mesh does not change; the
// splits received after it move down in the order, and their records stay valid (each node's
// stable ids map to the new places). On a refusal nothing changes.
Result forgetNode(Dataset& ds, uint32_t node);

// Receives and fully applies a chunk. On any failure the dataset stays at its last valid level.
Result applyChunk(Dataset& ds, uint32_t index, std::span<const uint8_t> file);

// Native convenience: reads DIR/manifest.json and applies the first `maxChunks` chunks (all
// when negative) from DIR, stopping inside a chunk once the mesh has `maxVertices` vertices.
Result loadPackedDir(const std::string& dir, Dataset& ds, int maxChunks = -1, uint32_t maxVertices = ~0u);

// Reads a whole file, refusing one larger than `limit` bytes (TooLarge).
Result readFileBytes(const std::string& path, uint64_t limit, std::vector<uint8_t>& out);

// True when DIR looks like a packed dataset (has a manifest.json).
bool isPackedDir(const std::string& path);

}  // namespace tetstream
