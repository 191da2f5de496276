// The phases of a distributed pack before simplification (distributed_pack.h): reading each
// rank's share, agreeing on the fields and on what the readers said, and preparing the parts as
// one process prepares the mesh (orientation, the quantization grid, the whole mesh's figures),
// every decision the same on every rank.
#pragma once
#include <string>
#include <vector>

#include "dist/comm.h"
#include "io/mesh_io.h"
#include "manifest.h"
#include "pack/packer.h"
#include "pack/part.h"

namespace tetstream::dist {

// Reads this rank's share: what its reader can read of the file alone (files of a listing,
// partitions, pieces, rows or zones: ReadOptions), or else its slice of the tets of the file
// read whole.
Result readShare(Comm& comm, const std::string& input, ReadOptions read, TetMesh& mesh, ReadReport& report);

// The fields every rank read, compared (ranks without tets take them). The same on every rank.
Result agreeOnFields(Comm& comm, TetMesh& mesh);

// What every rank's reader said: the format as the first rank that read anything saw it (said
// to be its share when ranks read shares), and every note once, with the ranks that made it
// unless every rank that read anything did.
void gatherReadReports(Comm& comm, const ReadReport& report, std::string& format, std::vector<std::string>& notes);

// The manifest's header fields, agreed: bounds and field ranges over the owned points, counts
// (each tet counted by the owner of its first vertex).
void describeWhole(Comm& comm, const PartMesh& p, const std::string& name, Manifest& m);

// Re-orients negatively oriented tets (an odd permutation), as packMesh does; returns how many
// of those this rank counts (those whose first vertex it owns).
uint64_t orient(PartMesh& p);

// The quantization grid: 16 bits unless snapping to it would flatten or turn over a tet
// somewhere; positions and fields snapped to it.
void chooseGrid(Comm& comm, PartMesh& p, Manifest& m, bool nonFinite, const PackOptions& opt,
                std::vector<std::string>& notes);

// The mean volume of an interior vertex over the whole mesh (SimplifyPart::meanVertexVolume), as
// the simplifier's set-up computes it: a quarter of each non-flat tet's volume to each vertex.
double meanVertexVolume(Comm& comm, const PartMesh& p);

}  // namespace tetstream::dist
