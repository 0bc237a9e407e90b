#pragma once
// Standard errors of least-squares parameters at the solution, from the Jacobian of the residuals
// (linearization; G. A. F. Seber, C. J. Wild, "Nonlinear regression", 2003, sections 2.1 and 5.2;
// what MATLAB's getcov and nlparci report). With J the m x p Jacobian of the (weighted) residuals r at
// the solution and, when known, s_i the standard deviation of residual i from the data's noise:
//
//   C = (J^T J)^-1 J^T diag(s^2) J (J^T J)^-1     (the sandwich form: right whatever weights r has)
//   C_jk *= sqrt(f_j f_k),  f_j = max(1, m / (m - p) sum_i L_ji^2 r_i^2 / sum_i L_ji^2 s_i^2),  L = (J^T J)^-1 J^T
//
// f_j widens parameter j's interval when the misfit is larger than the noise where j is decided: L_ji
// is how much residual i moves parameter j, so f_j is the chi2 per point weighted by that influence
// (a local chi2). A global factor chi2 / (m - p) would let a misfit far from a parameter (the model
// missing a flexible mode at 400 Hz) widen the interval of one decided by a few lines (the damping of
// a zero at 60 Hz) 30-fold. Where the model is adequate f_j ~ 1 (about 1 on average with pure noise,
// never below 1 here); with the same misfit everywhere f_j = chi2 / (m - p). It is the residuals'
// heteroscedasticity-consistent covariance (MacKinnon & White 1985, HC1) with the data's variance as
// its floor.
//
// and, when s is unknown, C = (J^T J)^-1 2 cost / (m - p) (every residual with the same variance).
// A 95 % interval is x +- kCoverage95 sqrt(C_jj).
// Units: the caller's (the parameters, residuals and tolerances are in the units of the caller's problem).
#include "piezobench/core/fields.hpp"
#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <string>
#include <utility>
#include <vector>

namespace piezobench::core {

// Two-sided 95 % coverage factor of a Gaussian: the intervals and the FRF bands are +- 1.96 sigma.
inline constexpr double kCoverage95 = 1.959963984540054;

// Correlations above this (in absolute value) are flagged: the two parameters trade against each
// other, and the data do not determine them separately.
inline constexpr double kHighCorrelation = 0.95;

struct FitCovariance {
  Eigen::MatrixXd covariance;       // p x p, in the parameters' units
  Eigen::VectorXd standard_error;   // sqrt of the diagonal
  Eigen::MatrixXd correlation;      // C_ij / (se_i se_j)
  double condition_number = 0.0;    // of J with unit-norm columns (the scale-free conditioning); inf if singular
  double chi2_per_dof = 0.0;        // chi2 / (m - p) with s known, else 2 cost / (m - p) (then not 1 by construction);
                                    // the global misfit, reported (the intervals use the local f_j)
  bool singular = false;            // J^T J not invertible: the standard errors are infinite
  std::vector<std::pair<int, int>> high_correlations;  // (i, j), i < j, |correlation| > kHighCorrelation
};

// J: m x p (m > p, else InputError); r: the m residuals at the solution; residual_std: m values > 0, or
// empty (unknown). A rank-deficient J gives singular = true and infinite standard errors.
//
// Correlated noise: residuals that are the (Re, Im) parts of complex residuals u_k = r_2k + i r_2k+1
// (interleaved) whose errors correlate with the next one's, E[u_k u_k+1^*] = c_k 2 s_2k s_2k+2 (a
// Welch FRF's adjacent lines, dsp/frf_variance.hpp), give `adjacent_correlation` (c_k, size m / 2 - 1,
// 0 where u_k and u_k+1 are not neighbours; a circular error: E[u_k u_k+1] = 0). The sandwich's
// middle is then J^T Sigma J with Sigma's off-diagonal blocks s_2k s_2k+2 [[Re c, -Im c], [Im c, Re c]]
// (rows Re u_k, Im u_k; columns Re u_k+1, Im u_k+1); the local chi2 f_j keeps its diagonal noise.
//
// Errors that are correlated over more than neighbours (a Welch estimate's leakage error at a sharp
// peak, dsp/leakage_covariance.hpp) come as blocks: `covariance` of the residuals first .. first + n - 1,
// added to Sigma (the sandwich's middle gets J_b^T covariance J_b) and its diagonal to s_i^2 in f_j.
struct ResidualCovarianceBlock {
  Eigen::Index first = 0;
  Eigen::SparseMatrix<double> covariance;  // n x n, symmetric (often banded), the residuals' units squared
};
[[nodiscard]] FitCovariance fit_covariance(const Eigen::MatrixXd& J, const Eigen::VectorXd& r,
                                           const Eigen::VectorXd& residual_std = {},
                                           const Eigen::VectorXcd& adjacent_correlation = {},
                                           const std::vector<ResidualCovarianceBlock>& blocks = {});

// A fit's parameters in their natural units with their standard errors: what results.json, --json,
// Python and the report print. Built from the FitCovariance of the solver's (scaled) parameters x
// and, per parameter, d value / d x (the solver's parameters map one to one onto the named ones:
// log k -> k, x / 0.01 -> xz, ...); a parameter held fixed has derivative 0 and standard error 0.
struct ParameterUncertainty {
  std::vector<std::string> names;
  Eigen::VectorXd value;            // natural units (as the fit's fields)
  Eigen::VectorXd standard_error;   // same units; inf when the fit is singular
  Eigen::MatrixXd correlation;      // of the fitted parameters (identity rows for the fixed ones)
  double condition_number = 0.0;
  double chi2_per_dof = 0.0;
  bool from_data_variance = false;  // true: the FRF's variance; false: the residuals' scatter
  std::vector<std::string> high_correlations;  // "wz/xz 0.97" for |correlation| > kHighCorrelation

  [[nodiscard]] bool empty() const { return names.empty(); }
  // The standard error of the named parameter; NaN when it is not there.
  [[nodiscard]] double standard_error_of(const std::string& name) const;
  // standard_error / |value| (inf for a zero value).
  [[nodiscard]] double relative_standard_error_of(const std::string& name) const;
};

// names, value, dvalue_dx: one per parameter; fitted(i) = the solver's parameter index of parameter i
// or -1 for a fixed one.
[[nodiscard]] ParameterUncertainty parameter_uncertainty(const std::vector<std::string>& names, const Eigen::VectorXd& value,
                                                         const Eigen::VectorXd& dvalue_dx, const std::vector<int>& fitted,
                                                         const FitCovariance& covariance, bool from_data_variance);

// "a/b 0.973" for each pair of covariance.high_correlations, named by names (one per parameter,
// InputError when the count differs): how results.json and the reports flag them.
[[nodiscard]] std::vector<std::string> high_correlation_labels(const FitCovariance& covariance, const std::vector<std::string>& names);

// The covariance of y = f(x) from that of x, to first order: G C G^T with G = dy/dx (q x p).
[[nodiscard]] Eigen::MatrixXd propagate_covariance(const Eigen::MatrixXd& G, const Eigen::MatrixXd& covariance);

constexpr auto describe(Type<FitCovariance>) {
  using S = FitCovariance;
  return fields<S>("FitCovariance", "the covariance of a least-squares fit's parameters at the solution",
      field("covariance", &S::covariance, shown::kNone, "p x p, in the parameters' units"),
      field("standard_error", &S::standard_error, shown::kNone, "sqrt of the diagonal (inf: singular)"),
      field("correlation", &S::correlation, shown::kNone, "C_ij / (se_i se_j)"),
      field("condition_number", &S::condition_number, shown::kRatio, "of J with unit-norm columns"),
      field("chi2_per_dof", &S::chi2_per_dof, shown::kRatio, "misfit per degree of freedom"),
      field("singular", &S::singular, shown::kNone, "J^T J not invertible"),
      field("high_correlations", &S::high_correlations, shown::kNone, "(i, j) with |correlation| > 0.95"));
}

constexpr auto describe(Type<ParameterUncertainty>) {
  using S = ParameterUncertainty;
  return fields<S>("ParameterUncertainty", "a fit's parameters with their standard errors",
      field("names", &S::names, shown::kNone, "the parameters"),
      field("value", &S::value, shown::kNone, "their values, natural units"),
      field("standard_error", &S::standard_error, shown::kNone, "their standard errors, same units (inf: singular)"),
      field("correlation", &S::correlation, shown::kNone, "correlation of the fitted parameters"),
      field("condition_number", &S::condition_number, shown::kRatio, "of the scaled normal matrix"),
      field("chi2_per_dof", &S::chi2_per_dof, shown::kRatio, "misfit per degree of freedom"),
      field("from_data_variance", &S::from_data_variance, shown::kNone, "true: from the FRF's variance; false: the residuals' scatter"),
      field("high_correlations", &S::high_correlations, shown::kNone, "\"wz/xz 0.97\" for the highly correlated pairs"));
}

}  // namespace piezobench::core
