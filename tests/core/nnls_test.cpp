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

TEST(Nnls, RefusesMismatchedSizes) {
  Eigen::MatrixXd a = Eigen::MatrixXd::Ones(3, 2);
  EXPECT_THROW(nnls(a, Eigen::VectorXd::Ones(4)), InputError);
  EXPECT_THROW(nnls(a, Eigen::VectorXd::Ones(3), {true}), InputError);
  a(0, 0) = std::nan("");
  EXPECT_THROW(nnls(a, Eigen::VectorXd::Ones(3)), InputError);
}

}  // namespace
}  // namespace piezobench
