#pragma once
// Fit of the IFF plant model of the report (eq. 2.3, section 2.6; plant::iff_plant) to a measured
// u -> Vs FRF:
//
//   G(s) = g0 (1 + 2 xz s/wz + s^2/wz^2) / (1 + 2 xp s/wp + s^2/wp^2) * s / (w_hpf + s) * exp(-s delay)
//
// The report tuned g0, wz, xz, wp, xp and w_hpf by hand and added a 200 us delay to match the phase;
// here all seven are fitted by Levenberg-Marquardt (core/least_squares.hpp) on the relative complex error
// sum_k v_k |G(j w_k) / H_k - 1|^2 (magnitude and phase at once) with v_k ~ 1/omega_k, so that on a
// uniform grid every decade weighs alike (else the mass line above the resonance, which holds most
// of the points, would decide the fit), divided by sqrt(eps^2 + 0.05^2) with eps each point's
// relative standard deviation when the FRF's variance is known (IffPlantFitOptions::
// effective_averages; 0.05 the model's own error, dsp::kFitModelRelativeError), with
// log-parameters for g0 (sign kept), wz, wp, xp, w_hpf. xz is free in sign: xz < 0 is a
// non-minimum-phase zero pair (mirrored into the right half plane), which is what the report's data
// show and what a minimum-phase fit cannot follow in phase. The fit is started from both signs of xz
// and the better result is kept.
//
// Starting values from the data: wp at the peak of |H| in the band, wz at the dip of |H| below it,
// damping ratios from the half-power width of the peak (xp) and 0.005 (xz), w_hpf from
// ident::fit_high_pass on the points below hpf_fmax (when there are three), g0 as the median of
// |H / G(g0 = 1)| below the anti-resonance, and the delay from the slope of the phase of
// H / G(delay = 0) above 1.5 wp.
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "piezobench/core/fields.hpp"
#include "piezobench/plant/iff_plant.hpp"
#include "piezobench/core/fit_covariance.hpp"
#include "piezobench/core/fit_quality.hpp"
#include "piezobench/core/least_squares.hpp"
#include "piezobench/dsp/resolution_kernel.hpp"
#include "piezobench/ident/features.hpp"
#include "piezobench/lti/state_space.hpp"
#include "piezobench/lti/transfer_function.hpp"

namespace piezobench::ident {

struct IffPlantFitOptions {
  double fmin_Hz = 0.0;       // band used (0 = from the lowest positive frequency)
  double fmax_Hz = 1000.0;    // 0 = up to the highest
  double hpf_fmax_Hz = 5.0;   // points below this start the high-pass corner
  double min_coherence = 0.0; // points with a known coherence below this are left out
  bool fit_delay = true;      // false: delay fixed at 0
  double fixed_w_hpf = 0.0;   // rad/s; > 0: the high-pass corner is not fitted but set to this
                              // (e.g. 1 / (R C) from the measured capacitance)
  int max_iterations = 200;
  // Welch's effective number of averages of the FRF (dsp::FrfProvenance::effective_averages). > 0
  // with a coherence: each point is also weighted by 1 / sqrt(eps^2 + 0.05^2), eps its relative
  // standard deviation (dsp/frf_variance.hpp; the lines at a dip, where the coherence drops, count
  // little) and the standard errors come from that variance (sandwich form, widened when the misfit
  // exceeds it); 0: from the residuals' scatter. With an active `resolution` whose provenance gives
  // the segments' layout, a second pass from that solution takes eps from the first pass's model (the
  // noise model of dsp::random_frf_std plus the window's predicted leakage) instead of the record's
  // coherence: weights from each record's own coherence follow its leakage realization and made the
  // resonance's standard error 1.25-1.4 times its scatter. The IFF plant's second pass also refers its
  // errors to the first pass's model, (G - H_k) / G_1(j w_k), not to the noisy H_k (biased at the dip).
  double effective_averages = 0.0;
  // The Welch estimate's resolution kernel of the FRF (dsp::resolution_kernel of its provenance;
  // dsp/resolution_kernel.hpp): active, the model is compared with the data through it,
  // sum_j c_j G(omega + j 2 pi df), which is what a Welch estimate converges to (the hann window's
  // smoothing biased the resonance damping +3 % on the virtual bench). Inactive (the default; an FRF
  // computed from a model, a file that does not say how it was estimated, or turned off): G itself.
  dsp::ResolutionKernel resolution;
  void validate() const;      // InputError (source "iff plant fit options")
};

// The fitted plant is a plant::IffPlantParams (g0 V/V signed, wz, wp, w_hpf rad/s, xz < 0 for a
// non-minimum-phase zero pair, xp, delay s) with how well it fits.
struct IffPlantFit : plant::IffPlantParams {
  double relative_rms_error = 0.0;           // rms |G/H - 1| over the points used (G through options.resolution)
  double weighted_relative_rms_error = 0.0;  // the same with the fit's per-decade weights
  double initial_relative_rms_error = 0.0;   // weighted, at the better of the two starts
  long points = 0;
  int iterations = 0;
  bool converged = false;
  core::LmStatus status = core::LmStatus::kMaxIterations;  // of the better of the two starts
  // Poor: relative_rms_error above core::kPoorRelativeError, wz or wp outside the band of the points
  // used, Levenberg-Marquardt stopped at max_iterations; impossible: a negative delay.
  core::FitQuality quality;
  // Standard errors (linearized at the solution, core/fit_covariance.hpp) of g0, wz, xz, wp, xp,
  // w_hpf, delay (0 for one held fixed), their correlations and the fit's conditioning.
  core::ParameterUncertainty uncertainty;

  [[nodiscard]] bool zero_is_nonminimum_phase() const { return xz < 0.0; }
  // G(s) as a transfer function (with the delay): plant::iff_plant(*this).
  [[nodiscard]] lti::TransferFunction transfer_function() const;
  // G(j omega) at every omega (rad/s): plant::iff_plant_response(*this, omega).
  [[nodiscard]] lti::CVector response(const lti::Vector& omega) const;
};

// Is the zero pair of u -> Vs at the anti-resonance non-minimum-phase (report sections 2.3, 2.4)?
// Three pieces of evidence, in this order of trust:
//  1. the data's phase change across the anti-resonance (AntiResonance::phase_change_deg, the sum of
//     the phase steps between neighbouring lines): +180 deg for a minimum-phase zero pair, -180 deg
//     for a mirrored one. When the dip is narrower than the line spacing, one step through it is
//     itself about 180 deg, and whether it counts as +180 or -180 is decided by the noise: a change
//     within `ambiguity_deg` of +-180 deg is ambiguous (a unit's -178 deg became +182 deg with
//     another noise realization);
//  2. the eq. 2.3 plant fit (fit_iff_plant): xz < 0 is a non-minimum-phase zero. It fits the whole
//     band with the delay, so it does not depend on the few lines through the dip;
//  3. the vector fit's zero (AntiResonance::nonminimum_phase_model): least trusted, a rational model
//     without a delay absorbs the delay's phase into its zeros (it calls a mirrored zero with a
//     delay minimum-phase).
// When the plant fit has a standard error of xz, its interval xz +- kVerdictCoverage se (99.7 %)
// decides alone: non-minimum-phase when the interval lies below 0, minimum-phase above, undetermined
// (nullopt) when it contains 0 (the noise at the dip hides the sign). A verdict is a decision that
// sends the unit to one control design or the other, so it is stated at 3 standard errors: a wrong
// one has a probability below 0.14 % when the standard error is right (at 1.96 a truly
// minimum-phase zero hidden by 1 % noise was called non-minimum-phase in 1 of 12 held-out seeds). Without one: the phase when it gives a
// verdict outside the ambiguity; else the plant fit's sign; else the ambiguous phase; else the fitted
// zero.
struct ZeroPhaseVerdict {
  std::optional<bool> nonminimum_phase;  // nullopt: undetermined or no evidence
  double xz = std::numeric_limits<double>::quiet_NaN();                 // of the plant fit
  double xz_standard_error = std::numeric_limits<double>::quiet_NaN();  // NaN: no plant fit or no standard error
  std::string from;    // "phase", "iff-plant-fit", "fitted-zero" or "none"
  std::string reason;  // e.g. "phase change -178.3 deg ambiguous (within 20 deg of +-180 deg); plant fit zero xz = -0.0047 < 0"
};
inline constexpr double kPhaseAmbiguityDeg = 20.0;
inline constexpr double kVerdictCoverage = 3.0;  // standard errors of xz on each side (two-sided 99.73 %)
// zero: the anti-resonance found in the data (nullptr: none); plant: the eq. 2.3 fit (nullptr: none).
[[nodiscard]] ZeroPhaseVerdict zero_phase_verdict(const AntiResonance* zero, const IffPlantFit* plant,
                                                  double ambiguity_deg = kPhaseAmbiguityDeg);

// omega: rad/s, increasing; h: u -> Vs (V/V); coherence: empty or same size. InputError (source)
// for sizes that differ, non-finite data, fewer than 12 usable points or no resonance above an
// anti-resonance in the band; NumericalError when Levenberg-Marquardt cannot reduce the error.
IffPlantFit fit_iff_plant(const lti::Vector& omega, const lti::CVector& h, const lti::Vector& coherence,
                          const IffPlantFitOptions& options = {}, const std::string& source = "");

// The mass-spring-damper seen from u to d_e (report section 2.3, and the damped plants u' -> d_e of
// section 2.6) with the measurement delay:
//   H(s) = k wn^2 / (s^2 + 2 zeta wn s + wn^2) * exp(-s delay)
// fitted by the same weighted Levenberg-Marquardt (log k with its sign kept, log wn, log zeta,
// delay), started from the peak of |H| (wn), its half-power width (zeta), the median low-frequency
// gain (k) and the phase slope above 1.5 wn (delay). The delay of d_e differs from the one of Vs
// (the force sensor's read-out has its own filter), which is why both plants carry their own.
struct DelayedSecondOrderFit {
  double static_gain = 0.0;        // k, output units / input units (signed)
  double natural_frequency = 0.0;  // wn, rad/s
  double damping = 0.0;            // zeta
  double delay = 0.0;              // s
  double relative_rms_error = 0.0; // rms |H_model / H - 1| over the points used (through options.resolution)
  long points = 0;
  // Standard errors of static_gain, natural_frequency, damping, delay (as IffPlantFit::uncertainty).
  core::ParameterUncertainty uncertainty;
  int iterations = 0;
  core::LmStatus status = core::LmStatus::kMaxIterations;
  // Poor: relative_rms_error above core::kPoorRelativeError, wn outside the band of the points used,
  // max_iterations reached; impossible: a negative delay.
  core::FitQuality quality;
  [[nodiscard]] lti::Complex pole() const;  // -zeta wn + j wn sqrt(1 - zeta^2) (Im >= 0)
  [[nodiscard]] lti::CVector response(const lti::Vector& omega) const;  // omega: rad/s
};

// omega (rad/s, increasing) and h as for fit_iff_plant; options.fmin_Hz/fmax_Hz/min_coherence,
// fit_delay and max_iterations apply (the high-pass options do not). InputError for bad data,
// fewer than 8 usable points or no peak inside the band.
DelayedSecondOrderFit fit_delayed_second_order(const lti::Vector& omega, const lti::CVector& h, const lti::Vector& coherence,
                                               const IffPlantFitOptions& options = {}, const std::string& source = "");

// Both plants of an actuator's FRFs u -> d_e and u -> Vs, fitted as `run` and `model tune` do (one
// procedure): u -> d_e by fit_delayed_second_order on [fmin_Hz, fmax_Hz], u -> Vs by fit_iff_plant
// on [iff_fmin_Hz, fmax_Hz] (down to the lowest frequency by default, for the high-pass corner),
// both on the points with a coherence of at least min_coherence and the delay fitted.
struct ActuatorPlantOptions {
  double fmin_Hz = 20.0;         // band of the d_e fit
  double fmax_Hz = 500.0;        // band of both fits
  double iff_fmin_Hz = 0.0;      // lowest frequency of the Vs fit
  double hpf_fmax_Hz = 5.0;      // points below this start the high-pass corner
  double fixed_w_hpf = 0.0;      // rad/s; > 0: the high-pass corner is known (1 / (R C_sensor))
  double min_coherence = 0.5;
  double effective_averages = 0.0;  // a count, of the FRF (IffPlantFitOptions::effective_averages), for both fits
  dsp::ResolutionKernel resolution;  // of the FRF (IffPlantFitOptions::resolution), for both fits
  void validate() const;         // InputError (source "actuator plant options")
};

struct ActuatorPlants {
  std::optional<DelayedSecondOrderFit> de;  // u -> d_e; nullopt when the fit failed
  std::optional<IffPlantFit> vs;            // u -> Vs
  IffPlantFitOptions de_options, vs_options;  // as used
  // "u -> d_e second-order fit: ..." / "IFF plant fit: ..." for a fit that failed (NumericalError).
  std::vector<std::string> failures;
};

// omega (rad/s, increasing), each output's H and coherence (empty = unknown) as for the fits above.
// Data problems are InputErrors; a fit that fails numerically is left out and listed in `failures`.
// omega: rad/s; coh_de, coh_vs: dimensionless.
ActuatorPlants fit_actuator_plants(const lti::Vector& omega, const lti::CVector& h_de, const lti::Vector& coh_de,
                                   const lti::CVector& h_vs, const lti::Vector& coh_vs,
                                   const ActuatorPlantOptions& options = {}, const std::string& source = "");

constexpr auto describe(core::Type<DelayedSecondOrderFit>) {
  using S = DelayedSecondOrderFit;
  using namespace core::shown;
  return core::fields<S>("DelayedSecondOrderFit", "k wn^2/(s^2 + 2 zeta wn s + wn^2) e^(-s delay) fitted to an FRF",
      core::field("static_gain", &S::static_gain, kNone, "k, output units / input units (signed)"),
      core::field("natural_frequency", &S::natural_frequency, kRadPerSecondAsHz, "wn"),
      core::field("damping", &S::damping, kRatio, "zeta"),
      core::field("delay", &S::delay, kSecond, "pure delay"),
      core::field("relative_rms_error", &S::relative_rms_error, kRatio, "rms |H_model / H - 1| over the points used"),
      core::field("points", &S::points, kNone, "frequencies used"),
      core::field("iterations", &S::iterations, kNone, "Levenberg-Marquardt steps"),
      core::field("status", &S::status, kNone, "why Levenberg-Marquardt stopped"),
      core::field("quality", &S::quality, kNone, "the verdict").key("."),
      core::field("uncertainty", &S::uncertainty, kNone, "standard errors of static_gain, natural_frequency, damping, delay"));
}

constexpr auto describe(core::Type<IffPlantFit>) {
  using S = IffPlantFit;
  using namespace core::shown;
  return core::fields<S>("IffPlantFit", "the IFF plant u -> Vs of eq. 2.3 with delay, fitted to an FRF",
      core::field("g0", &S::g0, kVoltPerVolt, "static gain (signed)").in_report(),
      core::field("wz", &S::wz, kRadPerSecondAsHz, "zero pair's natural frequency").in_report(),
      core::field("xz", &S::xz, kRatio, "zero pair's damping (< 0: non-minimum phase)").in_report(),
      core::field("wp", &S::wp, kRadPerSecondAsHz, "pole pair's natural frequency").in_report(),
      core::field("xp", &S::xp, kRatio, "pole pair's damping").in_report(),
      core::field("w_hpf", &S::w_hpf, kRadPerSecondAsHz, "high-pass corner of the read-out").in_report(),
      core::field("delay", &S::delay, kSecond, "pure delay").in_report(),
      core::field("relative_rms_error", &S::relative_rms_error, kRatio, "rms |G/H - 1| over the points used").in_report(),
      core::field("weighted_relative_rms_error", &S::weighted_relative_rms_error, kRatio, "the same with the per-decade weights"),
      core::field("initial_relative_rms_error", &S::initial_relative_rms_error, kRatio, "weighted, at the better start"),
      core::field("points", &S::points, kNone, "frequencies used"),
      core::field("iterations", &S::iterations, kNone, "Levenberg-Marquardt steps"),
      core::field("converged", &S::converged, kNone, "Levenberg-Marquardt converged"),
      core::field("status", &S::status, kNone, "why Levenberg-Marquardt stopped"),
      core::field("quality", &S::quality, kNone, "the verdict").key("."),
      core::field("uncertainty", &S::uncertainty, kNone, "standard errors of g0, wz, xz, wp, xp, w_hpf, delay"));
}

constexpr auto describe(core::Type<IffPlantFitOptions>) {
  using S = IffPlantFitOptions;
  using namespace core::shown;
  return core::fields<S>("IffPlantFitOptions", "the options of a plant fit (as used)",
      core::field("fmin_Hz", &S::fmin_Hz, kHertz, "band used (0 = from the lowest positive frequency)"),
      core::field("fmax_Hz", &S::fmax_Hz, kHertz, "0 = up to the highest"),
      core::field("hpf_fmax_Hz", &S::hpf_fmax_Hz, kHertz, "points below this start the high-pass corner"),
      core::field("min_coherence", &S::min_coherence, kRatio, "points with a known coherence below this are left out"),
      core::field("fit_delay", &S::fit_delay, kNone, "false: delay fixed at 0"),
      core::field("fixed_w_hpf", &S::fixed_w_hpf, kRadPerSecond, "> 0: the high-pass corner is set to this, not fitted"),
      core::field("max_iterations", &S::max_iterations, kNone, "Levenberg-Marquardt steps"),
      core::field("effective_averages", &S::effective_averages, kRatio, "Welch's n_d of the FRF (0: unknown)"));
}

constexpr auto describe(core::Type<ActuatorPlants>) {
  using S = ActuatorPlants;
  using namespace core::shown;
  return core::fields<S>("ActuatorPlants", "both plants of an actuator's FRF, fitted as `run` and `model tune` do",
      core::field("de", &S::de, kNone, "u -> d_e (absent when the fit failed)"),
      core::field("vs", &S::vs, kNone, "u -> Vs (absent when the fit failed)"),
      core::field("de_options", &S::de_options, kNone, "the d_e fit's options as used"),
      core::field("vs_options", &S::vs_options, kNone, "the Vs fit's options as used"),
      core::field("failures", &S::failures, kNone, "a fit that failed numerically, with its reason"));
}

}  // namespace piezobench::ident
