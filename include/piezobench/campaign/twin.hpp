#pragma once
// The digital twin of one unit (docs/twin.md): a virtual bench (bench/twin.hpp) whose parameters
// are identified on that unit's records, so that a controller or a feedforward can be designed on
// the twin before it runs on the unit.
//
// build_twin runs the campaign's analyses of the unit (analyze_unit) and then:
//   model    the tuned 2-DoF model (apa::tune_two_dof_measured) refined, with the delay and the
//            ground resistance of the non-minimum-phase zero, on the twin bench's own linear model
//            (amplifier bandwidth, sensor-stack coupling, high-pass, anti-aliasing filter: what the
//            twin will simulate) against the measured FRFs u -> d_e and u -> Vs, on the points of
//            [fmin_Hz, fmax_Hz] whose coherence is at least min_coherence (Levenberg-Marquardt on
//            the relative complex error);
//   chain    amplifier gain and suspended mass from the campaign's [bench]; the high-pass from the
//            unit's corner (R = 1 / (2 pi f_c C_sensor)); the capacitances measured;
//   hysteresis  the play operators of the bench's Prandtl-Ishlinskii law (8, thresholds i A / 8
//            for the largest amplitude A) fitted on the largest-amplitude hysteresis record
//            (ident::fit_hysteresis, with creep states of 5, 50 and 500 s);
//   creep    the voltage and load creep coefficients that make the twin's own records give the
//            creep the unit's records give (the creep of the hysteresis fit; the creep per decade
//            of the stiffness record's ident::fit_creep): the figure is linear in the coefficient,
//            so two simulations of the twin settle each;
//   noise    per channel, the white noise that gives the PSD measured on the unit's quiet segments
//            (a record where u, Va and the added mass are held: TwinOptions::quiet, the stiffness
//            record before the mass goes on), the quantization's share taken off.
// It then checks the twin against the unit: FRF errors, the hysteresis width at each amplitude
// measured (the twin's hysteresis experiment at that amplitude), the IFF optimum of the report's
// controller on the twin against the one on the unit's fitted IFF plant (eq. 2.3).
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "piezobench/bench/twin.hpp"
#include "piezobench/campaign/campaign_file.hpp"
#include "piezobench/campaign/unit_analysis.hpp"
#include "piezobench/control/iff.hpp"
#include "piezobench/core/fields.hpp"
#include "piezobench/core/fit_quality.hpp"
#include "piezobench/dsp/frf.hpp"

namespace piezobench::campaign {

struct TwinOptions {
  std::vector<std::filesystem::path> quiet;  // records with quiet segments (channels de and/or Vs)
  double min_coherence = 0.9;                // FRF points the model is refined on and judged by
  double fmin_Hz = 20.0, fmax_Hz = 500.0;    // their band
  double min_quiet_s = 1.0;                  // shortest quiet segment used, s
  // Verdict limits (the issue's): FRF within max_frf_error_dB, widths within max_width_error
  // (relative, for loops wider than 1 % of their stroke), IFF optimum within max_iff_error.
  double max_frf_error_dB = 1.0;
  double max_width_error = 0.10;  // relative
  double max_iff_error = 0.05;    // relative
  void validate() const;  // InputError (source "twin options") naming the field
};

struct TwinNoise {
  std::string channel;        // "de" or "Vs"
  bool measured = false;      // false: no quiet segment; the bench's default noise is kept
  std::string source;         // file and segment, e.g. "quiet.mat [0, 10] s"
  double seconds = 0.0;       // length of the segment
  double measured_rms = 0.0;  // m for d_e, V for Vs, of the segment (quantization included), from its median PSD level
  double white_rms = 0.0;     // the twin's noise option
  bench::NoiseSpectrum spectrum;  // measured, log-spaced
};

// A noise figure in its channel's SI unit, m for d_e and V for Vs, shown as is (no key suffix).
inline constexpr core::Shown kChannelSi{"m or V", "", 1.0};

constexpr auto describe(core::Type<TwinNoise>) {
  using S = TwinNoise;
  using namespace core::shown;
  return core::fields<S>("TwinNoise", "the white noise of one channel of a twin, from the unit's quiet segments",
      core::field("channel", &S::channel, kNone, "\"de\" or \"Vs\""),
      core::field("measured", &S::measured, kNone, "false: no quiet segment, the bench's default noise is kept"),
      core::field("source", &S::source, kNone, "file and segment, e.g. \"quiet.mat [0, 10] s\""),
      core::field("seconds", &S::seconds, kSecond, "length of the segment").key("seconds"),
      core::field("measured_rms", &S::measured_rms, kChannelSi, "rms of the segment (quantization included), from its median PSD level"),
      core::field("white_rms", &S::white_rms, kChannelSi, "the twin's white noise: the measured rms with the quantization's share taken off"),
      core::field("spectrum", &S::spectrum, kNone, "the segment's PSD, log-spaced (written in the twin file)").part_only());
}

struct TwinHysteresisCheck {
  double amplitude = 0.0;     // V
  double unit_width = 0.0;    // relative width (metrology::HysteresisResult::relative_width)
  double twin_width = 0.0;    // relative width
};

constexpr auto describe(core::Type<TwinHysteresisCheck>) {
  using S = TwinHysteresisCheck;
  using namespace core::shown;
  return core::fields<S>("TwinHysteresisCheck", "the hysteresis width of the twin against the unit's at one amplitude",
      core::field("amplitude", &S::amplitude, kVolt, "of the unit's hysteresis record"),
      core::field("unit_width", &S::unit_width, kRatio, "the unit's loop width / stroke"),
      core::field("twin_width", &S::twin_width, kRatio, "the twin's at the same amplitude"));
}

struct TwinFrfError {
  long points = 0;            // frequencies compared
  double max_dB = 0.0;        // largest |20 log10 |H_twin / H_unit||
  double median_dB = 0.0;
};

constexpr auto describe(core::Type<TwinFrfError>) {
  using S = TwinFrfError;
  using namespace core::shown;
  return core::fields<S>("TwinFrfError", "the twin's FRF against the unit's measured one, on the coherent points of the band",
      core::field("points", &S::points, kNone, "frequencies compared"),
      core::field("max_dB", &S::max_dB, kDecibel, "largest |20 log10 |H_twin / H_unit||"),
      core::field("median_dB", &S::median_dB, kDecibel, "median of the same"));
}

struct TwinBuild {
  bench::Twin twin;
  TwinFrfError de, vs;                  // after the refinement
  TwinFrfError de_tuned, vs_tuned;      // of the campaign's tuned model on the same bench (before)
  std::vector<TwinHysteresisCheck> hysteresis;
  TwinNoise de_noise, vs_noise;
  std::optional<double> unit_creep_per_decade, twin_creep_per_decade;  // stiffness record's ident::fit_creep
  double iff_optimal_gain = 0.0;                                       // V/V (IFF gain g), on the twin
  double iff_max_damping = 0.0;
  std::optional<double> iff_optimal_gain_unit;  // on the unit's fitted IFF plant (eq. 2.3), as `run`
  core::FitQuality quality;             // poor when a check above fails its limit
  std::vector<std::string> notes;       // what was not measured, what was assumed
  double seconds = 0.0;                 // wall time of the build
};

// What TwinBuild's documents show of its twin (the twin file's content, bench::Twin, is not declared:
// its model and the rest of its chain are written by `piezobench twin --json` itself), and its two
// noise results as one list (de, then Vs).
inline int twin_unit_id_of(const TwinBuild& b) { return b.twin.unit.id; }
inline const std::string* twin_name_of(const TwinBuild& b) { return &b.twin.name; }
inline double twin_delay_of(const TwinBuild& b) { return b.twin.options.delay; }                        // s
inline double twin_hpf_resistance_of(const TwinBuild& b) { return b.twin.options.hpf_resistance; }      // Ohm
inline double twin_ground_resistance_of(const TwinBuild& b) { return b.twin.options.ground_resistance; }  // Ohm
inline const std::vector<double>* twin_thresholds_of(const TwinBuild& b) { return &b.twin.unit.hysteresis_thresholds; }  // V
inline const std::vector<double>* twin_weights_of(const TwinBuild& b) { return &b.twin.unit.hysteresis_weights; }        // V/V
inline double twin_voltage_creep_of(const TwinBuild& b) { return b.twin.unit.creep_coefficient; }
inline double twin_load_creep_of(const TwinBuild& b) { return b.twin.unit.load_creep_coefficient; }
inline std::array<const TwinNoise*, 2> twin_noise_of(const TwinBuild& b) { return {&b.de_noise, &b.vs_noise}; }

constexpr auto describe(core::Type<TwinBuild>) {
  using S = TwinBuild;
  using namespace core::shown;
  return core::fields<S>("TwinBuild", "the digital twin of one unit and its checks against the unit's records (docs/twin.md)",
      core::derived("unit", &twin_unit_id_of, kNone, "the unit's id"),
      core::derived("name", &twin_name_of, kNone, "the unit's name"),
      core::derived("delay", &twin_delay_of, kSecond, "the twin's delay, refined on the FRFs").key("chain.delay_s"),
      core::derived("hpf_resistance", &twin_hpf_resistance_of, kOhm, "resistor of the twin's high-pass: the unit's corner").key("chain.hpf_resistance_ohm"),
      core::derived("ground_resistance", &twin_ground_resistance_of, kOhm, "ground-return resistance of the non-minimum-phase zero").key("chain.ground_resistance_ohm"),
      core::derived("hysteresis_thresholds", &twin_thresholds_of, kVolt, "thresholds of the play operators").key("hysteresis_thresholds_V"),
      core::derived("hysteresis_weights", &twin_weights_of, kVoltPerVolt, "weights of the play operators").key("hysteresis_weights"),
      core::derived("voltage_creep", &twin_voltage_creep_of, kRatio, "the twin's voltage creep per decade of time").key("creep.voltage_per_decade"),
      core::derived("load_creep", &twin_load_creep_of, kRatio, "the twin's load creep per decade of time").key("creep.load_per_decade"),
      core::field("de", &S::de, kNone, "u -> d_e, the refined twin").key("frf_error.de"),
      core::field("vs", &S::vs, kNone, "u -> Vs, the refined twin").key("frf_error.Vs"),
      core::field("de_tuned", &S::de_tuned, kNone, "u -> d_e, the campaign's tuned model on the same bench").key("frf_error_tuned.de"),
      core::field("vs_tuned", &S::vs_tuned, kNone, "u -> Vs, the campaign's tuned model on the same bench").key("frf_error_tuned.Vs"),
      core::field("hysteresis", &S::hysteresis, kNone, "the width at each amplitude measured"),
      core::field("de_noise", &S::de_noise, kNone, "noise of d_e (results.json: noise[0])").part_only(),
      core::field("vs_noise", &S::vs_noise, kNone, "noise of Vs (results.json: noise[1])").part_only(),
      core::derived("noise", &twin_noise_of, kNone, "de_noise, then vs_noise"),
      core::field("unit_creep_per_decade", &S::unit_creep_per_decade, kRatio, "the unit's stiffness record's creep per decade (ident::fit_creep)").key("creep.unit_creep_per_decade"),
      core::field("twin_creep_per_decade", &S::twin_creep_per_decade, kRatio, "the same of the twin's own stiffness record").key("creep.twin_creep_per_decade"),
      core::field("iff_optimal_gain", &S::iff_optimal_gain, kVoltPerVolt, "IFF gain g of maximum damping on the twin").key("iff.optimal_gain"),
      core::field("iff_max_damping", &S::iff_max_damping, kRatio, "the damping there").key("iff.max_damping"),
      core::field("iff_optimal_gain_unit", &S::iff_optimal_gain_unit, kVoltPerVolt, "the same on the unit's fitted IFF plant (eq. 2.3)").key("iff.optimal_gain_unit_plant"),
      core::field("quality", &S::quality, kNone, "poor when a check fails its limit").key("."),
      core::field("notes", &S::notes, kNone, "what was not measured, what was assumed"),
      core::field("seconds", &S::seconds, kSecond, "wall time of the build").key("seconds"));
}

// InputError when the unit has no FRF record or its tuning failed (the twin needs the model).
TwinBuild build_twin(const Campaign& campaign, const UnitSpec& unit, const TwinOptions& options = {}, const Log& log = {});

// The FRF u -> [de, Vs] of a virtual bench's linear model (outputs named "de" and "Vs").
dsp::Frf bench_frf(const bench::UnitTruth& unit, const bench::BenchOptions& options, const Eigen::VectorXd& freq_Hz);

// The gain of maximum damping of the report's IFF controller on a virtual bench (its linear
// u -> Vs, control::iff_root_locus): {gain, damping}.
std::pair<double, double> bench_iff_optimum(const bench::UnitTruth& unit, const bench::BenchOptions& options,
                                            const control::IffControllerParams& controller);

// The one-sided PSD of a quiet record (linear trend removed; Welch, Hann, 1 s segments at most a
// quarter of the record) and its median level over [2 Hz, 0.4 fs]: unit^2/Hz.
struct QuietSpectrum {
  Eigen::VectorXd freq_Hz, psd;  // psd: unit^2/Hz
  double median_level = 0.0;     // unit^2/Hz
};
// x: the record's unit; sample_rate: Hz.
QuietSpectrum quiet_spectrum(const Eigen::VectorXd& x, double sample_rate);

}  // namespace piezobench::campaign
