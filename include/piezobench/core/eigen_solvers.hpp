#pragma once
// Eigen's dense solvers for double (and complex double) matrices, compiled once.
//
// A solver such as Eigen::EigenSolver<MatrixXd> is a template: every translation unit that uses it
// compiles all of it again (Hessenberg reduction, Francis QR steps, eigenvectors), 7 to 28 s of
// compiler CPU each for EigenSolver, GeneralizedEigenSolver and JacobiSVD, in each of CI's three
// build trees. Including this header instead declares them as instantiated elsewhere (extern
// template): src/core/eigen_solvers*.cpp instantiate them once, and the users link to that code.
// Only the exact types below are shared (a solver of a fixed-size matrix, or compute() called on an
// expression rather than a MatrixXd, still compiles where it is used: correct, only slower to build).
// docs/performance.md ("Build time") has the figures.
#include <Eigen/Dense>

#define PIEZOBENCH_EIGEN_INSTANCE(...) extern template __VA_ARGS__;
#include "eigen_solvers.inc"  // beside this header: found whatever the include path
#undef PIEZOBENCH_EIGEN_INSTANCE
