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

}  // namespace tetstream
