#pragma once
// The bench module: the virtual test bench (the report's experiments simulated on a batch of units
// with noise, its truth file, the hysteresis tracking experiment, a unit's digital twin file).
#include "piezobench/bench/experiments.hpp"
#include "piezobench/bench/tracking.hpp"
#include "piezobench/bench/truth.hpp"
#include "piezobench/bench/twin.hpp"
#include "piezobench/bench/virtual_bench.hpp"
