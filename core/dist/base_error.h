// The base's field error at the input's vertices (ChunkInfo::fieldRms and fieldMax, FORMAT.md
// §1), measured by the ranks together: rank 0 shares the base (a few MB), every rank locates its
// own input vertices in it and adds up their errors, and the sums are joined. One process
// measures every level as it replays the stream; a distributed pack measures the base (what a
// viewer shows first, and what the pack's summary reports) and the full level (the input itself:
// no error).
#pragma once
#include "dist/comm.h"
#include "mesh.h"
#include "pack/part.h"

namespace tetstream::dist {

// `base` on rank 0 (null on the others); `input`: this rank's first part, whose owned vertices
// are its share of the input (positions and the quantized samples of field `field`). Every rank
// gets the RMS and the largest error, in field units. A vertex outside the base (where a coarse
// boundary cuts across a curved one) takes the tet of its grid cell it is least outside of, its
// coordinates clamped to that tet.
void measureBaseError(Comm& comm, const TetMesh* base, const PartMesh& input, int field, double& rms, double& max);

}  // namespace tetstream::dist
