#include "piezobench/apa/tuning.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <fmt/format.h>
#include <limits>
#include <map>
#include <numbers>
#include <tuple>
#include <utility>
#include <vector>

#include "piezobench/core/error.hpp"
#include "piezobench/core/fit_covariance.hpp"
#include "piezobench/core/least_squares.hpp"
#include "piezobench/dsp/frf_variance.hpp"
#include "piezobench/dsp/leakage_covariance.hpp"
#include "piezobench/dsp/resolution_kernel.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::apa {

std::string to_string(TuningStatus s) {
  switch (s) {
    case TuningStatus::kConverged: return "converged";
    case TuningStatus::kMaxIterations: return "max-iterations";
    case TuningStatus::kNoProgress: return "no-progress";
    case TuningStatus::kNotRefined: return "not-refined";
  }
  return "unknown";
}

TuningStatus tuning_status_from_string(const std::string& s) {
  for (const TuningStatus v :
       {TuningStatus::kConverged, TuningStatus::kMaxIterations, TuningStatus::kNoProgress, TuningStatus::kNotRefined}) {
    if (to_string(v) == s) return v;
  }
  throw InputError("", "status", "one of converged, max-iterations, no-progress, not-refined", "'" + s + "'");
}

void TuningOptions::validate() const {
  const std::string src = "tuning options";
  if (!(std::isfinite(mass) && mass > 0.0)) throw InputError(src, "mass", "a mass > 0 kg", format_number(mass));
  bench.validate(src);
  if (bench.suspended_mass != 0.0 || bench.added_mass != 0.0) {
    throw InputError(src, "bench.suspended_mass", "0 (the tuned mass is `mass`)",
                     format_number(bench.suspended_mass) + " / added " + format_number(bench.added_mass));
  }
  if (!(std::isfinite(fmin_Hz) && fmin_Hz >= 0.0)) throw InputError(src, "fmin_Hz", "a frequency >= 0 Hz", format_number(fmin_Hz));
  if (!(std::isfinite(fmax_Hz) && fmax_Hz >= 0.0)) throw InputError(src, "fmax_Hz", "a frequency >= 0 Hz", format_number(fmax_Hz));
  if (fmax_Hz > 0.0 && fmax_Hz <= fmin_Hz) {
    throw InputError(src, "fmax_Hz", fmt::format("a frequency above fmin_Hz = {} Hz (or 0)", format_number(fmin_Hz)), format_number(fmax_Hz));
  }
  if (!(min_coherence >= 0.0 && min_coherence < 1.0)) {
    throw InputError(src, "min_coherence", "a value in [0, 1)", format_number(min_coherence));
  }
  if (!(std::isfinite(stack_stiffness_ratio) && stack_stiffness_ratio >= 0.0)) {
    throw InputError(src, "stack_stiffness_ratio", "a ratio ke/ka > 0 (or 0 = free)", format_number(stack_stiffness_ratio));
  }
  if (!(std::isfinite(stack_damping_ratio) && stack_damping_ratio >= 0.0)) {
    throw InputError(src, "stack_damping_ratio", "a ratio ce/ca > 0 (or 0 = free)", format_number(stack_damping_ratio));
  }
  if (max_iterations < 1) throw InputError(src, "max_iterations", "at least 1", std::to_string(max_iterations));
  if (de_output.empty()) throw InputError(src, "de_output", "an output name", "an empty name");
  if (vs_output.empty()) throw InputError(src, "vs_output", "an output name", "an empty name");
}

std::string TwoDofTuning::brief_report() const {
  return fmt::format("2-DoF tuning: {} after {} iterations on {} points; rms relative error d_e {:.3g} (initial {:.3g}), "
                     "Vs {:.3g} (initial {:.3g})",
                     to_string(status), iterations, points, fit_error_de, initial_fit_error_de, fit_error_vs,
                     initial_fit_error_vs);
}

namespace {

using lti::Complex;
using lti::CVector;
using lti::Index;
using lti::Vector;

// The data the fit works on: input Va (amplifier divided out), high-pass and delay removed.
struct FitData {
  Vector omega;  // rad/s
  CVector de;    // m/V
  CVector vs;    // V/V
  // Relative standard deviation of each point (dsp/frf_variance.hpp, floored at 1e-4) when the FRF's
  // variance is known (coherence of both outputs and n_d); empty otherwise.
  Vector eps_de, eps_vs;
  // The Welch estimate's resolution kernel the model is seen through (inactive: the model itself).
  dsp::ResolutionKernel kernel;
  dsp::KernelGrid grid;  // omega through the kernel: each line's model response evaluated once
  double effective_averages = 0.0;  // n_d of the Welch estimate (0: unknown)
};

// The quality verdict of a tuning (tuning.hpp).
core::FitQuality assess(const TwoDofTuning& t, const FitData& d) {
  core::FitQuality q;
  const TwoDofParams& p = t.params;
  bool finite = true;
  for (const auto& name : TwoDofParams::names()) {
    const double v = p.get(name);
    const bool gain = name == "ga" || name == "gs";
    if (!std::isfinite(v) || (gain ? v == 0.0 : v <= 0.0)) {
      q.add_problem(fmt::format("{} = {} is not physical", name, format_number(v, 4)), false);
      finite = false;
    }
  }
  const double largest = std::max({p.k1, p.ke, p.ka});
  for (const auto& [v, name] : {std::pair{p.k1, "k1"}, std::pair{p.ke, "ke"}, std::pair{p.ka, "ka"}}) {
    if (finite && v < 1e-6 * largest) {
      q.add_problem(fmt::format("{} = {} N/m is negligible against {} N/m: no actuator has such stiffnesses", name,
                                format_number(v, 4), format_number(largest, 4)),
                    false);
    }
  }
  q.check_error("u -> d_e", t.fit_error_de);
  q.check_error("u -> Vs", t.fit_error_vs);
  if (finite) {
    const double wp = std::sqrt(p.total_stiffness() / p.m), wz = std::sqrt(p.k1 / p.m);
    const double lo = d.omega(0), hi = d.omega(d.omega.size() - 1);
    for (const auto& [w, name] : {std::pair{wp, "resonance"}, std::pair{wz, "anti-resonance"}}) {
      if (!(w >= lo && w <= hi)) {
        q.add_problem(fmt::format("the model's {} {} Hz is outside the band used, {} to {} Hz", name,
                                  format_number(w / kTwoPi, 4), format_number(lo / kTwoPi, 4),
                                  format_number(hi / kTwoPi, 4)));
      }
    }
  }
  if (t.status == TuningStatus::kMaxIterations) q.add_problem("the refinement stopped at its iteration limit");
  q.advise("a band around the anti-resonance and the resonance where the coherence is high (--fmin/--fmax), the "
           "right --mass and --amplifier-gain, or check that the outputs are d_e (m) and Vs (V)");
  return q;
}

FitData prepare(const dsp::Frf& frf, const TuningOptions& o, const std::string& source) {
  const Index ide = frf.output_index(o.de_output);
  const Index ivs = frf.output_index(o.vs_output);
  const auto has_coh = [&](Index i) {
    return static_cast<std::size_t>(i) < frf.coherence.size() && frf.coherence[static_cast<std::size_t>(i)].size() > 0;
  };
  std::vector<Index> used;
  for (Index k = 0; k < frf.freq_Hz.size(); ++k) {
    const double f = frf.freq_Hz(k);
    if (f <= 0.0 || f < o.fmin_Hz || (o.fmax_Hz > 0.0 && f > o.fmax_Hz)) continue;
    if (o.min_coherence > 0.0) {
      if (has_coh(ide) && frf.coherence[static_cast<std::size_t>(ide)](k) < o.min_coherence) continue;
      if (has_coh(ivs) && frf.coherence[static_cast<std::size_t>(ivs)](k) < o.min_coherence) continue;
    }
    used.push_back(k);
  }
  // 8 unknowns at most, 4 real equations per frequency; the peak picking needs a few more points.
  if (used.size() < 8) {
    throw InputError(source, "freq_Hz", "at least 8 frequencies > 0 in the band (and above the coherence threshold)",
                     std::to_string(used.size()));
  }
  FitData d;
  if (o.window_resolution) d.kernel = dsp::resolution_kernel(frf.provenance);
  const auto n = static_cast<Index>(used.size());
  d.omega.resize(n);
  d.de.resize(n);
  d.vs.resize(n);
  const double wc = o.bench.hpf_corner();
  // The FRF's variance: its std_H where it carries one (every output or none, dsp/frf.hpp), else from
  // the coherence and n_d.
  const bool has_std = frf.std_H.size() == frf.H.size() && frf.std_H[static_cast<std::size_t>(ide)].size() > 0;
  const bool variance = has_std || (has_coh(ide) && has_coh(ivs) && frf.provenance.effective_averages > 0.0);
  const auto relative_std = [&](Index output, Index k) {
    const auto io = static_cast<std::size_t>(output);
    const double eps = has_std ? frf.std_H[io](k) / std::abs(frf.H[io](k))
                               : dsp::frf_relative_std(frf.coherence[io](k), frf.provenance.effective_averages);
    return std::max(eps, dsp::kMinFitRelativeStd);
  };
  if (variance) {
    d.eps_de.resize(n);
    d.eps_vs.resize(n);
  }
  for (Index i = 0; i < n; ++i) {
    const Index k = used[static_cast<std::size_t>(i)];
    if (variance) {
      d.eps_de(i) = relative_std(ide, k);
      d.eps_vs(i) = relative_std(ivs, k);
    }
    const double w = kTwoPi * frf.freq_Hz(k);
    const Complex s(0.0, w);
    Complex chain = o.bench.amplifier_gain * std::exp(-s * o.bench.delay);
    d.omega(i) = w;
    d.de(i) = frf.H[static_cast<std::size_t>(ide)](k) / chain;
    if (wc > 0.0) chain *= s / (s + wc);
    d.vs(i) = frf.H[static_cast<std::size_t>(ivs)](k) / chain;
    for (const auto& [value, name] : {std::pair{d.de(i), o.de_output}, std::pair{d.vs(i), o.vs_output}}) {
      if (!(std::isfinite(value.real()) && std::isfinite(value.imag())) || value == Complex(0.0)) {
        throw InputError(source, name, "finite nonzero values",
                         fmt::format("{} + {}j at {} Hz", value.real(), value.imag(), frf.freq_Hz(k)));
      }
    }
  }
  d.grid = dsp::KernelGrid(d.kernel, d.omega);
  d.effective_averages = frf.provenance.effective_averages;
  return d;
}

// Vertex of the parabola through (x[i-1..i+1], y[i-1..i+1]): (x, y).
std::pair<double, double> vertex(double x0, double x1, double x2, double y0, double y1, double y2) {
  // Newton form: y = y0 + a (x - x0) + b (x - x0)(x - x1)
  const double a = (y1 - y0) / (x1 - x0);
  const double b = ((y2 - y1) / (x2 - x1) - a) / (x2 - x0);
  if (b == 0.0) return {x1, y1};
  const double xv = 0.5 * (x0 + x1) - a / (2.0 * b);
  const double xc = std::clamp(xv, x0, x2);
  return {xc, y0 + a * (xc - x0) + b * (xc - x0) * (xc - x1)};
}

// Extremum of |h| over indices [lo, hi] (interior), refined in log-log: (omega, |h|).
std::pair<double, double> extremum(const Vector& omega, const CVector& h, Index lo, Index hi, bool maximum,
                                   const char* what) {
  Index best = -1;
  for (Index k = lo; k <= hi; ++k) {
    if (best < 0 || (maximum ? std::abs(h(k)) > std::abs(h(best)) : std::abs(h(k)) < std::abs(h(best)))) best = k;
  }
  if (best <= 0 || best >= omega.size() - 1 || best <= lo || best >= hi) {
    throw NumericalError("2-DoF tuning", fmt::format("no {} inside the frequency band (the extremum of the "
                                                     "magnitude is at its edge)", what),
                         /*retry_may_help=*/true);
  }
  const auto [x, y] = vertex(std::log(omega(best - 1)), std::log(omega(best)), std::log(omega(best + 1)),
                             std::log(std::abs(h(best - 1))), std::log(std::abs(h(best))),
                             std::log(std::abs(h(best + 1))));
  return {std::exp(x), std::exp(y)};
}

// Free parameters of the refinement, as logarithms.
struct Layout {
  double mass = 0.0;
  double ga_sign = 1.0, gs_sign = 1.0;
  double ke_ratio = 0.0;  // 0 = ke free
  double ce_ratio = 0.0;  // 0 = ce free

  [[nodiscard]] Vector pack(const TwoDofParams& p) const {
    std::vector<double> v = {p.k1, p.c1, p.ka, p.ca, std::abs(p.ga), std::abs(p.gs)};
    if (ke_ratio == 0.0) v.push_back(p.ke);
    if (ce_ratio == 0.0) v.push_back(p.ce);
    Vector x(static_cast<Index>(v.size()));
    for (std::size_t i = 0; i < v.size(); ++i) x(static_cast<Index>(i)) = std::log(v[i]);
    return x;
  }
  [[nodiscard]] TwoDofParams unpack(const Vector& x) const {
    TwoDofParams p;
    p.m = mass;
    p.k1 = std::exp(x(0));
    p.c1 = std::exp(x(1));
    p.ka = std::exp(x(2));
    p.ca = std::exp(x(3));
    p.ga = ga_sign * std::exp(x(4));
    p.gs = gs_sign * std::exp(x(5));
    Index next = 6;
    p.ke = ke_ratio == 0.0 ? std::exp(x(next++)) : ke_ratio * p.ka;
    p.ce = ce_ratio == 0.0 ? std::exp(x(next++)) : ce_ratio * p.ca;
    return p;
  }
};

// A parameter driven more than this factor away from the report's procedure's value has reached the
// edge of what the log-parameters can reach (towards 0 or infinity): it is undetermined.
constexpr double kBoundRatio = 1e3;

// The solver's parameters within kBoundRatio of the start x0 (log form): the columns the covariance
// keeps. One driven to a bound (c1 -> 0 where the shell's damping does not show) has a column of
// zeros or nearly, which would make every standard error infinite.
std::vector<Index> unbounded(const Vector& x, const Vector& x0) {
  std::vector<Index> keep;
  for (Index i = 0; i < x.size(); ++i) {
    if (std::abs(x(i) - x0(i)) < std::log(kBoundRatio)) keep.push_back(i);
  }
  return keep;
}

// The parameters' standard errors from the covariance of the solver's kept log-parameters `keep`
// (d value / d log value = value); ke and ce tied to ka and ca move with them (the same solver index,
// correlation 1); a parameter at a bound has an infinite standard error.
core::ParameterUncertainty tuning_uncertainty(const TwoDofParams& p, const Layout& l, const std::vector<Index>& keep,
                                              const core::FitCovariance& cov, bool from_variance) {
  const std::vector<std::string> names = TwoDofParams::names();
  Eigen::VectorXd value(static_cast<Index>(names.size())), deriv(static_cast<Index>(names.size()));
  std::vector<int> fitted;
  std::vector<Index> at_bound;
  const int ke = l.ke_ratio == 0.0 ? 6 : 2;
  const int ce = l.ce_ratio == 0.0 ? (l.ke_ratio == 0.0 ? 7 : 6) : 3;
  const std::map<std::string, int> index = {{"m", -1}, {"k1", 0}, {"c1", 1}, {"ka", 2}, {"ca", 3}, {"ga", 4}, {"gs", 5}, {"ke", ke}, {"ce", ce}};
  for (std::size_t i = 0; i < names.size(); ++i) {
    value(static_cast<Index>(i)) = p.get(names[i]);
    deriv(static_cast<Index>(i)) = p.get(names[i]);
    const int solver = index.at(names[i]);
    const auto kept = std::find(keep.begin(), keep.end(), static_cast<Index>(solver));
    fitted.push_back(kept == keep.end() ? -1 : static_cast<int>(kept - keep.begin()));
    if (solver >= 0 && kept == keep.end()) at_bound.push_back(static_cast<Index>(i));
  }
  core::ParameterUncertainty u = core::parameter_uncertainty(names, value, deriv, fitted, cov, from_variance);
  for (const Index i : at_bound) u.standard_error(i) = std::numeric_limits<double>::infinity();
  return u;
}

bool usable(const TwoDofParams& p) {
  for (const auto& n : TwoDofParams::names()) {
    if (!std::isfinite(p.get(n))) return false;
  }
  return p.k1 > 0.0 && p.ke > 0.0 && p.ka > 0.0 && p.ca + p.ce > 0.0 && p.ga != 0.0 && p.gs != 0.0;
}

// The model's u -> d_e and u -> Vs of the actuator alone (a bench of unit amplifier gain) at omega
// (rad/s), columns kOutputDe and kOutputVs.
lti::CMatrix actuator_at(const TwoDofParams& p, const Vector& omega) {
  TwoDofBench bare;
  bare.amplifier_gain = 1.0;
  return two_dof_response(p, bare, omega);
}
// What the tuning compares with the data at every step: actuator_at through the Welch estimate's
// resolution kernel when it is active, sum_j c_j H(omega + j 2 pi df) (dsp/resolution_kernel.hpp; the
// chain divided out of the data is smooth over a line and left outside the kernel).
lti::CMatrix actuator_response(const TwoDofParams& p, const FitData& d) { return d.grid.smooth(actuator_at(p, d.grid.nodes())); }

// Per-point weights of the complex errors H_model - H_data of each output, relative to a reference
// model's response G0 (the previous pass's): v_k / |G0_k| with v_k = 1 (unknown variance) or
// 1/sqrt((std_k/|G0_k|)^2 + kFitModelRelativeError^2), std_k = eps_k |H_k| the point's standard
// deviation (dsp/frf_variance.hpp), v normalized per output to a mean square of 1/points (the two
// outputs alike). The errors are not divided by the noisy H_data: 1/H of a noisy point near the dip
// is biased towards 0 (E[1/(h + n)] = (1 - exp(-|h|^2/sigma^2))/h for circular Gaussian n), so the
// relative error H_model/H_data - 1 filled the dip and biased the dampings (c1 +54 %, ca -30 % on the
// virtual bench, issue 30), while H_data - H_model is centred wherever the noise is.
struct Weights {
  Vector de, vs;       // v_k / |G0_k|: multiply H_model - H_data
  Vector std_de, std_vs;  // the weighted residual's standard deviation, v_k std_k / |G0_k|; empty without the variance
};
// One output's weights from the reference's |G0_k| (mag) and each point's standard deviation relative
// to it (relative_std; empty when the variance is unknown, v_k = 1), as Weights: w = v / |G0|, sd = v
// relative_std (left untouched without the variance).
void output_weights(const Vector& mag, const Vector& relative_std, Vector& w, Vector& sd) {
  const bool variance = relative_std.size() > 0;
  Vector v = variance ? Vector(relative_std.unaryExpr([](double e) { return 1.0 / std::hypot(e, dsp::kFitModelRelativeError); }))
                      : Vector(Vector::Ones(mag.size()));
  v *= 1.0 / std::sqrt(v.squaredNorm());  // mean square 1/n
  w = v.cwiseQuotient(mag);
  if (variance) sd = relative_std.cwiseProduct(v);
}

Weights weights(const FitData& d, const TwoDofParams& reference) {
  const lti::CMatrix g0 = actuator_response(reference, d);
  const bool variance = d.eps_de.size() == d.omega.size();
  Weights out;
  const auto one = [&](Index o, const CVector& h, const Vector& eps, Vector& w, Vector& sd) {
    const Vector mag = g0.col(o).cwiseAbs();
    output_weights(mag, variance ? Vector(eps.cwiseProduct(h.cwiseAbs()).cwiseQuotient(mag)) : Vector(), w, sd);  // std_k / |G0_k|
  };
  one(kOutputDe, d.de, d.eps_de, out.de, out.std_de);
  one(kOutputVs, d.vs, d.eps_vs, out.vs, out.std_vs);
  return out;
}

// The standard deviation of each weighted residual part, [Re, Im] of d_e then of Vs (each part of the
// circular complex error carries std_k, dsp/frf_variance.hpp), for the covariance; empty without the
// FRF's variance.
Vector residual_std(const Weights& w) {
  const Index n = w.de.size();
  if (w.std_de.size() != n) return {};
  Vector s(4 * n);
  for (Index k = 0; k < n; ++k) {
    s(2 * k) = s(2 * k + 1) = w.std_de(k);
    s(2 * n + 2 * k) = s(2 * n + 2 * k + 1) = w.std_vs(k);
  }
  return s;
}

// residual_std() from the FRF's random error alone (dsp::random_frf_std at the model, at_nodes its
// actuator_at(p, d.grid.nodes()): the window's leakage at the resonance and the dip left out), for the
// intervals; the measured one without n_d.
Vector random_residual_std(const FitData& d, const lti::CMatrix& at_nodes, const Weights& wt) {
  Vector s = residual_std(wt);
  const Index n = d.omega.size();
  if (s.size() == 0 || !(d.effective_averages > 0.0)) return s;
  const lti::CMatrix at_lines = d.grid.smooth(at_nodes);
  for (const Index o : {kOutputDe, kOutputVs}) {
    const CVector& h = o == kOutputDe ? d.de : d.vs;
    const Vector std_h = (o == kOutputDe ? d.eps_de : d.eps_vs).cwiseProduct(h.cwiseAbs());
    const Vector random = dsp::random_frf_std(h, std_h, at_lines.col(o), d.grid.leakage_coherence(at_nodes.col(o)), d.effective_averages).std;
    const Vector& w = o == kOutputDe ? wt.de : wt.vs;
    for (Index k = 0; k < n; ++k) s(2 * n * o + 2 * k) = s(2 * n * o + 2 * k + 1) = w(k) * random(k);
  }
  return s;
}

// The window's leakage error in residuals() (dsp::leakage_residual_blocks): the random input's own error
// at the resonance and the dip, which random_residual_std leaves out. A residual (G_k - H_k) w_k carries
// u_k = -w_k e_k; e_k is the actuator's own (the chain divided out of the data is smooth over a line,
// so its leakage is the actuator model's times the chain). The lines' noise from random_sd (w_k std_k).
// d_e's rows first, as residuals(). at_nodes: actuator_at(p, d.grid.nodes()).
std::vector<core::ResidualCovarianceBlock> leakage_blocks(const FitData& d, const TwoDofParams& p, const lti::CMatrix& at_nodes,
                                                          const Weights& wt, const Vector& random_sd) {
  const Index n = d.omega.size();
  if (random_sd.size() != 4 * n || !dsp::knows_leakage(d.kernel)) return {};
  std::vector<core::ResidualCovarianceBlock> blocks;
  for (const Index o : {kOutputDe, kOutputVs}) {
    const CVector& h = o == kOutputDe ? d.de : d.vs;
    const Vector& w = o == kOutputDe ? wt.de : wt.vs;
    Eigen::VectorXcd g(n);
    Vector noise(n);
    for (Index k = 0; k < n; ++k) {
      g(k) = -w(k);
      noise(k) = w(k) > 0.0 ? random_sd(2 * n * o + 2 * k) / (w(k) * std::abs(h(k))) : 0.0;
    }
    const auto response = [&](const Vector& omega) -> CVector { return actuator_at(p, omega).col(o); };
    for (auto& b : dsp::leakage_residual_blocks(d.kernel, d.grid, d.omega, g, noise, at_nodes.col(o), response, 2 * n * o)) {
      blocks.push_back(std::move(b));
    }
  }
  return blocks;
}

// c_k of core::fit_covariance for residuals(): the Welch estimate's error correlates between
// neighbouring lines (dsp::adjacent_line_pairs), within each output's block of n complex residuals,
// not between the last d_e line and the first Vs line. The chain divided out of the data rotates the
// error by its phase step between two lines, below 1e-3 rad (the delay: 2 pi df tau; the high-pass,
// far below the band), taken as 0.
Eigen::VectorXcd adjacent_correlation(const FitData& d) {
  const Vector pairs = dsp::adjacent_line_pairs(d.kernel, d.omega);
  const Index n = d.omega.size();
  if (pairs.size() == 0) return {};
  Eigen::VectorXcd c = Eigen::VectorXcd::Zero(2 * n - 1);
  c.head(n - 1) = pairs.cast<Complex>();
  c.tail(n - 1) = pairs.cast<Complex>();
  return c;
}

// Weighted complex errors (H_model - H_data) w_k, [Re, Im] of d_e then of Vs (weights()); NaN when the
// parameters are out of range.
Vector residuals(const TwoDofParams& p, const FitData& d, const Weights& wt) {
  const Index n = d.omega.size();
  Vector r(4 * n);
  if (!usable(p)) return Vector::Constant(4 * n, std::numeric_limits<double>::quiet_NaN());
  const lti::CMatrix h = actuator_response(p, d);
  for (Index k = 0; k < n; ++k) {
    const Complex ede = (h(k, kOutputDe) - d.de(k)) * wt.de(k);
    const Complex evs = (h(k, kOutputVs) - d.vs(k)) * wt.vs(k);
    r(2 * k) = ede.real();
    r(2 * k + 1) = ede.imag();
    r(2 * n + 2 * k) = evs.real();
    r(2 * n + 2 * k + 1) = evs.imag();
  }
  return r;
}

// rms |H_model / H_data - 1| per output (what the tuning reports as its error).
std::pair<double, double> fit_errors(const TwoDofParams& p, const FitData& d) {
  const Index n = d.omega.size();
  if (!usable(p)) return {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
  const lti::CMatrix h = actuator_response(p, d);
  double de = 0.0, vs = 0.0;
  for (Index k = 0; k < n; ++k) {
    de += std::norm(h(k, kOutputDe) / d.de(k) - 1.0);
    vs += std::norm(h(k, kOutputVs) / d.vs(k) - 1.0);
  }
  return {std::sqrt(de / static_cast<double>(n)), std::sqrt(vs / static_cast<double>(n))};
}

// Parameters the data do not determine (tuning.hpp): relative standard error above
// kUndeterminedRelativeError, no standard error at all, or driven 1000 times away from the report's
// procedure (towards 0 or infinity, i.e. to the edge of what the log-parameters can reach). The
// verdict cannot then be good.
void mark_undetermined(TwoDofTuning& t, const TuningOptions& o) {
  if (t.status == TuningStatus::kNotRefined) return;
  for (const auto& name : TwoDofParams::names()) {
    if (name == "m") continue;
    const double v = t.params.get(name), v0 = t.initial.get(name);
    const double ratio = v0 != 0.0 ? std::abs(v / v0) : 1.0;
    const double rel = t.uncertainty_with_misfit.empty() ? std::numeric_limits<double>::infinity()
                                                         : t.uncertainty_with_misfit.relative_standard_error_of(name);
    std::string why;
    if (!(ratio > 1.0 / kBoundRatio && ratio < kBoundRatio)) {
      why = fmt::format("{} = {} driven to a bound ({} times the report's procedure's {})", name, format_number(v, 3),
                        format_number(ratio, 2), format_number(v0, 3));
    } else if (!(rel <= kUndeterminedRelativeError)) {
      why = fmt::format("{} = {} undetermined (relative standard error with the misfit {} > {})", name, format_number(v, 3),
                        format_number(rel, 2), format_number(kUndeterminedRelativeError));
    }
    if (why.empty()) continue;
    t.undetermined.push_back(name);
    t.quality.add_problem(why);
  }
  if (!t.undetermined.empty()) {
    t.quality.advise(o.stack_damping_ratio == 0.0 || o.stack_stiffness_ratio == 0.0
                         ? "impose the stack ratios (ke/ka = ce/ca = 2, the report's) or use a band reaching the node relaxation"
                         : "a band with more points of high coherence around the resonance and the anti-resonance");
  }
}

// What the report's procedure reads off the FRFs: the resonance of u -> d_e and the
// anti-resonance of u -> Vs (rad/s), their damping, and the static levels.
struct ReportFeatures {
  double wp = 0.0, peak = 0.0, zeta_p = 0.0;  // resonance, |H| there, damping
  double wz = 0.0, dip = 0.0, zeta_z = 0.0;   // anti-resonance, |Vs| there, damping
  double de0 = 0.0, vs0 = 0.0;                // static levels of d_e and Vs
};

ReportFeatures report_features(const FitData& d) {
  const Index n = d.omega.size();
  ReportFeatures f;
  std::tie(f.wp, f.peak) = extremum(d.omega, d.de, 0, n - 1, /*maximum=*/true, "resonance peak of u -> d_e");
  const double wp = f.wp;
  // The lowest frequency, corrected for the resonance's static amplification 1/(1 - w^2/wp^2).
  const double w0 = d.omega(0);
  f.de0 = std::abs(d.de(0)) * std::abs(1.0 - (w0 / wp) * (w0 / wp));
  // Peak over static = quality factor 1/(2 zeta) (exact at the undamped natural frequency).
  f.zeta_p = std::clamp(f.de0 / (2.0 * f.peak), 1e-5, 0.5);
  // The dip of Vs must lie below the resonance.
  Index below = 0;
  while (below + 1 < n && d.omega(below + 1) < wp) ++below;
  std::tie(f.wz, f.dip) = extremum(d.omega, d.vs, 0, below, /*maximum=*/false, "anti-resonance of u -> Vs below the resonance");
  const double wz = f.wz;
  // Near the zero, Vs ~ K (1 - w^2/wz^2 + 2 j zeta_z w/wz) / (1 - w^2/wp^2): the depth gives zeta_z.
  f.vs0 = std::abs(d.vs(0)) * std::abs(1.0 - (w0 / wp) * (w0 / wp)) / std::abs(1.0 - (w0 / wz) * (w0 / wz));
  f.zeta_z = std::clamp(f.dip * std::abs(1.0 - (wz / wp) * (wz / wp)) / (2.0 * f.vs0), 1e-6, 0.5);
  return f;
}

// The report's procedure: the shell from the anti-resonance, the stacks from the resonance with
// ke = rk ka and ce = rc ca.
TwoDofParams report_stiffness_and_damping(const ReportFeatures& f, double m, double rk, double rc) {
  TwoDofParams p;
  p.m = m;
  p.k1 = m * f.wz * f.wz;
  p.c1 = 2.0 * f.zeta_z * std::sqrt(p.k1 * m);
  const double ktot = m * f.wp * f.wp;
  if (!(ktot > p.k1)) {
    throw NumericalError("2-DoF tuning",
                         fmt::format("the resonance ({} Hz) is not above the anti-resonance ({} Hz) of u -> Vs",
                                     format_number(f.wp / kTwoPi, 4), format_number(f.wz / kTwoPi, 4)),
                         /*retry_may_help=*/true);
  }
  const double series = rk / (1.0 + rk);  // ke ka/(ke + ka) = series ka when ke = rk ka
  p.ka = (ktot - p.k1) / series;
  p.ke = rk * p.ka;
  // Same series factor for the dampers when ce = rc ca with rc = rk (the report's case); otherwise
  // a first guess that the refinement corrects. A floor keeps the damping positive when the
  // estimate of zeta_p is below the shell's share.
  const double c_crit = 2.0 * std::sqrt(ktot * m);
  p.ca = std::max(f.zeta_p * c_crit - p.c1, 1e-3 * c_crit) * (1.0 + rc) / rc;
  p.ce = rc * p.ca;
  return p;
}

// Gains: linear least squares of the relative error with unit gains.
void fit_gains(const FitData& d, TwoDofParams& p) {
  const Index n = d.omega.size();
  p.ga = 1.0;
  p.gs = 1.0;
  const lti::CMatrix h = actuator_response(p, d);
  double num = 0.0, den = 0.0;
  for (Index k = 0; k < n; ++k) {
    const Complex a = h(k, kOutputDe) / d.de(k);
    num += a.real();
    den += std::norm(a);
  }
  p.ga = num / den;
  num = den = 0.0;
  for (Index k = 0; k < n; ++k) {
    const Complex b = p.ga * h(k, kOutputVs) / d.vs(k);
    num += b.real();
    den += std::norm(b);
  }
  p.gs = num / den;
  if (!usable(p) || p.ga == 0.0 || p.gs == 0.0) {
    throw NumericalError("2-DoF tuning", "the initial gains ga, gs came out zero or not finite", /*retry_may_help=*/false);
  }
}

// Per-point weights as weights(), with the variance of each line from the model G (actuator_at(p,
// d.grid.nodes()): at_nodes) rather than from the record's coherence: the noise model of
// dsp::random_frf_std plus the window's leakage, |G_k|^2 (1/gamma_leak^2 - 1)/(2 n_d). The record's own
// coherence follows its leakage realization: weights taken from it down-weight the lines whose error
// is largest, and that fit's stiffnesses scatter less than the sandwich with the model's variance
// says (unit 6 of the calibration: k1, ka, gs covering 98.5-99 %, docs/uncertainty.md,
// section 6). Needs the FRF's variance and n_d.
Weights model_weights(const FitData& d, const lti::CMatrix& at_nodes) {
  const Index n = d.omega.size();
  const lti::CMatrix at_lines = d.grid.smooth(at_nodes);
  Weights out;
  const auto one = [&](Index o, const CVector& h, const Vector& eps, Vector& w, Vector& sd) {
    const Vector leak = d.grid.leakage_coherence(at_nodes.col(o)).cwiseMax(1e-12);
    const Vector random = dsp::random_frf_std(h, eps.cwiseProduct(h.cwiseAbs()), at_lines.col(o), leak, d.effective_averages).std;
    const Vector mag = at_lines.col(o).cwiseAbs();
    Vector relative_std(n);
    for (Index k = 0; k < n; ++k) {
      const double relative_noise = random(k) / mag(k);
      relative_std(k) = std::max(std::sqrt(relative_noise * relative_noise + (1.0 / leak(k) - 1.0) / (2.0 * d.effective_averages)),
                                 dsp::kMinFitRelativeStd);
    }
    output_weights(mag, relative_std, w, sd);
  };
  one(kOutputDe, d.de, d.eps_de, out.de, out.std_de);
  one(kOutputVs, d.vs, d.eps_vs, out.vs, out.std_vs);
  return out;
}

// The solver's log-parameters x within reach of the report's procedure's `start` (refine_tuning).
Vector within_reach(const Vector& x, const Vector& start) {
  const double reach = 2.0 * std::log(kBoundRatio);
  return x.array().max(start.array() - reach).min(start.array() + reach).matrix();
}

// Step 3: the stiffnesses and the sensor's gain (k1, ka, gs; ke when free) again, weighted by the
// model's variance (model_weights, from step 2's solution), the dampers and ga held at step 2's values;
// their standard errors from the sandwich of all the kept parameters with these weights, the FRF's
// random error and the leakage (leakage_blocks). The dampers are not refitted so: with the model's
// weights the undetermined dampers moved by 6-10 % (ca -10 %, c1 +6 % on the virtual bench,
// docs/uncertainty.md, section 6); nor is ga, whose pseudo-true value moved with the weights by 1.7
// of its standard errors (the 2-DoF model misses the bench, so each weighting has its own best fit),
// while step 2's ga covers its truth in 97 %. Keeps step 2's correlations; changes nothing when the
// FRF's variance or n_d is unknown or the pass does not converge.
void reweight_stiffnesses(const FitData& d, const Layout& layout, const Vector& start, const std::vector<Index>& keep,
                          const Vector& x, TwoDofTuning& out, const core::LmOptions& lm) {
  if (d.eps_de.size() != d.omega.size() || !(d.effective_averages > 0.0)) return;
  const Weights wt = model_weights(d, actuator_at(layout.unpack(x), d.grid.nodes()));
  std::vector<Index> free = {0, 2, 5};  // k1, ka, gs (Layout)
  if (layout.ke_ratio == 0.0) free.push_back(6);
  const auto full = [&](const Vector& s) {
    Vector v = x;
    for (std::size_t i = 0; i < free.size(); ++i) v(free[i]) = s(static_cast<Index>(i));
    return within_reach(v, start);
  };
  const core::ResidualFunction sub = [&](const Vector& s) { return residuals(layout.unpack(full(s)), d, wt); };
  const core::LmResult r = core::levenberg_marquardt(sub, x(free), lm);
  const Vector y = full(r.x);
  const TwoDofParams p = layout.unpack(y);
  if (!r.converged() || !y.allFinite() || !usable(p)) return;
  const core::ResidualFunction residual = [&](const Vector& v) { return residuals(layout.unpack(within_reach(v, start)), d, wt); };
  const Eigen::MatrixXd jacobian = core::central_difference_jacobian(residual, y)(Eigen::all, keep);
  const lti::CMatrix at_nodes = actuator_at(p, d.grid.nodes());
  const Vector random_sd = random_residual_std(d, at_nodes, wt);
  const core::FitCovariance cov = core::fit_covariance(jacobian, Vector::Zero(jacobian.rows()), random_sd, adjacent_correlation(d),
                                                       leakage_blocks(d, p, at_nodes, wt, random_sd));
  const core::ParameterUncertainty u = tuning_uncertainty(p, layout, keep, cov, true);
  for (std::size_t i = 0; i < u.names.size(); ++i) {
    const std::string& name = u.names[i];
    if (name == "k1" || name == "ka" || name == "ke" || name == "gs") {
      out.uncertainty.standard_error(static_cast<Index>(i)) = u.standard_error(static_cast<Index>(i));
    }
  }
  out.uncertainty.value = u.value;
  out.uncertainty_with_misfit.value = u.value;
  out.params = p;
  out.iterations += r.iterations;
  out.message += fmt::format("; k1, ka, gs refitted weighted by the model's variance: {} steps, cost {} -> {}", r.iterations,
                             format_number(r.initial_cost, 4), format_number(r.cost, 4));
}

// Step 2: Levenberg-Marquardt on the log-parameters from the report's procedure's.
void refine_tuning(const FitData& d, const TuningOptions& o, TwoDofTuning& out) {
  const TwoDofParams& p = out.initial;
  Layout layout;
  layout.mass = o.mass;
  layout.ga_sign = p.ga > 0.0 ? 1.0 : -1.0;
  layout.gs_sign = p.gs > 0.0 ? 1.0 : -1.0;
  layout.ke_ratio = o.stack_stiffness_ratio;
  layout.ce_ratio = o.stack_damping_ratio;
  core::LmOptions lm;
  lm.max_iterations = o.max_iterations;
  // Two passes: the weights relative to the report's procedure's model, then to the first pass's.
  const Vector start = layout.pack(p);
  Vector x = start;
  core::LmResult r;
  int iterations = 0;
  Weights wt;
  // The solver's parameters stay within kBoundRatio^2 of the report's procedure's values: beyond, the
  // residuals see the bound. A parameter the data do not show (c1) would otherwise run towards
  // exp(-inf), and with ||x|| in the millions the step tolerance, relative to ||x||, would stop the
  // solver while the others still move by per cents (ce, ca then depended on round-off).
  const auto bounded = [&](const Vector& v) -> Vector { return within_reach(v, start); };
  const core::ResidualFunction residual = [&](const Vector& v) { return residuals(layout.unpack(bounded(v)), d, wt); };
  for (int pass = 0; pass < 2; ++pass) {
    const TwoDofParams reference = layout.unpack(x);
    if (pass > 0 && !(x.allFinite() && usable(reference))) break;
    wt = weights(d, reference);
    r = core::levenberg_marquardt(residual, x, lm);
    iterations += r.iterations;
    x = bounded(r.x);
  }
  // A parameter the data do not show (c1) can run to exp(-745) = 0, "not physical": it is reported
  // at kBoundRatio^2 from the report's procedure's value instead (undetermined, at a bound; the fit
  // does not see the difference).
  r.x = bounded(r.x);
  out.params = layout.unpack(r.x);
  const std::vector<Index> keep = unbounded(r.x, start);
  if (r.x.allFinite() && usable(out.params) && !keep.empty()) {
    const Eigen::MatrixXd jacobian = core::central_difference_jacobian(residual, r.x)(Eigen::all, keep);
    const Vector res = residual(r.x), sd = residual_std(wt);
    const bool from_variance = sd.size() > 0;
    const Eigen::VectorXcd adjacent = from_variance ? adjacent_correlation(d) : Eigen::VectorXcd();
    const core::FitCovariance with_misfit = core::fit_covariance(jacobian, res, sd, adjacent);
    // With the FRF's variance the interval is the random error alone: the covariance of zero residuals
    // has no misfit widening (f_j = 1, core/fit_covariance.hpp), with the FRF's random error without
    // the window's leakage (random_residual_std). The 2-DoF model's misfit on a real bench is a bias,
    // the same for every record, not a scatter: widened by it, the intervals of k1, ka, ga, gs were 2-5
    // times the scatter over 200 noise seeds; with the leakage counted as noise, those of ka, ga, gs
    // were 1.6 times (docs/uncertainty.md, section 6). The misfit, against the measured variance,
    // still decides which parameters are undetermined (uncertainty_with_misfit).
    // The leakage's own random error at the resonance and the dip (leakage_blocks) is in it.
    core::FitCovariance random = with_misfit;
    if (from_variance) {
      const lti::CMatrix at_nodes = actuator_at(out.params, d.grid.nodes());
      const Vector random_sd = random_residual_std(d, at_nodes, wt);
      random = core::fit_covariance(jacobian, Vector::Zero(res.size()), random_sd, adjacent, leakage_blocks(d, out.params, at_nodes, wt, random_sd));
    }
    random.chi2_per_dof = with_misfit.chi2_per_dof;
    out.uncertainty = tuning_uncertainty(out.params, layout, keep, random, from_variance);
    out.uncertainty_with_misfit = tuning_uncertainty(out.params, layout, keep, with_misfit, from_variance);
  }
  out.iterations = iterations;
  out.status = r.converged() ? TuningStatus::kConverged
               : r.status == core::LmStatus::kMaxIterations ? TuningStatus::kMaxIterations
                                                              : TuningStatus::kNoProgress;
  out.message =
      fmt::format("Levenberg-Marquardt: {} after {} steps ({} evaluations), cost {} -> {}", core::to_string(r.status),
                  r.iterations, r.evaluations, format_number(r.initial_cost, 4), format_number(r.cost, 4));
  if (r.converged() && !out.uncertainty.empty() && out.uncertainty.from_data_variance) {
    reweight_stiffnesses(d, layout, start, keep, r.x, out, lm);
  }
  std::tie(out.fit_error_de, out.fit_error_vs) = fit_errors(out.params, d);
}

}  // namespace

TwoDofTuning tune_two_dof(const dsp::Frf& frf, const TuningOptions& o) {
  o.validate();
  const std::string source = frf.provenance.source.empty() ? "FRF" : frf.provenance.source;
  frf.validate(source);
  const FitData d = prepare(frf, o, source);
  const double rk = o.stack_stiffness_ratio > 0.0 ? o.stack_stiffness_ratio : 2.0;
  const double rc = o.stack_damping_ratio > 0.0 ? o.stack_damping_ratio : 2.0;

  // ---- Step 1: the report's procedure.
  TwoDofTuning out;
  out.bench = o.bench;
  out.points = d.omega.size();
  const ReportFeatures f = report_features(d);
  TwoDofParams p = report_stiffness_and_damping(f, o.mass, rk, rc);
  fit_gains(d, p);
  const double g = o.bench.amplifier_gain;
  out.features = {f.wp, f.zeta_p, f.wz, f.zeta_z, g * std::copysign(f.de0, d.de(0).real()), g * std::copysign(f.vs0, d.vs(0).real())};
  out.initial = p;
  std::tie(out.initial_fit_error_de, out.initial_fit_error_vs) = fit_errors(p, d);
  out.params = p;
  out.fit_error_de = out.initial_fit_error_de;
  out.fit_error_vs = out.initial_fit_error_vs;
  out.status = TuningStatus::kNotRefined;
  out.message = "report's procedure only (refinement disabled)";
  if (!o.refine) {
    out.quality = assess(out, d);
    return out;
  }
  refine_tuning(d, o, out);
  out.quality = assess(out, d);
  mark_undetermined(out, o);
  return out;
}

TwoDofTuning tune_two_dof_measured(const dsp::Frf& frf, TuningOptions options, const ident::DelayedSecondOrderFit* de_plant,
                                   const ident::IffPlantFit* vs_plant) {
  dsp::Frf data = frf;
  if (vs_plant) {
    // Only the corner 1 / (R C) matters: keep the R (else the C) given, else the report's 80.6 kOhm.
    if (options.bench.hpf_resistance > 0.0) {
      options.bench.hpf_capacitance = 1.0 / (options.bench.hpf_resistance * vs_plant->w_hpf);
    } else if (options.bench.hpf_capacitance > 0.0) {
      options.bench.hpf_resistance = 1.0 / (options.bench.hpf_capacitance * vs_plant->w_hpf);
    } else {
      options.bench.hpf_resistance = 80.6e3;
      options.bench.hpf_capacitance = 1.0 / (options.bench.hpf_resistance * vs_plant->w_hpf);
    }
  }
  if (de_plant) {
    options.bench.delay = std::max(0.0, de_plant->delay);
    if (vs_plant) {
      const Eigen::Index vs = data.output_index(options.vs_output);
      const double extra = vs_plant->delay - options.bench.delay;
      for (Eigen::Index k = 0; k < data.freq_Hz.size(); ++k) {
        data.H[static_cast<std::size_t>(vs)](k) *= std::exp(std::complex<double>(0.0, kTwoPi * data.freq_Hz(k) * extra));
      }
    }
  }
  return tune_two_dof(data, options);
}

}  // namespace piezobench::apa
