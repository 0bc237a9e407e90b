// The decompositions group of core/eigen_solvers.hpp's shared Eigen instantiations, compiled here once.
#include <Eigen/Dense>

#define PIEZOBENCH_EIGEN_GROUP_EIGENVALUES 0
#define PIEZOBENCH_EIGEN_INSTANCE(...) template __VA_ARGS__;
#include "piezobench/core/eigen_solvers.inc"
#undef PIEZOBENCH_EIGEN_INSTANCE
