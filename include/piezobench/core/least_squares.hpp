#pragma once
// The one Levenberg-Marquardt solver of piezobench (the 2-DoF tuning, the IFF-plant and delayed
// second-order fits, the second-order FRF fit), with a ceres-style termination status.
//
// Minimizes 0.5 ||r(x)||^2 with the Jacobian from central differences (or the caller's). Each step solves the
// damped normal equations (J^T J + lambda D^T D) dx = -J^T r in the least-squares form
// [J; sqrt(lambda) D] dx = [-r; 0] (column-pivoting QR, no J^T J squaring of the condition number),
// D = diag of the column norms of J (Marquardt's scaling, kept monotone as in MINPACK lmder).
// lambda follows Nielsen's update (H. B. Nielsen, "Damping parameter in Marquardt's method",
// IMM-REP-1999-05): on success lambda *= max(1/3, 1 - (2 rho - 1)^3), on failure lambda *= nu,
// nu *= 2. References: K. Madsen, H. B. Nielsen, O. Tingleff, "Methods for non-linear least
// squares problems", IMM 2004, section 3.2; J. J. More, "The Levenberg-Marquardt algorithm:
// implementation and theory", 1978.
// Units: the caller's (the parameters, residuals and tolerances are in the units of the caller's problem).
#include <Eigen/Dense>
#include <functional>
#include <string>

namespace piezobench::core {

struct LmOptions {
  int max_iterations = 200;          // accepted or rejected steps
  double cost_tolerance = 1e-12;     // stop when an accepted step lowers the cost by less than this, relatively
  double step_tolerance = 1e-10;     // stop when ||dx|| <= step_tolerance (||x|| + step_tolerance)
  double gradient_tolerance = 1e-12; // stop when ||J^T r||_inf <= gradient_tolerance * (cost + tiny)
  double initial_lambda = 1e-3;      // for the scaled problem, where the columns of J D^-1 have unit norm
  double jacobian_step = 1e-6;       // central-difference step, absolute in x (x is O(1) in log form)
  void validate() const;             // InputError (source "Levenberg-Marquardt options") naming the field
};

// As ceres::TerminationType with its reason: the three convergences (function, parameter and
// gradient tolerance), no convergence within max_iterations, and failure (no step lowers the cost:
// the damping grew without bound, or the step is not finite).
enum class LmStatus { kCostConverged, kStepConverged, kGradientConverged, kMaxIterations, kNoProgress };
// "cost-converged", "step-converged", "gradient-converged", "max-iterations", "no-progress"
std::string to_string(LmStatus s);
LmStatus lm_status_from_string(const std::string& s);  // InputError for an unknown name

struct LmResult {
  Eigen::VectorXd x;
  double cost = 0.0;          // 0.5 ||r||^2 at x
  double initial_cost = 0.0;
  int iterations = 0;         // steps tried
  int evaluations = 0;        // calls of the residual function
  LmStatus status = LmStatus::kMaxIterations;
  [[nodiscard]] bool converged() const {
    return status != LmStatus::kMaxIterations && status != LmStatus::kNoProgress;
  }
};

// r must return a vector of the same size at every x; a non-finite residual makes a trial step
// fail (it is treated as a cost increase). At x0 it must be finite (asserted by the caller).
using ResidualFunction = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;
// J(x), rows as r(x), one column per parameter.
using JacobianFunction = std::function<Eigen::MatrixXd(const Eigen::VectorXd&)>;
LmResult levenberg_marquardt(const ResidualFunction& r, const Eigen::VectorXd& x0, const LmOptions& options = {});
// J(x) by central differences with the absolute step `step` in every x (what the solver uses
// without an analytic Jacobian; 2 size(x) evaluations of r).
Eigen::MatrixXd central_difference_jacobian(const ResidualFunction& r, const Eigen::VectorXd& x, double step = 1e-6);
// The same with an analytic Jacobian.
LmResult levenberg_marquardt(const ResidualFunction& r, const JacobianFunction& jacobian, const Eigen::VectorXd& x0,
                             const LmOptions& options = {});

}  // namespace piezobench::core
