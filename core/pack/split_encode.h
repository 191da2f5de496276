// Turns the simplifier's collapse log into the progressive stream (FORMAT.md §3-§4): the base
// mesh and vertex-split chunks, newest collapse first. The encoder replays every split on the
// same ProgressiveMesh code the viewer runs, so the neighbourhoods it encodes against are
// exactly the ones a decoder will see.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "manifest.h"
#include "mesh.h"
#include "pack/simplify.h"
#include "status.h"

namespace tetstream {

struct StreamOptions {
  uint32_t firstChunkBytes = 16u << 10;  // compressed size aimed at by the first split chunk
  uint32_t chunkBytes = 256u << 10;      // later chunks double up to this size
  int zstdLevel = 18;
  // Rings as walks in p_j's link (split flag bit 5). Off: every ring vertex by its place among
  // p_j's neighbours, as packs before that flag (for tests of readers).
  bool ringWalk = true;
  // Inside each chunk, splits in waves by kept vertex instead of in cost order (split_order.h):
  // a smaller kept-vertex column. Needs the simplifier's read sets (recordReadSets).
  bool orderSplits = false;
  int threads = 2;  // threads that measure each level's field error (1 or 2; the same figures)
  std::function<void(uint32_t done, uint32_t planned)> progress;  // splits encoded so far
};

struct EncodedStream {
  TetMesh base;                             // vertices and tets in stream order
  std::vector<uint8_t> baseFile;            // the base chunk (index 0), compressed
  ChunkInfo baseInfo;                       // its manifest entry (file name left empty)
  std::vector<std::vector<uint8_t>> files;  // split chunk files, chunk 1 onwards
  std::vector<ChunkInfo> chunks;            // their manifest entries (file names left empty)
  std::vector<uint32_t> streamVertexOf;     // original vertex id -> id in the stream
  std::vector<uint32_t> streamTetOf;        // original tet id -> id in the stream
  double baseFieldError = 0;                // estimated field error of the base mesh
  uint32_t movedMasks = 0;                  // splits whose T_moved does not follow from T_new (vertex_link.h)
  std::vector<NodeInfo> nodes;              // the patch hierarchy's nodes, in stream order (FORMAT.md §1.1)
};

// `mesh` is the simplifier's input (values on the quantization grid of `m` unless lossless; its
// positions and fields are read, not its tets, which simplifyMesh may have taken over);
// `m` supplies bounds, fields and quantization. The base mesh is compressed as chunk 0 while the
// splits are encoded, and the split chunks follow from index 1. s.tets is released once the base
// mesh is built (the peak memory of a pack is the simplifier's or the encoder's).
Result encodeStream(const TetMesh& mesh, SimplifyResult& s, const Manifest& m, const StreamOptions& opt,
                    EncodedStream& out);

// Packing on several processes (pack/distributed.h) encodes the stream in units: a part's
// collapses (SimplifyPart) as the splits of its nodes, from the mesh the part left (its
// "handoff": every vertex and tet alive at the end of its simplification) back to the mesh it
// started from. Split records name vertices by stable id (FORMAT.md §1.1), so a unit needs the
// stable ids of its handoff, which the unit above it hands down; the ids its own splits create
// are a range known from the counts of the units before it in manifest order.
struct UnitEncodeOptions {
  StreamOptions stream;                    // (orderSplits is not supported here; no progress needed)
  std::vector<uint64_t> stableVertex;      // per vertex of the part's mesh alive at the end: its stable id (else ~0)
  std::vector<uint64_t> stableTet;         // per tet of the part alive at the end: its stable id (else ~0)
  uint64_t vertexBegin = 0, tetBegin = 0;  // the stable ids of the unit's first new vertex and tet
  // As SimplifyPart::topIsRegion: false, the part is the root and its top node's chunks start at
  // firstChunkBytes and taper like encodeStream's root; true, all its chunks aim at chunkBytes.
  bool topIsRegion = false;
  // Per vertex of the part's mesh, whether to measure the field error there (level_error.h): the
  // vertices a part of the input at full resolution owns, so that each of its nodes gets the
  // measured error in its region before its splits (UnitNode::fieldRms, fieldMax), as
  // encodeStream gives its nodes. Null: nothing measured (a part made of coarse parts).
  const std::vector<uint8_t>* measureAt = nullptr;
};

// One split chunk, not yet compressed: its index in the manifest is known only once every unit
// is encoded (finishUnitChunk sets it). Counts in stable terms.
struct UnitChunk {
  std::vector<uint8_t> raw;  // header (index 0 for now) and payload
  uint32_t splits = 0;
  uint64_t vertices = 0, tets = 0;  // the whole stream's counts after this chunk (stable ids)
  // The largest CollapseLog::fieldError of its splits, as logged (not yet capped at the field's
  // range as encodeStream's chunk estimates are).
  float maxCollapseError = 0;
};

// A node of the unit: the section of the part's log made by `node` (RegionTree numbering of the
// part's own tree), in the unit's order (the part's top node first, leaves last).
struct UnitNode {
  uint32_t node = 0;
  uint32_t firstChunk = 0, chunkCount = 0;                            // in UnitEncoded::chunks
  uint64_t vertexBegin = 0, vertexEnd = 0, tetBegin = 0, tetEnd = 0;  // stable ids
  // Its field error before its splits, measured at UnitEncodeOptions::measureAt; -1 when not.
  double fieldRms = -1, fieldMax = -1;
};

struct UnitEncoded {
  std::vector<UnitChunk> chunks;
  std::vector<UnitNode> nodes;
  // The handoff mesh in stable order (vertex k: the k-th smallest stable id; tets likewise, their
  // vertices by that rank) with the values a reader decodes (fitted values snapped): the base,
  // for the root unit.
  TetMesh handoff;
  // After all splits: per vertex and tet of the part's mesh alive at its start (before any of
  // its collapses), its stable id (~0 otherwise): the stable ids the units below need. A vertex
  // or tet of the handoff keeps the id it was given; one the unit's m-th split creates has
  // vertexBegin + m (tets: tetBegin plus its place among the recreated tets, in record order).
  std::vector<uint64_t> startVertex, startTet;
  // ... and, with fitted values, the fitted field's value there as a reader has it after all of the
  // unit's splits (the value the units below start from; NaN otherwise).
  std::vector<float> startValue;
};

// Encodes the splits of part `s` (simplifyMesh with SimplifyOptions::part) on `mesh` (the part's
// mesh as simplified: positions, fields). The stream's order within the unit is that of
// encodeStream (its nodes' sections from the last to the first, each newest collapse first), and
// chunk sizes aim at the same bytes with an assumed compression ratio (the real one is known only
// after compression). The field error is measured by node only with UnitEncodeOptions::measureAt,
// never by chunk.
// Stable ids are read where s.vertexAlive/s.tetAlive hold; each must be below vertexBegin/tetBegin
// and none taken twice (BadArgument otherwise), and the unit's ids must stay below 2^31 (TooLarge).
// Like encodeStream, it releases s.tets.
Result encodeUnit(const TetMesh& mesh, SimplifyResult& s, const Manifest& m, const UnitEncodeOptions& opt,
                  UnitEncoded& out);

// Sets the chunk's manifest index in its header (bytes 8-11) and compresses it (finishChunk);
// fills `info` except its file name and fieldError (the caller's: they span units). Counts of
// 2^31 or more are refused (TooLarge), as readers would (FORMAT.md §5).
Result finishUnitChunk(UnitChunk& chunk, uint32_t index, int zstdLevel, std::vector<uint8_t>& file, ChunkInfo& info);

}  // namespace tetstream
