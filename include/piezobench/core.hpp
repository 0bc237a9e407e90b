#pragma once
// The core module: errors (InputError, NumericalError, UsageError) and shared constants.
#include "piezobench/core/error.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/core/usage_error.hpp"
