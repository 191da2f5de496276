// Part of a packed dataset: the base and a chosen set of nodes of its patch hierarchy (FORMAT.md
// §1.1), applied parents first. Any such set is a valid mesh; with the nodes an isovalue needs
// (nodesForIsovalue) its isosurface is the full-resolution one, exactly.
//
// Vertex and tet ids are the mesh's own: each applied node's new vertices and tets follow the
// mesh's, so a node's ids are above its ancestors' (the order FORMAT.md §4's rules take by id
// is then the same as in the whole stream). Records name vertices by stable id; the reader maps
// them through VertexIdMap (split_stream.h).
#pragma once
#include <cstdint>
#include <functional>
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

// The nodes whose range of field `field` holds `isovalue` (closed interval), ascending. Ranges
// nest, so the set holds every selected node's parent: it can be applied as it is.
std::vector<uint32_t> nodesForIsovalue(const Manifest& m, int field, float isovalue);

// Closes a set of nodes under "parent of": adds every ancestor, ascending.
std::vector<uint32_t> withAncestors(const Manifest& m, std::span<const uint32_t> nodes);

// The largest field error of a mesh made of the applied nodes (applied[k] per node): of the
// regions still before their splits (each node not applied whose parent is, or the root), the
// error before them. A region's splits change nothing outside it, so each such node's manifest
// figure holds whatever the other regions hold; where every node is applied the mesh is the
// input. `measured`: from NodeInfo::fieldMax, -1 when one of those nodes lacks it; `estimate`:
// from NodeInfo::fieldError.
struct FrontierError {
  double estimate = 0, measured = 0;
};
FrontierError frontierFieldError(const Manifest& m, std::span<const uint8_t> applied);

struct PartialDataset {
  static constexpr uint32_t kNotLoaded = ~0u;
  Manifest manifest;
  Quantizer quant;
  ProgressiveMesh pm;
  ChunkDecoder decoder;
  SplitReader reader;
  std::vector<uint32_t> vertexStart;  // per node: the mesh id of its first vertex, or kNotLoaded
  std::vector<uint32_t> applied;      // nodes in the order applied
  uint64_t bytesLoaded = 0;           // compressed bytes of the chunks used, base included

  bool loaded(uint32_t node) const { return vertexStart[node] != kNotLoaded; }
  // The stable id (FORMAT.md §1.1) of every vertex of the mesh.
  std::vector<uint32_t> stableVertexIds() const;
};

// Reads a chunk file: chunk `index` of the manifest, into `file`.
using ChunkSource = std::function<Result(uint32_t index, std::vector<uint8_t>& file)>;

// Parses the manifest and applies the base chunk.
Result openPartial(PartialDataset& pd, std::string_view manifestJson, const ChunkSource& read);

// Applies node `node`'s chunks. Its parent must be applied and the node not yet. On failure
// (a missing, corrupt or hostile chunk) the mesh is left as it was, and the message names the
// node's region. `changed`, when given, receives the changed tets (progressive.h's contract).
Result applyNode(PartialDataset& pd, uint32_t node, const ChunkSource& read, std::vector<uint32_t>* changed = nullptr);

// Undoes the node applied last (none of its descendants can be applied: they came after it).
void undoLastNode(PartialDataset& pd, std::vector<uint32_t>* changed = nullptr);

// Native: opens DIR and applies `nodes` (with their ancestors), parents first.
Result loadPartialDir(const std::string& dir, std::span<const uint32_t> nodes, PartialDataset& pd);

// Reads DIR/manifest.json into `json`.
Result readManifestFile(const std::string& dir, std::string& json);

}  // namespace tetstream
