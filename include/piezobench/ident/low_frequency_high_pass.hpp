#pragma once
// The resistor high-pass of a measured u -> Vs at low frequency (report section 2.5, Figure 2.7):
// a first-order high-pass g s / (s + w_c) fitted (fit_high_pass, features.hpp) to the FRF's lines
// in (0, fmax_Hz] whose coherence is at least min_coherence.
//
// Observability: a corner below a third of the FRF's lowest line changes |H| there by less than
// 5 %, so the record cannot show it; such a fitted corner is an upper bound, not a number
// (`observable` false). The same rule decides whether ident::analyze_actuator_frf reports a
// fitted corner.
#include <optional>
#include <string>

#include "piezobench/core/fields.hpp"
#include "piezobench/dsp/frf.hpp"

namespace piezobench::ident {

// A fitted corner below the FRF's lowest line divided by this is not observable.
inline constexpr double kHighPassObservableDivisor = 3.0;

struct LowFrequencyHighPassOptions {
  std::string output = "Vs";   // the FRF's output fitted
  double fmax_Hz = 5.0;        // Hz, lines in (0, fmax_Hz] are fitted
  double min_coherence = 0.0;  // of the lines fitted (0: all)
  std::string source;          // errors: InputError(source, ...)
};

struct LowFrequencyHighPass {
  double lowest_line_Hz = 0.0;        // Hz, the FRF's lowest line above 0 Hz (0: none)
  double observable_above_Hz = 0.0;   // Hz, lowest_line_Hz / kHighPassObservableDivisor
  double fmax_Hz = 0.0;               // Hz, the band (0, fmax_Hz] fitted
  long points = 0;                    // lines fitted (0: fewer than 3 in the band, no fit)
  std::optional<double> corner_Hz;    // Hz, the fitted corner w_c / 2 pi (nullopt: no fit)
  double gain = 0.0;                  // V/V for u -> Vs (the output's unit per the input's): g, the high-frequency gain, signed
  double relative_rms_error = 0.0;    // rms |model - data| / rms |data| over the lines fitted
  bool observable = false;            // corner_Hz >= observable_above_Hz
};

constexpr auto describe(core::Type<LowFrequencyHighPass>) {
  using S = LowFrequencyHighPass;
  using namespace core::shown;
  return core::fields<S>("LowFrequencyHighPass", "a first-order high-pass fitted to an FRF at low frequency (report 2.5)",
      core::field("lowest_line_Hz", &S::lowest_line_Hz, kHertz, "the FRF's lowest line above 0 Hz"),
      core::field("observable_above_Hz", &S::observable_above_Hz, kHertz, "a third of it"),
      core::field("fmax_Hz", &S::fmax_Hz, kHertz, "the band (0, fmax_Hz] fitted"),
      core::field("points", &S::points, kNone, "lines fitted"),
      core::field("corner_Hz", &S::corner_Hz, kHertz, "the fitted corner"),
      core::field("gain", &S::gain, kNone, "high-frequency gain, output unit per input unit"),
      core::field("relative_rms_error", &S::relative_rms_error, kRatio, "of the fit"),
      core::field("observable", &S::observable, kNone, "corner_Hz >= observable_above_Hz"));
}

// `frf` as measured (Hz). InputError: the output is not in the FRF, or the FRF is invalid
// (Frf::validate); fewer than 3 lines in the band is no fit (corner_Hz nullopt), not an error.
LowFrequencyHighPass fit_low_frequency_high_pass(const dsp::Frf& frf, const LowFrequencyHighPassOptions& options);

}  // namespace piezobench::ident
