#pragma once
// Phase unwrapping: the one implementation behind the fits' delay estimates and the report's phase
// curves.
#include <vector>

#include "piezobench/core/units.hpp"

namespace piezobench::dsp {

// Each phase moved by the multiple of `period` (kTwoPi for radians, 360 for degrees) that brings it
// within half a period of the previous unwrapped one (numpy.unwrap with that period: the steps
// between neighbours reduced into [-period/2, period/2] and summed); the first
// stays as it is. Non-finite values stay as they are and the next value is unwrapped against the
// last finite one.
[[nodiscard]] std::vector<double> unwrap_phase(std::vector<double> phase, double period = kTwoPi);

}  // namespace piezobench::dsp
