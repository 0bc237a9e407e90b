#pragma once
// Private to the lti module: diagonal balancing by powers of two (no permutations), as LAPACK's
// dgebal with job 'S' (Parlett & Reinsch 1969). Exact in floating point: scaling by powers of two
// introduces no round-off.
#include "piezobench/lti/state_space.hpp"

namespace piezobench::lti::detail {

// Returns d (powers of two) such that D^-1 A D has rows and columns of comparable norms.
Vector balancing_scales(const Matrix& a);

// Balances a state-space realization: A <- D^-1 A D, B <- D^-1 B, C <- C D with the scales of
// balancing_scales applied to the compound matrix [A B; C 0] restricted to the state coordinates.
// Frequency responses, poles and zeros are unchanged (a similarity transform).
void balance_realization(Matrix& a, Matrix& b, Matrix& c);

}  // namespace piezobench::lti::detail
