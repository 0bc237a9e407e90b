#pragma once
// The core module: errors (InputError, NumericalError, UsageError), shared constants, the one
// Levenberg-Marquardt, the one golden-section search, fit-quality verdicts and sign-constrained
// linear least squares.
#include "piezobench/core/error.hpp"
#include "piezobench/core/fit_quality.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/least_squares.hpp"
#include "piezobench/core/minimize.hpp"
#include "piezobench/core/nnls.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/core/usage_error.hpp"
