// What the manifest says of each region of the patch hierarchy besides its chunks (FORMAT.md
// §1.1): its bounding box, the range of every field over it at full resolution, and the
// simplifier's estimate of its field error before its splits.
#pragma once
#include <vector>

#include "manifest.h"
#include "mesh.h"
#include "pack/simplify.h"

namespace tetstream {

struct RegionStats {
  // Per node (RegionTree numbering; index 0 unused): over the input vertices of its region.
  std::vector<Bounds> bounds;
  std::vector<std::vector<Range>> ranges;  // per node, per field
  // The largest collapse error estimate (CollapseLog::fieldError) of the node and the nodes below
  // it: while its splits are not applied, all of those collapses are in place in its region.
  std::vector<float> fieldError;
};

// `mesh`: the simplifier's input (positions and fields; its tets are not read). Vertices of no
// tet belong to no region. Bounds and ranges are kept within the manifest's, which were taken
// before the values were snapped to the grid (a snapped value may lie an ulp outside).
RegionStats regionStats(const TetMesh& mesh, const SimplifyResult& s, const Manifest& m);

}  // namespace tetstream
