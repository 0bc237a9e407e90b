// The Levenberg-Marquardt solver on problems with known minima.
#include "piezobench/core/least_squares.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "piezobench/core/error.hpp"
#include "test_util.hpp"

namespace piezobench::core {
namespace {

using Eigen::VectorXd;
using test::all_near;
using test::Tolerance;

TEST(LevenbergMarquardt, Rosenbrock) {
  // r = [10 (x2 - x1^2), 1 - x1]: the minimum 0 is at (1, 1), reached through a curved valley.
  const auto r = [](const VectorXd& x) {
    VectorXd v(2);
    v << 10.0 * (x(1) - x(0) * x(0)), 1.0 - x(0);
    return v;
  };
  VectorXd x0(2);
  x0 << -1.2, 1.0;
  const LmResult res = levenberg_marquardt(r, x0);
  EXPECT_TRUE(res.converged()) << to_string(res.status);
  EXPECT_TRUE(all_near(res.x, VectorXd::Ones(2), Tolerance{0.0, 1e-8}));
  EXPECT_LT(res.cost, 1e-20);
  EXPECT_GT(res.iterations, 5);  // it had to follow the valley
}

TEST(LevenbergMarquardt, ExponentialFitWithResidual) {
  // y_k = 3 exp(-0.7 t_k) + e_k with a fixed alternating e_k of zero mean: the least-squares
  // solution satisfies the normal equations J^T r = 0, which we check instead of the values.
  const int n = 40;
  VectorXd t(n), y(n);
  for (int k = 0; k < n; ++k) {
    t(k) = 0.1 * k;
    y(k) = 3.0 * std::exp(-0.7 * t(k)) + ((k % 2 == 0) ? 1e-3 : -1e-3);
  }
  const auto r = [&](const VectorXd& x) -> VectorXd {
    return (x(0) * (-x(1) * t.array()).exp() - y.array()).matrix();
  };
  VectorXd x0(2);
  x0 << 1.0, 0.1;
  const LmResult res = levenberg_marquardt(r, x0);
  EXPECT_TRUE(res.converged()) << to_string(res.status);
  EXPECT_NEAR(res.x(0), 3.0, 2e-3);
  EXPECT_NEAR(res.x(1), 0.7, 2e-3);
  // Gradient at the solution, analytic Jacobian.
  Eigen::MatrixXd J(n, 2);
  J.col(0) = (-res.x(1) * t.array()).exp().matrix();
  J.col(1) = (-res.x(0) * t.array() * (-res.x(1) * t.array()).exp()).matrix();
  const VectorXd rr = r(res.x);
  EXPECT_LT((J.transpose() * rr).lpNorm<Eigen::Infinity>(), 1e-6 * J.norm() * rr.norm());
  EXPECT_LT(res.cost, res.initial_cost);
}

TEST(LevenbergMarquardt, NonFiniteTrialStepsAreRejected) {
  // log(x) is undefined for x <= 0: a step that lands there must be refused, not accepted.
  const auto r = [](const VectorXd& x) {
    VectorXd v(1);
    v << (x(0) > 0.0 ? std::log(x(0)) - std::log(2.0) : std::numeric_limits<double>::quiet_NaN());
    return v;
  };
  VectorXd x0(1);
  x0 << 50.0;
  const LmResult res = levenberg_marquardt(r, x0);
  EXPECT_TRUE(res.converged()) << to_string(res.status);
  EXPECT_NEAR(res.x(0), 2.0, 1e-8);
}

TEST(LevenbergMarquardt, IterationLimit) {
  const auto r = [](const VectorXd& x) {
    VectorXd v(2);
    v << 10.0 * (x(1) - x(0) * x(0)), 1.0 - x(0);
    return v;
  };
  VectorXd x0(2);
  x0 << -1.2, 1.0;
  LmOptions o;
  o.max_iterations = 2;
  const LmResult res = levenberg_marquardt(r, x0, o);
  EXPECT_EQ(res.status, LmStatus::kMaxIterations);
  EXPECT_FALSE(res.converged());
  EXPECT_EQ(res.iterations, 2);
}

TEST(LevenbergMarquardt, StatusNames) {
  for (const LmStatus s : {LmStatus::kCostConverged, LmStatus::kStepConverged, LmStatus::kGradientConverged,
                           LmStatus::kMaxIterations, LmStatus::kNoProgress}) {
    EXPECT_EQ(lm_status_from_string(to_string(s)), s);
  }
  EXPECT_THROW((void)lm_status_from_string("done"), InputError);
}

TEST(LevenbergMarquardt, OptionsErrorShowsATinyToleranceAsWritten) {
  // std::to_string printed -1e-12 as "-0.000000": the message must show the value the caller gave.
  LmOptions o;
  o.cost_tolerance = -1e-12;
  try {
    o.validate();
    FAIL() << "no error for a negative tolerance";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "cost_tolerance");
    EXPECT_EQ(std::string(e.what()),
              "Levenberg-Marquardt options: cost_tolerance: expected a finite tolerance >= 0, found -1e-12");
  }
}

}  // namespace
}  // namespace piezobench::core
