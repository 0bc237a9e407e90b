#include "piezobench/ident/actuator_frf.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/dsp/resolution_kernel.hpp"
#include "piezobench/ident/low_frequency_high_pass.hpp"
#include "piezobench/ident/vector_fit_uncertainty.hpp"

namespace piezobench::ident {

namespace {

using Eigen::Index;

// "source: field" for the fits' messages.
std::string fit_source(const ActuatorFrfOptions& o) { return o.field.empty() ? o.source : o.source + ": " + o.field; }

// One output of the FRF over [fmin_Hz, fmax_Hz] (the 0 Hz line left out), as measured.
dsp::Frf output_band(const dsp::Frf& frf, Index output, double fmin_Hz, double fmax_Hz, double min_coherence = 0.0) {
  return dsp::select_band(frf, dsp::BandSelection{fmin_Hz, fmax_Hz, /*exclude_dc=*/true, min_coherence, {output}});
}

// The line of the largest |H| of a one-output band (the first of equals).
Index peak_line(const dsp::Frf& band) {
  const Eigen::VectorXcd& h = band.H[0];
  Index peak = 0;
  for (Index k = 1; k < h.size(); ++k) {
    if (std::abs(h(k)) > std::abs(h(peak))) peak = k;
  }
  return peak;
}

// The feature nearest in frequency (log scale) to `target_rad_s`; nullptr when there is none.
template <typename T>
const T* nearest(const std::vector<T>& features, double target_rad_s) {
  const T* best = nullptr;
  for (const T& f : features) {
    if (!best || std::abs(std::log(f.natural_frequency / target_rad_s)) < std::abs(std::log(best->natural_frequency / target_rad_s))) best = &f;
  }
  return best;
}

FrfFeatureOptions vector_fit_options(const ActuatorFrfOptions& o) {
  FrfFeatureOptions fo;
  fo.fit.order = o.fit_order;
  fo.fit.fail_if_not_converged = false;
  return fo;
}

FrfFeatures vector_fit_features(const dsp::Frf& band, const ActuatorFrfOptions& o) {
  return frf_features(kTwoPi * band.freq_Hz, band.H[0], vector_fit_options(o));
}

// The covariance of the features' vector fit of a one-output band: its std_H when it has one, with
// the correlation of neighbouring lines of `kernel` (the plant fits' resolution kernel, computed once
// per FRF: its window sums are what cost), else the noise estimated from the residuals. nullopt when
// it is singular (a pole with a vanishing residue, as a noise-free FRF fitted with more poles than it
// has gives: its place is undetermined, and so, linearized, is every parameter; the standard errors
// are then left out, not written as 0 or inf), and with a warning when it cannot be had.
std::optional<VectorFitUncertainty> features_uncertainty(const dsp::Frf& band, const FrfFeatures& f, const ActuatorFrfOptions& o,
                                                         const dsp::ResolutionKernel& kernel, const std::string& what,
                                                         ActuatorFrfResult& r) {
  try {
    const Vector omega = kTwoPi * band.freq_Hz;
    const bool variance = band.std_H.size() == 1 && band.std_H[0].size() == omega.size();
    const Matrix std_h = variance ? Matrix(band.std_H[0]) : Matrix();
    const Vector pairs = variance ? dsp::adjacent_line_pairs(kernel, omega) : Vector();
    VectorFitUncertainty u = vector_fit_uncertainty(omega, CMatrix(band.H[0]), f.fit, vector_fit_options(o).fit, {}, std_h, pairs);
    if (!u.covariance.singular) return u;
  } catch (const Error& e) {
    r.warnings.push_back("vector fit of " + what + ": no standard errors: " + e.what());
  }
  return std::nullopt;
}

// The summary of a vector fit, with its covariance's conditioning and flagged correlations when it has one.
VectorFitSummary summary(const FrfFeatures& f, const ActuatorFrfOptions& o, const std::optional<VectorFitUncertainty>& u) {
  VectorFitSummary s;
  s.order = o.fit_order;
  s.relative_rms_error = f.fit.relative_rms_error;
  s.converged = f.fit.converged;
  if (u) {
    s.condition_number = u->covariance.condition_number;
    s.high_correlations = core::high_correlation_labels(u->covariance, u->names);
  }
  return s;
}

// x when finite, else nullopt (an undetermined standard error is not written).
std::optional<double> finite(double x) { return std::isfinite(x) ? std::optional<double>(x) : std::nullopt; }

// u -> d_e by vector fitting: the static gain, and the resonance nearest the peak of |H|.
std::optional<ModalFeature> de_features(const dsp::Frf& de, const ActuatorFrfOptions& o, const dsp::ResolutionKernel& kernel,
                                        ActuatorFrfResult& r) {
  try {
    const FrfFeatures f = vector_fit_features(de, o);
    ActuatorFrfAnalysis& a = r.analysis;
    a.static_gain_vector_fit = f.static_gain;
    a.static_gain = f.static_gain;
    a.static_gain_source = to_string(f.static_gain_source);
    const ModalFeature* m = nearest(f.resonances, kTwoPi * de.freq_Hz(peak_line(de)));
    const std::optional<VectorFitUncertainty> u = features_uncertainty(de, f, o, kernel, "u -> d_e", r);
    a.fit_de = summary(f, o, u);
    if (u) {
      if (f.static_gain_source == StaticGainSource::kModelDcGain) {
        a.static_gain_vector_fit_standard_error = finite(std::sqrt(response_covariance(f.fit, *u, 0, Complex(0.0, 0.0))(0, 0)));
      }
      // The pole the resonance is (frf_features copies it: root = the pole with Im > 0).
      for (Index k = 0; m && k < f.fit.poles.size(); ++k) {
        if (f.fit.poles(k) != m->root) continue;
        const RootUncertainty& pu = u->poles[static_cast<std::size_t>(k)];
        a.resonance_vector_fit_standard_error_Hz = finite(pu.natural_frequency_se / kTwoPi);
        a.resonance_vector_fit_damping_standard_error = finite(pu.damping_se);
      }
    }
    if (m) return *m;
  } catch (const NumericalError& e) {
    r.failed.push_back(std::string("frf u -> d_e features: ") + e.what());
  }
  return std::nullopt;
}

// u -> Vs by vector fitting: the static gain, and the zero nearest the dip of |H| below its peak
// (the anti-resonance below the resonance) with its phase verdict.
std::optional<AntiResonance> vs_features(const dsp::Frf& vs, const ActuatorFrfOptions& o, const dsp::ResolutionKernel& kernel,
                                         ActuatorFrfResult& r) {
  try {
    const FrfFeatures f = vector_fit_features(vs, o);
    const Eigen::VectorXcd& h = vs.H[0];
    const Index peak = peak_line(vs);
    Index dip = -1;
    for (Index k = 0; k < peak; ++k) {
      if (dip < 0 || std::abs(h(k)) < std::abs(h(dip))) dip = k;
    }
    const AntiResonance* z = dip >= 0 ? nearest(f.antiresonances, kTwoPi * vs.freq_Hz(dip)) : nullptr;
    if (z) r.analysis.nmp.zero = NmpEvidence::Zero{z->phase_verdict, z->phase_change_deg, z->root, z->nonminimum_phase_model};
    const std::optional<VectorFitUncertainty> u = z ? features_uncertainty(vs, f, o, kernel, "u -> Vs", r) : std::nullopt;
    if (u) {
      const RootUncertainty zu = zero_uncertainty(f.fit, *u, 0, CVector::Constant(1, z->root)).front();
      r.analysis.antiresonance_vector_fit_standard_error_Hz = finite(zu.natural_frequency_se / kTwoPi);
      r.analysis.antiresonance_vector_fit_damping_standard_error = finite(zu.damping_se);
    }
    r.analysis.static_gain_vs = f.static_gain;
    r.analysis.fit_vs = summary(f, o, u);
    if (z) return *z;
  } catch (const NumericalError& e) {
    r.failed.push_back(std::string("frf u -> Vs features: ") + e.what());
  }
  return std::nullopt;
}

// The plants of `run` and `model tune` (fit_actuator_plants): u -> d_e as a mass-spring-damper
// with its own delay, u -> Vs as eq. 2.3 with delay (its corner fixed at w_rc when known).
void fit_plants(const dsp::Frf& frf, Index de, Index vs, const ActuatorFrfOptions& o, double w_rc, const dsp::ResolutionKernel& kernel,
                ActuatorFrfResult& r) {
  ActuatorPlantOptions po;
  po.fmin_Hz = o.fmin_Hz;
  po.fmax_Hz = o.fmax_Hz;
  po.iff_fmin_Hz = w_rc > 0.0 ? o.fmin_Hz : 0.0;
  po.hpf_fmax_Hz = o.hpf_fmax_Hz;
  po.fixed_w_hpf = w_rc;
  po.min_coherence = o.min_coherence;
  po.effective_averages = frf.provenance.effective_averages;
  po.resolution = kernel;
  const auto coherence = [&](Index i) { return frf.coherence.empty() ? Eigen::VectorXd() : frf.coherence[static_cast<std::size_t>(i)]; };
  ActuatorPlants plants = fit_actuator_plants(kTwoPi * frf.freq_Hz, frf.H[static_cast<std::size_t>(de)], coherence(de),
                                              frf.H[static_cast<std::size_t>(vs)], coherence(vs), po, fit_source(o));
  for (auto& f : plants.failures) r.failed.push_back(std::move(f));
  ActuatorFrfAnalysis& a = r.analysis;
  a.de_plant = std::move(plants.de);
  if (plants.vs) {
    a.iff_plant = std::move(plants.vs);
    a.iff_plant_fmin_Hz = plants.vs_options.fmin_Hz;
    a.iff_plant_fmax_Hz = plants.vs_options.fmax_Hz;
    a.iff_plant_w_hpf_measured = w_rc > 0.0;
    a.nmp.iff_plant_fit_xz = a.iff_plant->xz;
    if (const double se = a.iff_plant->uncertainty.standard_error_of("xz"); std::isfinite(se)) a.nmp.iff_plant_fit_xz_standard_error = se;
  }
}

// The unit's corner: 1/(2 pi R C_sensor) when the bench has a resistor and C_sensor is measured;
// else the IFF plant fit's, else the first-order fit's, each only when observable in the record (at
// least hpf.observable_above_Hz, low_frequency_high_pass.hpp's rule): a bench without the resistor
// has no high-pass the record can show, and a default resistance must not invent one.
void choose_high_pass_corner(const ActuatorFrfOptions& o, double w_rc, HighPassCorner& hpf) {
  const std::string bench = o.hpf_resistance_ohm ? fmt::format("R = {:g} Ohm from [bench]", *o.hpf_resistance_ohm)
                                             : "no resistor in [bench] (hpf_resistance_ohm)";
  if (w_rc > 0.0) {
    hpf.corner_Hz = w_rc / kTwoPi;
    hpf.method = "1/(2 pi R C_sensor), " + bench + ", C_sensor measured";
    return;
  }
  for (const auto& [fit, name] : {std::pair{hpf.iff_plant_fit_Hz, "IFF plant fit (eq. 2.3) down to the lowest frequency"},
                                  std::pair{hpf.first_order_fit_Hz, "first-order fit below hpf_fmax_Hz"}}) {
    if (!fit) continue;
    if (*fit >= hpf.observable_above_Hz) {
      hpf.corner_Hz = fit;
      hpf.method = std::string(name) + "; " + bench;
    } else {
      hpf.method = fmt::format("{}; the fitted corner {:.3g} Hz is below a third of the lowest line ({:.3g} Hz): not observable, "
                               "no corner reported",
                               bench, *fit, hpf.observable_above_Hz);
    }
    return;
  }
  hpf.method = bench + "; no fit of the corner";
}

// The cross-checks of the corner that disagree by more than kHighPassCrossCheckRatio: 1/(2 pi R C)
// against each fit, and the two fits against each other when both are observable.
void high_pass_warnings(const HighPassCorner& hpf, std::vector<std::string>& out) {
  const auto apart = [](double a, double b) { return std::max(a, b) / std::min(a, b) > kHighPassCrossCheckRatio; };
  const std::string limit = fmt::format("more than a factor {:g} apart", kHighPassCrossCheckRatio);
  if (hpf.r_c_Hz) {
    for (const auto& [fit, name] : {std::pair{hpf.iff_plant_fit_Hz, "the IFF plant fit"}, std::pair{hpf.first_order_fit_Hz, "the first-order fit"}}) {
      if (fit && *fit > 0.0 && apart(*hpf.r_c_Hz, *fit)) {
        out.push_back(fmt::format("high-pass corner: 1/(2 pi R C_sensor) = {:.3g} Hz but {} of u -> Vs gives {:.3g} Hz ({}): is the "
                                  "resistor of [bench] hpf_resistance_ohm on the bench, and is C_sensor right? The report uses {:.3g} Hz",
                                  *hpf.r_c_Hz, name, *fit, limit, *hpf.r_c_Hz));
      }
    }
  } else if (hpf.iff_plant_fit_Hz && hpf.first_order_fit_Hz && *hpf.iff_plant_fit_Hz >= hpf.observable_above_Hz &&
             *hpf.first_order_fit_Hz >= hpf.observable_above_Hz && apart(*hpf.iff_plant_fit_Hz, *hpf.first_order_fit_Hz)) {
    out.push_back(fmt::format("high-pass corner: the IFF plant fit gives {:.3g} Hz, the first-order fit {:.3g} Hz ({}); the report uses "
                              "the IFF plant fit's",
                              *hpf.iff_plant_fit_Hz, *hpf.first_order_fit_Hz, limit));
  }
}

// The resistor high-pass: a first-order fit of u -> Vs below hpf_fmax_Hz; 1/(2 pi R C_sensor) when
// known (report section 2.5), then eq. 2.3 refitted with a free corner down to the lowest line as a
// cross-check (the FRF below a few Hz is dominated by the stacks' creep and hysteresis); else the
// IFF plant fit's own corner. Then the choice and the cross-checks that disagree.
void high_pass(const dsp::Frf& frf, Index vs, const ActuatorFrfOptions& o, double w_rc, ActuatorFrfResult& r) {
  HighPassCorner& hpf = r.analysis.hpf;
  LowFrequencyHighPassOptions lo;
  lo.output = o.vs_output;
  lo.fmax_Hz = o.hpf_fmax_Hz;
  lo.min_coherence = o.min_coherence;
  lo.source = fit_source(o);
  const LowFrequencyHighPass low = fit_low_frequency_high_pass(frf, lo);
  hpf.first_order_fit_Hz = low.corner_Hz;
  hpf.first_order_fit_points = low.points;
  hpf.observable_above_Hz = low.observable_above_Hz;
  if (w_rc > 0.0) {
    hpf.r_c_Hz = w_rc / kTwoPi;
    try {
      IffPlantFitOptions free;
      free.fmin_Hz = 0.0;
      free.fmax_Hz = o.fmax_Hz;
      free.hpf_fmax_Hz = o.hpf_fmax_Hz;
      free.min_coherence = o.min_coherence;
      const auto i = static_cast<std::size_t>(vs);
      const Eigen::VectorXd coherence = frf.coherence.empty() ? Eigen::VectorXd() : frf.coherence[i];
      hpf.iff_plant_fit_Hz = fit_iff_plant(kTwoPi * frf.freq_Hz, frf.H[i], coherence, free, fit_source(o)).w_hpf / kTwoPi;
    } catch (const Error& e) {
      hpf.iff_plant_fit_error = e.what();
    }
  } else if (r.analysis.iff_plant) {
    hpf.iff_plant_fit_Hz = r.analysis.iff_plant->w_hpf / kTwoPi;
  }
  choose_high_pass_corner(o, w_rc, hpf);
  high_pass_warnings(hpf, r.warnings);
}

// A feature read two ways (the reported value and its cross-check) that differ by more than
// `tolerance` (relative): a warning naming both.
void cross_check(std::vector<std::string>& warnings, const std::string& what, const std::string& unit, const std::optional<double>& reported,
                 const std::string& reported_from, const std::optional<double>& check, const std::string& check_from, double tolerance) {
  if (!reported || !check || *reported == 0.0) return;
  const double d = std::abs(*check / *reported - 1.0);
  if (d <= tolerance) return;
  warnings.push_back(fmt::format("{}: {} {} {} but {} {} {} ({} % apart, more than {} %); the report uses the {}", what,
                                 reported_from, format_number(*reported, 4), unit, check_from, format_number(*check, 4),
                                 unit, format_number_fixed(100.0 * d, 0), format_number_fixed(100.0 * tolerance, 0),
                                 reported_from));
}

// The reported features. Static gain, resonance and its damping: from the mass-spring-damper fit of
// u -> d_e with its delay (else the vector fit, else the IFF plant fit). Anti-resonance: from the
// IFF plant fit, whose zero pair is exactly the model's (the order-N vector fit spreads the narrow
// notch over its poles). The vector fits are kept as cross-checks. The verdict on the zero pair:
// zero_phase_verdict (the interval of xz in the IFF plant fit, else the phase of the data, else the
// vector fit's zero).
void choose_features(const std::optional<ModalFeature>& resonance, const std::optional<AntiResonance>& zero, const ActuatorFrfOptions& o,
                     ActuatorFrfResult& r) {
  ActuatorFrfAnalysis& a = r.analysis;
  const ZeroPhaseVerdict zv = zero_phase_verdict(zero ? &*zero : nullptr, a.iff_plant ? &*a.iff_plant : nullptr);
  a.zero_is_nonminimum_phase = zv.nonminimum_phase;
  a.nmp.verdict_from = zv.from;
  a.nmp.verdict_reason = zv.reason;
  std::optional<double> res_w, res_z, anti_w, anti_z;  // rad/s, damping ratio
  if (zero) {
    anti_w = zero->natural_frequency;
    anti_z = zero->damping;
    a.antiresonance_vector_fit_Hz = *anti_w / kTwoPi;
    a.antiresonance_vector_fit_damping = *anti_z;
  }
  if (resonance) {
    res_w = resonance->natural_frequency;
    res_z = resonance->damping;
    a.resonance_vector_fit_Hz = *res_w / kTwoPi;
    a.resonance_vector_fit_damping = *res_z;
  }
  if (a.de_plant) {
    res_w = a.de_plant->natural_frequency;
    res_z = a.de_plant->damping;
    a.static_gain = a.de_plant->static_gain;
    a.static_gain_source = "second-order fit of u -> d_e with delay";
  } else if (!res_w && a.iff_plant) {
    res_w = a.iff_plant->wp;
    res_z = a.iff_plant->xp;
  }
  if (a.iff_plant) {
    anti_w = a.iff_plant->wz;
    anti_z = std::abs(a.iff_plant->xz);
  }
  r.resonance_rad_s = res_w;
  if (res_w) a.resonance_Hz = *res_w / kTwoPi;
  a.resonance_damping = res_z;
  if (anti_w) a.antiresonance_Hz = *anti_w / kTwoPi;
  // Signed as in the truth: negative for a non-minimum-phase zero pair; the plant fit's own sign when
  // the verdict is undetermined (its best estimate, whose interval contains 0).
  if (anti_z) {
    const std::optional<bool>& nmp = a.zero_is_nonminimum_phase;
    const double sign = nmp ? (*nmp ? -1.0 : 1.0) : (a.iff_plant && a.iff_plant->xz < 0.0 ? -1.0 : 1.0);
    a.antiresonance_damping = sign * *anti_z;
  }
  if (anti_w) a.shell_stiffness = o.suspended_mass_kg * *anti_w * *anti_w;
}

}  // namespace

}  // namespace piezobench::ident

namespace piezobench::ident {

ActuatorFrfResult analyze_actuator_frf(const dsp::Frf& frf, const ActuatorFrfOptions& o) {
  frf.validate(fit_source(o));
  const Index de_output = frf.output_index(o.de_output), vs_output = frf.output_index(o.vs_output);
  const dsp::Frf de = output_band(frf, de_output, o.fmin_Hz, o.fmax_Hz);
  const dsp::Frf vs = output_band(frf, vs_output, o.fmin_Hz, o.fmax_Hz);
  if (de.freq_Hz.size() < 20) {
    const double resolution_Hz = frf.provenance.nfft > 0 ? frf.provenance.sample_rate / static_cast<double>(frf.provenance.nfft)
                                                         : (frf.freq_Hz.size() > 1 ? frf.freq_Hz(1) - frf.freq_Hz(0) : 0.0);
    throw InputError(o.source, o.field, fmt::format("at least 20 FRF points in [{}, {}] Hz", o.fmin_Hz, o.fmax_Hz),
                     fmt::format("{} (resolution {} Hz)", de.freq_Hz.size(), resolution_Hz));
  }
  ActuatorFrfResult r;
  r.analysis.welch = frf.provenance;
  // The Welch estimate's resolution kernel (inactive without window_resolution or a provenance that
  // gives it), for the plant fits and the correlation of neighbouring lines in every fit's covariance.
  const dsp::ResolutionKernel kernel = o.window_resolution ? dsp::resolution_kernel(frf.provenance) : dsp::ResolutionKernel{};
  const std::optional<ModalFeature> resonance = de_features(de, o, kernel, r);
  // rad/s; 0 when the capacitance is not measured or the bench has no resistor.
  const double w_rc = o.sensor_capacitance_F && o.hpf_resistance_ohm ? 1.0 / (*o.hpf_resistance_ohm * *o.sensor_capacitance_F) : 0.0;
  fit_plants(frf, de_output, vs_output, o, w_rc, kernel, r);
  const std::optional<AntiResonance> zero = vs_features(vs, o, kernel, r);
  high_pass(frf, vs_output, o, w_rc, r);
  choose_features(resonance, zero, o, r);
  ActuatorFrfAnalysis& a = r.analysis;
  cross_check(r.warnings, "resonance", "Hz", a.resonance_Hz, "second-order fit of u -> d_e", a.resonance_vector_fit_Hz, "the vector fit",
              kFeatureCrossCheckTolerance);
  cross_check(r.warnings, "anti-resonance", "Hz", a.antiresonance_Hz, "IFF plant fit", a.antiresonance_vector_fit_Hz, "the vector fit",
              kFeatureCrossCheckTolerance);
  cross_check(r.warnings, "static gain u -> d_e", "m/V", a.static_gain, a.static_gain_source, a.static_gain_vector_fit, "the vector fit",
              kFeatureCrossCheckTolerance);
  return r;
}

}  // namespace piezobench::ident
