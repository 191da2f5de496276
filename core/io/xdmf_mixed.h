// The cells of an XDMF Mixed topology. Each cell is its type code (xdmf_topology.h), for a type
// of no fixed size its node count (for a polyhedron its face count, then per face its node count
// and nodes), then its node ids. Nothing but the cells before it says where a cell begins, so a
// share of the cells (core/dist) is found by walking the codes from the first cell, and a large
// topology can be walked a window of values at a time.
#pragma once
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "io/xdmf_topology.h"
#include "status.h"

namespace tetstream::xdmf {

// Cells as VTK cell arrays; a cell tetstream does not read keeps its place as type 0
// (VTK_EMPTY_CELL), so that cell data stays aligned, and is counted by its XDMF type.
struct MixedCells {
  std::vector<int64_t> connectivity, offsets{0}, types;
  std::map<const TopologyKind*, uint64_t> notRead;
};

// Walks the cells of a Mixed topology from its first value: those numbered [keepFrom, keepTo)
// are appended to a MixedCells, with `base` (XDMF 2's BaseOffset) taken off their node ids; the
// others are only stepped over. Without `skippedNodes` a cell tetstream does not read is kept
// without its nodes (a share then reads no point for it). `where` starts every message.
class MixedWalker {
 public:
  MixedWalker(std::string where, int64_t base, uint64_t keepFrom, uint64_t keepTo, bool skippedNodes = true)
      : where_(std::move(where)), base_(base), keepFrom_(keepFrom), keepTo_(keepTo), skippedNodes_(skippedNodes) {}
  // The next values of the topology, from the first one not used yet. Walks every cell that lies
  // wholly in them, up to keepTo; `used` says how many values those cells took. With `end` the
  // topology ends with these values, and a cell they cut short is an error.
  Result walk(std::span<const int64_t> values, bool end, MixedCells& out, size_t& used);
  uint64_t cells() const { return cell_; }  // walked so far
  bool done() const { return cell_ >= keepTo_; }

 private:
  std::string where_;
  int64_t base_;
  uint64_t keepFrom_, keepTo_;
  bool skippedNodes_;
  uint64_t cell_ = 0;
};

}  // namespace tetstream::xdmf
