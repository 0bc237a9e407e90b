#include "piezobench/core/nnls.hpp"

#include <gtest/gtest.h>

#include <Eigen/QR>
#include <cmath>

#include "piezobench/core/error.hpp"

namespace piezobench {
namespace {

// A full-rank 12 x 5 problem whose unconstrained solution has one negative entry.
void problem(Eigen::MatrixXd& a, Eigen::VectorXd& b) {
  a.resize(12, 5);
  b.resize(12);
  for (int i = 0; i < 12; ++i) {
    for (int j = 0; j < 5; ++j) a(i, j) = std::sin(0.3 * i * j + 0.5 * j * j + i);
    b(i) = std::cos(0.4 * i) + 0.3 * i;
  }
}

TEST(Nnls, MatchesScipy) {
  Eigen::MatrixXd a;
  Eigen::VectorXd b;
  problem(a, b);
  const NnlsResult r = nnls(a, b);
  // scipy.optimize.nnls(A, b) (scipy 1.x, same A and b).
  const double expected[5] = {0.14804357783235952, 0.8458094295131617, 0.41257401067043575, 0.0, 0.16938077478486416};
  ASSERT_TRUE(r.converged);
  for (int j = 0; j < 5; ++j) EXPECT_NEAR(r.x(j), expected[j], 1e-12) << j;
  EXPECT_NEAR(r.residual_norm, 5.22848462975029, 1e-12);
  EXPECT_TRUE(r.active[3]);
  EXPECT_FALSE(r.active[0]);
}

TEST(Nnls, FreeVariableGivesTheUnconstrainedSolutionWhenTheOthersArePositive) {
  Eigen::MatrixXd a;
  Eigen::VectorXd b;
  problem(a, b);
  const Eigen::VectorXd ls = a.colPivHouseholderQr().solve(b);
  ASSERT_LT(ls(3), 0.0);
  const NnlsResult r = nnls(a, b, {false, false, false, true, false});
  ASSERT_TRUE(r.converged);
  for (int j = 0; j < 5; ++j) EXPECT_NEAR(r.x(j), ls(j), 1e-12) << j;
}

TEST(Nnls, RecoversAFeasibleExactSolution) {
  Eigen::MatrixXd a;
  Eigen::VectorXd b;
  problem(a, b);
  Eigen::VectorXd x(5);
  x << 0.0, 2.0, 0.0, 0.5, 1.5;
  const NnlsResult r = nnls(a, a * x);
  for (int j = 0; j < 5; ++j) EXPECT_NEAR(r.x(j), x(j), 1e-12) << j;
  EXPECT_LT(r.residual_norm, 1e-12);
}

// A tall problem (40 x 6, solved through its triangular factor) with two equal columns: x is not
// unique, the residual and A x are.
TEST(Nnls, TallRankDeficientProblemMatchesScipysResidual) {
  constexpr int m = 40, n = 6;
  Eigen::MatrixXd a(m, n);
  Eigen::VectorXd b(m);
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < n; ++j) a(i, j) = std::sin(0.3 * i * j + 0.5 * j * j + i);
    a(i, 5) = a(i, 2);
    b(i) = std::cos(0.4 * i) + 0.3 * i - 0.01 * i * i;
  }
  const NnlsResult r = nnls(a, b);
  // scipy.optimize.nnls(A, b), scipy 1.10.1: x = [0, 0.03085241, 0, 0, 0.12411347, 0].
  ASSERT_TRUE(r.converged);
  EXPECT_NEAR(r.residual_norm, 12.013198575957487, 1e-12);
  const Eigen::VectorXd fit = a * r.x;
  EXPECT_NEAR(fit(0), 0.13758411506839838, 1e-12);
  EXPECT_NEAR(fit(1), -0.056818326404451815, 1e-12);
  EXPECT_NEAR(fit(2), -0.01927084458093238, 1e-12);
  for (int j = 0; j < n; ++j) EXPECT_GE(r.x(j), 0.0) << j;
}

TEST(Nnls, RefusesMismatchedSizes) {
  Eigen::MatrixXd a = Eigen::MatrixXd::Ones(3, 2);
  EXPECT_THROW(nnls(a, Eigen::VectorXd::Ones(4)), InputError);
  EXPECT_THROW(nnls(a, Eigen::VectorXd::Ones(3), {true}), InputError);
  a(0, 0) = std::nan("");
  EXPECT_THROW(nnls(a, Eigen::VectorXd::Ones(3)), InputError);
}

}  // namespace
}  // namespace piezobench
