#pragma once
// The control module: the IFF controller of eq. 2.4 (around the plant of plant/iff_plant.hpp), its loop and root locus, the discrete controller, the inverse hysteresis feedforward.
#include "piezobench/control/discrete_iff.hpp"
#include "piezobench/control/hysteresis_feedforward.hpp"
#include "piezobench/control/iff.hpp"
