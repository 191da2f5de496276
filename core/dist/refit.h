// The base's values fitted again, all together, against the whole input: what one process's
// simplifier does at its end (simplify_refit.cpp), done by the ranks together. Rank 0 shares the
// base (a few MB); every rank locates its own input vertices in it and adds their rows to the
// normal equations; the sums are joined and rank 0 solves them, each value kept to the range of
// the region that fitted it last (CarriedVertexState::fitRange), so a region left out still shows
// no surface of a value outside its range. Splits give back the values before, so only the base
// changes.
#pragma once
#include "dist/comm.h"
#include "dist/units.h"

namespace tetstream::dist {

// `root`: the root unit on rank 0 (its simplification's values are changed), null elsewhere;
// `input`: this rank's first part (its owned vertices and their quantized samples of `field`).
void refitBase(Comm& comm, Unit* root, const PartMesh& input, int field);

}  // namespace tetstream::dist
