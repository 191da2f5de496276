// The units of a distributed pack (distributed_pack.h): one per group of the tree of ranks, on
// the group's first rank. What each holds, the figures of each rank's region, and how the units'
// stable ids are laid out before any is encoded.
#pragma once
#include <cstdint>
#include <vector>

#include "dist/comm.h"
#include "dist/partition.h"
#include "manifest.h"
#include "pack/part.h"
#include "pack/simplify.h"
#include "pack/split_encode.h"

namespace tetstream::dist {

struct StableIds {
  std::vector<uint64_t> vertices, tets;  // in the order of a handoff's vertices and tets
  // The fitted field's value at each vertex as a reader has it when the unit starts (the unit
  // above may have changed a value its own splits do not give back: the refit base); empty: its own.
  std::vector<float> values;
};

struct Unit {
  int group = -1;
  PartMesh part;     // the part as simplified (its mesh holds the tets at the start)
  SimplifyResult s;  // its simplification
  PartMesh handoff;  // what it left (partAfter)
  // A group of two ranks or more: its children's handoffs by input id (the stable ids go down
  // to them in their own order), and the low child's stable ids once encoded (it is on this rank).
  std::vector<uint64_t> childVertexIds[2], childTetIds[2];
  StableIds childStable[1];
  UnitEncoded encoded;
};

// Every rank's region: the bounding box and each field's range over its owned points (on the
// quantization grid, within the manifest's ranges).
struct RegionFigures {
  std::vector<Bounds> bounds;              // per rank
  std::vector<std::vector<Range>> ranges;  // per rank, per field
  Bounds groupBounds(const RankTree::Group& g) const;
  Range groupRange(const RankTree::Group& g, size_t field) const;
};
RegionFigures regionFigures(Comm& comm, const PartMesh& part, const Manifest& m);

// How many vertices `p` owns.
uint64_t ownedCount(const PartMesh& p);

// The extent of the owned points of `p`: lo/hi [0, 3) of their positions, [3, 3 + F) of each
// field's finite values (±infinity where there are none).
void ownedExtent(const PartMesh& p, std::vector<double>& lo, std::vector<double>& hi);

// TETSTREAM_FAULT="RANK:PHASE": rank RANK fails in PHASE (distributed_pack.cpp; for tests).
Result injectedFault(int rank, const char* phase);

// Stable ids per unit, from every unit's counts: the base first, then the units in preorder.
struct UnitLayout {
  uint64_t baseVertices = 0, baseTets = 0;
  std::vector<uint64_t> vertexBegin, tetBegin;  // per group
  std::vector<uint64_t> newVertices, newTets;   // per group
};
UnitLayout planUnits(Comm& comm, const RankTree& tree, const std::vector<Unit>& units);

// Encodes unit u, its handoff's stable ids (and the values the unit starts from) given in the
// handoff's order.
Result encodeOne(Unit& u, const StableIds& hand, const Manifest& m, UnitEncodeOptions& options);

// The stable ids of child `side` (0 low, 1 high) of encoded unit u, in its handoff's order.
StableIds stableIdsOf(const Unit& u, int side);

}  // namespace tetstream::dist
