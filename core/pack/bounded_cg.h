// The least-squares fit behind the refit of a level's values (simplify_refit.cpp, and the
// distributed pack's refit of the base): the normal equations A x = b, A symmetric positive
// semi-definite and sparse (rows in compressed form), solved by conjugate gradients with a
// Jacobi preconditioner from the given x, each x[r] kept inside [lo[r], hi[r]]: a value that
// ends up outside is held at the bound it crossed and the others are solved again, up to
// `rounds` times. held[r] is 2 for a row without a positive diagonal (no data: x[r] unchanged),
// 1 for a value held at a bound.
#pragma once
#include <cstdint>
#include <vector>

namespace tetstream {

void solveBoundedLeastSquares(const std::vector<uint32_t>& rowStart, const std::vector<uint32_t>& cols,
                              const std::vector<double>& a, const std::vector<double>& rhs,
                              const std::vector<double>& lo, const std::vector<double>& hi, int rounds, int iterations,
                              std::vector<double>& x, std::vector<uint8_t>& held);

}  // namespace tetstream
