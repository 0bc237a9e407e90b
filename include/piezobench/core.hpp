#pragma once
// The core module: errors (InputError, NumericalError, UsageError), shared constants, the one
// Levenberg-Marquardt, the one golden-section search, fit-quality verdicts and sign-constrained
// linear least squares, the median, a runner of independent jobs on a few threads, text helpers
// whole-file input/output shared by the readers, shared libraries loaded on first use, and files
// linked into the binary (incbin.hpp); complex division and delay phasors with the library's bits
// (complex_division.hpp); Eigen's dense solvers compiled once (eigen_solvers.hpp).
#include "piezobench/core/checked_number.hpp"
#include "piezobench/core/complex_division.hpp"
#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/file.hpp"
#include "piezobench/core/fit_covariance.hpp"
#include "piezobench/core/field_types.hpp"
#include "piezobench/core/fields.hpp"
#include "piezobench/core/fit_quality.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/incbin.hpp"
#include "piezobench/core/least_squares.hpp"
#include "piezobench/core/memory.hpp"
#include "piezobench/core/minimize.hpp"
#include "piezobench/core/nnls.hpp"
#include "piezobench/core/parallel.hpp"
#include "piezobench/core/shared_library.hpp"
#include "piezobench/core/statistics.hpp"
#include "piezobench/core/text.hpp"
#include "piezobench/core/timestamp.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/core/usage_error.hpp"
