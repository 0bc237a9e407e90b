#include "piezobench/core/least_squares.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <utility>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"

namespace piezobench::core {

std::string to_string(LmStatus s) {
  switch (s) {
    case LmStatus::kCostConverged: return "cost-converged";
    case LmStatus::kStepConverged: return "step-converged";
    case LmStatus::kGradientConverged: return "gradient-converged";
    case LmStatus::kMaxIterations: return "max-iterations";
    case LmStatus::kNoProgress: return "no-progress";
  }
  return "unknown";
}

LmStatus lm_status_from_string(const std::string& s) {
  for (const LmStatus v : {LmStatus::kCostConverged, LmStatus::kStepConverged, LmStatus::kGradientConverged,
                           LmStatus::kMaxIterations, LmStatus::kNoProgress}) {
    if (to_string(v) == s) return v;
  }
  throw InputError("", "status",
                   "one of cost-converged, step-converged, gradient-converged, max-iterations, no-progress",
                   "'" + s + "'");
}

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

double half_norm2(const VectorXd& r) { return 0.5 * r.squaredNorm(); }

}  // namespace

void LmOptions::validate() const {
  const std::string src = "Levenberg-Marquardt options";
  if (max_iterations < 1) throw InputError(src, "max_iterations", "at least 1", std::to_string(max_iterations));
  for (const auto& [v, name] : {std::pair{cost_tolerance, "cost_tolerance"}, std::pair{step_tolerance, "step_tolerance"},
                                std::pair{gradient_tolerance, "gradient_tolerance"}}) {
    if (!(std::isfinite(v) && v >= 0.0)) throw InputError(src, name, "a finite tolerance >= 0", format_number_exact(v));
  }
  for (const auto& [v, name] : {std::pair{initial_lambda, "initial_lambda"}, std::pair{jacobian_step, "jacobian_step"}}) {
    if (!(std::isfinite(v) && v > 0.0)) throw InputError(src, name, "a finite value > 0", format_number_exact(v));
  }
}

MatrixXd central_difference_jacobian(const ResidualFunction& fun, const VectorXd& x, double step) {
  MatrixXd J;
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    VectorXd xp = x, xm = x;
    xp(j) += step;
    xm(j) -= step;
    const VectorXd d = (fun(xp) - fun(xm)) / (2.0 * step);
    if (j == 0) J.resize(d.size(), x.size());
    J.col(j) = d;
  }
  return J;
}

LmResult levenberg_marquardt(const ResidualFunction& fun, const VectorXd& x0, const LmOptions& options) {
  return levenberg_marquardt(fun, JacobianFunction(), x0, options);
}

LmResult levenberg_marquardt(const ResidualFunction& fun, const JacobianFunction& analytic, const VectorXd& x0,
                             const LmOptions& options) {
  options.validate();
  LmResult out;
  out.x = x0;
  VectorXd r = fun(x0);
  out.evaluations = 1;
  assert(r.allFinite());
  out.cost = out.initial_cost = half_norm2(r);
  const Eigen::Index n = x0.size();
  const Eigen::Index m = r.size();

  MatrixXd J(m, n);
  auto jacobian = [&](const VectorXd& x) {
    if (analytic) {
      J = analytic(x);
      return;
    }
    J = central_difference_jacobian(fun, x, options.jacobian_step);
    out.evaluations += 2 * static_cast<int>(n);
  };

  jacobian(out.x);
  VectorXd scale = J.colwise().norm().transpose().cwiseMax(1e-300);
  double lambda = options.initial_lambda;
  double nu = 2.0;
  out.status = LmStatus::kMaxIterations;
  while (out.iterations < options.max_iterations) {
    ++out.iterations;
    const VectorXd g = J.transpose() * r;
    if (g.lpNorm<Eigen::Infinity>() <= options.gradient_tolerance * (out.cost + 1e-300)) {
      out.status = LmStatus::kGradientConverged;
      break;
    }
    // [J; sqrt(lambda) D] dx = [-r; 0]; lambda is relative to the scaled problem, where every
    // column of J D^-1 has unit norm.
    MatrixXd aug(m + n, n);
    aug.topRows(m) = J;
    aug.bottomRows(n) = (std::sqrt(lambda) * scale).asDiagonal();
    VectorXd rhs = VectorXd::Zero(m + n);
    rhs.head(m) = -r;
    const VectorXd dx = aug.colPivHouseholderQr().solve(rhs);
    if (!dx.allFinite()) {
      out.status = LmStatus::kNoProgress;
      break;
    }
    if (dx.norm() <= options.step_tolerance * (out.x.norm() + options.step_tolerance)) {
      out.status = LmStatus::kStepConverged;
      break;
    }
    const VectorXd x_new = out.x + dx;
    const VectorXd r_new = fun(x_new);
    ++out.evaluations;
    const double cost_new = r_new.allFinite() ? half_norm2(r_new) : std::numeric_limits<double>::infinity();
    // Gain ratio: actual over predicted decrease; the model decrease of the damped step is
    // 0.5 dx^T (lambda D^2 dx - g).
    const double predicted = 0.5 * dx.dot(lambda * scale.cwiseAbs2().cwiseProduct(dx) - g);
    const double rho = predicted > 0.0 ? (out.cost - cost_new) / predicted : -1.0;
    if (rho > 0.0 && std::isfinite(cost_new)) {
      const double decrease = (out.cost - cost_new) / std::max(out.cost, 1e-300);
      out.x = x_new;
      r = r_new;
      out.cost = cost_new;
      lambda *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
      nu = 2.0;
      if (decrease < options.cost_tolerance) {
        out.status = LmStatus::kCostConverged;
        break;
      }
      jacobian(out.x);
      scale = scale.cwiseMax(J.colwise().norm().transpose());
    } else {
      lambda *= nu;
      nu *= 2.0;
      if (!std::isfinite(lambda) || lambda > 1e300) {
        out.status = LmStatus::kNoProgress;
        break;
      }
    }
  }
  return out;
}

}  // namespace piezobench::core
