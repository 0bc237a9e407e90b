#include "piezobench/core/fit_covariance.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <limits>
#include <string>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"

namespace piezobench::core {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

// J^T Sigma J for the (scaled) Jacobian Js and Sigma = diag(s^2) plus the adjacent lines' blocks
// (fit_covariance's header).
MatrixXd noise_middle(const MatrixXd& Js, const VectorXd& s, const Eigen::VectorXcd& c) {
  const MatrixXd U = s.asDiagonal() * Js;  // row i: s_i dr_i/dx
  MatrixXd B = U.transpose() * U;
  for (Index k = 0; k < c.size(); ++k) {
    if (c(k) == std::complex<double>(0.0)) continue;
    const auto a0 = U.row(2 * k), b0 = U.row(2 * k + 1), a1 = U.row(2 * k + 2), b1 = U.row(2 * k + 3);
    // E[a0 a1] = E[b0 b1] = Re c, E[b0 a1] = Im c, E[a0 b1] = -Im c (in units of s s).
    const MatrixXd same = a0.transpose() * a1 + b0.transpose() * b1;
    const MatrixXd cross = b0.transpose() * a1 - a0.transpose() * b1;
    const MatrixXd term = c(k).real() * same + c(k).imag() * cross;
    B += term + term.transpose();
  }
  return B;
}

// "a/b 0.973": a highly correlated pair as results.json and the reports print it.
std::string correlation_label(const std::string& a, const std::string& b, double correlation) {
  char buf[32];
  std::snprintf(buf, sizeof buf, " %.3f", correlation);
  return a + "/" + b + buf;
}

}  // namespace

FitCovariance fit_covariance(const MatrixXd& J, const VectorXd& r, const VectorXd& residual_std,
                             const Eigen::VectorXcd& adjacent_correlation, const std::vector<ResidualCovarianceBlock>& blocks) {
  const Index m = J.rows(), p = J.cols();
  if (m <= p || p < 1) throw InputError("fit covariance", "Jacobian", "more residuals than parameters (>= 1)", std::to_string(m) + " x " + std::to_string(p));
  if (r.size() != m) throw InputError("fit covariance", "residuals", std::to_string(m) + " values", std::to_string(r.size()));
  if (residual_std.size() != 0 && residual_std.size() != m) {
    throw InputError("fit covariance", "residual_std", std::to_string(m) + " values or none", std::to_string(residual_std.size()));
  }
  if (adjacent_correlation.size() != 0 && (residual_std.size() != m || m % 2 != 0 || adjacent_correlation.size() != m / 2 - 1)) {
    throw InputError("fit covariance", "adjacent_correlation", std::to_string(m / 2 - 1) + " values (complex residuals, residual_std given) or none",
                     std::to_string(adjacent_correlation.size()));
  }
  for (const ResidualCovarianceBlock& b : blocks) {
    const Index n = b.covariance.rows();
    const bool finite = std::all_of(b.covariance.valuePtr(), b.covariance.valuePtr() + b.covariance.nonZeros(), [](double v) { return std::isfinite(v); });
    if (residual_std.size() != m || b.covariance.cols() != n || b.first < 0 || b.first + n > m || !finite) {
      throw InputError("fit covariance", "blocks", "finite square blocks inside the " + std::to_string(m) + " residuals (residual_std given)",
                       std::to_string(n) + " x " + std::to_string(b.covariance.cols()) + " at " + std::to_string(b.first));
    }
  }
  FitCovariance out;
  const double inf = std::numeric_limits<double>::infinity();
  const double dof = static_cast<double>(m - p);
  // Column scaling makes the conditioning (and the inverse) independent of the parameters' units.
  const VectorXd norms = J.colwise().norm().transpose();
  out.singular = (norms.array() == 0.0).any() || !J.allFinite();
  const MatrixXd Js = J * norms.cwiseMax(1e-300).cwiseInverse().asDiagonal();
  const Eigen::JacobiSVD<MatrixXd> svd(Js, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const VectorXd sv = svd.singularValues();
  out.condition_number = sv(p - 1) > 0.0 ? sv(0) / sv(p - 1) : inf;
  out.singular = out.singular || !(out.condition_number < 1e14);
  if (residual_std.size() == m) {
    out.chi2_per_dof = r.cwiseQuotient(residual_std).squaredNorm() / dof;
  } else {
    out.chi2_per_dof = r.squaredNorm() / dof;
  }
  if (out.singular) {
    out.covariance = MatrixXd::Constant(p, p, inf);
    out.standard_error = VectorXd::Constant(p, inf);
    out.correlation = MatrixXd::Identity(p, p);
    return out;
  }
  // (Js^T Js)^-1 = V S^-2 V^T; in the parameters' units divide by the column norms on both sides.
  const MatrixXd V = svd.matrixV();
  const MatrixXd A = V * sv.array().square().inverse().matrix().asDiagonal() * V.transpose();  // scaled (J^T J)^-1
  MatrixXd Cs;
  if (residual_std.size() == m) {
    // L = (J^T J)^-1 J^T: row j is parameter j's influence of each residual; the local chi2 f_j.
    const MatrixXd L = A * Js.transpose();
    const Eigen::ArrayXXd L2 = L.array().square();
    VectorXd variance = residual_std.array().square().matrix();
    for (const ResidualCovarianceBlock& b : blocks) variance.segment(b.first, b.covariance.rows()) += b.covariance.diagonal();
    const VectorXd noise = L2.matrix() * variance;
    const VectorXd misfit = (L2.matrix() * r.array().square().matrix());
    VectorXd widen(p);
    const double hc1 = static_cast<double>(m) / dof;  // the residuals' lost degrees of freedom
    for (Index j = 0; j < p; ++j) widen(j) = noise(j) > 0.0 ? std::sqrt(std::max(1.0, hc1 * misfit(j) / noise(j))) : 1.0;
    MatrixXd B = noise_middle(Js, residual_std, adjacent_correlation);
    for (const ResidualCovarianceBlock& b : blocks) {
      const auto Jb = Js.middleRows(b.first, b.covariance.rows());
      const MatrixXd SJ = b.covariance * Jb;
      B += Jb.transpose() * SJ;
    }
    Cs = widen.asDiagonal() * (A * B * A) * widen.asDiagonal();
  } else {
    Cs = A * out.chi2_per_dof;
  }
  const VectorXd inv = norms.cwiseInverse();
  out.covariance = inv.asDiagonal() * Cs * inv.asDiagonal();
  out.standard_error = out.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  out.correlation = MatrixXd::Identity(p, p);
  for (Index i = 0; i < p; ++i) {
    for (Index j = i + 1; j < p; ++j) {
      const double d = out.standard_error(i) * out.standard_error(j);
      const double c = d > 0.0 ? out.covariance(i, j) / d : 0.0;
      out.correlation(i, j) = out.correlation(j, i) = c;
      if (std::abs(c) > kHighCorrelation) out.high_correlations.emplace_back(static_cast<int>(i), static_cast<int>(j));
    }
  }
  return out;
}

double ParameterUncertainty::standard_error_of(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return standard_error(static_cast<Index>(i));
  }
  return std::numeric_limits<double>::quiet_NaN();
}

double ParameterUncertainty::relative_standard_error_of(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) {
      const double v = std::abs(value(static_cast<Index>(i)));
      return v > 0.0 ? standard_error(static_cast<Index>(i)) / v : std::numeric_limits<double>::infinity();
    }
  }
  return std::numeric_limits<double>::quiet_NaN();
}

ParameterUncertainty parameter_uncertainty(const std::vector<std::string>& names, const VectorXd& value, const VectorXd& dvalue_dx,
                                           const std::vector<int>& fitted, const FitCovariance& covariance, bool from_data_variance) {
  const auto n = static_cast<Index>(names.size());
  if (value.size() != n || dvalue_dx.size() != n || static_cast<Index>(fitted.size()) != n) {
    throw InputError("parameter uncertainty", "sizes", std::to_string(n) + " values, derivatives and indices", "other counts");
  }
  ParameterUncertainty u;
  u.names = names;
  u.value = value;
  u.standard_error = VectorXd::Zero(n);
  u.correlation = MatrixXd::Identity(n, n);
  u.condition_number = covariance.condition_number;
  u.chi2_per_dof = covariance.chi2_per_dof;
  u.from_data_variance = from_data_variance;
  for (Index i = 0; i < n; ++i) {
    const int a = fitted[static_cast<std::size_t>(i)];
    if (a < 0) continue;
    u.standard_error(i) = std::abs(dvalue_dx(i)) * covariance.standard_error(a);
    for (Index j = 0; j < n; ++j) {
      const int b = fitted[static_cast<std::size_t>(j)];
      if (b < 0 || j == i) continue;
      if (a == b) {  // tied to one solver parameter (e.g. ke = 2 ka): moves with it by construction
        u.correlation(i, j) = 1.0;
        continue;
      }
      // A monotone map per parameter keeps the correlation up to the sign of the derivatives.
      const double sign = (dvalue_dx(i) < 0.0) != (dvalue_dx(j) < 0.0) ? -1.0 : 1.0;
      u.correlation(i, j) = sign * covariance.correlation(a, b);
      if (j > i && std::abs(u.correlation(i, j)) > kHighCorrelation) {
        u.high_correlations.push_back(correlation_label(names[static_cast<std::size_t>(i)], names[static_cast<std::size_t>(j)], u.correlation(i, j)));
      }
    }
  }
  return u;
}

std::vector<std::string> high_correlation_labels(const FitCovariance& covariance, const std::vector<std::string>& names) {
  if (static_cast<Index>(names.size()) != covariance.correlation.rows()) {
    throw InputError("high correlations", "names", std::to_string(covariance.correlation.rows()) + " names", std::to_string(names.size()));
  }
  std::vector<std::string> out;
  for (const auto& [i, j] : covariance.high_correlations) {
    out.push_back(correlation_label(names[static_cast<std::size_t>(i)], names[static_cast<std::size_t>(j)], covariance.correlation(i, j)));
  }
  return out;
}

MatrixXd propagate_covariance(const MatrixXd& G, const MatrixXd& covariance) {
  if (G.cols() != covariance.rows() || covariance.rows() != covariance.cols()) {
    throw InputError("covariance propagation", "sizes", std::to_string(covariance.rows()) + " columns in the Jacobian",
                     std::to_string(G.cols()));
  }
  return G * covariance * G.transpose();
}

}  // namespace piezobench::core
