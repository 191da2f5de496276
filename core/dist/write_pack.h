// The last phase of a distributed pack (distributed_pack.h): every rank compresses its units'
// chunks under their places in the manifest and writes them into the shared output folder;
// rank 0 writes the base chunk, gathers every unit's chunks and nodes, and writes the manifest
// (last, so a reader never sees a manifest without its chunks).
#pragma once
#include <string>
#include <vector>

#include "dist/distributed_pack.h"
#include "dist/units.h"

namespace tetstream::dist {

// The field error measured at the input's vertices (base_error.h), for the manifest.
struct MeasuredError {
  double baseRms = -1, baseMax = -1;
};

Result writeDistributed(Comm& comm, const RankTree& tree, const UnitLayout& layout, std::vector<Unit>& units,
                        const RegionFigures& regions, Manifest& m, const std::string& outDir, const PackOptions& opt,
                        const RankFigures& mine, const MeasuredError& measured, DistributedSummary& out);

}  // namespace tetstream::dist
