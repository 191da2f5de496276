// Vertex-split chunks (FORMAT.md §4), decode side: reads one record at a time from a chunk's
// payload and applies it to a ProgressiveMesh, so a viewer can spread a chunk over frames.
// Every field of a record is checked against the current mesh before anything changes.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "manifest.h"
#include "progressive.h"
#include "quantize.h"
#include "status.h"
#include "varint.h"
#include "vertex_link.h"

namespace tetstream {

inline constexpr uint32_t kSplitFlagLossless = 1;
// Records also carry p_j's value after the split: of every field (bit 1, as the first packers
// with fitted values wrote them), or of the manifest's isoField only, the one field whose values the packer fits
// (bit 2). Never both.
inline constexpr uint32_t kSplitFlagKeptValues = 2;
inline constexpr uint32_t kSplitFlagKeptIsoValue = 4;
// The records' fields are stored column by column (FORMAT.md §4): all kept-vertex deltas, then
// all moved masks, and so on. zstd's entropy stage codes each block with one table, so a column
// of one kind of number compresses far better than records that interleave six kinds.
inline constexpr uint32_t kSplitFlagColumns = 8;
// Each record's moved field starts with a byte: 0, T_moved follows from T_new (vertex_link.h)
// and no mask is stored; 1, the mask follows. Most records then need one byte (which zstd all
// but removes) instead of a mask.
inline constexpr uint32_t kSplitFlagImpliedMoved = 16;
// A cycle's or path's vertices after the first are named among the link neighbours of the one
// before (vertex_link.h): a handful of choices instead of every neighbour of p_j.
inline constexpr uint32_t kSplitFlagRingWalk = 32;

// The fields of a split record, in record order; with kSplitFlagColumns each is a column.
enum class SplitColumn : uint32_t { KeptVertex, Moved, NewTetCount, NewTets, Position, Values };
inline constexpr uint32_t kSplitColumns = 6;

// How a split record lists its recreated tets (i, j, a, b) (FORMAT.md §4).
enum class RingMode : uint32_t {
  Pairs = 0,  // m pairs (a, b)
  Cycle = 1,  // m vertices v_k: tets (i, j, v_k, v_(k+1) mod m), the link of an interior edge
  Path = 2,   // m + 1 vertices: tets (i, j, v_k, v_(k+1)), the link of a boundary edge
};
inline constexpr uint32_t kMaxNewTetsPerSplit = 4096;

// Stable vertex ids (FORMAT.md §1.1) to the ids of a mesh that holds some of a dataset's nodes:
// the base's and, for the node being applied, its ancestors' and its own, each a run of ids.
// A record of the node may name no other vertex.
struct VertexIdMap {
  struct Run {
    uint32_t stableBegin, stableEnd, localBegin;
  };
  std::vector<Run> runs;  // disjoint stable ranges

  bool toLocal(uint32_t stable, uint32_t& local) const {
    for (const Run& r : runs)  // (a chain of a few tens of nodes, a run per chunk)
      if (stable >= r.stableBegin && stable < r.stableEnd) {
        local = r.localBegin + (stable - r.stableBegin);
        return true;
      }
    return false;
  }
};

struct SplitReader {
  // One cursor per column; records in one row (no kSplitFlagColumns) use in[0] for every field.
  ByteReader in[kSplitColumns];
  bool columns = false;
  bool impliedMoved = false;  // kSplitFlagImpliedMoved
  bool ringWalk = false;      // kSplitFlagRingWalk
  uint32_t remaining = 0;     // records left in the chunk
  uint32_t prevJ = 0;
  bool lossless = false;
  // Records carry j's kept values of fields [keptFirst, keptFirst + keptCount) (from the flags).
  uint32_t keptFirst = 0, keptCount = 0;
  // scratch, reused across records
  std::vector<uint32_t> star, candidates, moved, newTets, ring;
  std::vector<float> fields, jFields;  // jFields: keptCount values
  VertexLink link;                     // of j, for ring walks and T_moved
  // Records name vertices by stable id; with a map they are translated (a partial mesh), without
  // one they are the mesh's own (every node applied in stream order).
  const VertexIdMap* ids = nullptr;

  ByteReader& column(SplitColumn c) { return in[columns ? uint32_t(c) : 0]; }
  // Where the next record starts (one offset per column), and going back there.
  void tell(uint32_t* offsets) const;
  void seek(const uint32_t* offsets);
  bool atEnd() const;
};

// Starts reading a split chunk's payload (after the chunk header) at its first record. The
// payload must outlive the reader's use.
Result beginSplits(SplitReader& r, std::span<const uint8_t> payload, const ChunkInfo& info, const Manifest& m);

// Decodes the next record and applies it; appends changed tet ids (moved, then new) to
// `changed`. On failure nothing of that record is applied.
Result applyNextSplit(SplitReader& r, ProgressiveMesh& pm, const Quantizer& q, std::vector<uint32_t>& changed);

// After the last record: the payload must be fully consumed.
Result endSplits(const SplitReader& r);

}  // namespace tetstream
