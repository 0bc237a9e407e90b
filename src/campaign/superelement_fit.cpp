#include "piezobench/campaign/superelement_fit.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/statistics.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::campaign {
namespace {

const char* const kSource = "superelement fit";
// gs is tuned on the band's frequencies farther than this from the model's anti-resonance.
constexpr double kZeroExclusion = 0.15;

using core::median;

// The model's u -> [d_e, e_s] per newton of actuator force at `hz`, by modal superposition on
// the model's modes (its damping is modal, so this is the dense solution to round-off without a
// complex LU per frequency: the fit evaluates ~1,000 frequencies per unit).
lti::FrequencyResponse response(const fem::StructuralModel& model, const fem::Modes& modes, const Eigen::VectorXd& hz) {
  return fem::frequency_response(model, modes, kTwoPi * hz);
}

}  // namespace

void SuperElementFitOptions::validate() const {
  if (!(moving_mass >= 0.0 && std::isfinite(moving_mass))) throw InputError(kSource, "moving_mass", "a mass >= 0 kg", fmt::format("{}", moving_mass));
  if (!(amplifier_gain != 0.0 && std::isfinite(amplifier_gain))) throw InputError(kSource, "amplifier_gain", "a nonzero gain", fmt::format("{}", amplifier_gain));
  if (!(modal_damping > 0.0 && modal_damping < 1.0)) throw InputError(kSource, "modal_damping", "a damping ratio in (0, 1)", fmt::format("{}", modal_damping));
  if (!(band_min_Hz > 0.0 && std::isfinite(band_min_Hz))) throw InputError(kSource, "band_min_Hz", "a frequency > 0 Hz", fmt::format("{}", band_min_Hz));
  if (!(band_fraction > 0.0 && band_fraction < 1.0)) throw InputError(kSource, "band_fraction", "a fraction in (0, 1)", fmt::format("{}", band_fraction));
  if (!(error_max_Hz > band_min_Hz && std::isfinite(error_max_Hz))) throw InputError(kSource, "error_max_Hz", "a frequency above band_min_Hz", fmt::format("{}", error_max_Hz));
}

fem::StructuralModel superelement_bench_model(const fem::SuperElement& se, const fem::SuperElementSetup& setup,
                                              const SuperElementFitOptions& options) {
  options.validate();
  const std::string& src = setup.source;
  if (setup.model.forces.empty()) throw InputError(src, "actuator", "the actuator force pair", "none");
  if (setup.model.outputs.size() < 2) throw InputError(src, "sensor", "two outputs: d_e and the sensor stack", "fewer");
  const fem::DisplacementOutput& out = setup.model.outputs[0];
  if (out.node_a >= 0 || fem::is_rotation(out.direction)) {
    throw InputError(src, "output", "the moving interface, NODE:x|y|z", out.to_string());
  }
  fem::ModelOptions o;
  o.fixed_nodes = setup.model.fixed_nodes;
  o.masses = setup.model.masses;
  o.masses.push_back({out.node_b, options.moving_mass, 0.0});
  o.guided.push_back({out.node_b, out.direction});
  o.forces = {setup.model.forces[0]};
  o.outputs = {setup.model.outputs[0], setup.model.outputs[1]};
  o.damping.kind = fem::DampingKind::kModal;
  o.damping.zeta = options.modal_damping;
  return fem::assemble(se, o);
}

SuperElementFit fit_superelement(const fem::SuperElement& se, const fem::SuperElementSetup& setup, const dsp::Frf& measured,
                                 const SuperElementFitOptions& options) {
  const fem::StructuralModel model = superelement_bench_model(se, setup, options);
  const fem::Modes modes = fem::modes(model);
  const Eigen::Index ide = measured.output_index("de");
  const Eigen::Index ivs = measured.output_index("Vs");
  const Eigen::VectorXd& f = measured.freq_Hz;
  SuperElementFit r;

  // The model's resonance and anti-resonance on a fine log grid.
  const Eigen::Index n = 800;
  const Eigen::VectorXd grid = Eigen::VectorXd::LinSpaced(n, std::log10(std::max(1.0, f(0))), std::log10(std::max(2.0, f(f.size() - 1))))
                                   .unaryExpr([](double x) { return std::pow(10.0, x); });
  const lti::FrequencyResponse hg = response(model, modes, grid);
  const Eigen::VectorXd grid_de = hg.channel(0, 0).cwiseAbs(), grid_s = hg.channel(1, 0).cwiseAbs();
  Eigen::Index peak = 0;
  for (Eigen::Index k = 1; k < n; ++k) {
    if (grid_de(k) > grid_de(peak)) peak = k;
  }
  r.resonance_Hz = grid(peak);
  Eigen::Index dip = -1;
  for (Eigen::Index k = 1; k + 1 < peak; ++k) {
    if (grid_s(k) < grid_s(k - 1) && grid_s(k) < grid_s(k + 1)) dip = k;
  }
  r.antiresonance_Hz = dip >= 0 ? grid(dip) : 0.0;

  // The measured resonance: the peak of |u -> d_e|.
  Eigen::Index mpeak = 0;
  for (Eigen::Index k = 1; k < f.size(); ++k) {
    if (std::abs(measured.H[static_cast<std::size_t>(ide)](k)) > std::abs(measured.H[static_cast<std::size_t>(ide)](mpeak))) mpeak = k;
  }
  r.band_lo_Hz = options.band_min_Hz;
  r.band_hi_Hz = options.band_fraction * std::min(r.resonance_Hz, f(mpeak));
  std::vector<Eigen::Index> band;
  for (Eigen::Index k = 0; k < f.size(); ++k) {
    if (f(k) >= r.band_lo_Hz && f(k) <= r.band_hi_Hz) band.push_back(k);
  }
  if (band.size() < 3) {
    throw InputError(measured.provenance.source, "frf",
                     fmt::format("frequencies in the tuning band {}-{} Hz", format_number(r.band_lo_Hz, 3),
                                 format_number(r.band_hi_Hz, 3)),
                     fmt::format("{} of them", band.size()));
  }
  Eigen::VectorXd fb(static_cast<Eigen::Index>(band.size()));
  for (std::size_t i = 0; i < band.size(); ++i) fb(static_cast<Eigen::Index>(i)) = f(band[i]);
  const lti::FrequencyResponse hb = response(model, modes, fb);
  std::vector<double> ga_ratio, gs_ratio, de_phase, vs_phase;
  for (std::size_t i = 0; i < band.size(); ++i) {
    const std::complex<double> m_de = measured.H[static_cast<std::size_t>(ide)](band[i]);
    const std::complex<double> h_de = options.amplifier_gain * hb.H[i](0, 0);
    ga_ratio.push_back(std::abs(m_de) / std::abs(h_de));
    de_phase.push_back(std::cos(std::arg(m_de / h_de)));
  }
  // gs away from the anti-resonance, where the ratio measures where the two zeros sit rather than
  // gs; every point of the band when fewer than 3 are left.
  for (const bool exclude : {true, false}) {
    for (std::size_t i = 0; i < band.size(); ++i) {
      if (exclude && r.antiresonance_Hz > 0.0 && std::abs(fb(static_cast<Eigen::Index>(i)) / r.antiresonance_Hz - 1.0) < kZeroExclusion) continue;
      const std::complex<double> m_vs = measured.H[static_cast<std::size_t>(ivs)](band[i]);
      const std::complex<double> h_s = options.amplifier_gain * hb.H[i](1, 0);
      gs_ratio.push_back(std::abs(m_vs) / std::abs(h_s));  // divided by |ga| below
      vs_phase.push_back(std::cos(std::arg(m_vs / h_s)));
    }
    if (gs_ratio.size() >= 3) break;
    gs_ratio.clear();
    vs_phase.clear();
  }
  r.ga = median(ga_ratio) * (median(de_phase) < 0.0 ? -1.0 : 1.0);
  const double ga_sign = r.ga < 0.0 ? -1.0 : 1.0;
  r.gs = median(gs_ratio) / std::abs(r.ga) * (median(vs_phase) * ga_sign < 0.0 ? -1.0 : 1.0);
  if (!std::isfinite(r.ga) || !std::isfinite(r.gs) || r.ga == 0.0 || r.gs == 0.0) {
    throw NumericalError("super element sensitivities", "the model has no response to the actuator in the band", false);
  }

  // The tuned model at the measured frequencies, and its error up to error_max_Hz.
  // (On the measured grid itself: freq_Hz is f, not f converted to rad/s and back.)
  const lti::FrequencyResponse h = response(model, modes, f);
  r.model.freq_Hz = f;
  r.model.input = "u";
  r.model.outputs = {"de", "Vs"};
  r.model.H = {options.amplifier_gain * r.ga * h.channel(0, 0), options.amplifier_gain * r.ga * r.gs * h.channel(1, 0)};
  r.model.provenance.source = "super element " + setup.source + " on the bench, ga and gs tuned";
  const Eigen::VectorXcd &de = r.model.H[0], &vs = r.model.H[1];
  std::vector<double> e_de, e_vs;
  for (Eigen::Index k = 0; k < f.size(); ++k) {
    if (f(k) >= r.band_lo_Hz && f(k) <= options.error_max_Hz) {
      e_de.push_back(std::abs(20.0 * std::log10(std::abs(de(k)) / std::abs(measured.H[static_cast<std::size_t>(ide)](k)))));
      e_vs.push_back(std::abs(20.0 * std::log10(std::abs(vs(k)) / std::abs(measured.H[static_cast<std::size_t>(ivs)](k)))));
    }
  }
  r.de_error_dB = e_de.empty() ? 0.0 : median(e_de);
  r.vs_error_dB = e_vs.empty() ? 0.0 : median(e_vs);
  return r;
}

}  // namespace piezobench::campaign
