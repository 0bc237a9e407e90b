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
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "piezobench/bench/twin.hpp"
#include "piezobench/campaign/campaign_file.hpp"
#include "piezobench/campaign/unit_analysis.hpp"
#include "piezobench/control/iff.hpp"
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

struct TwinHysteresisCheck {
  double amplitude = 0.0;     // V
  double unit_width = 0.0;    // relative width (metrology::HysteresisResult::relative_width)
  double twin_width = 0.0;    // relative width
};

struct TwinFrfError {
  long points = 0;            // frequencies compared
  double max_dB = 0.0;        // largest |20 log10 |H_twin / H_unit||
  double median_dB = 0.0;
};

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
