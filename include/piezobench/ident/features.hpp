#pragma once
// Features of a measured frequency response function (report sections 2.3 to 2.6): static gain,
// resonances and anti-resonances with frequency and damping, whether an anti-resonance is a
// non-minimum-phase zero, the corner of a first-order high-pass, and second-order fits.
//
// Resonances and anti-resonances come from a rational model fitted by vector fitting: its lightly
// damped poles, and the lightly damped transmission zeros of its state space (lti::zeros). A
// non-minimum-phase zero is judged twice, independently: from the fitted zero (Re z > 0) and from
// the measured phase across the anti-resonance (a minimum-phase zero pair raises the phase by
// 180 deg, a mirrored one lowers it by 180 deg, as in report section 2.3).
//
// All frequencies are rad/s unless the name says _Hz; responses are complex, output / input.
#include <string>
#include <vector>

#include "piezobench/ident/vector_fitting.hpp"

namespace piezobench::dsp {
struct Frf;
}

namespace piezobench::ident {

// Where the static gain came from: the fitted model's DC gain, or the data's low-frequency plateau
// when the model has a high-pass (its DC gain is far below the low-frequency data).
enum class StaticGainSource { kModelDcGain, kDataPlateau };
std::string to_string(StaticGainSource s);                // "model-dc-gain", "data-plateau"
StaticGainSource static_gain_source_from_string(const std::string& s);  // throws InputError

// Verdict of the phase of the data across an anti-resonance.
enum class PhaseVerdict { kMinimumPhase, kNonMinimumPhase, kUndetermined };
std::string to_string(PhaseVerdict v);  // "minimum-phase", "non-minimum-phase", "undetermined"
PhaseVerdict phase_verdict_from_string(const std::string& s);  // throws InputError

// A lightly damped pole pair (resonance) or zero pair (anti-resonance) of the fitted model.
struct ModalFeature {
  Complex root;                    // rad/s, the member of the pair with Im > 0
  double natural_frequency = 0.0;  // |root|, rad/s
  double damping = 0.0;            // |Re root| / |root| (positive also for a mirrored zero)
  [[nodiscard]] double frequency_Hz() const;
};

struct AntiResonance : ModalFeature {
  bool nonminimum_phase_model = false;  // the fitted zero has Re > 0
  PhaseVerdict phase_verdict = PhaseVerdict::kUndetermined;
  double phase_change_deg = 0.0;        // unwrapped phase change of the data across the zero
  Index phase_points = 0;               // data points in the band that was examined
};

struct FrfFeatureOptions {
  // The rational model: order and asymptote (none or d; d + s e is rejected because its zeros are
  // not those of a proper state space).
  VectorFittingOptions fit;
  // A pole or zero pair counts as lightly damped when its damping is below this.
  double max_damping = 0.2;
  // A pole pair is a resonance when its modal peak |r| / |Re p| is at least this fraction of the
  // fitted response at that frequency (rejects spurious poles with negligible residues).
  double min_significance = 0.1;
  // A zero and a pole closer than this relative distance cancel and are both ignored, one to one
  // (the closest pairs first: a spurious pole-zero pair beside a resonance leaves the resonance).
  double cancellation_tolerance = 0.02;
  // Relative half-width of the band examined around an anti-resonance for the phase verdict; it is
  // widened to 5 damping ratios for broad zeros and narrowed to half the distance to the nearest
  // other pole or zero.
  double phase_band = 0.1;  // relative
  // |phase change| above this (deg) gives a verdict; below, kUndetermined.
  double phase_threshold_deg = 90.0;
  // The model is taken to have a high-pass when |DC gain| < this fraction of |H| at the lowest
  // frequency.
  double high_pass_ratio = 0.5;

  void validate() const;  // throws InputError (source "frf feature options")
};

struct FrfFeatures {
  double static_gain = 0.0;  // output units / input units, signed (negative: phase 180 deg)
  StaticGainSource static_gain_source = StaticGainSource::kModelDcGain;
  double plateau_frequency = 0.0;          // rad/s, where the plateau was read (kDataPlateau only)
  std::vector<ModalFeature> resonances;    // by increasing frequency, inside the data band
  std::vector<AntiResonance> antiresonances;
  VectorFittingResult fit;                 // the model the features come from
};

// omega: rad/s as for vector_fit; h: the response of one output. Throws InputError / NumericalError
// as vector_fit does.
FrfFeatures frf_features(const Vector& omega, const CVector& h, const FrfFeatureOptions& options);
// One named output of an FRF; errors name the FRF's source file.
FrfFeatures frf_features(const dsp::Frf& frf, const std::string& output, const FrfFeatureOptions& options);

// First-order high-pass g * s / (s + corner) fitted to the data with omega <= max_omega
// (0 = all), least squares on the complex error, g real. The corner is found by a grid search over
// [omega_min / 100, omega_max * 100] refined by golden section on log(corner); g follows in closed
// form for each corner (variable projection).
struct HighPassFit {
  double corner = 0.0;              // rad/s
  double gain = 0.0;                // output unit per input unit, high-frequency gain g, signed
  double relative_rms_error = 0.0;  // rms |model - data| / rms |data| over the fitted points
  [[nodiscard]] double corner_Hz() const;
};
// omega, max_omega: rad/s.
HighPassFit fit_high_pass(const Vector& omega, const CVector& h, double max_omega = 0.0);

// Second-order low-pass k wn^2 / (s^2 + 2 zeta wn s + wn^2): by nonlinear least squares
// (Levy's linearization to start, then Levenberg-Marquardt on the complex error), or by vector
// fitting with 2 poles and a constant term (what the report used, vectfit3).
enum class SecondOrderMethod { kNonlinearLeastSquares, kVectorFitting };
std::string to_string(SecondOrderMethod m);  // "nls", "vector-fitting"
SecondOrderMethod second_order_method_from_string(const std::string& s);  // throws InputError

struct SecondOrderFitOptions {
  SecondOrderMethod method = SecondOrderMethod::kNonlinearLeastSquares;
  int max_iterations = 200;  // Levenberg-Marquardt steps
  void validate() const;     // throws InputError
};

struct SecondOrderFit {
  double static_gain = 0.0;         // output unit per input unit, k (model DC gain for vector fitting)
  double natural_frequency = 0.0;   // wn, rad/s
  double damping = 0.0;             // zeta (> 1: two real poles)
  CVector poles;                    // rad/s, 2
  double feedthrough = 0.0;         // output unit per input unit, d of the vector-fitting model (0 for nls)
  double relative_rms_error = 0.0;
  int iterations = 0;
  [[nodiscard]] double frequency_Hz() const;
};
// omega: rad/s.
SecondOrderFit fit_second_order(const Vector& omega, const CVector& h,
                                const SecondOrderFitOptions& options = {});

constexpr auto describe(core::Type<ModalFeature>) {
  using S = ModalFeature;
  using namespace core::shown;
  return core::fields<S>("ModalFeature", "a lightly damped pole pair (resonance) of the fitted model",
      core::field("root", &S::root, kRadPerSecond, "the member of the pair with Im > 0"),
      core::field("natural_frequency", &S::natural_frequency, kRadPerSecondAsHz, "|root|"),
      core::field("damping", &S::damping, kRatio, "|Re root| / |root| (positive also for a mirrored zero)"));
}

constexpr auto describe(core::Type<AntiResonance>) {
  using S = AntiResonance;
  using namespace core::shown;
  return core::extended_fields<S>("AntiResonance", "a lightly damped zero pair of the fitted model, with its two phase verdicts",
      core::kFields<ModalFeature>,
      core::field("nonminimum_phase_model", &S::nonminimum_phase_model, kNone, "the fitted zero has Re > 0"),
      core::field("phase_verdict", &S::phase_verdict, kNone, "from the data's phase across the zero"),
      core::field("phase_change_deg", &S::phase_change_deg, kDegree, "unwrapped phase change of the data across the zero"),
      core::field("phase_points", &S::phase_points, kNone, "data points in the band examined"));
}

constexpr auto describe(core::Type<FrfFeatures>) {
  using S = FrfFeatures;
  using namespace core::shown;
  return core::fields<S>("FrfFeatures", "static gain, resonances and anti-resonances of one response",
      core::field("static_gain", &S::static_gain, kNone, "output units / input units, signed (negative: phase 180 deg)"),
      core::field("static_gain_source", &S::static_gain_source, kNone, "the model's DC gain or the data's plateau"),
      core::field("plateau_frequency", &S::plateau_frequency, kRadPerSecondAsHz, "where the plateau was read (data-plateau only)"),
      core::field("resonances", &S::resonances, kNone, "by increasing frequency, inside the data band"),
      core::field("antiresonances", &S::antiresonances, kNone, "by increasing frequency"),
      core::field("fit", &S::fit, kNone, "the model the features come from"));
}

constexpr auto describe(core::Type<HighPassFit>) {
  using S = HighPassFit;
  using namespace core::shown;
  return core::fields<S>("HighPassFit", "first-order high-pass g s / (s + corner) fitted to the low-frequency points",
      core::field("corner", &S::corner, kRadPerSecondAsHz, "corner frequency"),
      core::field("gain", &S::gain, kNone, "high-frequency gain g, output unit per input unit, signed"),
      core::field("relative_rms_error", &S::relative_rms_error, kRatio, "rms |model - data| / rms |data| over the fitted points"));
}

constexpr auto describe(core::Type<SecondOrderFit>) {
  using S = SecondOrderFit;
  using namespace core::shown;
  return core::fields<S>("SecondOrderFit", "k wn^2 / (s^2 + 2 zeta wn s + wn^2) fitted to an FRF",
      core::field("static_gain", &S::static_gain, kNone, "k, output unit per input unit (model DC gain for vector fitting)"),
      core::field("natural_frequency", &S::natural_frequency, kRadPerSecondAsHz, "wn"),
      core::field("damping", &S::damping, kRatio, "zeta (> 1: two real poles)"),
      core::field("poles", &S::poles, kRadPerSecond, "the two poles"),
      core::field("feedthrough", &S::feedthrough, kNone, "d of the vector-fitting model, output unit per input unit (0 for nls)"),
      core::field("relative_rms_error", &S::relative_rms_error, kRatio, "rms |model - data| / rms |data|"),
      core::field("iterations", &S::iterations, kNone, "Levenberg-Marquardt steps"));
}

}  // namespace piezobench::ident
