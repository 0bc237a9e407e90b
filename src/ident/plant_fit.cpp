#include "piezobench/ident/plant_fit.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <utility>
#include <vector>

#include "piezobench/core/complex_division.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/fit_covariance.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/least_squares.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/dsp/frf_variance.hpp"
#include "piezobench/dsp/leakage_covariance.hpp"
#include "piezobench/dsp/unwrap.hpp"
#include "piezobench/ident/features.hpp"

namespace piezobench::ident {

using lti::Complex;
using lti::CVector;
using lti::Index;
using lti::Vector;

void IffPlantFitOptions::validate() const {
  const std::string src = "iff plant fit options";
  if (!(std::isfinite(fmin_Hz) && fmin_Hz >= 0.0)) throw InputError(src, "fmin_Hz", "a frequency >= 0 Hz", fmt::format("{}", fmin_Hz));
  if (!(std::isfinite(fmax_Hz) && fmax_Hz >= 0.0) || (fmax_Hz > 0.0 && fmax_Hz <= fmin_Hz)) {
    throw InputError(src, "fmax_Hz", "0 or a frequency above fmin_Hz", fmt::format("{}", fmax_Hz));
  }
  if (!(std::isfinite(hpf_fmax_Hz) && hpf_fmax_Hz > 0.0)) throw InputError(src, "hpf_fmax_Hz", "a frequency > 0 Hz", fmt::format("{}", hpf_fmax_Hz));
  if (!(std::isfinite(fixed_w_hpf) && fixed_w_hpf >= 0.0)) {
    throw InputError(src, "fixed_w_hpf", "0 (fitted) or a corner > 0 rad/s", fmt::format("{}", fixed_w_hpf));
  }
  if (!(min_coherence >= 0.0 && min_coherence < 1.0)) throw InputError(src, "min_coherence", "a value in [0, 1)", fmt::format("{}", min_coherence));
  if (max_iterations < 1) throw InputError(src, "max_iterations", "at least 1", std::to_string(max_iterations));
  if (!(std::isfinite(effective_averages) && effective_averages >= 0.0)) {
    throw InputError(src, "effective_averages", "0 (unknown) or Welch's n_d > 0", fmt::format("{}", effective_averages));
  }
}

namespace {

// The delay a phase falling linearly with omega implies (a start value of both fits): minus the
// least-squares slope (a straight line with an intercept) of the unwrapped phase (rad) against
// omega (rad/s), clamped to [0, 0.1] s; nullopt when omega does not vary.
std::optional<double> delay_from_phase(const std::vector<double>& omega, const std::vector<double>& phase) {
  const std::vector<double> y = dsp::unwrap_phase(phase);
  const auto n = static_cast<double>(omega.size());
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < omega.size(); ++i) {
    mx += omega[i] / n;
    my += y[i] / n;
  }
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < omega.size(); ++i) {
    sxy += (omega[i] - mx) * (y[i] - my);
    sxx += (omega[i] - mx) * (omega[i] - mx);
  }
  if (!(sxx > 0.0)) return std::nullopt;
  return std::clamp(-sxy / sxx, 0.0, 0.1);
}

// Points of the band with finite data and enough coherence (c: their coherence, empty when unknown).
void select_band(const Vector& omega, const CVector& h, const Vector& coherence, const IffPlantFitOptions& options,
                 const std::string& source, Vector& w, CVector& d, Vector& c) {
  if (omega.size() != h.size()) {
    throw InputError(source, "H", fmt::format("{} values (one per frequency)", omega.size()), std::to_string(h.size()));
  }
  if (coherence.size() != 0 && coherence.size() != h.size()) {
    throw InputError(source, "coherence", fmt::format("{} values or none", h.size()), std::to_string(coherence.size()));
  }
  const double wmin = kTwoPi * options.fmin_Hz;
  const double wmax = options.fmax_Hz > 0.0 ? kTwoPi * options.fmax_Hz : std::numeric_limits<double>::infinity();
  std::vector<Index> use;
  for (Index k = 0; k < omega.size(); ++k) {
    if (!std::isfinite(omega(k)) || !std::isfinite(h(k).real()) || !std::isfinite(h(k).imag())) {
      throw InputError(source, "H", "finite values", fmt::format("a non-finite value at point {}", k));
    }
    if (omega(k) <= 0.0 || omega(k) < wmin || omega(k) > wmax || h(k) == Complex(0.0)) continue;
    if (coherence.size() > 0 && coherence(k) < options.min_coherence) continue;
    use.push_back(k);
  }
  w.resize(static_cast<Index>(use.size()));
  d.resize(static_cast<Index>(use.size()));
  c.resize(coherence.size() > 0 ? static_cast<Index>(use.size()) : 0);
  for (std::size_t i = 0; i < use.size(); ++i) {
    w(static_cast<Index>(i)) = omega(use[i]);
    d(static_cast<Index>(i)) = h(use[i]);
    if (c.size() > 0) c(static_cast<Index>(i)) = coherence(use[i]);
  }
}

// Weights of the relative residual G/H_k - 1 of both fits. Every decade counts alike: on a uniform
// grid the weight is 1/sqrt(omega), otherwise the mass line above the resonance, which holds most
// of the points, would decide the fit. With the FRF's relative standard deviation eps_k known (from
// the coherence and n_d, dsp/frf_variance.hpp, or estimated from a first fit's residuals), each point
// is further divided by sqrt(eps_k^2 + kFitModelRelativeError^2): a line where the noise is large
// (the anti-resonance) counts little. residual_std is then the standard deviation of each weighted
// residual part's random error (weight_k eps_k), for the sandwich covariance; else empty.
struct PointWeights {
  Vector weight, residual_std;
};
PointWeights point_weights(const Vector& w, const Vector& eps_known) {
  PointWeights p;
  p.weight.resize(w.size());
  for (Index k = 0; k < w.size(); ++k) p.weight(k) = 1.0 / std::sqrt(w(k));
  const bool known = eps_known.size() == w.size() && w.size() > 0;
  if (known) {
    p.residual_std.resize(2 * w.size());
    for (Index k = 0; k < w.size(); ++k) {
      const double eps = std::max(eps_known(k), dsp::kMinFitRelativeStd);
      p.weight(k) /= std::hypot(eps, dsp::kFitModelRelativeError);
      p.residual_std(2 * k) = p.residual_std(2 * k + 1) = p.weight(k) * eps;
    }
  }
  const double norm = std::sqrt(p.weight.squaredNorm() / static_cast<double>(w.size()));
  p.weight /= norm;
  if (known) p.residual_std /= norm;
  return p;
}

// eps_k from the coherence and Welch's n_d; empty when either is unknown.
Vector coherence_relative_std(const Vector& c, double effective_averages) {
  if (c.size() == 0 || !(effective_averages > 0.0)) return {};
  Vector eps(c.size());
  for (Index k = 0; k < c.size(); ++k) eps(k) = dsp::frf_relative_std(c(k), effective_averages);
  return eps;
}

// The covariance of the solver's parameters at its solution x (core/fit_covariance.hpp), with the
// residual's analytic Jacobian.
template <class Residual>
core::FitCovariance covariance_at(const Residual& residual, const Eigen::VectorXd& x, const Vector& residual_std,
                                  const Eigen::VectorXcd& adjacent = {}, const std::vector<core::ResidualCovarianceBlock>& blocks = {}) {
  return core::fit_covariance(residual.jacobian(x), residual(x), residual_std, adjacent, blocks);
}

// The Welch estimate's leakage error in the residuals a_k (G_k / H_k - 1): u_k = g_k e_k with
// g_k = -a_k G_k / H_k^2, or in a_k (G_k - H_k) / R_k (ref: R, a fixed reference): g_k = -a_k / R_k
// (dsp::leakage_residual_blocks); the lines' noise from residual_std / a_k (relative to |H_k|). Without
// the FRF's variance (residual_std empty) or a provenance that says how the segments were laid out: none.
std::vector<core::ResidualCovarianceBlock> leakage_blocks(const dsp::ResolutionKernel& kernel, const dsp::KernelGrid& grid, const Vector& w,
                                                          const CVector& d, const Vector& weight, const Vector& residual_std,
                                                          const CVector& model_at_nodes,
                                                          const std::function<CVector(const Vector&)>& response,
                                                          const CVector* ref = nullptr) {
  if (residual_std.size() != 2 * w.size() || !dsp::knows_leakage(kernel) || w.size() < 2) return {};
  const CVector model = grid.smooth(model_at_nodes);
  Eigen::VectorXcd g(w.size());
  Vector noise(w.size());
  for (Index k = 0; k < w.size(); ++k) {
    g(k) = ref != nullptr ? -weight(k) / (*ref)(k) : -weight(k) * model(k) / (d(k) * d(k));
    noise(k) = weight(k) > 0.0 ? residual_std(2 * k) / weight(k) : 0.0;
  }
  return dsp::leakage_residual_blocks(kernel, grid, w, g, noise, model_at_nodes, response);
}

// c_k of core::fit_covariance for the relative residuals G/H_k - 1 ~ -e_k / H_k of a Welch estimate:
// its error e is circular with the real correlation rho_1 between neighbouring lines
// (dsp::adjacent_line_pairs); dividing by H rotates it: c_k = rho_1 e^(i (phi_k+1 - phi_k)), phi the
// model's phase at the solution. None without the residuals' noise or the correlation.
Eigen::VectorXcd adjacent_correlation(const dsp::ResolutionKernel& kernel, const Vector& w, const CVector& model, const Vector& residual_std) {
  const Vector pairs = dsp::adjacent_line_pairs(kernel, w);
  if (pairs.size() == 0 || residual_std.size() == 0) return {};
  Eigen::VectorXcd c = Eigen::VectorXcd::Zero(pairs.size());
  for (Index k = 0; k < pairs.size(); ++k) {
    if (pairs(k) > 0.0 && model(k) != Complex(0.0) && model(k + 1) != Complex(0.0)) {
      c(k) = pairs(k) * std::polar(1.0, std::arg(model(k + 1)) - std::arg(model(k)));
    }
  }
  return c;
}

Complex model(const IffPlantFit& p, double w) { return plant::iff_plant_response(p, w); }

// The model as the data see it: through the Welch estimate's resolution kernel when it is active.
Complex model(const IffPlantFit& p, double w, const dsp::ResolutionKernel& kernel) {
  return dsp::smoothed_response(kernel, w, [&](double x) { return model(p, x); });
}

// Scaled parameters: log|g0|, log wz, xz / 0.01, log wp, log xp, log w_hpf, delay / 100 us.
constexpr double kXzScale = 0.01;
constexpr double kDelayScale = 1e-4;

// Which parameters are free: g0, wz, xz, wp, xp always; w_hpf and the delay optionally.
struct Layout {
  bool hpf = true;
  bool delay = true;
  [[nodiscard]] Index size() const { return 5 + (hpf ? 1 : 0) + (delay ? 1 : 0); }
};

Eigen::VectorXd to_x(const IffPlantFit& p, const Layout& l) {
  Eigen::VectorXd x(l.size());
  x(0) = std::log(std::abs(p.g0));
  x(1) = std::log(p.wz);
  x(2) = p.xz / kXzScale;
  x(3) = std::log(p.wp);
  x(4) = std::log(p.xp);
  Index i = 5;
  if (l.hpf) x(i++) = std::log(p.w_hpf);
  if (l.delay) x(i++) = p.delay / kDelayScale;
  return x;
}

IffPlantFit from_x(const Eigen::VectorXd& x, double sign, const Layout& l, double fixed_w_hpf) {
  IffPlantFit p;
  p.g0 = sign * std::exp(x(0));
  p.wz = std::exp(x(1));
  p.xz = x(2) * kXzScale;
  p.wp = std::exp(x(3));
  p.xp = std::exp(x(4));
  Index i = 5;
  p.w_hpf = l.hpf ? std::exp(x(i++)) : fixed_w_hpf;
  p.delay = l.delay ? x(i++) * kDelayScale : 0.0;
  return p;
}

// A fitted frequency (rad/s) must lie inside the band of the points used.
void check_in_band(core::FitQuality& q, const char* what, double w, const Vector& band) {
  if (w >= band(0) && w <= band(band.size() - 1)) return;
  q.add_problem(fmt::format("{} {} Hz outside the band used, {} to {} Hz", what, format_number(w / kTwoPi, 4),
                            format_number(band(0) / kTwoPi, 4), format_number(band(band.size() - 1) / kTwoPi, 4)));
}

void check_lm(core::FitQuality& q, core::LmStatus status) {
  if (status == core::LmStatus::kMaxIterations) q.add_problem("Levenberg-Marquardt stopped at its iteration limit");
}

// Levenberg-Marquardt on the scaled parameters (core/least_squares.hpp), with the residual's analytic
// Jacobian (a residual type with jacobian(x): one model evaluation per step instead of 2 size(x) + 1).
template <class Residual>
core::LmResult least_squares(const Residual& residual, const Eigen::VectorXd& x0, int max_iterations) {
  core::LmOptions o;
  o.max_iterations = max_iterations;
  return core::levenberg_marquardt(residual, [&residual](const Eigen::VectorXd& x) { return residual.jacobian(x); }, x0, o);
}

// The rows of d r / d x for residuals r_k = a_k (G_k / H_k - 1) or a_k (G_k - H_k) / R_k: the model's
// derivatives at the grid's nodes (one column per parameter) through the kernel, over `d` (H_k or R_k),
// weighted; interleaved (Re, Im) as r.
Eigen::MatrixXd relative_residual_jacobian(const dsp::KernelGrid& grid, const Eigen::MatrixXcd& dg_at_nodes, const CVector& d,
                                           const Vector& weight) {
  const Eigen::MatrixXcd dg = grid.smooth(dg_at_nodes);
  Eigen::MatrixXd j(2 * d.size(), dg.cols());
  for (Index c = 0; c < dg.cols(); ++c) {
    for (Index k = 0; k < d.size(); ++k) {
      const Complex e = core::divide(dg(k, c), d(k)) * weight(k);
      j(2 * k, c) = e.real();
      j(2 * k + 1, c) = e.imag();
    }
  }
  return j;
}

}  // namespace

lti::TransferFunction IffPlantFit::transfer_function() const { return plant::iff_plant(*this); }

CVector IffPlantFit::response(const Vector& omega) const { return plant::iff_plant_response(*this, omega); }

ZeroPhaseVerdict zero_phase_verdict(const AntiResonance* zero, const IffPlantFit* plant, double ambiguity_deg) {
  ZeroPhaseVerdict v;
  const auto kind = [](bool nmp) { return std::string(nmp ? "non-minimum-phase" : "minimum-phase"); };
  if (plant) {
    v.xz = plant->xz;
    v.xz_standard_error = plant->uncertainty.standard_error_of("xz");
  }
  // The plant fit's interval xz +- kVerdictCoverage se decides when it has one: the sign only when
  // the whole interval has it, else undetermined (the noise at the dip hides the sign).
  if (plant && std::isfinite(v.xz_standard_error)) {
    const double half = kVerdictCoverage * v.xz_standard_error;
    const double lo = v.xz - half, hi = v.xz + half;
    v.from = "iff-plant-fit";
    const std::string interval = fmt::format("plant fit zero xz = {:.3g}, standard error {:.2g} (99.7 %: [{:.3g}, {:.3g}])", v.xz,
                                             v.xz_standard_error, lo, hi);
    if (hi < 0.0 || lo > 0.0) {
      v.nonminimum_phase = hi < 0.0;
      v.reason = interval + ": " + kind(*v.nonminimum_phase);
    } else {
      v.reason = interval + " contains 0: undetermined";
    }
    if (zero && zero->phase_verdict != PhaseVerdict::kUndetermined) {
      v.reason += fmt::format("; phase change {} deg", format_number_fixed(zero->phase_change_deg, 1));
    }
    return v;
  }
  std::string phase;  // what the phase says, for the reason
  bool ambiguous = false;
  if (zero) {
    const double change = zero->phase_change_deg;
    ambiguous = std::abs(std::abs(change) - 180.0) <= ambiguity_deg;
    if (zero->phase_verdict == PhaseVerdict::kUndetermined) {
      phase = fmt::format("phase change {:.1f} deg undetermined", change);
    } else if (ambiguous) {
      phase = fmt::format("phase change {:.1f} deg ambiguous (within {:g} deg of +-180 deg)", change, ambiguity_deg);
    } else {
      v.nonminimum_phase = zero->phase_verdict == PhaseVerdict::kNonMinimumPhase;
      v.from = "phase";
      v.reason = fmt::format("phase change {} deg across the anti-resonance: {}", format_number_fixed(change, 1),
                             kind(*v.nonminimum_phase));
      return v;
    }
  } else {
    phase = "no anti-resonance in the data's fit";
  }
  if (plant) {
    v.nonminimum_phase = plant->zero_is_nonminimum_phase();
    v.from = "iff-plant-fit";
    v.reason = fmt::format("{}; plant fit zero xz = {} {} 0", phase, format_number(plant->xz, 3),
                           plant->xz < 0.0 ? "<" : ">=");
  } else if (zero && zero->phase_verdict != PhaseVerdict::kUndetermined) {
    v.nonminimum_phase = zero->phase_verdict == PhaseVerdict::kNonMinimumPhase;
    v.from = "phase";
    v.reason = fmt::format("{}, no plant fit to decide: {} as counted", phase, kind(*v.nonminimum_phase));
  } else if (zero) {
    v.nonminimum_phase = zero->nonminimum_phase_model;
    v.from = "fitted-zero";
    v.reason =
        fmt::format("{}, no plant fit; vector fit zero Re = {} rad/s", phase, format_number(zero->root.real(), 3));
  } else {
    v.from = "none";
    v.reason = phase + ", no plant fit";
  }
  return v;
}

namespace {

// The points of the band a fit uses: omega (rad/s), H and the coherence (empty when unknown).
struct FitBand {
  Vector w, c;
  CVector d;
};

FitBand fit_band(const Vector& omega, const CVector& h, const Vector& coherence, const IffPlantFitOptions& options,
                 const std::string& source) {
  FitBand b;
  select_band(omega, h, coherence, options, source, b.w, b.d, b.c);
  return b;
}

// The relative random error of each line from the additive + proportional noise model of
// dsp::random_frf_std, fitted on the lines the window's leakage leaves clean (the model at the
// solution, at the grid's nodes, predicts where it does not); empty when no such model can be fitted
// (fewer than 8 clean lines: a band narrow around the peak, a noise-free record) or the coherence or
// n_d is unknown.
Vector noise_model_relative_std(const FitBand& b, double effective_averages, const dsp::KernelGrid& grid, const CVector& model_at_nodes,
                                const Vector& leak) {
  if (b.c.size() != b.w.size() || !(effective_averages > 0.0)) return {};
  Vector std_h(b.w.size());
  for (Index k = 0; k < b.w.size(); ++k) std_h(k) = dsp::frf_relative_std(b.c(k), effective_averages) * std::abs(b.d(k));
  const dsp::RandomFrfStd random = dsp::random_frf_std(b.d, std_h, grid.smooth(model_at_nodes), leak, effective_averages);
  if (!(random.noise.additive_std > 0.0 || random.noise.relative_std > 0.0)) return {};
  Vector eps(b.w.size());
  for (Index k = 0; k < b.w.size(); ++k) eps(k) = random.std(k) / std::abs(b.d(k));
  return eps;
}

// The weights' eps_k for a second pass of the fits, from the model at the first pass's solution
// rather than from each line's measured coherence: the noise model's variance plus the leakage's,
// (1/gamma_leak^2 - 1) / (2 n_d) (B&P's eps with the model's leakage coherence). The measured
// coherence near a sharp resonance is lowered by the same leakage realization whose error is large
// at that line, so weights taken from it down-weight the fit's own largest errors, and a covariance
// that takes the weights as fixed overstated the natural frequency's scatter 1.25-1.4 times
// (docs/uncertainty.md, section 6). Empty (keep the first pass) when the leakage is not modelled
// (the provenance does not say how the segments were laid out) or there is no noise model.
Vector smooth_relative_std(const FitBand& b, double effective_averages, const dsp::KernelGrid& grid, const CVector& model_at_nodes,
                           const dsp::ResolutionKernel& kernel) {
  if (!dsp::knows_leakage(kernel) || b.c.size() != b.w.size() || !(effective_averages > 0.0)) return {};
  const Vector leak = grid.leakage_coherence(model_at_nodes);
  Vector eps = noise_model_relative_std(b, effective_averages, grid, model_at_nodes, leak);
  for (Index k = 0; k < eps.size(); ++k) {
    const double q = leak(k) > 0.0 ? 1.0 / leak(k) - 1.0 : 0.0;
    eps(k) = std::sqrt(eps(k) * eps(k) + q / (2.0 * effective_averages));
  }
  return eps.allFinite() ? eps : Vector{};
}

// The residuals' noise (PointWeights::residual_std) from the coherence with the window's leakage
// divided out (dsp::KernelGrid::leakage_coherence of the model at the solution): near the resonance
// the Welch estimate's coherence drops by the leakage of a sharp peak, which is not a random error, and
// B&P's eps would count it as one (the resonance's and the gains' intervals were 1.7-6 times their
// scatter). Unchanged without a coherence, n_d or kernel.
//
// When the leakage's own error is modelled (leakage_blocks: the provenance says how the segments were
// laid out), the noise is instead noise_model_relative_std: at the peak the coherence's leakage part is
// 10^3-10^5 times the noise's, and what the division leaves there is the kernel's approximation error,
// not noise (it doubled the resonance's interval on the virtual bench). Without such a model, the
// division.
Vector leakage_free_residual_std(const PointWeights& pw, const FitBand& b, double effective_averages, const dsp::KernelGrid& grid,
                                 const CVector& model_at_nodes, bool leakage_modelled) {
  if (b.c.size() != b.w.size() || !(effective_averages > 0.0) || pw.residual_std.size() != 2 * b.w.size()) return pw.residual_std;
  const Vector leak = grid.leakage_coherence(model_at_nodes);
  Vector s = pw.residual_std;
  // Without a noise model random_frf_std keeps the measured std, leakage and all, which the blocks
  // would then count twice (the resonance's standard error 5 times its scatter): the coherence with
  // the leakage divided out instead (2 times).
  const Vector noise = leakage_modelled ? noise_model_relative_std(b, effective_averages, grid, model_at_nodes, leak) : Vector{};
  for (Index k = 0; k < b.w.size(); ++k) {
    const double eps = noise.size() > 0 ? noise(k) : dsp::frf_relative_std(std::min(1.0, b.c(k) / leak(k)), effective_averages);
    s(2 * k) = s(2 * k + 1) = pw.weight(k) * std::max(eps, dsp::kMinFitRelativeStd);
  }
  return s;
}

// The residuals' noise relative to |H_k| (PointWeights::residual_std) as that of (G_k - H_k) / R_k:
// times |H_k| / |R_k|.
Vector referred(Vector residual_std, const CVector& d, const CVector& ref) {
  if (residual_std.size() != 2 * d.size()) return residual_std;
  for (Index k = 0; k < d.size(); ++k) {
    const double f = std::abs(d(k)) / std::abs(ref(k));
    residual_std(2 * k) *= f;
    residual_std(2 * k + 1) *= f;
  }
  return residual_std;
}

// Half the width between the half-power points around `peak` over its frequency, clamped to
// [lo_clamp, hi_clamp]; the lower point is searched down to `lowest`.
double half_power_damping(const FitBand& b, Index peak, Index lowest, double lo_clamp, double hi_clamp) {
  const double half = std::abs(b.d(peak)) / std::sqrt(2.0);
  Index lo = peak, hi = peak;
  while (lo > lowest && std::abs(b.d(lo)) > half) --lo;
  while (hi + 1 < b.w.size() && std::abs(b.d(hi)) > half) ++hi;
  return std::clamp((b.w(hi) - b.w(lo)) / (2.0 * b.w(peak)), lo_clamp, hi_clamp);
}

// The high-pass corner and a first gain from the points below hpf_fmax (fit_high_pass when there
// are three), else from the first point.
void iff_start_high_pass(const FitBand& b, double w_hpf_band, IffPlantFit& start) {
  std::vector<Index> low;
  for (Index k = 0; k < b.w.size(); ++k) {
    if (b.w(k) <= w_hpf_band) low.push_back(k);
  }
  Vector w_low(static_cast<Index>(low.size()));
  CVector d_low(static_cast<Index>(low.size()));
  for (std::size_t i = 0; i < low.size(); ++i) {
    w_low(static_cast<Index>(i)) = b.w(low[i]);
    d_low(static_cast<Index>(i)) = b.d(low[i]);
  }
  if (w_low.size() >= 3) {
    const ident::HighPassFit hp = ident::fit_high_pass(w_low, d_low);
    start.w_hpf = std::clamp(hp.corner, b.w(0) / 100.0, w_hpf_band);
    start.g0 = hp.gain;
  } else {
    start.w_hpf = b.w(0) / 10.0;
    start.g0 = b.d(0).real() >= 0.0 ? std::abs(b.d(0)) : -std::abs(b.d(0));
  }
}

// g0 from the points below the anti-resonance with the model's other factors divided out (the
// median ratio, robust to a noisy point).
double iff_start_gain(const FitBand& b, Index dip, const IffPlantFit& start) {
  IffPlantFit unit_gain = start;
  unit_gain.g0 = 1.0;
  std::vector<double> re, mag;
  for (Index k = 0; k < dip; ++k) {
    const Complex g = b.d(k) / model(unit_gain, b.w(k));
    re.push_back(g.real());
    mag.push_back(std::abs(g));
  }
  if (mag.empty()) {
    const Complex g = b.d(0) / model(unit_gain, b.w(0));
    re.push_back(g.real());
    mag.push_back(std::abs(g));
  }
  std::sort(mag.begin(), mag.end());
  double sum_re = 0.0;
  for (const double x : re) sum_re += x;
  return (sum_re >= 0.0 ? 1.0 : -1.0) * mag[mag.size() / 2];
}

// The delay from the slope of the unwrapped phase of H / G(delay = 0) against omega (straight
// line with an intercept), above 1.5 wp where the model's own phase is smooth (all points above
// the anti-resonance when fewer than 10 are that high); unchanged with fewer than 3 points.
void iff_start_delay(const FitBand& b, IffPlantFit& start) {
  std::vector<Index> use_k;
  for (Index k = 0; k < b.w.size(); ++k) {
    if (b.w(k) > 1.5 * start.wp) use_k.push_back(k);
  }
  if (use_k.size() < 10) {
    use_k.clear();
    for (Index k = 0; k < b.w.size(); ++k) {
      if (b.w(k) > 1.2 * start.wz) use_k.push_back(k);
    }
  }
  if (use_k.size() < 3) return;
  std::vector<double> x, phase;
  for (const Index k : use_k) {
    x.push_back(b.w(k));
    phase.push_back(std::arg(b.d(k) / model(start, b.w(k))));
  }
  if (const auto delay = delay_from_phase(x, phase)) start.delay = *delay;
}

// Starting values: the resonance at the highest peak above the high-pass band, the anti-resonance
// at the lowest dip below it, then the high-pass corner, the gain and the delay.
IffPlantFit iff_start(const FitBand& b, const IffPlantFitOptions& options, const std::string& source) {
  const double w_hpf_band = kTwoPi * options.hpf_fmax_Hz;
  Index peak = -1;
  for (Index k = 0; k < b.w.size(); ++k) {
    if (b.w(k) > w_hpf_band && (peak < 0 || std::abs(b.d(k)) > std::abs(b.d(peak)))) peak = k;
  }
  Index dip = -1;
  for (Index k = 0; k < peak; ++k) {
    if (b.w(k) > w_hpf_band && (dip < 0 || std::abs(b.d(k)) < std::abs(b.d(dip)))) dip = k;
  }
  if (peak < 0 || dip < 0) {
    throw InputError(source, "H", "a resonance above an anti-resonance inside the band", "none found");
  }
  IffPlantFit start;
  start.wp = b.w(peak);
  start.wz = b.w(dip);
  start.xp = half_power_damping(b, peak, dip, 0.002, 0.3);
  start.xz = 0.005;
  iff_start_high_pass(b, w_hpf_band, start);
  if (options.fixed_w_hpf > 0.0) start.w_hpf = options.fixed_w_hpf;
  start.g0 = iff_start_gain(b, dip, start);
  if (options.fit_delay) iff_start_delay(b, start);
  return start;
}

// The weighted relative complex error of the IFF plant at the solver's parameters x.
struct IffResidual {
  const FitBand& b;
  const Vector& weight;
  // The residual's reference: none, G / H_k - 1 (the first pass); R, (G - H_k) / R_k with R the first
  // pass's model at the lines (the second pass: not divided by the noisy H, whose inverse near the dip
  // is biased towards 0).
  const CVector* ref;
  double sign;
  Layout layout;
  double fixed_w_hpf;
  dsp::KernelGrid grid;  // b.w through the FRF's resolution kernel: the model at each line once

  // d r / d x: G's derivatives in the scaled parameters, from its factors (eq. 2.3).
  [[nodiscard]] Eigen::MatrixXd jacobian(const Eigen::VectorXd& x) const {
    const IffPlantFit p = from_x(x, sign, layout, fixed_w_hpf);
    const Vector& nodes = grid.nodes();
    Eigen::MatrixXcd dg(nodes.size(), layout.size());
    for (Index i = 0; i < nodes.size(); ++i) {
      const Complex s(0.0, nodes(i));
      const Complex g = plant::iff_plant_response(p, nodes(i));
      const Complex num = 1.0 + 2.0 * p.xz * s / p.wz + s * s / (p.wz * p.wz);
      const Complex den = 1.0 + 2.0 * p.xp * s / p.wp + s * s / (p.wp * p.wp);
      dg(i, 0) = g;                                                                        // log|g0|
      dg(i, 1) = -core::divide(g * (2.0 * p.xz * s / p.wz + 2.0 * s * s / (p.wz * p.wz)), num);  // log wz
      dg(i, 2) = core::divide(g * (kXzScale * 2.0 * s / p.wz), num);                          // xz / 0.01
      dg(i, 3) = core::divide(g * (2.0 * p.xp * s / p.wp + 2.0 * s * s / (p.wp * p.wp)), den);   // log wp
      dg(i, 4) = -core::divide(g * (2.0 * p.xp * s / p.wp), den);                             // log xp
      Index c = 5;
      if (layout.hpf) dg(i, c++) = -core::divide(g * p.w_hpf, p.w_hpf + s);                  // log w_hpf
      if (layout.delay) dg(i, c++) = -g * s * kDelayScale;                                  // delay / 100 us
    }
    return relative_residual_jacobian(grid, dg, ref != nullptr ? *ref : b.d, weight);
  }

  Eigen::VectorXd operator()(const Eigen::VectorXd& x) const {
    const IffPlantFit p = from_x(x, sign, layout, fixed_w_hpf);
    const CVector g = grid.smooth(plant::iff_plant_response(p, grid.nodes()));
    Eigen::VectorXd r(2 * b.w.size());
    for (Index k = 0; k < b.w.size(); ++k) {
      const Complex e = (ref != nullptr ? core::divide(g(k) - b.d(k), (*ref)(k)) : core::divide(g(k), b.d(k)) - 1.0) * weight(k);
      r(2 * k) = e.real();
      r(2 * k + 1) = e.imag();
    }
    return r;
  }
};

// The better of the two Levenberg-Marquardt runs from xz = +-start.xz; `initial_cost` gets the
// lower starting cost.
core::LmResult best_iff_solution(const IffResidual& residual, const IffPlantFit& start, int max_iterations, double& initial_cost,
                                 const std::string& source) {
  core::LmResult best;
  best.cost = std::numeric_limits<double>::infinity();
  initial_cost = std::numeric_limits<double>::infinity();
  for (const double zs : {1.0, -1.0}) {
    IffPlantFit s0 = start;
    s0.xz = zs * start.xz;
    const Eigen::VectorXd x0 = to_x(s0, residual.layout);
    const Eigen::VectorXd r0 = residual(x0);
    if (!r0.allFinite()) continue;
    initial_cost = std::min(initial_cost, r0.squaredNorm());
    const core::LmResult o = least_squares(residual, x0, max_iterations);
    if (o.cost < best.cost) best = o;
  }
  if (!std::isfinite(best.cost)) {
    throw NumericalError("IFF plant fit (" + source + ")", "Levenberg-Marquardt found no finite error", true);
  }
  return best;
}

// Standard errors of the plant's parameters, linearized at the solution.
core::ParameterUncertainty iff_uncertainty(const IffResidual& residual, const core::LmResult& best, const IffPlantFit& fit,
                                           const Vector& residual_std, bool from_frf_variance, const dsp::ResolutionKernel& kernel,
                                           const CVector& model_at_nodes) {
  const CVector model = residual.grid.smooth(model_at_nodes);
  const auto response = [&fit](const Vector& omega) { return plant::iff_plant_response(fit, omega); };
  const Vector sd = residual.ref != nullptr ? referred(residual_std, residual.b.d, *residual.ref) : residual_std;
  const core::FitCovariance cov =
      covariance_at(residual, best.x, sd, adjacent_correlation(kernel, residual.b.w, model, sd),
                    leakage_blocks(kernel, residual.grid, residual.b.w, residual.b.d, residual.weight, residual_std, model_at_nodes, response,
                                   residual.ref));
  // Solver parameters: log|g0|, log wz, xz / 0.01, log wp, log xp, [log w_hpf], [delay / 1e-4].
  const Layout& layout = residual.layout;
  const int hpf = layout.hpf ? 5 : -1, delay = layout.delay ? (layout.hpf ? 6 : 5) : -1;
  Eigen::VectorXd value(7), deriv(7);
  value << fit.g0, fit.wz, fit.xz, fit.wp, fit.xp, fit.w_hpf, fit.delay;
  deriv << fit.g0, fit.wz, kXzScale, fit.wp, fit.xp, layout.hpf ? fit.w_hpf : 0.0, layout.delay ? kDelayScale : 0.0;
  return core::parameter_uncertainty({"g0", "wz", "xz", "wp", "xp", "w_hpf", "delay"}, value, deriv, {0, 1, 2, 3, 4, hpf, delay}, cov,
                                     from_frf_variance);
}

}  // namespace

IffPlantFit fit_iff_plant(const Vector& omega, const CVector& h, const Vector& coherence, const IffPlantFitOptions& options,
                          const std::string& source) {
  options.validate();
  const FitBand b = fit_band(omega, h, coherence, options, source);
  if (b.w.size() < 12) throw InputError(source, "H", "at least 12 usable points in the band", std::to_string(b.w.size()));
  IffPlantFit start = iff_start(b, options, source);
  if (start.g0 == 0.0) start.g0 = 1.0;
  const double sign = start.g0 > 0.0 ? 1.0 : -1.0;
  const Vector eps = coherence_relative_std(b.c, options.effective_averages);
  PointWeights pw = point_weights(b.w, eps);
  const Layout layout{options.fixed_w_hpf == 0.0, options.fit_delay};
  const dsp::KernelGrid grid(options.resolution, b.w);
  CVector ref;  // the second pass's reference (IffResidual::ref)
  const auto residual_with = [&](const PointWeights& weights) {
    return IffResidual{b, weights.weight, ref.size() > 0 ? &ref : nullptr, sign, layout, options.fixed_w_hpf, grid};
  };
  double initial_cost = 0.0;
  core::LmResult best = best_iff_solution(residual_with(pw), start, options.max_iterations, initial_cost, source);
  const auto at = [&](const Eigen::VectorXd& x) { return plant::iff_plant_response(from_x(x, sign, layout, options.fixed_w_hpf), grid.nodes()); };
  if (eps.size() > 0) {
    // A second pass weighted by the model's variance, not the record's (as fit_delayed_second_order),
    // its errors referred to the first pass's model rather than to the noisy H: near the dip 1/H is
    // biased towards 0, which moved wz by +1.1 of its standard errors from the noise-free record's on
    // the virtual bench (+0.85 referred to the model; docs/uncertainty.md section 6). Not in the
    // second-order fit, which has no dip: there it made the resonance's interval too narrow.
    const CVector first = at(best.x);
    if (const Vector smooth = smooth_relative_std(b, options.effective_averages, grid, first, options.resolution); smooth.size() > 0) {
      pw = point_weights(b.w, smooth);
      ref = grid.smooth(first);
      const core::LmResult second = least_squares(residual_with(pw), best.x, options.max_iterations);
      if (!std::isfinite(second.cost)) {
        throw NumericalError("IFF plant fit (" + source + ")", "Levenberg-Marquardt found no finite error", true);
      }
      best = second;
    }
  } else {
    // No variance recorded: the noise this fit's residuals show (additive and proportional) weights
    // a second fit, whose residuals give the noise of its standard errors (two-step feasible
    // generalized least squares). Without it the lines of the dip, where the sensor's noise is
    // largest relative to H, would decide xz with a standard error taken from the average line.
    for (int round = 0; round < 2; ++round) {
      const CVector g = grid.smooth(at(best.x));
      pw = point_weights(b.w, dsp::estimate_frf_noise(b.d, g).relative_std_at(g));
      if (round == 0) best = best_iff_solution(residual_with(pw), start, options.max_iterations, initial_cost, source);
    }
  }
  const IffResidual residual = residual_with(pw);

  const double n = static_cast<double>(b.w.size());
  IffPlantFit fit = from_x(best.x, sign, residual.layout, options.fixed_w_hpf);
  double plain = 0.0;
  for (Index k = 0; k < b.w.size(); ++k) plain += std::norm(model(fit, b.w(k), options.resolution) / b.d(k) - 1.0);
  fit.relative_rms_error = std::sqrt(plain / n);
  fit.weighted_relative_rms_error = std::sqrt(2.0 * best.cost / n);
  fit.initial_relative_rms_error = std::sqrt(initial_cost / n);
  fit.points = b.w.size();
  fit.iterations = best.iterations;
  fit.converged = best.converged();
  fit.status = best.status;
  const CVector at_nodes = plant::iff_plant_response(fit, grid.nodes());  // the solution's model, for both
  const Vector noise = leakage_free_residual_std(pw, b, options.effective_averages, grid, at_nodes, dsp::knows_leakage(options.resolution));
  fit.uncertainty = iff_uncertainty(residual, best, fit, noise, eps.size() > 0, options.resolution, at_nodes);
  fit.quality.check_error("u -> Vs (IFF plant, eq. 2.3)", fit.relative_rms_error);
  check_in_band(fit.quality, "anti-resonance wz", fit.wz, b.w);
  check_in_band(fit.quality, "resonance wp", fit.wp, b.w);
  check_lm(fit.quality, best.status);
  if (fit.delay < 0.0)
    fit.quality.add_problem(fmt::format("delay {} s < 0 (acausal)", format_number(fit.delay, 3)), false);
  fit.quality.advise("a band around the anti-resonance and the resonance where the coherence is high");
  return fit;
}

namespace {

Complex second_order(const DelayedSecondOrderFit& p, double w) {
  const Complex s(0.0, w);
  const double wn = p.natural_frequency;
  return core::divide(Complex(p.static_gain * wn * wn), s * s + 2.0 * p.damping * wn * s + wn * wn) * core::delay_phasor(w, p.delay);
}

// The second order as the data see it (through the resolution kernel when it is active).
Complex second_order(const DelayedSecondOrderFit& p, double w, const dsp::ResolutionKernel& kernel) {
  return dsp::smoothed_response(kernel, w, [&](double x) { return second_order(p, x); });
}

// Starting values: the natural frequency at the peak, the damping from its half-power points, the
// gain as the median ratio below half the peak's frequency, and the delay from the phase above
// 1.5 wn.
DelayedSecondOrderFit second_order_start(const FitBand& b, Index peak, bool fit_delay) {
  const Vector& w = b.w;
  const CVector& d = b.d;
  DelayedSecondOrderFit start;
  start.natural_frequency = w(peak);
  start.damping = half_power_damping(b, peak, 0, 0.002, 0.9);
  DelayedSecondOrderFit unit = start;
  unit.static_gain = 1.0;
  std::vector<double> mag;
  double sum_re = 0.0;
  for (Index k = 0; k < std::max<Index>(1, peak / 2); ++k) {
    const Complex g = d(k) / second_order(unit, w(k));
    mag.push_back(std::abs(g));
    sum_re += g.real();
  }
  std::sort(mag.begin(), mag.end());
  start.static_gain = (sum_re >= 0.0 ? 1.0 : -1.0) * mag[mag.size() / 2];
  if (fit_delay) {
    std::vector<double> x, phase;
    for (Index k = 0; k < w.size(); ++k) {
      if (w(k) <= 1.5 * start.natural_frequency) continue;
      x.push_back(w(k));
      phase.push_back(std::arg(d(k) / second_order(start, w(k))));
    }
    if (x.size() >= 3) {
      if (const auto delay = delay_from_phase(x, phase)) start.delay = *delay;
    }
  }
  return start;
}

}  // namespace

Complex DelayedSecondOrderFit::pole() const {
  const double z = damping;
  if (z >= 1.0) return {-natural_frequency * (z - std::sqrt(z * z - 1.0)), 0.0};
  return {-z * natural_frequency, natural_frequency * std::sqrt(1.0 - z * z)};
}

CVector DelayedSecondOrderFit::response(const Vector& omega) const {
  CVector h(omega.size());
  for (Index k = 0; k < omega.size(); ++k) h(k) = second_order(*this, omega(k));
  return h;
}

namespace {

// The resonance peak, inside the band.
Index second_order_peak(const FitBand& b, const std::string& source) {
  Index peak = 0;
  for (Index k = 1; k < b.w.size(); ++k) {
    if (std::abs(b.d(k)) > std::abs(b.d(peak))) peak = k;
  }
  if (peak == 0 || peak == b.w.size() - 1) {
    throw InputError(source, "H", "a resonance peak inside the band",
                     fmt::format("the largest |H| at the band's edge ({} Hz)", format_number(b.w(peak) / kTwoPi, 4)));
  }
  return peak;
}

// The weighted relative complex error of the delayed second order at the solver's parameters x:
// log|k|, log wn, log zeta, [delay / 1e-4].
struct SecondOrderResidual {
  const FitBand& b;
  const Vector& weight;
  double sign;
  bool fit_delay;
  dsp::KernelGrid grid;  // b.w through the FRF's resolution kernel: the model at each line once

  [[nodiscard]] DelayedSecondOrderFit unpack(const Eigen::VectorXd& x) const {
    DelayedSecondOrderFit p;
    p.static_gain = sign * std::exp(x(0));
    p.natural_frequency = std::exp(x(1));
    p.damping = std::exp(x(2));
    p.delay = fit_delay ? x(3) * kDelayScale : 0.0;
    return p;
  }

  // d r / d x: log|k|, log wn, log zeta, [delay / 1e-4].
  [[nodiscard]] Eigen::MatrixXd jacobian(const Eigen::VectorXd& x) const {
    const DelayedSecondOrderFit p = unpack(x);
    const Vector& nodes = grid.nodes();
    const double wn = p.natural_frequency;
    Eigen::MatrixXcd dg(nodes.size(), fit_delay ? 4 : 3);
    for (Index i = 0; i < nodes.size(); ++i) {
      const Complex s(0.0, nodes(i));
      const Complex g = second_order(p, nodes(i));
      const Complex den = s * s + 2.0 * p.damping * wn * s + wn * wn;
      dg(i, 0) = g;
      dg(i, 1) = g * (2.0 - core::divide(2.0 * p.damping * wn * s + 2.0 * wn * wn, den));
      dg(i, 2) = -core::divide(g * (2.0 * p.damping * wn * s), den);
      if (fit_delay) dg(i, 3) = -g * s * kDelayScale;
    }
    return relative_residual_jacobian(grid, dg, b.d, weight);
  }

  Eigen::VectorXd operator()(const Eigen::VectorXd& x) const {
    const DelayedSecondOrderFit p = unpack(x);
    const CVector g = grid.smooth(p.response(grid.nodes()));
    Eigen::VectorXd r(2 * b.w.size());
    for (Index k = 0; k < b.w.size(); ++k) {
      const Complex e = (core::divide(g(k), b.d(k)) - 1.0) * weight(k);
      r(2 * k) = e.real();
      r(2 * k + 1) = e.imag();
    }
    return r;
  }
};

Eigen::VectorXd second_order_x0(const DelayedSecondOrderFit& start, bool fit_delay) {
  Eigen::VectorXd x0(fit_delay ? 4 : 3);
  x0(0) = std::log(std::abs(start.static_gain));
  x0(1) = std::log(start.natural_frequency);
  x0(2) = std::log(start.damping);
  if (fit_delay) x0(3) = start.delay / kDelayScale;
  return x0;
}

// Standard errors of static_gain, natural_frequency, damping and delay, linearized at the solution.
core::ParameterUncertainty second_order_uncertainty(const SecondOrderResidual& residual, const core::LmResult& o,
                                                    const DelayedSecondOrderFit& fit, const Vector& residual_std,
                                                    bool from_frf_variance, const dsp::ResolutionKernel& kernel,
                                                    const CVector& model_at_nodes) {
  const CVector model = residual.grid.smooth(model_at_nodes);
  const auto response = [&fit](const Vector& omega) { return fit.response(omega); };
  const core::FitCovariance cov =
      covariance_at(residual, o.x, residual_std, adjacent_correlation(kernel, residual.b.w, model, residual_std),
                    leakage_blocks(kernel, residual.grid, residual.b.w, residual.b.d, residual.weight, residual_std, model_at_nodes, response));
  Eigen::VectorXd value(4), deriv(4);
  value << fit.static_gain, fit.natural_frequency, fit.damping, fit.delay;
  deriv << fit.static_gain, fit.natural_frequency, fit.damping, residual.fit_delay ? kDelayScale : 0.0;
  return core::parameter_uncertainty({"static_gain", "natural_frequency", "damping", "delay"}, value, deriv,
                                     {0, 1, 2, residual.fit_delay ? 3 : -1}, cov, from_frf_variance);
}

}  // namespace

DelayedSecondOrderFit fit_delayed_second_order(const Vector& omega, const CVector& h, const Vector& coherence,
                                               const IffPlantFitOptions& options, const std::string& source) {
  options.validate();
  const FitBand b = fit_band(omega, h, coherence, options, source);
  if (b.w.size() < 8) throw InputError(source, "H", "at least 8 usable points in the band", std::to_string(b.w.size()));
  const DelayedSecondOrderFit start = second_order_start(b, second_order_peak(b, source), options.fit_delay);
  const Vector eps = coherence_relative_std(b.c, options.effective_averages);
  PointWeights pw = point_weights(b.w, eps);
  const dsp::KernelGrid grid(options.resolution, b.w);
  const double sign = start.static_gain >= 0.0 ? 1.0 : -1.0;
  const Eigen::VectorXd x0 = second_order_x0(start, options.fit_delay);
  if (!SecondOrderResidual{b, pw.weight, sign, options.fit_delay, grid}(x0).allFinite()) {
    throw NumericalError("second-order fit (" + source + ")", "the starting point gives a non-finite error", true);
  }
  const auto solve = [&](const PointWeights& weights, const Eigen::VectorXd& from) {
    const core::LmResult o = least_squares(SecondOrderResidual{b, weights.weight, sign, options.fit_delay, grid}, from, options.max_iterations);
    if (!std::isfinite(o.cost)) {
      throw NumericalError("second-order fit (" + source + ")", "Levenberg-Marquardt found no finite error", true);
    }
    return o;
  };
  core::LmResult o = solve(pw, x0);
  const auto unpack = [&](const Eigen::VectorXd& x) { return SecondOrderResidual{b, pw.weight, sign, options.fit_delay, grid}.unpack(x); };
  if (eps.size() == 0) {
    // No variance recorded: the noise of this fit's residuals weights a second fit and gives the
    // standard errors (as fit_iff_plant does).
    for (int round = 0; round < 2; ++round) {
      const CVector g = grid.smooth(unpack(o.x).response(grid.nodes()));
      pw = point_weights(b.w, dsp::estimate_frf_noise(b.d, g).relative_std_at(g));
      if (round == 0) o = solve(pw, x0);
    }
  } else if (const Vector smooth = smooth_relative_std(b, options.effective_averages, grid, unpack(o.x).response(grid.nodes()), options.resolution);
             smooth.size() > 0) {
    // A second pass weighted by the model's variance, not the record's.
    pw = point_weights(b.w, smooth);
    o = solve(pw, o.x);
  }
  const SecondOrderResidual residual{b, pw.weight, sign, options.fit_delay, grid};
  DelayedSecondOrderFit fit = residual.unpack(o.x);
  double plain = 0.0;
  for (Index k = 0; k < b.w.size(); ++k) plain += std::norm(second_order(fit, b.w(k), options.resolution) / b.d(k) - 1.0);
  fit.relative_rms_error = std::sqrt(plain / static_cast<double>(b.w.size()));
  fit.points = b.w.size();
  fit.iterations = o.iterations;
  fit.status = o.status;
  const CVector at_nodes = fit.response(grid.nodes());  // the solution's model, for both
  const Vector noise = leakage_free_residual_std(pw, b, options.effective_averages, grid, at_nodes, dsp::knows_leakage(options.resolution));
  fit.uncertainty = second_order_uncertainty(residual, o, fit, noise, eps.size() > 0, options.resolution, at_nodes);
  fit.quality.check_error("second-order fit", fit.relative_rms_error);
  check_in_band(fit.quality, "natural frequency", fit.natural_frequency, b.w);
  check_lm(fit.quality, o.status);
  if (fit.delay < 0.0)
    fit.quality.add_problem(fmt::format("delay {} s < 0 (acausal)", format_number(fit.delay, 3)), false);
  fit.quality.advise("a band around the resonance where the coherence is high");
  return fit;
}

void ActuatorPlantOptions::validate() const {
  const std::string src = "actuator plant options";
  for (const auto& [v, name] : {std::pair{fmin_Hz, "fmin_Hz"}, std::pair{iff_fmin_Hz, "iff_fmin_Hz"}, std::pair{fixed_w_hpf, "fixed_w_hpf"}}) {
    if (!(std::isfinite(v) && v >= 0.0)) throw InputError(src, name, "a finite value >= 0", fmt::format("{}", v));
  }
  if (!(std::isfinite(fmax_Hz) && fmax_Hz > fmin_Hz && fmax_Hz > iff_fmin_Hz)) {
    throw InputError(src, "fmax_Hz", "a frequency above fmin_Hz and iff_fmin_Hz", fmt::format("{}", fmax_Hz));
  }
  if (!(std::isfinite(hpf_fmax_Hz) && hpf_fmax_Hz > 0.0)) throw InputError(src, "hpf_fmax_Hz", "a frequency > 0 Hz", fmt::format("{}", hpf_fmax_Hz));
  if (!(min_coherence >= 0.0 && min_coherence < 1.0)) throw InputError(src, "min_coherence", "a value in [0, 1)", fmt::format("{}", min_coherence));
  if (!(std::isfinite(effective_averages) && effective_averages >= 0.0)) {
    throw InputError(src, "effective_averages", "0 (unknown) or Welch's n_d > 0", fmt::format("{}", effective_averages));
  }
}

ActuatorPlants fit_actuator_plants(const Vector& omega, const CVector& h_de, const Vector& coh_de, const CVector& h_vs,
                                   const Vector& coh_vs, const ActuatorPlantOptions& options, const std::string& source) {
  options.validate();
  ActuatorPlants out;
  out.de_options.fmin_Hz = options.fmin_Hz;
  out.de_options.fmax_Hz = options.fmax_Hz;
  out.de_options.min_coherence = options.min_coherence;
  out.de_options.effective_averages = options.effective_averages;
  out.vs_options.effective_averages = options.effective_averages;
  out.de_options.resolution = out.vs_options.resolution = options.resolution;
  out.vs_options.fmin_Hz = options.iff_fmin_Hz;
  out.vs_options.fmax_Hz = options.fmax_Hz;
  out.vs_options.hpf_fmax_Hz = options.hpf_fmax_Hz;
  out.vs_options.min_coherence = options.min_coherence;
  out.vs_options.fixed_w_hpf = options.fixed_w_hpf;
  try {
    out.de = fit_delayed_second_order(omega, h_de, coh_de, out.de_options, source);
  } catch (const NumericalError& e) {
    out.failures.push_back(std::string("u -> d_e second-order fit: ") + e.what());
  }
  try {
    out.vs = fit_iff_plant(omega, h_vs, coh_vs, out.vs_options, source);
  } catch (const NumericalError& e) {
    out.failures.push_back(std::string("IFF plant fit: ") + e.what());
  }
  return out;
}

}  // namespace piezobench::ident
