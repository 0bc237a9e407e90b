#include "piezobench/ident/flexible_modes.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "piezobench/core/error.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::ident {

FlexibleModeAnalysis identify_flexible_modes(const dsp::Frf& frf, const FlexibleModeOptions& o) {
  frf.validate(o.source);
  if (!(o.fmin_Hz >= 0.0 && o.fmax_Hz > o.fmin_Hz && std::isfinite(o.fmax_Hz))) {
    throw InputError(o.source, "band", "a band 0 <= fmin_Hz < fmax_Hz", fmt::format("[{}, {}] Hz", o.fmin_Hz, o.fmax_Hz));
  }
  const dsp::Frf part =
      dsp::select_band(frf, dsp::BandSelection{o.fmin_Hz, o.fmax_Hz, /*exclude_dc=*/true, 0.0, {frf.output_index(o.output)}});
  const Vector omega = kTwoPi * part.freq_Hz;  // rad/s, as the fitters take it
  const CVector& h = part.H[0];
  FlexibleModeAnalysis out;
  out.lines = static_cast<long>(omega.size());
  try {
    PeakPickingOptions po;
    po.max_modes = o.max_peaks;
    out.peak_picking = peak_picking(omega, h, po);
  } catch (const NumericalError& e) {
    out.failed.push_back(std::string("peak picking: ") + e.what());
  }
  try {
    LscfOptions lo;
    lo.max_order = std::min<Index>(o.max_lscf_order, omega.size() - 1);
    out.lscf = lscf(omega, h, lo).modes;
  } catch (const NumericalError& e) {
    out.failed.push_back(std::string("LSCF: ") + e.what());
  }
  return out;
}

}  // namespace piezobench::ident
