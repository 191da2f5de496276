// A part of a mesh packed on several processes (SimplifyPart, simplify.h): a region's vertices
// ("owned") with their halo, in the numbering of the whole input, and what the simplifier carries
// from one level of the tree of ranks to the next. A rank simplifies its part, hands the state it
// leaves to the rank that combines it with its sibling, and so on up to the root.
#pragma once
#include <cstdint>
#include <vector>

#include "mesh.h"
#include "pack/simplify.h"

namespace tetstream {

struct PartMesh {
  // Positions (on the quantization grid), the input's samples of every field, and the current
  // tets (all alive), in local ids.
  TetMesh mesh;
  std::vector<uint64_t> vertexId;  // per local vertex: its id in the whole input (ascending)
  std::vector<uint64_t> tetId;     // per local tet: its id in the whole input (ascending)
  std::vector<uint8_t> owned;      // per local vertex: 1 in this part's region, 0 halo
  CarriedVertexState carried;      // empty on the first level (computed from the input)
};

// The part as simplification `s` of `in` left it: the vertices and tets still alive (in the
// same relative order), the current tets, and the carried state at the end (s.carried, which
// simplifyMesh fills with SimplifyOptions::part; without it the result carries none). Positions
// and every field keep the input's samples (the fitted values are in the carried state). The
// tets are read from s.tets, not in.mesh.tets (which simplifyMesh may have taken over).
PartMesh partAfter(const PartMesh& in, const SimplifyResult& s);

// Two sibling parts as one: the union of their vertices and tets by input id (in ascending id
// order); a vertex is owned when either part owns it, and takes the state of the part that owns
// it (of `a` when neither does). Both parts carry state, or neither.
PartMesh mergeParts(const PartMesh& a, const PartMesh& b);

// Serialised for sending between ranks (native byte order: the ranks of one job share it).
void writePart(const PartMesh& p, std::vector<uint8_t>& out);
// False when `in` is not a whole serialised part (the sizes do not add up, a tet names a vertex
// past the end, ids are not ascending, flags are not 0 or 1); never reads past the end.
bool readPart(const std::vector<uint8_t>& in, PartMesh& p);

}  // namespace tetstream
