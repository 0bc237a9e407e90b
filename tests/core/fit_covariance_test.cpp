#include "piezobench/core/fit_covariance.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <complex>
#include <limits>
#include <string>
#include <vector>

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

// Complex residuals whose errors correlate with the next one's (a Welch FRF's neighbouring lines):
// the covariance is (J^T J)^-1 J^T Sigma J (J^T J)^-1 with Sigma written out densely here from its
// definition (E[u_k u_k+1^*] = c_k 2 s s, circular), the local chi2 at 1 (zero residuals). A smooth
// parameter (a constant offset of the real parts) gets the variance of a mean of positively
// correlated errors: larger than with independent ones; a wrongly sized c is refused.
TEST(FitCovariance, AdjacentCorrelationEntersTheSandwichAsItsDenseForm) {
  const int n = 6, m = 2 * n;  // 6 complex residuals
  MatrixXd J(m, 3);
  for (int k = 0; k < n; ++k) {
    J.row(2 * k) << 1.0, 0.3 * k, 0.0;
    J.row(2 * k + 1) << 0.0, 0.1 * k * k, 1.0 - 0.2 * k;
  }
  VectorXd s(m);
  for (int i = 0; i < m; ++i) s(i) = 0.5 + 0.1 * (i / 2);
  Eigen::VectorXcd c(n - 1);
  c << std::complex<double>(0.4, 0.1), std::complex<double>(0.0, 0.0), std::complex<double>(0.3, -0.2),
      std::complex<double>(0.44, 0.0), std::complex<double>(-0.1, 0.3);
  MatrixXd sigma = s.cwiseAbs2().asDiagonal();
  for (int k = 0; k + 1 < n; ++k) {
    const double ss = s(2 * k) * s(2 * k + 2);
    // rows Re u_k, Im u_k; columns Re u_k+1, Im u_k+1: [[Re c, -Im c], [Im c, Re c]]
    sigma(2 * k, 2 * k + 2) = c(k).real() * ss;
    sigma(2 * k, 2 * k + 3) = -c(k).imag() * ss;
    sigma(2 * k + 1, 2 * k + 2) = c(k).imag() * ss;
    sigma(2 * k + 1, 2 * k + 3) = c(k).real() * ss;
  }
  sigma.triangularView<Eigen::StrictlyLower>() = sigma.transpose().triangularView<Eigen::StrictlyLower>();
  const MatrixXd A = (J.transpose() * J).inverse();
  const MatrixXd expected = A * J.transpose() * sigma * J * A;
  const FitCovariance f = fit_covariance(J, VectorXd::Zero(m), s, c);
  EXPECT_LT((f.covariance - expected).norm(), 1e-12 * expected.norm());
  // The dense form's circularity: Sigma's 2x2 block for u_k, u_k+1 has E[Re Re] = E[Im Im].
  const FitCovariance independent = fit_covariance(J, VectorXd::Zero(m), s);
  const MatrixXd expected_independent = A * J.transpose() * s.cwiseAbs2().asDiagonal() * J * A;
  EXPECT_LT((independent.covariance - expected_independent).norm(), 1e-12 * expected_independent.norm());
  // A mean of n equally correlated neighbours (real c = rho): variance s^2 (n + 2 (n - 1) rho) / n^2.
  MatrixXd mean(m, 1);
  for (int k = 0; k < n; ++k) mean(2 * k, 0) = 1.0, mean(2 * k + 1, 0) = 0.0;
  MatrixXd mean2(m, 2);
  mean2.col(0) = mean.col(0);
  for (int k = 0; k < n; ++k) mean2(2 * k, 1) = 0.0, mean2(2 * k + 1, 1) = 1.0;
  const double rho = 0.45;
  const FitCovariance g = fit_covariance(mean2, VectorXd::Zero(m), VectorXd::Ones(m), Eigen::VectorXcd::Constant(n - 1, rho));
  EXPECT_NEAR(g.covariance(0, 0), (n + 2.0 * (n - 1) * rho) / (n * n), 1e-14);
  EXPECT_NEAR(g.covariance(1, 1), (n + 2.0 * (n - 1) * rho) / (n * n), 1e-14);
  EXPECT_THROW((void)fit_covariance(J, VectorXd::Zero(m), s, Eigen::VectorXcd::Zero(n)), InputError);
  EXPECT_THROW((void)fit_covariance(J, VectorXd::Zero(m), VectorXd(), c), InputError);
}

// A block of correlated residuals (a Welch estimate's leakage error) adds to the sandwich's middle
// exactly its dense form, J^T (diag(s^2) + Sigma_b) J, and its diagonal to f_j's noise: a misfit equal
// to the block's own scatter does not widen.
TEST(FitCovariance, CovarianceBlocksEnterTheSandwichAndTheLocalChi2) {
  const int m = 10;
  MatrixXd J(m, 2);
  for (int i = 0; i < m; ++i) J.row(i) << 1.0, 0.2 * i - 0.7;
  const VectorXd s = VectorXd::Constant(m, 0.1);
  MatrixXd bd(4, 4);
  bd << 4.0, 2.0, 1.0, 0.0,
       2.0, 4.0, 2.0, 1.0,
       1.0, 2.0, 4.0, 2.0,
       0.0, 1.0, 2.0, 4.0;
  bd *= 0.25;
  const Eigen::SparseMatrix<double> b = bd.sparseView();
  MatrixXd sigma = MatrixXd(s.cwiseAbs2().asDiagonal());
  sigma.block(3, 3, 4, 4) += bd;
  const MatrixXd A = (J.transpose() * J).inverse();
  const MatrixXd expected = A * J.transpose() * sigma * J * A;
  const FitCovariance f = fit_covariance(J, VectorXd::Zero(m), s, {}, {ResidualCovarianceBlock{3, b}});
  EXPECT_LT((f.covariance - expected).norm(), 1e-13 * expected.norm());
  // Residuals of the block's size (1 on rows 3-6, its variance): with the block no widening beyond
  // m / (m - p) * misfit / noise; without it the misfit is 100 times the noise there.
  VectorXd r = VectorXd::Zero(m);
  r.segment(3, 4).setConstant(1.0);
  const FitCovariance with = fit_covariance(J, r, s, {}, {ResidualCovarianceBlock{3, b}});
  const FitCovariance without = fit_covariance(J, r, s);
  EXPECT_LT(with.standard_error(0), 1.2 * f.standard_error(0));
  EXPECT_GT(without.standard_error(0), 5.0 * fit_covariance(J, VectorXd::Zero(m), s).standard_error(0));
  EXPECT_THROW((void)fit_covariance(J, r, s, {}, {ResidualCovarianceBlock{8, b}}), InputError);      // past the residuals
  EXPECT_THROW((void)fit_covariance(J, r, VectorXd(), {}, {ResidualCovarianceBlock{3, b}}), InputError);  // no residual_std
}

TEST(FitCovariance, NearlyCollinearColumnsAreFlaggedAndDependentOnesSingular) {
  MatrixXd J(6, 2);
  for (int i = 0; i < 6; ++i) J.row(i) << 1.0 + i, 1.0 + i + 1e-3 * (i % 2);
  const FitCovariance c = fit_covariance(J, VectorXd::Zero(6), VectorXd::Ones(6));
  ASSERT_EQ(c.high_correlations.size(), 1u);
  EXPECT_GT(c.condition_number, 100.0);
  // Named as results.json and the reports print them: "a/b" and the correlation to 3 decimals.
  const std::vector<std::string> labels = high_correlation_labels(c, {"gain", "slope"});
  ASSERT_EQ(labels.size(), 1u);
  char expected[64];
  std::snprintf(expected, sizeof expected, "gain/slope %.3f", c.correlation(0, 1));
  EXPECT_EQ(labels[0], expected);
  EXPECT_GT(std::abs(c.correlation(0, 1)), 0.95);  // nearly equal columns: the parameters trade, -1.000
  EXPECT_THROW((void)high_correlation_labels(c, {"gain"}), InputError);
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
