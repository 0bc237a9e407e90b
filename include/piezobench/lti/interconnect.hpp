#pragma once
// Interconnections of state-space systems. All operands must share the sample time.
//
// Delays: series() of SISO systems adds their delays (delays commute with SISO LTI blocks). Any
// other interconnection through a delayed channel throws InputError: approximate the delay with
// lti::pade() first.
#include <vector>

#include "piezobench/lti/state_space.hpp"

namespace piezobench::lti {

enum class FeedbackSign { kNegative = -1, kPositive = +1 };

// y = second(first(u)) (MATLAB: series(first, second) = second * first).
StateSpace series(const StateSpace& first, const StateSpace& second);
// y = a(u) + b(u).
StateSpace parallel(const StateSpace& a, const StateSpace& b);
// k * sys (output scaled).
// k: dimensionless.
StateSpace scale(const StateSpace& sys, double k);
// Block-diagonal [a 0; 0 b]: inputs and outputs of a first, then b's.
StateSpace append(const StateSpace& a, const StateSpace& b);
// The subsystem from the listed inputs to the listed outputs (in that order).
StateSpace select(const StateSpace& sys, const std::vector<Index>& outputs, const std::vector<Index>& inputs);

// Closed loop from r to y of   y = forward(u),  u = r + sign * back(y)
// (MATLAB feedback(forward, back) with sign kNegative). Throws NumericalError when I - sign*D_f*D_b
// is singular (an algebraic loop with no solution).
StateSpace feedback(const StateSpace& forward, const StateSpace& back, FeedbackSign sign = FeedbackSign::kNegative);
// MIMO form: back takes forward's outputs `feedout` and adds to forward's inputs `feedin`:
//   u[feedin] += sign * back(y[feedout]); the closed loop keeps all of forward's inputs and outputs.
StateSpace feedback(const StateSpace& forward, const StateSpace& back, const std::vector<Index>& feedin,
                    const std::vector<Index>& feedout, FeedbackSign sign = FeedbackSign::kNegative);

}  // namespace piezobench::lti
