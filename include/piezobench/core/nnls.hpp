#pragma once
// Linear least squares with sign constraints: min ||A x - b||_2 subject to x_i >= 0 for the
// constrained variables (the others free). The active-set method of C. L. Lawson and R. J. Hanson,
// "Solving Least Squares Problems", Prentice-Hall 1974, ch. 23 (NNLS), with the free variables kept
// in the passive set from the start (so the free ones never leave it); each subproblem is solved by
// a column-pivoting Householder QR of the passive columns. The one place for constrained linear
// least squares in piezobench (the hysteresis identification, ident/hysteresis.hpp, uses it).
// Units: the caller's (the parameters, residuals and tolerances are in the units of the caller's problem).
#include <Eigen/Core>
#include <vector>

namespace piezobench {

struct NnlsOptions {
  int max_iterations = 0;   // outer iterations (variables added to the passive set); 0 = 3 * columns
  double tolerance = 0.0;   // stop when max_i w_i <= tolerance (w = A^T (b - A x), the dual of the
                            // constrained variables out of the passive set); 0 = 10 eps ||A||_1 max(rows, cols)
  // InputError (source "nnls options") naming the field: max_iterations >= 0, tolerance >= 0 and finite.
  void validate() const;
};

struct NnlsResult {
  Eigen::VectorXd x;            // the solution; x_i >= 0 for the constrained variables
  double residual_norm = 0.0;   // ||A x - b||_2
  int iterations = 0;
  bool converged = false;       // false: max_iterations reached (x is feasible but may not be optimal)
  std::vector<bool> active;     // active[i]: constrained variable held at 0 by its bound
};

// `free_variables` (empty: every variable constrained) marks the unconstrained ones. InputError
// for mismatched sizes or non-finite entries; NumericalError never (a rank-deficient passive set is
// solved in the minimum-norm sense of the pivoting QR).
NnlsResult nnls(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, const std::vector<bool>& free_variables = {},
                const NnlsOptions& options = {});

}  // namespace piezobench
