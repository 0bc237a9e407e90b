#pragma once
// A measured (or computed) frequency response: one input, one or more named outputs, on a common
// frequency grid, with the coherence where it is known and how it was obtained.
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "piezobench/core/fields.hpp"
#include "piezobench/lti/freqresp.hpp"

namespace piezobench::dsp {

// How an FRF was estimated (empty / zero where it does not apply, e.g. an FRF read from a file
// that does not say).
struct FrfProvenance {
  std::string source;        // file the time series came from
  std::string estimator;     // "H1" or "H2"
  std::string window;        // e.g. "hann-periodic"
  Eigen::Index nfft = 0;     // segment length, samples
  double overlap = 0.0;      // fraction of nfft
  std::string detrend;       // "none", "mean", "linear"
  Eigen::Index averages = 0; // number of segments averaged
  double sample_rate = 0.0;  // Hz
  double effective_averages = 0.0;  // Welch's independent averages n_d (dsp/frf_variance.hpp); 0 = unknown
};

struct Frf {
  Eigen::VectorXd freq_Hz;                 // Hz, >= 0, strictly increasing
  std::string input;                       // input channel name
  std::vector<std::string> outputs;        // output channel names
  std::vector<Eigen::VectorXcd> H;         // H[i](k): output i / input at freq_Hz(k)
  std::vector<Eigen::VectorXd> coherence;  // same layout as H, in [0, 1]; empty (no vector at all) = unknown
  // Standard deviation of the random error of H, same layout, in H's units: each of the error's real
  // and imaginary parts (a circular complex Gaussian, dsp/frf_variance.hpp), i.e. std |H| and, divided
  // by |H|, std of the phase in rad. Empty (no vector at all) = unknown; 0 for a computed response.
  std::vector<Eigen::VectorXd> std_H;
  FrfProvenance provenance;

  // Index of the named output; throws InputError (field "output", expected one of the names).
  [[nodiscard]] Eigen::Index output_index(const std::string& name) const;
  // Throws InputError for inconsistent sizes, non-finite values, a non-increasing grid, a negative
  // frequency, a coherence outside [0, 1] (1e-9 of round-off admitted) or a std_H that is negative or
  // not finite.
  void validate(const std::string& source = "") const;
};

// The two FRF layouts and their converters. dsp::Frf is what is measured, read and written: Hz, one
// input, named outputs, one vector per output (H[i](k)), coherence and provenance.
// lti::FrequencyResponse is what a model gives: rad/s, one outputs x inputs matrix per frequency
// (H[k](i, j)), no names. Only these two convert into each other: omega = 2 pi freq_Hz.
//
// The FRF as a single-input lti::FrequencyResponse: omega = 2 pi freq_Hz (rad/s), H[k] is
// outputs x 1 at omega[k]. Names, coherence and provenance are dropped. Validates the FRF first.
[[nodiscard]] lti::FrequencyResponse to_frequency_response(const Frf& frf);
// Input `input` of a model's response as a dsp::Frf: freq_Hz = omega / (2 pi), H[i](k) =
// response.H[k](i, input), named `input_name` and `output_names` (one per output), no coherence.
// InputError (source "frequency response") for names that do not match the outputs, an input out of
// range, inconsistent sizes or a grid Frf::validate refuses (negative, non-increasing, non-finite).
[[nodiscard]] Frf to_frf(const lti::FrequencyResponse& response, const std::string& input_name,
                         const std::vector<std::string>& output_names, Eigen::Index input = 0);

// The part of an FRF a fit or a summary uses: the lines with fmin_Hz <= f <= fmax_Hz, of the
// outputs listed, with their coherence and std_H (if known). A line is dropped where the coherence of a kept
// output is below min_coherence. The result has no line when none qualifies (the caller decides whether
// that is an error); InputError for an output index out of range.
struct BandSelection {
  double fmin_Hz = 0.0;               // Hz
  double fmax_Hz = 0.0;               // Hz; <= 0: no upper bound
  bool exclude_dc = false;            // drop the 0 Hz line even when fmin_Hz is 0
  double min_coherence = 0.0;         // in [0, 1]
  std::vector<Eigen::Index> outputs;  // indices into Frf::outputs; empty: all, in order
};
[[nodiscard]] Frf select_band(const Frf& frf, const BandSelection& selection);

// The band an FRF's input excited, read from the coherence: its lowest and highest frequency > 0
// where the coherence of the best output (the largest coherence of the outputs whose coherence is
// known), and its median over 9 neighbouring bins, are at least min_coherence. A dip inside (an
// anti-resonance) does not split it; isolated noisy bins outside do not widen it. Without any
// coherence the whole positive grid is returned (`from_coherence` false).
struct FrequencyBand {
  double fmin_Hz = 0.0;
  double fmax_Hz = 0.0;
  bool from_coherence = false;
};
// InputError (source: the FRF's) when no bin reaches min_coherence: "the input did not excite the
// outputs; check the channels".
FrequencyBand excited_band(const Frf& frf, double min_coherence = 0.5);

constexpr auto describe(core::Type<FrfProvenance>) {
  using S = FrfProvenance;
  using namespace core::shown;
  return core::fields<S>("FrfProvenance", "how an FRF was estimated",
      core::field("source", &S::source, kNone, "file the time series came from").part_only(),
      core::field("estimator", &S::estimator, kNone, "\"H1\" or \"H2\""),
      core::field("window", &S::window, kNone, "e.g. \"hann-periodic\""),
      core::field("nfft", &S::nfft, kNone, "segment length, samples"),
      core::field("overlap", &S::overlap, kRatio, "fraction of nfft"),
      core::field("detrend", &S::detrend, kNone, "\"none\", \"mean\", \"linear\""),
      core::field("averages", &S::averages, kNone, "segments averaged"),
      core::field("sample_rate", &S::sample_rate, kHertz, "of the time series").part_only(),
      core::field("effective_averages", &S::effective_averages, kRatio, "Welch's independent averages n_d (0: unknown)").part_only());
}

constexpr auto describe(core::Type<Frf>) {
  using S = Frf;
  using namespace core::shown;
  return core::fields<S>("Frf", "a measured frequency response: one input, named outputs",
      core::field("freq_Hz", &S::freq_Hz, kHertz, "strictly increasing"),
      core::field("input", &S::input, kNone, "input channel name"),
      core::field("outputs", &S::outputs, kNone, "output channel names"),
      core::field("H", &S::H, kNone, "H[i](k): output i / input at freq_Hz(k)"),
      core::field("coherence", &S::coherence, kRatio, "same layout as H (empty: unknown)"),
      core::field("std_H", &S::std_H, kNone, "standard deviation of H's random error, H's units"),
      core::field("provenance", &S::provenance, kNone, "how it was estimated"));
}

}  // namespace piezobench::dsp
