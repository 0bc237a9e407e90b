#include "piezobench/ident/low_frequency_high_pass.hpp"

#include "piezobench/core/units.hpp"
#include "piezobench/ident/features.hpp"

namespace piezobench::ident {

LowFrequencyHighPass fit_low_frequency_high_pass(const dsp::Frf& frf, const LowFrequencyHighPassOptions& options) {
  frf.validate(options.source);
  const Eigen::Index output = frf.output_index(options.output);
  LowFrequencyHighPass out;
  for (Eigen::Index k = 0; k < frf.freq_Hz.size(); ++k) {
    if (frf.freq_Hz(k) > 0.0) {
      out.lowest_line_Hz = frf.freq_Hz(k);
      break;
    }
  }
  out.observable_above_Hz = out.lowest_line_Hz / kHighPassObservableDivisor;
  out.fmax_Hz = options.fmax_Hz;
  const dsp::Frf low =
      dsp::select_band(frf, dsp::BandSelection{0.0, options.fmax_Hz, /*exclude_dc=*/true, options.min_coherence, {output}});
  if (low.freq_Hz.size() < 3) return out;
  const HighPassFit h = fit_high_pass(kTwoPi * low.freq_Hz, low.H[0]);
  out.points = static_cast<long>(low.freq_Hz.size());
  out.corner_Hz = h.corner_Hz();
  out.gain = h.gain;
  out.relative_rms_error = h.relative_rms_error;
  out.observable = h.corner_Hz() >= out.observable_above_Hz;
  return out;
}

}  // namespace piezobench::ident
