#include "piezobench/core/fit_covariance.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"

namespace piezobench::core {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// The straight line y = a + b x: the textbook covariance sigma^2 (X^T X)^-1.
MatrixXd line_design(int m) {
  MatrixXd X(m, 2);
  for (int i = 0; i < m; ++i) X.row(i) << 1.0, static_cast<double>(i);
  return X;
}

TEST(FitCovariance, KnownNoiseGivesTheTextbookCovariance) {
  const int m = 11;
  const MatrixXd X = line_design(m);
  const double sigma = 0.3;
  // Residuals of a perfect fit scaled by 1/sigma (chi2 = 0 < 1: no inflation).
  const MatrixXd J = X / sigma;
  const FitCovariance c = fit_covariance(J, VectorXd::Zero(m), VectorXd::Ones(m));
  const MatrixXd want = (X.transpose() * X).inverse() * sigma * sigma;
  EXPECT_LT((c.covariance - want).norm(), 1e-12 * want.norm());
  // se(a) = sigma sqrt(sum x^2 / (m Sxx)), se(b) = sigma / sqrt(Sxx) with Sxx = 110.
  EXPECT_NEAR(c.standard_error(1), sigma / std::sqrt(110.0), 1e-12);
  EXPECT_NEAR(c.standard_error(0), sigma * std::sqrt(385.0 / (11.0 * 110.0)), 1e-12);
  // corr(a, b) = -mean(x) / sqrt(mean(x^2)) = -5 / sqrt(35).
  EXPECT_NEAR(c.correlation(0, 1), -5.0 / std::sqrt(35.0), 1e-12);
  EXPECT_TRUE(c.high_correlations.empty());
  EXPECT_FALSE(c.singular);
}

TEST(FitCovariance, UnweightedResidualsAndSandwichAndInflation) {
  const int m = 11;
  const MatrixXd X = line_design(m);
  VectorXd r(m);
  for (int i = 0; i < m; ++i) r(i) = (i % 2 == 0 ? 0.2 : -0.2);
  // Unknown noise: s^2 = |r|^2 / (m - 2).
  const FitCovariance u = fit_covariance(X, r);
  const double s2 = r.squaredNorm() / (m - 2);
  EXPECT_LT((u.covariance - (X.transpose() * X).inverse() * s2).norm(), 1e-12);
  // Unweighted residuals whose noise is known per point: the sandwich, then chi2 > 1 inflates it (the
  // same misfit at every point: the local chi2 of each parameter is the global one).
  const VectorXd s = VectorXd::Constant(m, 0.1);
  const FitCovariance w = fit_covariance(X, r, s);
  const double chi2 = (r / 0.1).squaredNorm() / (m - 2);
  EXPECT_NEAR(w.chi2_per_dof, chi2, 1e-12);
  EXPECT_LT((w.covariance - (X.transpose() * X).inverse() * 0.01 * chi2).norm(), 1e-12);
}

// Two parameters decided by separate points (a block-diagonal Jacobian): a misfit where only b is
// decided widens b's interval by its local chi2 and leaves a's as the noise gives it.
TEST(FitCovariance, MisfitWidensOnlyTheParametersItInfluences) {
  const int m = 20;
  MatrixXd J = MatrixXd::Zero(m, 2);
  VectorXd r = VectorXd::Zero(m);
  for (int i = 0; i < 10; ++i) J(i, 0) = 1.0;
  for (int i = 10; i < m; ++i) {
    J(i, 1) = 1.0;
    r(i) = (i % 2 == 0 ? 0.3 : -0.3);  // 3 sigma of misfit
  }
  const FitCovariance c = fit_covariance(J, r, VectorXd::Constant(m, 0.1));
  EXPECT_NEAR(c.standard_error(0), 0.1 / std::sqrt(10.0), 1e-12);
  // f_b = m / (m - p) * mean(r^2) / s^2 = 20 / 18 * 9.
  EXPECT_NEAR(c.standard_error(1), 0.1 / std::sqrt(10.0) * std::sqrt(20.0 / 18.0 * 9.0), 1e-12);
  // The global chi2 per degree of freedom is still reported: 10 * 9 / 18.
  EXPECT_NEAR(c.chi2_per_dof, 5.0, 1e-12);
}

TEST(FitCovariance, NearlyCollinearColumnsAreFlaggedAndDependentOnesSingular) {
  MatrixXd J(6, 2);
  for (int i = 0; i < 6; ++i) J.row(i) << 1.0 + i, 1.0 + i + 1e-3 * (i % 2);
  const FitCovariance c = fit_covariance(J, VectorXd::Zero(6), VectorXd::Ones(6));
  ASSERT_EQ(c.high_correlations.size(), 1u);
  EXPECT_GT(c.condition_number, 100.0);
  J.col(1) = 2.0 * J.col(0);
  const FitCovariance s = fit_covariance(J, VectorXd::Zero(6));
  EXPECT_TRUE(s.singular);
  EXPECT_TRUE(std::isinf(s.standard_error(0)));
  EXPECT_THROW((void)fit_covariance(MatrixXd::Ones(2, 2), VectorXd::Zero(2)), InputError);
}

TEST(FitCovariance, PropagationIsFirstOrder) {
  MatrixXd C(2, 2);
  C << 4.0, 1.0, 1.0, 9.0;
  MatrixXd G(1, 2);
  G << 1.0, -1.0;  // var(a - b) = 4 + 9 - 2
  EXPECT_NEAR(propagate_covariance(G, C)(0, 0), 11.0, 1e-15);
}

}  // namespace
}  // namespace piezobench::core
