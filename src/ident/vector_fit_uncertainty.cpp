#include "piezobench/ident/vector_fit_uncertainty.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "piezobench/core/error.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/dsp/frf.hpp"
#include "piezobench/dsp/frf_variance.hpp"
#include "piezobench/dsp/resolution_kernel.hpp"

namespace piezobench::ident {

// The helpers in their own namespace: a unity batch compiles this file with vector_fitting.cpp.
namespace fit_uncertainty {
namespace {

constexpr const char* kSource = "vector fit uncertainty";
constexpr Complex kJ(0.0, 1.0);

// Where each real parameter of the model sits: the pole it belongs to (or -1), the output (or -1 for a
// pole), and what it is.
enum class Kind { kPoleRe, kPoleIm, kRealPole, kResidueRe, kResidueIm, kRealResidue, kD, kE };
struct Parameter {
  Kind kind;
  Index pole = -1;    // index into fit.poles (the pair's upper member)
  Index output = -1;  // residues, d, e
};

std::vector<Parameter> layout(const VectorFittingResult& fit, std::vector<std::string>& names) {
  std::vector<Parameter> out;
  const Index n = fit.poles.size();
  const auto pole_name = [](Index k) { return "p" + std::to_string(k); };
  for (Index k = 0; k < n; ++k) {
    if (fit.poles(k).imag() < 0.0) continue;  // the lower member of a pair: its upper one carries it
    if (fit.poles(k).imag() == 0.0) {
      out.push_back({Kind::kRealPole, k});
      names.push_back(pole_name(k));
    } else {
      out.push_back({Kind::kPoleRe, k});
      out.push_back({Kind::kPoleIm, k});
      names.push_back(pole_name(k) + ".re");
      names.push_back(pole_name(k) + ".im");
    }
  }
  for (Index i = 0; i < fit.outputs(); ++i) {
    const std::string o = std::to_string(i);
    for (Index k = 0; k < n; ++k) {
      if (fit.poles(k).imag() < 0.0) continue;
      const std::string r = "r" + o + "." + std::to_string(k);
      if (fit.poles(k).imag() == 0.0) {
        out.push_back({Kind::kRealResidue, k, i});
        names.push_back(r);
      } else {
        out.push_back({Kind::kResidueRe, k, i});
        out.push_back({Kind::kResidueIm, k, i});
        names.push_back(r + ".re");
        names.push_back(r + ".im");
      }
    }
    // d and e count as fitted when nonzero (vector_fit leaves them exactly 0 otherwise).
    if (fit.d(i) != 0.0) {
      out.push_back({Kind::kD, -1, i});
      names.push_back("d" + o);
    }
    if (fit.e(i) != 0.0) {
      out.push_back({Kind::kE, -1, i});
      names.push_back("e" + o);
    }
  }
  return out;
}

// d f_output(s) / d parameter (0 for a parameter of another output).
Complex derivative(const VectorFittingResult& fit, const Parameter& q, Index output, Complex s) {
  if (q.output >= 0 && q.output != output) return 0.0;
  if (q.kind == Kind::kD) return 1.0;
  if (q.kind == Kind::kE) return s;
  const Complex p = fit.poles(q.pole);
  const Complex a = 1.0 / (s - p), b = 1.0 / (s - std::conj(p));
  switch (q.kind) {
    case Kind::kRealPole: return fit.residues(output, q.pole) * a * a;
    case Kind::kRealResidue: return a;
    case Kind::kResidueRe: return a + b;
    case Kind::kResidueIm: return kJ * (a - b);
    case Kind::kPoleRe:
    case Kind::kPoleIm: {
      const Complex r = fit.residues(output, q.pole);
      const Complex da = r * a * a, db = std::conj(r) * b * b;
      return q.kind == Kind::kPoleRe ? da + db : kJ * (da - db);
    }
    default: return 0.0;
  }
}

// A root's frequency and damping with their standard errors from the 2 x 2 covariance of (Re, Im).
RootUncertainty root_uncertainty(Complex root, const Eigen::Matrix2d& c) {
  RootUncertainty u;
  u.root = root;
  const double x = root.real(), y = root.imag(), r = std::abs(root);
  u.natural_frequency = r;
  u.damping = r > 0.0 ? -x / r : 0.0;
  u.real_se = std::sqrt(std::max(c(0, 0), 0.0));
  u.imag_se = std::sqrt(std::max(c(1, 1), 0.0));
  if (!c.allFinite()) {
    u.natural_frequency_se = u.damping_se = u.real_se = u.imag_se = std::numeric_limits<double>::infinity();
    return u;
  }
  if (r > 0.0) {
    const Eigen::Vector2d gf(x / r, y / r), gz(-y * y / (r * r * r), x * y / (r * r * r));
    u.natural_frequency_se = std::sqrt(std::max(gf.dot(c * gf), 0.0));
    u.damping_se = std::sqrt(std::max(gz.dot(c * gz), 0.0));
  }
  return u;
}

Eigen::Matrix2d block(const Matrix& c, Index i, Index j) {
  Eigen::Matrix2d b;
  b << c(i, i), c(i, j), c(j, i), c(j, j);
  return b;
}

}  // namespace
}  // namespace fit_uncertainty

VectorFitUncertainty vector_fit_uncertainty(const Vector& omega, const CMatrix& data, const VectorFittingResult& fit,
                                            const VectorFittingOptions& options, const Matrix& user_weights, const Matrix& std_H,
                                            const Vector& adjacent_correlation) {
  const Index m = omega.size(), nc = data.cols();
  if (data.rows() != m || fit.outputs() != nc) {
    throw InputError(fit_uncertainty::kSource, "data", std::to_string(m) + " points x " + std::to_string(fit.outputs()) + " outputs",
                     std::to_string(data.rows()) + " x " + std::to_string(nc));
  }
  if (user_weights.size() != 0 && (user_weights.rows() != m || (user_weights.cols() != 1 && user_weights.cols() != nc))) {
    throw InputError(fit_uncertainty::kSource, "weights", std::to_string(m) + " x 1 or x " + std::to_string(nc),
                     std::to_string(user_weights.rows()) + " x " + std::to_string(user_weights.cols()));
  }
  const Matrix weights = vector_fitting_weights(data, user_weights, options);
  if (std_H.size() != 0 && (std_H.rows() != m || std_H.cols() != nc)) {
    throw InputError(fit_uncertainty::kSource, "std_H", std::to_string(m) + " x " + std::to_string(nc), std::to_string(std_H.rows()) + " x " + std::to_string(std_H.cols()));
  }
  if (adjacent_correlation.size() != 0 && (std_H.size() == 0 || adjacent_correlation.size() != m - 1)) {
    throw InputError(fit_uncertainty::kSource, "adjacent_correlation", std::to_string(m - 1) + " values with std_H, or none",
                     std::to_string(adjacent_correlation.size()) + (std_H.size() == 0 ? " without std_H" : ""));
  }
  VectorFitUncertainty out;
  const std::vector<fit_uncertainty::Parameter> params = fit_uncertainty::layout(fit, out.names);
  const auto p = static_cast<Index>(params.size());
  // Rows: output by output, each point's real then imaginary part of w (f - H).
  Matrix J(2 * m * nc, p);
  Vector r(2 * m * nc), s(2 * m * nc);
  out.from_data_variance = std_H.size() != 0;
  const CMatrix model = fit.evaluate(omega);
  // Without the data's variance, each output's noise from the fit's residuals, additive plus
  // proportional (dsp::estimate_frf_noise, as the plant fits do): equal weights would take the dip's
  // few noisy lines as precise as the peak's, and a zero's damping error would be many times too small.
  Matrix noise = std_H;
  if (!out.from_data_variance) {
    noise.resize(m, nc);
    for (Index i = 0; i < nc; ++i) {
      const dsp::FrfNoiseEstimate e = dsp::estimate_frf_noise(data.col(i), model.col(i));
      for (Index k = 0; k < m; ++k) noise(k, i) = std::hypot(e.additive_std, e.relative_std * std::abs(model(k, i)));
    }
  }
  for (Index i = 0; i < nc; ++i) {
    for (Index k = 0; k < m; ++k) {
      const double w = weights(k, weights.cols() == 1 ? 0 : i);
      const Index row = 2 * (i * m + k);
      const Complex e = w * (model(k, i) - data(k, i));
      r(row) = e.real();
      r(row + 1) = e.imag();
      s(row) = s(row + 1) = w * noise(k, i);
      const Complex sk(0.0, omega(k));
      for (Index j = 0; j < p; ++j) {
        const Complex d = w * fit_uncertainty::derivative(fit, params[static_cast<std::size_t>(j)], i, sk);
        J(row, j) = d.real();
        J(row + 1, j) = d.imag();
      }
    }
  }
  if (J.rows() <= p) throw InputError(fit_uncertainty::kSource, "data", "more real residuals than the model's " + std::to_string(p) + " parameters", std::to_string(J.rows()));
  // The complex residuals run output by output: neighbours within an output correlate, across none.
  Eigen::VectorXcd neighbours;
  if (adjacent_correlation.size() != 0) {
    neighbours = Eigen::VectorXcd::Zero(m * nc - 1);
    for (Index i = 0; i < nc; ++i) neighbours.segment(i * m, m - 1) = adjacent_correlation.cast<Complex>();
  }
  out.covariance = core::fit_covariance(J, r, s, neighbours);
  const Matrix& c = out.covariance.covariance;
  for (Index k = 0; k < fit.poles.size(); ++k) {
    const Complex pole = fit.poles(k);
    const Index upper = pole.imag() < 0.0 ? k - 1 : k;  // a pair's lower member follows its upper one
    if (upper < 0 || (upper != k && fit.poles(upper) != std::conj(pole))) {
      throw InputError(fit_uncertainty::kSource, "poles", "pairs in vector_fit's order (Im > 0 first)", "a lower member without its upper one before it");
    }
    Index at = 0;
    while (params[static_cast<std::size_t>(at)].pole != upper) ++at;
    Eigen::Matrix2d ck = Eigen::Matrix2d::Zero();
    if (pole.imag() == 0.0) {
      ck(0, 0) = c(at, at);
    } else {
      ck = fit_uncertainty::block(c, at, at + 1);
      if (pole.imag() < 0.0) ck(0, 1) = ck(1, 0) = -ck(0, 1);  // Im of the conjugate
    }
    out.poles.push_back(fit_uncertainty::root_uncertainty(pole, ck));
  }
  return out;
}

VectorFitUncertainty vector_fit_uncertainty(const dsp::Frf& frf, const VectorFittingResult& fit, const VectorFittingOptions& options) {
  const Index n = frf.freq_Hz.size(), outputs = static_cast<Index>(frf.H.size());
  CMatrix data(n, outputs);
  Matrix std_h(n, outputs);
  bool variance = frf.std_H.size() == frf.H.size();
  for (Index i = 0; i < outputs; ++i) {
    const auto io = static_cast<std::size_t>(i);
    data.col(i) = frf.H[io];
    variance = variance && frf.std_H[io].size() == n;
    if (variance) std_h.col(i) = frf.std_H[io];
  }
  const Vector omega = kTwoPi * frf.freq_Hz;
  const Vector pairs = variance ? dsp::adjacent_line_pairs(dsp::resolution_kernel(frf.provenance), omega) : Vector();
  return vector_fit_uncertainty(omega, data, fit, options, frf_row_weights(frf, options), variance ? std_h : Matrix(), pairs);
}

namespace fit_uncertainty {
namespace {
// The parameters of `fit` after checking that `output` is one of its outputs and u is its covariance.
std::vector<Parameter> checked_layout(const VectorFittingResult& fit, const VectorFitUncertainty& u, Index output) {
  if (output < 0 || output >= fit.outputs()) {
    throw InputError(kSource, "output", "0 to " + std::to_string(fit.outputs() - 1), std::to_string(output));
  }
  std::vector<std::string> names;
  std::vector<Parameter> params = layout(fit, names);
  if (names != u.names) throw InputError(kSource, "uncertainty", "the covariance of this fit", "another fit's");
  return params;
}
}  // namespace
}  // namespace fit_uncertainty

Eigen::Matrix2d response_covariance(const VectorFittingResult& fit, const VectorFitUncertainty& u, Index output, Complex s) {
  const std::vector<fit_uncertainty::Parameter> params = fit_uncertainty::checked_layout(fit, u, output);
  if (u.covariance.singular) return Eigen::Matrix2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Matrix<double, 2, Eigen::Dynamic> g(2, static_cast<Index>(params.size()));
  for (Index j = 0; j < g.cols(); ++j) {
    const Complex d = fit_uncertainty::derivative(fit, params[static_cast<std::size_t>(j)], output, s);
    g(0, j) = d.real();
    g(1, j) = d.imag();
  }
  return core::propagate_covariance(g, u.covariance.covariance);
}

std::vector<RootUncertainty> zero_uncertainty(const VectorFittingResult& fit, const VectorFitUncertainty& u, Index output,
                                              const CVector& zeros) {
  const std::vector<fit_uncertainty::Parameter> params = fit_uncertainty::checked_layout(fit, u, output);
  std::vector<RootUncertainty> out;
  for (Index z = 0; z < zeros.size(); ++z) {
    const Complex s = zeros(z);
    // f'(s) = e - sum_n r_n / (s - p_n)^2
    Complex slope = fit.e(output);
    for (Index n = 0; n < fit.poles.size(); ++n) slope -= fit.residues(output, n) / ((s - fit.poles(n)) * (s - fit.poles(n)));
    Eigen::Matrix<double, 2, Eigen::Dynamic> g(2, static_cast<Index>(params.size()));
    for (Index j = 0; j < g.cols(); ++j) {
      const Complex dz = -fit_uncertainty::derivative(fit, params[static_cast<std::size_t>(j)], output, s) / slope;
      g(0, j) = dz.real();
      g(1, j) = dz.imag();
    }
    const Eigen::Matrix2d c = u.covariance.singular ? Eigen::Matrix2d::Constant(std::numeric_limits<double>::infinity())
                                                    : Eigen::Matrix2d(core::propagate_covariance(g, u.covariance.covariance));
    out.push_back(fit_uncertainty::root_uncertainty(s, c));
  }
  return out;
}

}  // namespace piezobench::ident
