#pragma once
// The flexible modes of a hammer test's FRF F -> v (report section 1.4 / 2.7), from the FRF as
// measured: over [fmin_Hz, fmax_Hz] (the 0 Hz line left out), the most prominent peaks by peak
// picking and the stable modes by LSCF (modal.hpp), side by side.
#include <string>
#include <vector>

#include "piezobench/dsp/frf.hpp"
#include "piezobench/ident/modal.hpp"

namespace piezobench::ident {

struct FlexibleModeOptions {
  std::string output = "v";   // the FRF's output
  double fmin_Hz = 0.0;       // Hz, the band searched
  double fmax_Hz = 0.0;       // Hz, > fmin_Hz
  long max_peaks = 6;         // peak picking keeps the most prominent ones
  long max_lscf_order = 24;   // LSCF orders swept up to this (at most the band's lines - 1)
  std::string source;         // errors: InputError(source, ...)
};

struct FlexibleModeAnalysis {
  std::vector<Mode> peak_picking;  // by increasing frequency (natural_frequency rad/s)
  std::vector<Mode> lscf;          // by increasing frequency, stable over LscfOptions::min_stable_orders
  long lines = 0;                  // lines in the band
  // "peak picking: ...", "LSCF: ...": a method that failed on valid data (NumericalError).
  std::vector<std::string> failed;
};

// `frf` as measured (Hz). InputError: the output is not in the FRF, an invalid FRF, a band that is
// not 0 <= fmin_Hz < fmax_Hz. A method that fails numerically is listed in `failed`.
FlexibleModeAnalysis identify_flexible_modes(const dsp::Frf& frf, const FlexibleModeOptions& options);

}  // namespace piezobench::ident
