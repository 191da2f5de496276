// `tetstream pack` on several processes (MPI ranks): the same packed dataset as one process
// makes (FORMAT.md; every guarantee holds, the viewer needs nothing new), built without ever
// holding the whole mesh in one place. For a given input and rank count the output is the same
// bytes from run to run.
//
// The phases, every one ending in an agreement on failure (comm.h):
//   read        each rank reads its share of the listed pieces (a single file: every rank reads
//               it and keeps its share of the tets);
//   partition   one region per rank, cut together; tets and points sent to their owners
//               (partition.h);
//   prepare     orientation, the quantization grid and the whole mesh's normalisers, agreed;
//   simplify    each rank its part, as a tree of regions on its threads (SimplifyPart), then the
//               parts combined pairwise up the tree of ranks: the lower rank of a group takes
//               its sibling's finished part (a coarse mesh) and simplifies the cut between them,
//               up to rank 0, which simplifies the root down to the base;
//   encode      top-down: each part's splits as a unit of nodes (encodeUnit), once the unit above
//               has handed down the stable ids of what the part left; counts known beforehand
//               give every unit its ids and, after encoding, its chunks' places;
//   write       each rank compresses and writes its own chunk files into the shared output folder;
//               rank 0 writes the base chunk and the manifest.
// The units in the manifest: the groups of the tree of ranks in preorder, each group's part (a
// group of one rank: that rank's tree of regions) before its children's.
#pragma once
#include <string>
#include <vector>

#include "dist/comm.h"
#include "io/mesh_io.h"
#include "pack/packer.h"

namespace tetstream::dist {

struct RankFigures {
  uint64_t ownedVertices = 0, tets = 0;  // of its first part (halo tets included)
  double peakMB = 0;                     // peak resident memory
  double simplifyMs = 0, encodeMs = 0;   // wall time in those phases (waits for other ranks included)
  double partMs = 0;                     // simplifying its own part
  double combineMs = 0;                  // simplifying the parts it combines (the top of the tree)
  double cpuSeconds = 0;                 // processor time of the whole run, all its threads
};

struct DistributedSummary {
  PackSummary pack;  // manifest, counts, notes (as one process reports them)
  std::string inputFormat;
  uint64_t inputTets = 0;
  std::vector<RankFigures> ranks;  // on rank 0: every rank's
  double readMs = 0, partitionMs = 0;
  double simplifyMs = 0;  // from the partition to the root: every rank's part and the top of the tree
};

// Packs `input` into `outDir` on every rank of `comm` (all ranks call it with the same
// arguments). Every rank returns the same Result; the summary is complete on rank 0.
Result packDistributed(Comm& comm, const std::string& input, const ReadOptions& read, const std::string& outDir,
                       const PackOptions& options, DistributedSummary& summary);

}  // namespace tetstream::dist
