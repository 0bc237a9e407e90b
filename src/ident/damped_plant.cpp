#include "piezobench/ident/damped_plant.hpp"

#include <fmt/format.h>

#include <cmath>
#include <complex>

#include "piezobench/core/error.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/dsp/resolution_kernel.hpp"

namespace piezobench::ident {

DampedPlantAnalysis analyze_damped_plant(const dsp::Frf& frf, const DampedPlantOptions& o) {
  const std::string source = o.field.empty() ? o.source : o.source + ": " + o.field;
  frf.validate(source);
  if (!(o.fmin_Hz >= 0.0 && o.fmax_Hz > o.fmin_Hz && std::isfinite(o.fmax_Hz))) {
    throw InputError(o.source, o.field, "a damped-plant band 0 <= fmin_Hz < fmax_Hz", fmt::format("[{}, {}] Hz", o.fmin_Hz, o.fmax_Hz));
  }
  if (!(o.delay_s >= 0.0 && std::isfinite(o.delay_s))) {
    throw InputError(o.source, o.field, "a delay to remove >= 0 s", fmt::format("{} s", o.delay_s));
  }
  const dsp::Frf part =
      dsp::select_band(frf, dsp::BandSelection{o.fmin_Hz, o.fmax_Hz, /*exclude_dc=*/true, 0.0, {frf.output_index(o.output)}});
  const Eigen::VectorXd omega = kTwoPi * part.freq_Hz;  // rad/s, as the fitters take it
  Eigen::VectorXcd h = part.H[0];
  for (Eigen::Index k = 0; k < omega.size(); ++k) h(k) *= std::exp(std::complex<double>(0.0, omega(k) * o.delay_s));
  // The coherence when the file has one (none: the fit estimates the noise from its residuals).
  const Eigen::VectorXd coherence = part.coherence.empty() ? Eigen::VectorXd() : part.coherence[0];
  DampedPlantAnalysis out;
  out.delay_removed_s = o.delay_s;
  out.fmin_Hz = o.fmin_Hz;
  out.fmax_Hz = o.fmax_Hz;
  out.lines = static_cast<long>(omega.size());
  try {
    DominantPoleOptions po;
    po.fit.order = o.fit_order;
    po.omega_min = kTwoPi * o.fmin_Hz;
    po.omega_max = kTwoPi * o.fmax_Hz;
    out.dominant_fit_order = static_cast<long>(po.fit.order);
    out.dominant = dominant_pole(omega, h, po);
  } catch (const NumericalError& e) {
    out.failed.push_back(std::string("dominant pole: ") + e.what());
  }
  try {
    IffPlantFitOptions so;
    so.fit_delay = false;
    // As the campaign's other plant fits: points weighted by the FRF's variance (coherence and n_d),
    // the model seen through the Welch estimate's resolution kernel when the provenance gives it.
    so.effective_averages = part.coherence.empty() ? 0.0 : frf.provenance.effective_averages;
    so.resolution = dsp::resolution_kernel(frf.provenance);
    out.second_order = fit_delayed_second_order(omega, h, coherence, so, source);
  } catch (const NumericalError& e) {
    out.second_order_error = e.what();
  }
  return out;
}

}  // namespace piezobench::ident
