#pragma once
// The core module: errors (InputError, NumericalError) and shared constants.
#include "piezobench/core/error.hpp"
#include "piezobench/core/units.hpp"
