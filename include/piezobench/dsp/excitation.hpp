#pragma once
// Excitation signals for the bench: band-limited noise, multisines, sine sweeps, quasi-static
// offset sines and ramped steps, each kept inside a voltage range and reproducible from a seed.
//
// Every generator builds u(t) = c(t) + v(t): a reference level c (the offset, or the rest level)
// that must itself lie inside the bounds (else InputError), and a varying part v. When c + v leaves
// [min, max] the policy decides: kScale (default) multiplies v by the largest s <= 1 that keeps
// every sample inside and reports it (Excitation::scaled, ::scale); kClip clamps the samples and
// counts them; kReject throws InputError. Sample k is at t = k / sample_rate.
//
// Random signals use std::mt19937_64 (whose output sequence the C++ standard fixes) with our own
// Box-Muller transform and uniform mapping, so a seed gives the same signal with any standard
// library.
#include <Eigen/Dense>
#include <cstdint>
#include <string>
#include <vector>

#include "piezobench/core/fields.hpp"

namespace piezobench::dsp {

enum class BoundsPolicy { kScale, kClip, kReject };
std::string to_string(BoundsPolicy policy);                     // "scale", "clip", "reject"
BoundsPolicy bounds_policy_from_string(const std::string& name);  // InputError field "bounds policy"

// Voltage range of the signal, V. Default: the APA300ML stack range -20..150 V seen through a
// 20 V/V amplifier at the DAC, i.e. -1..7.5 V (DESIGN.md).
struct VoltageBounds {
  double min = -1.0;
  double max = 7.5;  // V
  BoundsPolicy policy = BoundsPolicy::kScale;
  void validate() const;  // InputError field "bounds": finite, min < max
};

struct Excitation {
  Eigen::VectorXd u;             // V
  double sample_rate = 0.0;      // Hz
  std::string kind;              // "noise", "multisine-schroeder", "sweep-log", ...
  bool scaled = false;           // v was scaled by `scale` < 1 to fit the bounds
  double scale = 1.0;
  Eigen::Index clipped = 0;      // samples clamped (BoundsPolicy::kClip)
  Eigen::VectorXd lines_Hz;      // multisine: the excited lines; noise: the first and last line
  std::uint64_t seed = 0;        // random signals: the seed used
};

// s, the time of each sample of e.u: k / sample_rate.
inline Eigen::VectorXd excitation_times(const Excitation& e) {
  const Eigen::Index n = e.u.size();
  return Eigen::VectorXd::LinSpaced(n, 0.0, static_cast<double>(n - 1)) / e.sample_rate;
}

constexpr auto describe(core::Type<Excitation>) {
  using S = Excitation;
  using namespace core::shown;
  return core::fields<S>("Excitation", "an excitation signal with how it was made and fitted to the voltage bounds",
      core::field("u", &S::u, kVolt, "the samples"),
      core::derived("t", &excitation_times, kSecond, "time of each sample, k / sample_rate"),
      core::field("sample_rate", &S::sample_rate, kHertz, "sample rate of u"),
      core::field("kind", &S::kind, kNone, "\"noise\", \"multisine-schroeder\", \"sweep-log\", ..."),
      core::field("scaled", &S::scaled, kNone, "u was scaled by `scale` < 1 to fit the bounds"),
      core::field("scale", &S::scale, kRatio, "that factor (1: not scaled)"),
      core::field("clipped", &S::clipped, kNone, "samples clamped to the bounds (clip policy)"),
      core::field("lines_Hz", &S::lines_Hz, kHertz, "multisine: the excited lines; noise: the first and last line"),
      core::field("seed", &S::seed, kNone, "random signals: the seed used"));
}

// Gaussian noise made in the frequency domain: the DFT lines inside [f_low, f_high] (DC excluded:
// it is the offset; the Nyquist line allowed) are drawn as a white Gaussian sequence's DFT has
// them (independent real and imaginary parts of equal variance; a real Nyquist line of twice
// that), every other line is zero, and one inverse FFT gives the signal: Gaussian, periodic with
// period `samples`, its power exactly on the band's lines. The varying part has standard deviation
// (rms) exactly `rms` before any scaling.
struct NoiseOptions {
  double sample_rate = 10e3;   // Hz, > 0
  Eigen::Index samples = 0;    // >= 2
  double f_low = 0.0;          // Hz, >= 0
  double f_high = 0.0;         // Hz, f_low < f_high <= sample_rate / 2, at least one line inside
  double rms = 0.1;            // V, > 0
  double offset = 0.0;         // V
  std::uint64_t seed = 1;
  void validate() const;
};
Excitation band_limited_noise(const NoiseOptions& options, const VoltageBounds& bounds = {});

// Sum of cosines A_k cos(2 pi f_k t + phi_k) on lines f_k that are multiples of sample_rate /
// period_samples (a periodic signal with no leakage when analysed over whole periods), repeated
// `periods` times. Schroeder phases (M. R. Schroeder, "Synthesis of low-peak-factor signals and
// binary sequences with low autocorrelation", IEEE Trans. Inf. Theory 16(1), 1970):
// phi_k = -2 pi sum_{l<k} (k - l) p_l with p_l = A_l^2 / sum A^2 (for equal amplitudes
// -pi k (k-1) / F). Random phases: uniform in [0, 2 pi) from the seed.
enum class MultisinePhases { kSchroeder, kRandom };
std::string to_string(MultisinePhases phases);                        // "schroeder", "random"
MultisinePhases multisine_phases_from_string(const std::string& name);  // InputError field "phases"

struct MultisineOptions {
  double sample_rate = 10e3;         // Hz, > 0
  Eigen::Index period_samples = 0;   // N >= 2
  Eigen::Index periods = 1;          // >= 1
  std::vector<double> lines_Hz;      // each k * sample_rate / N with 1 <= k < N/2 (1e-9 relative), distinct
  std::vector<double> amplitudes;    // relative amplitudes (>= 0, one per line); empty = all equal
  double rms = 0.1;                  // V, rms of the varying part before any scaling
  double offset = 0.0;               // V
  MultisinePhases phases = MultisinePhases::kSchroeder;
  std::uint64_t seed = 1;            // used for kRandom
  void validate() const;
};
Excitation multisine(const MultisineOptions& options, const VoltageBounds& bounds = {});
// Phases of the lines, radians, as used by multisine().
Eigen::VectorXd multisine_phases(const MultisineOptions& options);

// offset + A e(t) sin(phi(t)) from f_start to f_end over `duration`:
//   linear       phi = 2 pi (f0 t + (f1 - f0) t^2 / (2 T))
//   logarithmic  phi = 2 pi f0 T / ln(f1/f0) (exp(t ln(f1/f0) / T) - 1)    (f0, f1 > 0)
// e(t) is a raised-cosine taper over ramp_time at each end (1 elsewhere; none when 0).
enum class SweepType { kLinear, kLogarithmic };
std::string to_string(SweepType type);                      // "linear", "log"
SweepType sweep_type_from_string(const std::string& name);  // InputError field "sweep"

struct SweepOptions {
  double sample_rate = 10e3;  // Hz, > 0
  double duration = 10.0;     // s, > 0 and at least 2 samples
  double f_start = 1.0;       // Hz, in (0, sample_rate / 2]  (>= 0 for linear)
  double f_end = 1e3;         // Hz, in (0, sample_rate / 2]
  double amplitude = 0.1;     // V, >= 0
  double offset = 0.0;        // V
  double ramp_time = 0.0;     // s, >= 0, 2 ramp_time <= duration
  SweepType type = SweepType::kLogarithmic;
  void validate() const;
};
Excitation sine_sweep(const SweepOptions& options, const VoltageBounds& bounds = {});
// Instantaneous frequency of the sweep at time t, Hz.
double sweep_frequency(const SweepOptions& options, double t);

// Quasi-static offset sine for hysteresis and stroke tests:
//   u(t) = rest + e(t) (offset - rest + amplitude sin(2 pi f (t - ramp_time)))
// where e rises from 0 to 1 over ramp_time (raised cosine), stays 1 for `cycles` periods and falls
// back to 0 over ramp_time: it starts and ends at `rest` with zero slope, and the slope is
// continuous everywhere. Duration 2 ramp_time + cycles / f.
struct OffsetSineOptions {
  double sample_rate = 10e3;  // Hz, > 0
  double rest = 0.0;          // V, level before and after
  double offset = 0.0;        // V
  double amplitude = 1.0;     // V, >= 0
  double frequency = 1.0;     // Hz, in (0, sample_rate / 2)
  double cycles = 1.0;        // > 0
  double ramp_time = 1.0;     // s, >= 0
  void validate() const;
};
Excitation offset_sine(const OffsetSineOptions& options, const VoltageBounds& bounds = {});

// Staircase: rest for hold_time, then for each level a linear ramp of ramp_time and a hold of
// hold_time, then a ramp back to rest and a final hold. Scaled about `rest` when out of bounds.
struct StepOptions {
  double sample_rate = 10e3;   // Hz, > 0
  double rest = 0.0;           // V
  std::vector<double> levels;  // V, at least one
  double hold_time = 1.0;      // s, > 0
  double ramp_time = 0.1;      // s, >= 0 (0: a jump within one sample)
  void validate() const;
};
Excitation steps(const StepOptions& options, const VoltageBounds& bounds = {});

}  // namespace piezobench::dsp
