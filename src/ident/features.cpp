#include "piezobench/ident/features.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <vector>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/least_squares.hpp"
#include "piezobench/core/minimize.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/dsp/frf.hpp"
#include "piezobench/lti/analysis.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::ident {
namespace {

constexpr const char* kFeatureSource = "frf features";

// Checks one response: sizes, finite values, a usable frequency grid.
void check_response(const char* source, const Vector& omega, const CVector& h) {
  if (h.size() != omega.size()) {
    throw InputError(source, "h", std::to_string(omega.size()) + " values (one per frequency)",
                     std::to_string(h.size()));
  }
  for (Index k = 0; k < omega.size(); ++k) {
    if (!std::isfinite(omega(k)) || omega(k) < 0.0 || (k > 0 && omega(k) <= omega(k - 1))) {
      throw InputError(source, "omega[" + std::to_string(k) + "]",
                       "finite, non-negative, strictly increasing frequencies", format_number(omega(k)));
    }
    if (!std::isfinite(h(k).real()) || !std::isfinite(h(k).imag())) {
      throw InputError(source, "h[" + std::to_string(k) + "]", "finite value", "non-finite");
    }
  }
}

ModalFeature make_feature(Complex root) {
  ModalFeature f;
  f.root = Complex(root.real(), std::abs(root.imag()));
  f.natural_frequency = std::abs(root);
  f.damping = f.natural_frequency > 0.0 ? std::abs(root.real()) / f.natural_frequency : 1.0;
  return f;
}

// Pole-zero cancellation, one to one: a pole and a zero closer than rel_tol (relative to the
// pole) cancel, the closest pairs first, and each pole or zero cancels at most one partner. A fit
// that adds a spurious pole-zero pair next to a true resonance (unit 1 of the demo: the resonance at
// 95.57 Hz with spurious pairs at 95.61 and 96.82 Hz) keeps the resonance: its nearest zero is the
// spurious pole's partner. Returns, per pole and per zero, whether it cancels.
struct Cancellation {
  std::vector<bool> pole, zero;
};
Cancellation cancellation(const CVector& poles, const CVector& zeros, double rel_tol) {
  struct Candidate {
    double distance;
    Index pole, zero;
  };
  std::vector<Candidate> near;
  for (Index i = 0; i < poles.size(); ++i) {
    for (Index j = 0; j < zeros.size(); ++j) {
      const double d = std::abs(poles(i) - zeros(j)) / std::abs(poles(i));
      if (d < rel_tol) near.push_back({d, i, j});
    }
  }
  std::sort(near.begin(), near.end(), [](const Candidate& a, const Candidate& b) { return a.distance < b.distance; });
  Cancellation c{std::vector<bool>(static_cast<std::size_t>(poles.size()), false), std::vector<bool>(static_cast<std::size_t>(zeros.size()), false)};
  for (const Candidate& n : near) {
    const auto i = static_cast<std::size_t>(n.pole), j = static_cast<std::size_t>(n.zero);
    if (c.pole[i] || c.zero[j]) continue;
    c.pole[i] = c.zero[j] = true;
  }
  return c;
}

// |d ln|H| / d ln w| of the fitted model at w (central difference, 1 % step).
double log_slope(const VectorFittingResult& fit, double w) {
  const double lo = std::abs(fit.evaluate_at(Complex(0.0, w / 1.01))(0));
  const double hi = std::abs(fit.evaluate_at(Complex(0.0, w * 1.01))(0));
  return std::abs(std::log(hi / lo) / std::log(1.01 * 1.01));
}

// Unwrapped phase change of the data over [w_lo, w_hi], from the phase of consecutive ratios.
// Exact as long as the true change between neighbouring points stays below 180 deg, which holds
// for a single zero pair (its total change is 180 deg, monotonic).
std::pair<double, Index> phase_change(const Vector& omega, const CVector& h, double w_lo, double w_hi) {
  double total = 0.0;
  Index count = 0;
  Index prev = -1;
  for (Index k = 0; k < omega.size(); ++k) {
    if (omega(k) < w_lo || omega(k) > w_hi) continue;
    ++count;
    if (prev >= 0) total += std::arg(h(k) / h(prev));
    prev = k;
  }
  return {total * 180.0 / std::numbers::pi, count};
}

}  // namespace

double ModalFeature::frequency_Hz() const { return natural_frequency / kTwoPi; }
double HighPassFit::corner_Hz() const { return corner / kTwoPi; }
double SecondOrderFit::frequency_Hz() const { return natural_frequency / kTwoPi; }

std::string to_string(StaticGainSource s) {
  return s == StaticGainSource::kModelDcGain ? "model-dc-gain" : "data-plateau";
}
StaticGainSource static_gain_source_from_string(const std::string& s) {
  if (s == "model-dc-gain") return StaticGainSource::kModelDcGain;
  if (s == "data-plateau") return StaticGainSource::kDataPlateau;
  throw InputError("", "static_gain_source", "one of model-dc-gain, data-plateau", "'" + s + "'");
}

std::string to_string(PhaseVerdict v) {
  switch (v) {
    case PhaseVerdict::kMinimumPhase: return "minimum-phase";
    case PhaseVerdict::kNonMinimumPhase: return "non-minimum-phase";
    case PhaseVerdict::kUndetermined: return "undetermined";
  }
  return "undetermined";
}
PhaseVerdict phase_verdict_from_string(const std::string& s) {
  if (s == "minimum-phase") return PhaseVerdict::kMinimumPhase;
  if (s == "non-minimum-phase") return PhaseVerdict::kNonMinimumPhase;
  if (s == "undetermined") return PhaseVerdict::kUndetermined;
  throw InputError("", "phase_verdict", "one of minimum-phase, non-minimum-phase, undetermined", "'" + s + "'");
}

std::string to_string(SecondOrderMethod m) {
  return m == SecondOrderMethod::kNonlinearLeastSquares ? "nls" : "vector-fitting";
}
SecondOrderMethod second_order_method_from_string(const std::string& s) {
  if (s == "nls") return SecondOrderMethod::kNonlinearLeastSquares;
  if (s == "vector-fitting") return SecondOrderMethod::kVectorFitting;
  throw InputError("", "method", "one of nls, vector-fitting", "'" + s + "'");
}

void FrfFeatureOptions::validate() const {
  const char* src = "frf feature options";
  fit.validate();
  if (fit.asymptote == Asymptote::kConstantAndLinear) {
    throw InputError(src, "fit.asymptote", "none or d (the zeros need a proper model)", "de");
  }
  const auto check = [&](const char* field, double v, double lo, double hi) {
    if (!std::isfinite(v) || v <= lo || v >= hi) {
      throw InputError(src, field, "value in (" + format_number(lo) + ", " + format_number(hi) + ")", format_number(v));
    }
  };
  check("max_damping", max_damping, 0.0, 1.0);
  check("min_significance", min_significance, -1e-300, 1.0);
  check("cancellation_tolerance", cancellation_tolerance, 0.0, 1.0);
  check("phase_band", phase_band, 0.0, 1.0);
  check("phase_threshold_deg", phase_threshold_deg, 0.0, 180.0);
  check("high_pass_ratio", high_pass_ratio, 0.0, 1.0);
}

void SecondOrderFitOptions::validate() const {
  if (max_iterations < 1) {
    throw InputError("second-order fit options", "max_iterations", ">= 1", std::to_string(max_iterations));
  }
}

FrfFeatures frf_features(const Vector& omega, const CVector& h, const FrfFeatureOptions& options) {
  options.validate();
  check_response(kFeatureSource, omega, h);
  FrfFeatures out;
  out.fit = vector_fit(omega, CMatrix(h), options.fit);
  const VectorFittingResult& fit = out.fit;
  const double w_lo = omega(0);
  const double w_hi = omega(omega.size() - 1);

  // Zeros of the fitted proper model (single output).
  lti::StateSpace siso;
  siso.A = fit.model.A;
  siso.B = fit.model.B;
  siso.C = fit.model.C.row(0);
  siso.D = fit.model.D.row(0);
  const CVector zeros = lti::zeros(siso);
  const CVector& poles = fit.poles;
  const Cancellation cancels = cancellation(poles, zeros, options.cancellation_tolerance);

  for (Index n = 0; n < poles.size(); ++n) {
    const Complex p = poles(n);
    if (p.imag() <= 0.0 || p.real() >= 0.0) continue;
    const ModalFeature f = make_feature(p);
    if (f.damping >= options.max_damping || p.imag() < w_lo || p.imag() > w_hi) continue;
    const double peak = std::abs(fit.residues(0, n)) / std::abs(p.real());
    const double level = std::abs(fit.evaluate_at(Complex(0.0, p.imag()))(0));
    if (peak < options.min_significance * level) continue;
    if (cancels.pole[static_cast<std::size_t>(n)]) continue;
    out.resonances.push_back(f);
  }
  for (Index n = 0; n < zeros.size(); ++n) {
    const Complex z = zeros(n);
    if (z.imag() <= 0.0) continue;
    AntiResonance a;
    static_cast<ModalFeature&>(a) = make_feature(z);
    if (a.damping >= options.max_damping || z.imag() < w_lo || z.imag() > w_hi) continue;
    if (cancels.zero[static_cast<std::size_t>(n)]) continue;
    a.nonminimum_phase_model = z.real() > 0.0;
    out.antiresonances.push_back(a);
  }
  const auto by_frequency = [](const ModalFeature& x, const ModalFeature& y) {
    return x.natural_frequency < y.natural_frequency;
  };
  std::sort(out.resonances.begin(), out.resonances.end(), by_frequency);
  std::sort(out.antiresonances.begin(), out.antiresonances.end(), by_frequency);

  // Phase across each anti-resonance, read from the data.
  for (AntiResonance& a : out.antiresonances) {
    const double w0 = a.root.imag();
    double delta = std::max(options.phase_band, 5.0 * a.damping);
    const auto limit = [&](double w_other) {
      if (w_other != w0) delta = std::min(delta, 0.5 * std::abs(w_other - w0) / w0);
    };
    for (const ModalFeature& r : out.resonances) limit(r.root.imag());
    for (const AntiResonance& other : out.antiresonances) limit(other.root.imag());
    const auto [change, count] = phase_change(omega, h, w0 * (1.0 - delta), w0 * (1.0 + delta));
    a.phase_change_deg = change;
    a.phase_points = count;
    if (count >= 2 && change > options.phase_threshold_deg) a.phase_verdict = PhaseVerdict::kMinimumPhase;
    if (count >= 2 && change < -options.phase_threshold_deg) a.phase_verdict = PhaseVerdict::kNonMinimumPhase;
  }

  // Static gain: the model's DC gain unless the model has a high-pass; then the data's plateau
  // below the first resonant feature, where the model's log-log slope is flattest.
  const double dc = fit.evaluate_at(Complex(0.0, 0.0))(0).real();
  if (std::isfinite(dc) && std::abs(dc) >= options.high_pass_ratio * std::abs(h(0))) {
    out.static_gain = dc;
    out.static_gain_source = StaticGainSource::kModelDcGain;
  } else {
    double w_feature = w_hi;
    for (const ModalFeature& r : out.resonances) w_feature = std::min(w_feature, r.natural_frequency);
    for (const AntiResonance& r : out.antiresonances) w_feature = std::min(w_feature, r.natural_frequency);
    Index best = 0;
    double best_slope = std::numeric_limits<double>::infinity();
    for (Index k = 0; k < omega.size() && omega(k) <= 0.5 * w_feature; ++k) {
      if (omega(k) <= 0.0) continue;
      const double slope = log_slope(fit, omega(k));
      if (slope < best_slope) {
        best_slope = slope;
        best = k;
      }
    }
    const double w_star = omega(best);
    Complex sum(0.0, 0.0);
    Index count = 0;
    for (Index k = 0; k < omega.size(); ++k) {
      if (omega(k) >= w_star / 1.2 && omega(k) <= w_star * 1.2) {
        sum += h(k);
        ++count;
      }
    }
    const Complex mean = sum / static_cast<double>(count);
    out.static_gain = (mean.real() < 0.0 ? -1.0 : 1.0) * std::abs(mean);
    out.static_gain_source = StaticGainSource::kDataPlateau;
    out.plateau_frequency = w_star;
  }
  return out;
}

FrfFeatures frf_features(const dsp::Frf& frf, const std::string& output, const FrfFeatureOptions& options) {
  frf.validate();
  const Index i = frf.output_index(output);
  try {
    return frf_features(kTwoPi * frf.freq_Hz, frf.H[static_cast<size_t>(i)], options);
  } catch (const InputError& e) {
    if (frf.provenance.source.empty()) throw;
    throw e.with_source(frf.provenance.source + " (output " + output + ")");
  }
}

HighPassFit fit_high_pass(const Vector& omega, const CVector& h, double max_omega) {
  const char* src = "high-pass fit";
  check_response(src, omega, h);
  if (!std::isfinite(max_omega) || max_omega < 0.0) {
    throw InputError(src, "max_omega", "finite value >= 0 rad/s (0 = all data)", format_number(max_omega));
  }
  std::vector<Index> used;
  for (Index k = 0; k < omega.size(); ++k) {
    if (omega(k) > 0.0 && (max_omega == 0.0 || omega(k) <= max_omega)) used.push_back(k);
  }
  if (used.size() < 2) {
    throw InputError(src, "omega", "at least 2 frequencies > 0 below max_omega", std::to_string(used.size()));
  }
  if (h.cwiseAbs().maxCoeff() == 0.0) throw InputError(src, "h", "a nonzero response", "all zeros");
  // Variable projection: for a corner wc the best real gain is closed form.
  const auto gain_and_cost = [&](double wc) {
    double num_g = 0.0, den = 0.0;
    for (Index k : used) {
      const Complex b = Complex(0.0, omega(k)) / Complex(wc, omega(k));
      num_g += (std::conj(b) * h(k)).real();
      den += std::norm(b);
    }
    const double g = num_g / den;
    double cost = 0.0;
    for (Index k : used) cost += std::norm(h(k) - g * Complex(0.0, omega(k)) / Complex(wc, omega(k)));
    return std::pair<double, double>{g, cost};
  };
  const double l_lo = std::log(omega(used.front()) / 100.0);
  const double l_hi = std::log(omega(used.back()) * 100.0);
  constexpr int kGrid = 400;
  int best = 0;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= kGrid; ++i) {
    const double c = gain_and_cost(std::exp(l_lo + (l_hi - l_lo) * i / kGrid)).second;
    if (c < best_cost) {
      best_cost = c;
      best = i;
    }
  }
  const double step = (l_hi - l_lo) / kGrid;
  const double a = l_lo + step * std::max(best - 1, 0);
  const double b = l_lo + step * std::min(best + 1, kGrid);
  const double l = core::golden_section_minimize([&](double x) { return gain_and_cost(std::exp(x)).second; }, a, b).x;
  HighPassFit fit;
  fit.corner = std::exp(l);
  const auto [g, cost] = gain_and_cost(fit.corner);
  fit.gain = g;
  double data = 0.0;
  for (Index k : used) data += std::norm(h(k));
  fit.relative_rms_error = std::sqrt(cost / data);
  return fit;
}

SecondOrderFit fit_second_order(const Vector& omega, const CVector& h, const SecondOrderFitOptions& options) {
  const char* src = "second-order fit";
  options.validate();
  check_response(src, omega, h);
  if (omega.size() < 3) throw InputError(src, "omega", "at least 3 frequencies", std::to_string(omega.size()));
  if (h.cwiseAbs().maxCoeff() == 0.0) throw InputError(src, "h", "a nonzero response", "all zeros");
  SecondOrderFit out;
  double a0 = 0.0, a1 = 0.0;
  const double scale = omega(omega.size() - 1);

  if (options.method == SecondOrderMethod::kVectorFitting) {
    VectorFittingOptions vo;
    vo.order = 2;
    vo.asymptote = Asymptote::kConstant;
    const VectorFittingResult r = vector_fit(omega, CMatrix(h), vo);
    a0 = (r.poles(0) * r.poles(1)).real();
    a1 = -(r.poles(0) + r.poles(1)).real();
    out.poles = r.poles;
    out.static_gain = r.evaluate_at(Complex(0.0, 0.0))(0).real();
    out.feedthrough = r.d(0);
    out.relative_rms_error = r.relative_rms_error;
    out.iterations = r.iterations;
  } else {
    // Normalized frequency x = omega / scale; model k' / (s^2 + a1 s + a0) with s = j x.
    const Index n = omega.size();
    CVector s(n);
    for (Index k = 0; k < n; ++k) s(k) = Complex(0.0, omega(k) / scale);
    // Levy: h (s^2 + a1 s + a0) = k'  ->  [1, -h s, -h] [k', a1, a0]^T = h s^2 (linear, real unknowns).
    Matrix a(2 * n, 3);
    Vector rhs(2 * n);
    for (Index k = 0; k < n; ++k) {
      const Complex c1 = -h(k) * s(k), c2 = -h(k), r = h(k) * s(k) * s(k);
      a.row(k) << 1.0, c1.real(), c2.real();
      a.row(n + k) << 0.0, c1.imag(), c2.imag();
      rhs(k) = r.real();
      rhs(n + k) = r.imag();
    }
    Vector p = a.colPivHouseholderQr().solve(rhs);
    // Levenberg-Marquardt on the complex output error (analytic Jacobian).
    const auto residual = [&](const Vector& q) {
      Vector res(2 * n);
      for (Index k = 0; k < n; ++k) {
        const Complex e = q(0) / (s(k) * s(k) + q(1) * s(k) + q(2)) - h(k);
        res(k) = e.real();
        res(n + k) = e.imag();
      }
      return res;
    };
    const auto jacobian = [&](const Vector& q) {
      Matrix jac(2 * n, 3);
      for (Index k = 0; k < n; ++k) {
        const Complex d = s(k) * s(k) + q(1) * s(k) + q(2);
        const Complex j0 = 1.0 / d, j1 = -q(0) * s(k) / (d * d), j2 = -q(0) / (d * d);
        jac.row(k) << j0.real(), j1.real(), j2.real();
        jac.row(n + k) << j0.imag(), j1.imag(), j2.imag();
      }
      return jac;
    };
    core::LmOptions lm;
    lm.max_iterations = options.max_iterations;
    const core::LmResult fit = core::levenberg_marquardt(residual, jacobian, p, lm);
    p = fit.x;
    const double cost = 2.0 * fit.cost;
    out.iterations = fit.iterations;
    if (!(p(2) > 0.0) || !p.allFinite()) {
      throw NumericalError(src, "the fitted denominator has no positive constant term (not a damped second-order "
                                "system); check the frequency band",
                           /*retry_may_help=*/true);
    }
    a0 = p(2) * scale * scale;
    a1 = p(1) * scale;
    out.static_gain = p(0) / p(2);
    out.relative_rms_error = std::sqrt(cost / h.squaredNorm());
    const Complex disc = std::sqrt(Complex(a1 * a1 / 4.0 - a0, 0.0));
    out.poles.resize(2);
    out.poles << -a1 / 2.0 + disc, -a1 / 2.0 - disc;
    if (out.poles(0).imag() < 0.0) std::swap(out.poles(0), out.poles(1));
  }
  if (!(a0 > 0.0)) {
    throw NumericalError(src, "the fitted poles have no positive natural frequency", /*retry_may_help=*/true);
  }
  out.natural_frequency = std::sqrt(a0);
  out.damping = a1 / (2.0 * out.natural_frequency);
  return out;
}

}  // namespace piezobench::ident
