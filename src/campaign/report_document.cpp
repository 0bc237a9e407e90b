#include "piezobench/campaign/report_document.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <numbers>
#include <optional>
#include <tuple>

#include "piezobench/apa/two_dof.hpp"
#include "piezobench/campaign/results_json.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/core/fit_covariance.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/dsp/frf_variance.hpp"
#include "piezobench/dsp/unwrap.hpp"
#include "piezobench/core/fields.hpp"
#include "piezobench/io/fields_json.hpp"
#include "piezobench/io/json.hpp"
#include "piezobench/version.hpp"
#include "report_table.hpp"
#include "shown_units.hpp"

namespace piezobench::campaign {

using Eigen::Index;
using Eigen::VectorXd;
using nlohmann::json;

namespace {

using namespace shown_units;

// ------------------------------------------------------------------------------------ curves
// The figures' data, made from the typed results: thinned records and log-spaced FRF lines.

// Samples as a JSON list (non-finite values as null), each times `scale`.
json values(const std::vector<double>& x, double scale = 1.0) {
  json out = json::array();
  for (const double v : x) out.push_back(std::isfinite(v) ? json(v * scale) : json(nullptr));
  return out;
}

// Phases in degrees, unwrapped along the list (no 360 deg jumps between neighbours).
json unwrapped_degrees(const std::vector<std::complex<double>>& h) {
  std::vector<double> deg;
  for (const auto& v : h) deg.push_back(std::arg(v) * 180.0 / std::numbers::pi);
  return dsp::unwrap_phase(std::move(deg), 360.0);
}

// Indices of a frequency grid thinned to ~`points` log-spaced values inside [fmin, fmax].
std::vector<Index> log_indices(const VectorXd& f, double fmin, double fmax, int points = 400) {
  std::vector<Index> idx;
  double next = fmin;
  const double ratio = std::pow(fmax / fmin, 1.0 / points);
  for (Index k = 0; k < f.size(); ++k) {
    if (f(k) < fmin || f(k) > fmax) continue;
    if (f(k) >= next) {
      idx.push_back(k);
      next = f(k) * ratio;
    }
  }
  return idx;
}

// A response's curves as the figures draw them: frequencies, |H| (scaled), unwrapped phase in
// degrees and, for measurements, the coherence (null where there is none).
struct Bode {
  json f = json::array(), abs = json::array(), phase = json::array(), coh = json::array();
  // The 95 % band of a measurement (dsp/frf_variance.hpp): |H| +- k std_H (scaled; the lower edge
  // kept above |H| / 1000 for the log axis) and phase +- k std_H / |H| (deg, at most 180), k the
  // band factor of the FRF's n_d (1.96 when its n_d is unknown); empty when the FRF has no std_H.
  json abs_lo = json::array(), abs_hi = json::array(), phase_lo = json::array(), phase_hi = json::array();
};

// |H|, coherence and unwrapped phase of one output at the indices `idx` (|H| times `scale`).
Bode frf_lines(const dsp::Frf& frf, Index output, const std::vector<Index>& idx, double scale) {
  const auto o = static_cast<std::size_t>(output);
  Bode p;
  std::vector<std::complex<double>> h;
  for (const Index k : idx) {
    p.f.push_back(frf.freq_Hz(k));
    p.abs.push_back(std::abs(frf.H[o](k)) * scale);
    p.coh.push_back(frf.coherence[o].size() > 0 ? json(frf.coherence[o](k)) : json(nullptr));
    h.push_back(frf.H[o](k));
  }
  p.phase = unwrapped_degrees(h);
  if (frf.std_H.size() > o) {
    const double n_d = frf.provenance.effective_averages;
    const double k = n_d > 1.0 ? dsp::frf_band_factor(n_d) : core::kCoverage95;
    for (std::size_t i = 0; i < idx.size(); ++i) {
      const double mag = std::abs(h[i]), s = k * frf.std_H[o](idx[i]);
      const double dphi = mag > 0.0 ? std::min(180.0, s / mag * 180.0 / std::numbers::pi) : 180.0;
      p.abs_lo.push_back(std::max(mag - s, 1e-3 * mag) * scale);
      p.abs_hi.push_back((mag + s) * scale);
      p.phase_lo.push_back(p.phase[i].get<double>() - dphi);
      p.phase_hi.push_back(p.phase[i].get<double>() + dphi);
    }
  }
  return p;
}

// A model's response h(k) at the frequencies f(k) [Hz], |h| times `scale`.
Bode model_lines(const json& f, const std::vector<std::complex<double>>& h, double scale) {
  Bode p;
  p.f = f;
  for (const auto& v : h) p.abs.push_back(std::abs(v) * scale);
  p.phase = unwrapped_degrees(h);
  return p;
}

// x against y (thinned records).
struct XY {
  json x, y;
};

struct HysteresisCurves {
  double amplitude_V = 0.0;
  XY loop;  // Va [V], d_e [um]
};

struct StiffnessCurves {
  json t, de_um, fit_um;
};

// One waveform of the tracking record: d_e against the command without and with the feedforward.
struct TrackingCurves {
  json c, open_um, ff_um;  // V, um, um
};

struct DampedCurves {
  double gain = 0.0;
  Bode measured, fit;  // u' -> d_e [um/V]; the vector fit with the delay put back
};

// What the figures draw of one unit, made from its typed results.
struct UnitCurves {
  const UnitAnalysis* result = nullptr;
  std::optional<Bode> de, vs;              // measured u -> d_e [um/V], u -> Vs [V/V] (same f)
  std::optional<Bode> model_de, model_vs;  // the tuned 2-DoF model
  std::optional<Bode> iff_fit;             // eq. 2.3 with delay, at vs's frequencies
  std::optional<Bode> nmp;                 // u -> Vs, every line around the anti-resonance
  std::optional<Bode> resistor_with, resistor_without;  // u -> Vs below 20 Hz
  std::vector<DampedCurves> damped;        // the identified damped plants
  std::optional<XY> hammer;                // force -> velocity |H|
  std::optional<XY> stroke;                // Va [V], d_e [um]
  std::vector<HysteresisCurves> hysteresis;
  std::optional<StiffnessCurves> stiffness, stiffness_open;
  std::optional<XY> hysteresis_model_record;  // Va [V], d_e [um]
  json hysteresis_model_um;                   // the model's d_e [um] at the same Va
  std::optional<TrackingCurves> tracking_sine, tracking_triangle;

  [[nodiscard]] const std::string& name() const { return result->name; }
};

StiffnessCurves stiffness_curves(const StiffnessAnalysis& s) { return {values(s.de.x), values(s.de.y, kUm), values(s.fit.y, kUm)}; }

UnitCurves unit_curves(const Campaign& c, const UnitAnalysis& u) {
  UnitCurves out;
  out.result = &u;
  if (u.stroke_analysis) out.stroke = XY{values(u.stroke_analysis->de_vs_va.x), values(u.stroke_analysis->de_vs_va.y, kUm)};
  for (const auto& h : u.hysteresis) out.hysteresis.push_back({h.result.amplitude, {values(h.loop.x), values(h.loop.y, kUm)}});
  if (u.hysteresis_model) {
    const HysteresisModelFit& h = *u.hysteresis_model;
    out.hysteresis_model_record = XY{values(h.loop.x), values(h.loop.y, kUm)};
    out.hysteresis_model_um = values(h.model_loop.y, kUm);
  }
  if (u.tracking) {
    const auto loop = [](const Curve& open, const Curve& ff) { return TrackingCurves{values(open.x), values(open.y, kUm), values(ff.y, kUm)}; };
    out.tracking_sine = loop(u.tracking->sine_open, u.tracking->sine_ff);
    out.tracking_triangle = loop(u.tracking->triangle_open, u.tracking->triangle_ff);
  }
  if (u.stiffness_analysis) out.stiffness = stiffness_curves(*u.stiffness_analysis);
  if (u.stiffness_open_analysis) out.stiffness_open = stiffness_curves(*u.stiffness_open_analysis);
  if (const dsp::Frf* measured = frf_of(u)) {
    const dsp::Frf& frf = *measured;
    const VectorXd& f = frf.freq_Hz;
    const std::vector<Index> idx = log_indices(f, std::max(0.5, f(1)), std::min(2.0 * c.analysis.fmax_Hz, f(f.size() - 1)));
    VectorXd w(static_cast<Index>(idx.size()));
    for (std::size_t i = 0; i < idx.size(); ++i) w(static_cast<Index>(i)) = kTwoPi * f(idx[i]);
    if (u.model_2dof) {
      const lti::CMatrix hm = apa::two_dof_response(u.model_2dof->tuning.params, u.model_2dof->bench, w);
      json fm = json::array();
      std::vector<std::complex<double>> mde, mvs;
      for (Index k = 0; k < w.size(); ++k) {
        fm.push_back(w(k) / kTwoPi);
        mde.push_back(hm(k, 0));
        mvs.push_back(hm(k, 1));
      }
      out.model_de = model_lines(fm, mde, kUmPerV);
      out.model_vs = model_lines(fm, mvs, 1.0);
    }
    out.de = frf_lines(frf, 0, idx, kUmPerV);
    out.vs = frf_lines(frf, 1, idx, 1.0);
    if (const ident::IffPlantFit* iff = iff_plant_of(u)) {
      const Eigen::VectorXcd g = iff->response(w);
      out.iff_fit = model_lines(out.vs->f, std::vector<std::complex<double>>(g.data(), g.data() + g.size()), 1.0);
    }
    // Every line around the anti-resonance (report Figure 2.6: coherence and phase there).
    if (const std::optional<double> antiresonance = antiresonance_Hz_of(u)) {
      const double fz = *antiresonance;
      std::vector<Index> near;
      for (Index k = 0; k < f.size(); ++k) {
        if (f(k) >= 0.7 * fz && f(k) <= 1.4 * fz) near.push_back(k);
      }
      out.nmp = frf_lines(frf, 1, near, 1.0);
    }
  }
  if (u.resistor) {
    // Figure 2.7: up to 20 Hz.
    const auto lines = [](const LowFrequencyVs& v) {
      const VectorXd& f = v.frf.freq_Hz;
      return frf_lines(v.frf, 0, log_indices(f, v.lowest_line_Hz, std::min(20.0, f(f.size() - 1)), 200), 1.0);
    };
    if (u.resistor->with_resistor) out.resistor_with = lines(*u.resistor->with_resistor);
    out.resistor_without = lines(u.resistor->without_resistor);
  }
  for (const DampedPlant& d : u.damped) {
    if (!d.identified) continue;
    const VectorXd& f = d.frf.freq_Hz;
    const std::vector<Index> idx =
        log_indices(f, std::max(f(1), 0.5 * c.analysis.damped_fmin_Hz), std::min(f(f.size() - 1), 2.0 * c.analysis.damped_fmax_Hz), 300);
    VectorXd om(static_cast<Index>(idx.size()));
    for (std::size_t i = 0; i < idx.size(); ++i) om(static_cast<Index>(i)) = kTwoPi * f(idx[i]);
    // The fit (delay removed) with the delay put back, to sit on the measurement.
    const Eigen::MatrixXcd fit = d.identified->fit.evaluate(om);
    json fd = json::array();
    std::vector<std::complex<double>> hm, hf;
    for (std::size_t i = 0; i < idx.size(); ++i) {
      const auto k = static_cast<Index>(i);
      fd.push_back(f(idx[i]));
      hm.push_back(d.frf.H[0](idx[i]));
      hf.push_back(fit(k, 0) * std::exp(std::complex<double>(0.0, -om(k) * d.delay_removed)));
    }
    out.damped.push_back({d.gain, model_lines(fd, hm, kUmPerV), model_lines(fd, hf, kUmPerV)});
  }
  if (u.flexible_modes) {
    const dsp::Frf& frf = u.flexible_modes->frf;
    XY h{json::array(), json::array()};
    for (const Index k : log_indices(frf.freq_Hz, std::max(1.0, frf.freq_Hz(1)), frf.freq_Hz(frf.freq_Hz.size() - 1), 500)) {
      h.x.push_back(frf.freq_Hz(k));
      h.y.push_back(std::abs(frf.H[0](k)));
    }
    out.hammer = h;
  }
  return out;
}

// ------------------------------------------------------------------------------------ layout

json trace(const std::string& name, const json& x, const json& y, const std::string& group = "", bool dash = false,
           const std::string& mode = "lines") {
  json t = {{"name", name}, {"x", x}, {"y", y}, {"mode", mode}, {"dash", dash}};
  if (!group.empty()) t["group"] = group;
  return t;
}

// The shaded band between lo and hi, drawn under the unit's curve (report.js mode "band").
json band_trace(const std::string& name, const json& f, const json& lo, const json& hi, const std::string& group) {
  json t = trace(name + " 95 % band", f, lo, group, false, "band");
  t["y_upper"] = hi;
  return t;
}

json with_text(json t, json text) {
  t["text"] = std::move(text);
  return t;
}

json panel(const std::string& y_label, bool y_log, json traces) {
  return {{"y_label", y_label}, {"y_log", y_log}, {"traces", std::move(traces)}};
}

json figure(const std::string& id, const std::string& title, const std::string& x_label, bool x_log, json panels,
            const std::string& text = "") {
  json f = {{"id", id}, {"title", title}, {"x_label", x_label}, {"x_log", x_log}, {"panels", std::move(panels)}};
  if (!text.empty()) f["text"] = text;
  return f;
}

json table(const std::string& title, const std::vector<std::string>& columns, json rows, const std::string& text = "") {
  json t = {{"title", title}, {"columns", columns}, {"rows", std::move(rows)}};
  if (!text.empty()) t["text"] = text;
  return t;
}

// A model's phase drawn on the measurement's branch: the model's unwrapped phase, continuous,
// moved by the one multiple of 360 degrees that brings most of its points nearest to the measured
// phase at the nearest frequency (phases are defined modulo 360 degrees; unwrapped separately, a
// model and its measurement can sit one turn apart). Where the model's zero is on the other side
// of the axis than the measured one, the curves part by 360 degrees past the anti-resonance
// instead of the model jumping there.
std::pair<json, json> on_branch(const json& f_model, const json& ph_model, const json& f_ref, const json& ph_ref) {
  std::map<long, int> votes;  // turns -> points
  std::size_t j = 0;
  for (std::size_t i = 0; i < f_model.size(); ++i) {
    if (!f_model[i].is_number() || !ph_model[i].is_number()) continue;
    const double f = f_model[i].get<double>(), ph = ph_model[i].get<double>();
    while (j + 1 < f_ref.size() && f_ref[j + 1].is_number() && std::abs(f_ref[j + 1].get<double>() - f) <= std::abs(f_ref[j].get<double>() - f)) ++j;
    if (j < ph_ref.size() && ph_ref[j].is_number()) ++votes[std::lround((ph_ref[j].get<double>() - ph) / 360.0)];
  }
  long turns = 0;
  int most = 0;
  for (const auto& [t, n] : votes) {
    if (n > most) std::tie(turns, most) = std::pair{t, n};
  }
  json x = json::array(), y = json::array();
  for (std::size_t i = 0; i < f_model.size(); ++i) {
    if (!f_model[i].is_number() || !ph_model[i].is_number()) continue;
    x.push_back(f_model[i]);
    y.push_back(ph_model[i].get<double>() + 360.0 * static_cast<double>(turns));
  }
  return {x, y};
}

// Magnitude and phase (and coherence) of one output, all units, the measurement solid and a model
// dashed, the model's phase on the measurement's branch. `measured` and `model` pick the curves of
// a unit (model: nullptr when the unit has none).
json frf_figure(const std::vector<UnitCurves>& units, const std::function<const Bode*(const UnitCurves&)>& measured,
                const std::function<const Bode*(const UnitCurves&)>& model, const std::string& id, const std::string& title,
                const std::string& unit_label, const std::string& model_name, bool coherence, const std::string& text) {
  json mag = json::array(), phase = json::array(), coh = json::array();
  for (const auto& u : units) {
    const Bode* p = measured(u);
    if (!p) continue;
    if (!p->abs_lo.empty()) {
      mag.push_back(band_trace(u.name(), p->f, p->abs_lo, p->abs_hi, u.name()));
      phase.push_back(band_trace(u.name(), p->f, p->phase_lo, p->phase_hi, u.name()));
    }
    mag.push_back(trace(u.name(), p->f, p->abs, u.name()));
    phase.push_back(trace(u.name(), p->f, p->phase, u.name()));
    if (coherence) coh.push_back(trace(u.name(), p->f, p->coh, u.name()));
    if (const Bode* m = model(u)) {
      mag.push_back(trace(u.name() + " " + model_name, m->f, m->abs, u.name(), true));
      const auto [x, y] = on_branch(m->f, m->phase, p->f, p->phase);
      phase.push_back(trace(u.name() + " " + model_name, x, y, u.name(), true));
    }
  }
  json panels = json::array({panel("|H| [" + unit_label + "]", true, mag), panel("Phase [deg]", false, phase)});
  if (coherence) panels.push_back(panel("Coherence", false, coh));
  return figure(id, title, "Frequency [Hz]", true, panels, text);
}

const Bode* measured_de(const UnitCurves& u) { return u.de ? &*u.de : nullptr; }
const Bode* measured_vs(const UnitCurves& u) { return u.vs ? &*u.vs : nullptr; }
const Bode* model_de(const UnitCurves& u) { return u.model_de ? &*u.model_de : nullptr; }
const Bode* model_vs(const UnitCurves& u) { return u.model_vs ? &*u.model_vs : nullptr; }
const Bode* iff_fit(const UnitCurves& u) { return u.iff_fit ? &*u.iff_fit : nullptr; }

std::string amplitude_label(double a) { return fmt::format("{:.3g} V", a); }

// The table cells hold the numbers of results.json as results_json.cpp writes them: `plain` for
// the numbers it writes as they are, io::to_json (non-finite as "nan", "inf") for the others.
json plain(const std::optional<double>& v, double scale = 1.0) { return v ? json(*v * scale) : json(nullptr); }
// A finite number times `scale`, else null (percentages of numbers written through io::to_json).
json finite_scaled(double v, double scale) { return std::isfinite(v) ? json(v * scale) : json(nullptr); }

// ---- the sections

json frf_section(const std::vector<UnitCurves>& units) {
  json figs = json::array();
  figs.push_back(frf_figure(units, measured_de, model_de, "frf-de", "Fig. 2.5a: u -> d_e", "um/V", "2-DoF model", true,
                            "Solid: measured (Welch H1); dashed: the tuned 2-DoF model (section 3). The model's phase is drawn "
                            "continuous, shifted by the whole turn that puts it on the measurement's."));
  figs.push_back(frf_figure(units, measured_vs, iff_fit, "frf-vs", "Fig. 2.5b: u -> Vs", "V/V", "IFF plant fit", true,
                            "Solid: measured; dashed: the IFF plant fit (eq. 2.3 with delay). The phase falls by 180 deg at the "
                            "anti-resonance: a non-minimum-phase zero."));
  json rows = json::array();
  for (const auto& u : units) {
    if (!u.result->frf_analysis) continue;
    const FrfAnalysis& f = *u.result->frf_analysis;
    const json verdict = f.zero_is_nonminimum_phase ? json(*f.zero_is_nonminimum_phase ? "non-minimum phase" : "minimum phase") : json(nullptr);
    json row = json::array({u.name()});
    report_cells(row, f);
    row.push_back(verdict);
    row.push_back(f.nmp.zero ? io::to_json(f.nmp.zero->phase_change_deg) : json(nullptr));
    row.push_back(io::shown_json(f.hpf.corner_Hz));
    rows.push_back(row);
  }
  std::vector<std::string> columns = {"unit"};
  report_columns<FrfAnalysis>(columns);
  columns.insert(columns.end(), {"zero pair", "phase change at the zero [deg]", "HPF corner [Hz]"});
  json tables = json::array({table("FRF features per unit", columns, rows,
                                   "Anti-resonance damping < 0: the zero is in the right half plane.")});
  // The vector fits' cross-checks, each with half its 95 % interval (kCoverage95 standard errors).
  json vrows = json::array();
  const auto half_interval = [](const std::optional<double>& se, double per_si = 1.0) {
    return se && std::isfinite(*se) ? json(core::kCoverage95 * *se * per_si) : json(nullptr);
  };
  // A fit's parameters correlated above 0.95 and its condition number ("none; cond 5.8").
  const auto correlated = [](const std::optional<ident::VectorFitSummary>& fit) {
    if (!fit || !fit->condition_number) return json(nullptr);
    std::string pairs;
    for (const auto& c : fit->high_correlations) pairs += (pairs.empty() ? "" : ", ") + c;
    return json(fmt::format("{}; cond {}", pairs.empty() ? "none" : pairs, format_number(*fit->condition_number, 3)));
  };
  for (const auto& u : units) {
    if (!u.result->frf_analysis) continue;
    const FrfAnalysis& f = *u.result->frf_analysis;
    constexpr double um_per_m = core::shown::kMetrePerVoltAsUmPerV.per_si;
    vrows.push_back(json::array({u.name(), io::to_json(f.resonance_vector_fit_Hz), half_interval(f.resonance_vector_fit_standard_error_Hz),
                                 io::to_json(f.resonance_vector_fit_damping), half_interval(f.resonance_vector_fit_damping_standard_error),
                                 io::to_json(f.antiresonance_vector_fit_Hz), half_interval(f.antiresonance_vector_fit_standard_error_Hz),
                                 io::to_json(f.antiresonance_vector_fit_damping),
                                 half_interval(f.antiresonance_vector_fit_damping_standard_error),
                                 io::shown_json(f.static_gain_vector_fit, um_per_m),
                                 half_interval(f.static_gain_vector_fit_standard_error, um_per_m),
                                 correlated(f.fit_de), correlated(f.fit_vs)}));
  }
  if (!vrows.empty()) {
    tables.push_back(table("Vector fits per unit (cross-checks, +- half the 95 % interval)",
                           {"unit", "resonance [Hz]", "+- (95 %) [Hz]", "damping", "+- (95 %)", "anti-resonance [Hz]", "+- (95 %) [Hz]",
                            "zero damping", "+- (95 %)", "static gain [um/V]", "+- (95 %) [um/V]", "u -> d_e: correlated > 0.95",
                            "u -> Vs: correlated > 0.95"},
                           vrows,
                           "The order-6 vector fits of u -> d_e and u -> Vs, kept as cross-checks of the plant fits above. +-: "
                           "1.96 standard errors from the FRF's variance, widened by the fit's local misfit (docs/uncertainty.md "
                           "section 5); they say how well the cross-check is pinned, not how far the order-6 model is from the "
                           "unit (its anti-resonance sits a few per cent high: it spreads the narrow notch over its poles). "
                           "Empty: not found, or the fit's covariance singular. Correlated: its real parameters (pN: pole N, rI.N: "
                           "residue of output I at pole N, dI: constant) that trade against each other above 0.95, and the "
                           "conditioning of the fit's Jacobian."));
  }
  json warnings = json::array();
  for (const auto& u : units) {
    for (const auto& w : u.result->warnings) warnings.push_back(u.name() + ": " + w);
  }
  return {{"id", "frf"}, {"title", "Frequency responses (report 2.3)"}, {"warnings", warnings},
          {"text", "FRFs from the DAC voltage u to the encoder d_e and to the force-sensor voltage Vs, all units "
                   "overlaid, with the coherence. The shaded bands are 95 % intervals of each measurement's random "
                   "error (|H| +- k std, phase +- k std / |H|, k the Student factor of each FRF's averages; Bendat & Piersol, Goodman, docs/uncertainty.md)."},
          {"tables", tables}, {"figures", figs}};
}

json nmp_section(const std::vector<UnitCurves>& units) {
  json coh = json::array(), phase = json::array(), mag = json::array();
  json rows = json::array();
  for (const auto& u : units) {
    if (!u.nmp) continue;
    const Bode& z = *u.nmp;
    if (!z.abs_lo.empty()) {
      mag.push_back(band_trace(u.name(), z.f, z.abs_lo, z.abs_hi, u.name()));
      phase.push_back(band_trace(u.name(), z.f, z.phase_lo, z.phase_hi, u.name()));
    }
    mag.push_back(trace(u.name(), z.f, z.abs, u.name(), false, "lines+markers"));
    coh.push_back(trace(u.name(), z.f, z.coh, u.name(), false, "lines+markers"));
    phase.push_back(trace(u.name(), z.f, z.phase, u.name(), false, "lines+markers"));
    json row = {u.name(), nullptr, nullptr, nullptr, nullptr, nullptr, nullptr};
    if (const auto& f = u.result->frf_analysis) {
      row = {u.name(), io::to_json(f->antiresonance_Hz), io::to_json(f->antiresonance_damping),
             f->nmp.zero ? json(f->nmp.zero->phase_change_deg) : json(nullptr),
             f->nmp.zero ? json(ident::to_string(f->nmp.zero->phase_verdict)) : json(nullptr), f->nmp.verdict_from,
             f->nmp.verdict_reason};
    }
    rows.push_back(row);
  }
  return {{"id", "nmp"}, {"title", "The non-minimum-phase zero (report 2.4)"},
          {"text", "u -> Vs around the anti-resonance, every frequency line. A minimum-phase zero pair raises the phase by 180 deg, "
                   "a non-minimum-phase one lowers it by 180 deg; the coherence says whether the data there can be trusted."},
          {"tables", json::array({table("Verdict per unit",
                                        {"unit", "anti-resonance [Hz]", "zero damping", "phase change [deg]", "verdict of the phase",
                                         "verdict from", "why"},
                                        rows)})},
          {"figures", json::array({figure("nmp-zoom", "Fig. 2.6: u -> Vs at the anti-resonance", "Frequency [Hz]", false,
                                          json::array({panel("|H| [V/V]", true, mag), panel("Coherence", false, coh),
                                                       panel("Phase [deg]", false, phase)}))})}};
}

// The corner of u -> Vs with or without the resistor as the table shows it.
json corner_cell(const LowFrequencyVs& v) {
  if (!v.fitted_corner_Hz) return nullptr;
  if (v.observable) return *v.fitted_corner_Hz;
  return fmt::format("below {:.2g} (not observable)", v.lowest_line_Hz / 3.0);
}

std::optional<json> resistor_section(const Campaign& c, const std::vector<UnitCurves>& units) {
  json mag = json::array(), phase = json::array(), rows = json::array();
  for (const auto& u : units) {
    if (!u.result->resistor) continue;
    const ResistorComparison& r = *u.result->resistor;
    for (const bool with : {true, false}) {
      const std::optional<Bode>& p = with ? u.resistor_with : u.resistor_without;
      if (!p) continue;
      const std::string name = u.name() + (with ? ", with R" : ", without R");
      mag.push_back(trace(name, p->f, p->abs, name));
      phase.push_back(trace(name, p->f, p->phase, name));
    }
    const auto& hpf = u.result->frf_analysis;
    rows.push_back({u.name(), r.with_resistor ? corner_cell(*r.with_resistor) : json(nullptr), corner_cell(r.without_resistor),
                    plain(r.without_resistor.fitted_corner_Hz), r.without_resistor.lowest_line_Hz,
                    hpf ? plain(hpf->hpf.r_c_Hz) : json(nullptr)});
  }
  if (mag.empty()) return std::nullopt;
  return json{{"id", "resistor"}, {"title", "The resistor across the force sensor (report 2.5)"},
              {"text", c.bench.hpf_resistance ? fmt::format("u -> Vs at low frequency with and without the {:.3g} kOhm resistor in parallel "
                                                                   "with the sensor stack: with it, a high-pass at 1/(2 pi R C).",
                                                                   *c.bench.hpf_resistance * 1e-3)
                                                     : std::string("u -> Vs at low frequency with and without a resistor in parallel with "
                                                                   "the sensor stack (its value is not in [bench] hpf_resistance_ohm).")},
              {"tables", json::array({table("High-pass corner per unit",
                                            {"unit", "with R [Hz]", "without R [Hz]", "fitted without R [Hz]", "lowest line [Hz]",
                                             "1/(2 pi R C_sensor) [Hz]"},
                                            rows,
                                            "First-order high-pass fitted below the campaign's hpf_fmax_Hz. A corner below a third "
                                            "of the record's lowest line is reported as not observable.")})},
              {"figures", json::array({figure("resistor", "Fig. 2.7: u -> Vs with and without the resistor", "Frequency [Hz]", true,
                                              json::array({panel("|H| [V/V]", true, mag), panel("Phase [deg]", false, phase)}))})}};
}

// Frequency [Hz] and damping of a pole [rad/s] for the table; nulls when it is not finite.
std::pair<json, json> pole_cells(std::complex<double> p) {
  if (!std::isfinite(p.real()) || !std::isfinite(p.imag())) return {nullptr, nullptr};
  const double w = std::abs(p);
  return {w / kTwoPi, -p.real() / w};
}

// Figure 2.10b: the root locus of the fitted plant with the report's controller.
json root_locus_figure(const IffStudy& s) {
  const auto gain_label = [](double g) { return fmt::format("g = {:.3g}", g); };
  json traces = json::array();
  for (const auto& b : s.branches) {
    json text = json::array();
    for (const double g : b.gains) text.push_back(gain_label(g));
    traces.push_back(with_text(trace("root locus of the model", values(b.re_im.x), values(b.re_im.y), "root locus of the model"), text));
  }
  traces.push_back(trace("open-loop poles", values(s.open_loop_poles.x), values(s.open_loop_poles.y), "", false, "markers"));
  traces.push_back(trace("open-loop zeros", values(s.open_loop_zeros.x), values(s.open_loop_zeros.y), "", true, "markers"));
  // The model's poles and the identified ones at the measured gains.
  const auto at_gains = [&](const std::vector<std::complex<double>>& poles) {
    json re = json::array(), im = json::array(), text = json::array();
    for (std::size_t i = 0; i < s.gains.size(); ++i) {
      re.push_back(poles[i].real());
      im.push_back(poles[i].imag());
      text.push_back(gain_label(s.gains[i]));
    }
    return std::tuple{re, im, text};
  };
  {
    const auto [re, im, text] = at_gains(s.model_poles);
    traces.push_back(with_text(trace("model at the measured gains", re, im, "", true, "markers"), text));
  }
  {
    const auto [re, im, text] = at_gains(s.damped_poles);
    if (!re.empty()) traces.push_back(with_text(trace("identified damped poles", re, im, "", false, "markers"), text));
  }
  traces.push_back(with_text(trace("optimum", json::array({s.optimal_pole.real()}), json::array({s.optimal_pole.imag()}), "", false, "markers"),
                             json::array({fmt::format("g = {:.3g}, damping {:.2f}", s.optimal_gain.value_or(0.0), s.max_damping.value_or(0.0))})));
  return figure("root-locus", fmt::format("Fig. 2.10b: root locus, APA {}", *s.unit), "Re [rad/s]", false,
                json::array({panel("Im [rad/s]", false, traces)}),
                "Closed-loop poles of 1 - g K(s) G(s) = 0 for the fitted plant G (eq. 2.3 with delay) and the report's "
                "controller K (eq. 2.4), every branch inside 3 w_p; open circles: the model's poles at the measured gains; "
                "filled: the poles identified on the measured damped plants (dominant pair of a vector fit). Hover for "
                "the gains.");
}

std::optional<json> iff_section(const std::vector<UnitCurves>& units, const IffStudy& s) {
  json figs = json::array(), tables = json::array(), warnings = json::array();
  // Figure 2.8: the IFF plant of the IFF unit against its fit.
  const UnitCurves* iff_unit = nullptr;
  for (const auto& u : units) {
    if (!iff_unit && u.iff_fit && (s.failed || !s.unit || *s.unit == u.result->id)) iff_unit = &u;
  }
  if (iff_unit) {
    const Bode& p = *iff_unit->vs;
    const Bode& fit = *iff_unit->iff_fit;
    const auto [x, y] = on_branch(fit.f, fit.phase, p.f, p.phase);
    figs.push_back(figure("iff-plant", fmt::format("Fig. 2.8: IFF plant of {} and its fit (eq. 2.3)", iff_unit->name()), "Frequency [Hz]", true,
                          json::array({panel("|H| [V/V]", true,
                                             json::array({trace("measured", p.f, p.abs, "measured"),
                                                          trace("fit (eq. 2.3 with delay)", fit.f, fit.abs, "fit", true)})),
                                       panel("Phase [deg]", false,
                                             json::array({trace("measured", p.f, p.phase, "measured"),
                                                          trace("fit (eq. 2.3 with delay)", x, y, "fit", true)})),
                                       panel("Coherence", false, json::array({trace("measured", p.f, p.coh, "measured")}))}),
                          "u -> Vs of the unit whose IFF data make the batch's IFF result, against the fitted plant model."));
  }
  // The fit's declared report columns, then half its 95 % interval of xz (the NMP verdict's).
  json prow = json::array();
  for (const auto& u : units) {
    if (!u.result->frf_analysis || !u.result->frf_analysis->iff_plant) continue;
    const ident::IffPlantFit& f = *u.result->frf_analysis->iff_plant;
    const double se_xz = f.uncertainty.standard_error_of("xz");
    json row = json::array({u.name()});
    report_cells(row, f);
    row.push_back(std::isfinite(se_xz) ? json(core::kCoverage95 * se_xz) : json(nullptr));
    prow.push_back(row);
  }
  if (!prow.empty()) {
    std::vector<std::string> columns{"unit"};
    report_columns<ident::IffPlantFit>(columns);
    columns.emplace_back("xz +- (95 %)");
    tables.push_back(table("IFF plant (eq. 2.3) per unit", columns,
                           prow,
                           "The report's hand-tuned values: g0 0.64, w_z 42.7 Hz, xi_z 0.4 %, w_p 95.2 Hz, xi_p 2 %, "
                           "w_HPF 0.4 Hz, 200 us. xz +-: half the 95 % interval; the zero is called non-minimum phase "
                           "only when the whole interval is below 0 (docs/uncertainty.md)."));
  }
  if (s.plant && !s.failed) figs.push_back(root_locus_figure(s));
  json mag = json::array(), phase = json::array();
  for (const auto& u : units) {
    for (const DampedCurves& d : u.damped) {
      const std::string name = fmt::format("{} g = {:.3g}", u.name(), d.gain);
      mag.push_back(trace(name, d.measured.f, d.measured.abs, name));
      mag.push_back(trace(name + " fit", d.fit.f, d.fit.abs, name, true));
      phase.push_back(trace(name, d.measured.f, d.measured.phase, name));
      const auto [x, y] = on_branch(d.fit.f, d.fit.phase, d.measured.f, d.measured.phase);
      phase.push_back(trace(name + " fit", x, y, name, true));
    }
  }
  if (!mag.empty()) {
    figs.push_back(figure("damped-plants", "Fig. 2.10a: damped plants u' -> d_e", "Frequency [Hz]", true,
                          json::array({panel("|H| [um/V]", true, mag), panel("Phase [deg]", false, phase)}),
                          "Solid: measured; dashed: the vector fits whose dominant pole is the identified damped pole."));
  }
  if (!s.failed && s.plant && !s.gains.empty()) {
    json rows = json::array();
    for (std::size_t i = 0; i < s.gains.size(); ++i) {
      const auto [fi, zi] = pole_cells(s.damped_poles.at(i));
      const auto [fm, zm] = i < s.model_poles.size() ? pole_cells(s.model_poles[i]) : std::pair<json, json>{nullptr, nullptr};
      rows.push_back({s.gains[i], fi, zi, fm, zm, i < s.relative_pole_distance.size() ? json(s.relative_pole_distance[i]) : json(nullptr)});
    }
    tables.push_back(table("Damped poles against the model's root locus",
                           {"gain g", "identified [Hz]", "identified damping", "model [Hz]", "model damping", "relative distance"},
                           rows,
                           fmt::format("Optimal gain of the model {}, maximum damping {}.",
                                       s.optimal_gain ? fmt::format("{:.3g}", *s.optimal_gain) : "-",
                                       s.plant && s.max_damping ? fmt::format("{:.2f}", *s.max_damping) : "-")));
  }
  if (!s.failed && s.plant && !s.damped_poles.empty() && s.warning) warnings.push_back(*s.warning);
  if (figs.empty() && tables.empty()) return std::nullopt;
  std::string text;
  if (mag.empty()) {
    text = "No damped plant was measured (no unit lists the iff experiment): Figure 2.10a and the damped poles against the "
           "root locus are not shown.";
  }
  if (s.failed) text += (text.empty() ? "" : " ") + std::string("The IFF study failed: ") + *s.failed;
  return json{{"id", "iff"}, {"title", "Integral Force Feedback (report 2.6)"}, {"text", text}, {"warnings", warnings}, {"tables", tables},
              {"figures", figs}};
}

json model_section(const std::vector<UnitCurves>& units) {
  json figs = json::array();
  figs.push_back(frf_figure(units, measured_de, model_de, "model-de", "Fig. 3.4a: 2-DoF model against the measurement, u -> d_e", "um/V",
                            "2-DoF model", false, "Solid: measured; dashed: the tuned 2-DoF model."));
  figs.push_back(frf_figure(units, measured_vs, model_vs, "model-vs", "Fig. 3.4b: 2-DoF model against the measurement, u -> Vs", "V/V",
                            "2-DoF model", false,
                            "Solid: measured; dashed: the tuned 2-DoF model. Its zero is minimum phase: where the measured phase "
                            "falls by 180 deg through the anti-resonance, the model's rises by 180 deg, so on one side of it the "
                            "two curves are one turn (360 deg) apart (the same phase modulo 360 deg)."));
  json rows = json::array(), se_rows = json::array();
  const std::vector<std::string> fitted = {"k1", "c1", "ke", "ce", "ka", "ca", "ga", "gs"};
  for (const auto& u : units) {
    if (!u.result->model_2dof) continue;
    const apa::TwoDofTuning& t = u.result->model_2dof->tuning;
    const apa::TwoDofParams& m = t.params;
    json values = json::array({u.name()});
    report_cells(values, m);
    report_cells(values, t);
    rows.push_back(values);
    if (t.uncertainty.empty()) continue;
    json row = json::array({u.name()});
    for (const auto& n : fitted) row.push_back(io::to_json(100.0 * t.uncertainty.relative_standard_error_of(n)));
    row.push_back(t.undetermined.empty() ? std::string("-") : fmt::format("{}", fmt::join(t.undetermined, ", ")));
    row.push_back(t.uncertainty.condition_number);
    row.push_back(t.uncertainty.high_correlations.empty() ? std::string("-") : fmt::format("{}", fmt::join(t.uncertainty.high_correlations, "; ")));
    se_rows.push_back(row);
  }
  std::vector<std::string> columns = {"unit"};
  report_columns<apa::TwoDofParams>(columns);
  report_columns<apa::TwoDofTuning>(columns);
  json tables = json::array({table("2-DoF parameters per unit (Table 3.1)", columns, rows,
                                    "Report: k1 0.38, c1 5, ke 5.0, ce 100, ka 2.5, ca 50, ga -2.58, gs 0.46. Signs (the report's "
                                    "convention): ga < 0, so more voltage lowers the APA (a negative static gain u -> d_e), while "
                                    "the sensor voltage Vs rises with it (gs > 0).")});
  if (!se_rows.empty()) {
    tables.push_back(table("2-DoF parameters: relative standard errors [%]",
                           {"unit", "k1", "c1", "ke", "ce", "ka", "ca", "ga", "gs", "undetermined", "condition number",
                            "correlations > 0.95"},
                           se_rows,
                           "The random error, linearized at the solution from the FRF's variance (docs/uncertainty.md); ke, "
                           "ce follow ka, ca (ratios 2 imposed). A parameter whose standard error widened by the model's "
                           "local misfit exceeds 5 % (a 95 % interval wider than +-10 %) is undetermined."));
  }
  return {{"id", "model"}, {"title", "Two degrees-of-freedom model (report 3)"},
          {"tables", tables},
          {"figures", figs}};
}

// (Va - middle) / half range against (d_e - middle) / half range: every loop fills [-1, 1].
json normalized(const json& v) {
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& x : v) {
    if (x.is_number()) lo = std::min(lo, x.get<double>()), hi = std::max(hi, x.get<double>());
  }
  json out = json::array();
  for (const auto& x : v) out.push_back(x.is_number() && hi > lo ? json((2.0 * x.get<double>() - lo - hi) / (hi - lo)) : json(nullptr));
  return out;
}

// A report section's figures and tables, filled by its parts in order.
struct SectionParts {
  json figs = json::array();
  json tables = json::array();
};

// Figure 2.3 (every amplitude of the first unit), each unit's normalized loops, and the table of
// the loops' widths per amplitude.
void add_hysteresis_loops(const std::vector<UnitCurves>& units, SectionParts& out) {
  json& figs = out.figs;
  json rows = json::array();
  bool absolute = false;
  std::vector<double> amplitudes;
  for (const auto& u : units) {
    for (const auto& h : u.result->hysteresis) {
      const double a = std::round(h.result.amplitude * 10.0) / 10.0;
      if (std::find(amplitudes.begin(), amplitudes.end(), a) == amplitudes.end()) amplitudes.push_back(a);
    }
  }
  std::sort(amplitudes.begin(), amplitudes.end());
  for (const auto& u : units) {
    if (u.hysteresis.empty()) continue;
    json loops = json::array(), normalized_loops = json::array();
    for (const auto& loop : u.hysteresis) {
      const std::string name = amplitude_label(loop.amplitude_V);
      loops.push_back(trace(name, loop.loop.x, loop.loop.y, name));
      normalized_loops.push_back(trace(name, normalized(loop.loop.x), normalized(loop.loop.y), name));
    }
    if (!absolute) {
      figs.push_back(figure("hysteresis", fmt::format("Fig. 2.3: {}, d_e against Va for each amplitude", u.name()), "Va [V]", false,
                            json::array({panel("d_e [um]", false, loops)})));
      absolute = true;
    }
    figs.push_back(figure(fmt::format("hysteresis-{}", u.result->id), u.name() + ": hysteresis loops, normalized", "(Va - mid) / half range",
                          false, json::array({panel("(d_e - mid) / half range", false, normalized_loops)}),
                          "Each loop scaled to fill [-1, 1] on both axes, so the small ones can be told apart: the wider the "
                          "loop, the larger the hysteresis relative to the stroke."));
    json row = json::array({u.name()});
    for (const double a : amplitudes) {
      json cell = nullptr;
      for (const auto& h : u.result->hysteresis) {
        if (std::abs(h.result.amplitude - a) < 0.05) cell = fmt::format("{:.3g} ({:.1f} %)", h.result.width * kUm, 100.0 * h.result.relative_width);
      }
      row.push_back(cell);
    }
    rows.push_back(row);
  }
  if (!rows.empty()) {
    std::vector<std::string> columns = {"unit"};
    for (const double a : amplitudes) columns.push_back(fmt::format("width at {:.3g} V [um] (of the stroke)", a));
    out.tables.push_back(table("Hysteresis: loop width at the offset per amplitude", columns, rows));
  }
}

// Figure 1.4b: the stroke of every unit.
void add_stroke(const std::vector<UnitCurves>& units, SectionParts& out) {
  json& figs = out.figs;
  json stroke = json::array();
  for (const auto& u : units) {
    if (u.stroke) stroke.push_back(trace(u.name(), u.stroke->x, u.stroke->y, u.name()));
  }
  if (!stroke.empty()) {
    figs.push_back(figure("stroke", "Fig. 1.4b: stroke, displacement against the stack voltage (slow ramp)", "Va [V]", false,
                          json::array({panel("d_e [um]", false, stroke)})));
  }
}

// The Prandtl-Ishlinskii model of the largest loop (docs/hysteresis.md): its fit and the loop it draws.
void add_hysteresis_models(const std::vector<UnitCurves>& units, SectionParts& out) {
  json& figs = out.figs;
  json model_rows = json::array();
  for (const auto& u : units) {
    if (!u.result->hysteresis_model) continue;
    const HysteresisModelFit& h = *u.result->hysteresis_model;
    const ident::HysteresisModel& m = h.fit.model;
    json weights = json::array();
    for (const double w : m.hysteresis.weights) weights.push_back(fmt::format("{:.3g}", w));
    const bool modified = !m.output.identity();
    const ident::HysteresisFit* plain = modified ? (h.alternative ? &*h.alternative : nullptr) : &h.fit;
    const ident::HysteresisFit* kuhnen = modified ? &h.fit : (h.alternative ? &*h.alternative : nullptr);
    const auto residual = [&](const ident::HysteresisFit* f) {
      if (f != nullptr) return fmt::format("{:.2f} % ({})", 100.0 * f->relative_residual, core::to_string(f->quality.verdict));
      return f == kuhnen && !h.alternative_error.empty() ? "failed: " + h.alternative_error : std::string("not fitted");
    };
    model_rows.push_back(json::array({u.name(), modified ? "modified PI" : "PI", fmt::format("{:.2f} %", 100.0 * h.asymmetry),
                                      fmt::format("{:.3g}", h.amplitude), fmt::format("{:.3g}", m.gain * kUmPerV),
                                      fmt::format("{}", fmt::join(weights, " ")),
                                      fmt::format("{:.3g} ({:.2f} %)", h.fit.rms_residual * kUm, 100.0 * h.fit.relative_residual),
                                      residual(plain) + " / " + residual(kuhnen),
                                      fmt::format("{:.1f} % / {:.1f} %", 100.0 * h.width, 100.0 * h.model_width),
                                      core::to_string(h.fit.quality.verdict)}));
    const XY& p = *u.hysteresis_model_record;
    figs.push_back(figure(fmt::format("hysteresis-model-{}", u.result->id), u.name() + ": hysteresis model against the record", "Va [V]", false,
                          json::array({panel("d_e [um]", false,
                                             json::array({trace("record", p.x, p.y, "record"),
                                                          trace(m.output.identity() ? "Prandtl-Ishlinskii model" : "modified Prandtl-Ishlinskii model",
                                                                p.x, u.hysteresis_model_um, "model")}))}),
                          "The model's inverse is the feedforward of the real-time loop (piezobench rt --feedforward) and of the tracking "
                          "experiment (docs/hysteresis.md)."));
  }
  if (!model_rows.empty()) {
    out.tables.push_back(table(fmt::format("Hysteresis model of the largest loop (Prandtl-Ishlinskii, thresholds (i - 1/2) R / n; Kuhnen's "
                                       "modified PI, {} dead zones per side, fitted too when the loop's asymmetry exceeds {:.0f} % "
                                       "of the stroke, kept when better)",
                                       kCampaignDeadZones, 100.0 * kHysteresisAsymmetryLimit),
                           {"unit", "model", "loop asymmetry", "amplitude [V]", "gain [um/V]", "weights", "rms residual [um] (of the stroke)",
                            "residual: PI / modified PI", "width (steady loop, from the best line): record / model", "fit"},
                           model_rows));
  }
}

// The tracking experiment (bench/tracking.hpp): d_e against the command without and with the
// inverse of the model as a feedforward.
void add_tracking(const std::vector<UnitCurves>& units, SectionParts& out) {
  json& figs = out.figs;
  json tracking_rows = json::array();
  for (const auto& u : units) {
    if (!u.result->tracking) continue;
    const TrackingAnalysis& t = *u.result->tracking;
    for (const auto& [w, f] : {std::pair<const char*, const bench::TrackingFigures&>{"sine", t.sine}, {"triangle", t.triangle}}) {
      tracking_rows.push_back(json::array({u.name(), fmt::format("1 Hz {}, {:.3g} V", w, t.amplitude),
                                           fmt::format("{:.1f} % -> {:.2f} %", 100.0 * f.width_open, 100.0 * f.width_ff),
                                           fmt::format("{:.2f} -> {:.2f} ({:.1f}x)", f.rms_open * kUm, f.rms_ff * kUm, f.rms_reduction()),
                                           fmt::format("{:.0f}", f.stroke_open * kUm),
                                           t.feedforward == "given" ? "the given model" : "identified from the open run"}));
    }
    json panels = json::array();
    for (const auto& [w, q] : {std::pair<const char*, const TrackingCurves&>{"sine", *u.tracking_sine}, {"triangle", *u.tracking_triangle}}) {
      panels.push_back(panel(fmt::format("{}: d_e [um]", w), false,
                             json::array({trace("without compensation", q.c, q.open_um, "without compensation"),
                                          trace("with the inverse feedforward", q.c, q.ff_um, "with the inverse feedforward")})));
    }
    figs.push_back(figure(fmt::format("tracking-{}", u.result->id),
                          u.name() + ": d_e against the command, without and with the inverse hysteresis feedforward", "command [V]", false,
                          panels,
                          "The 1 Hz sine and triangle of the tracking experiment (piezobench measure tracking), the last periods of each: "
                          "with the model's inverse in front of the amplifier the loop closes onto a straight line "
                          "(docs/hysteresis.md)."));
  }
  if (!tracking_rows.empty()) {
    out.tables.push_back(table("Tracking without -> with the inverse hysteresis feedforward",
                           {"unit", "command", "hysteresis width (of the stroke)", "rms tracking error [um]", "stroke [um]", "feedforward"},
                           tracking_rows,
                           "Hysteresis width: peak-to-peak deviation of d_e from its best straight line against the command, over the "
                           "stroke. rms tracking error: against the straight line the compensated actuator follows (the record's target)."));
  }
}

std::optional<json> quasi_static_section(const std::vector<UnitCurves>& units) {
  SectionParts parts;
  add_hysteresis_loops(units, parts);
  add_stroke(units, parts);
  add_hysteresis_models(units, parts);
  add_tracking(units, parts);
  if (parts.figs.empty()) return std::nullopt;
  return json{{"id", "quasi-static"}, {"title", "Stroke and hysteresis (report 1.3, 2.1)"}, {"tables", parts.tables}, {"figures", parts.figs}};
}

std::vector<std::string> flatness_columns() {
  std::vector<std::string> columns = {"unit"};
  report_columns<FlatnessAnalysis>(columns);
  return columns;
}

// Report 1.2 (Table 1.1): each unit's probe points against its fitted plane, by position.
std::optional<json> flatness_section(const Campaign& c, const std::vector<UnitCurves>& units) {
  json traces = json::array(), rows = json::array();
  for (const auto& u : units) {
    const auto& f = u.result->flatness_analysis;
    if (!f) continue;
    json x = json::array(), text = json::array();
    for (std::size_t i = 0; i < f->probe_xy.x.size() && i < f->deviation.size(); ++i) {
      x.push_back(static_cast<long>(i) + 1);
      text.push_back(fmt::format("x {:.4g} mm, y {:.4g} mm: {:+.3g} um", f->probe_xy.x[i] * 1e3, f->probe_xy.y[i] * 1e3, f->deviation[i] * kUm));
    }
    json dev = values(std::vector<double>(f->deviation.begin(), f->deviation.begin() + static_cast<std::ptrdiff_t>(x.size())), kUm);
    traces.push_back(with_text(trace(u.name(), x, dev, u.name(), false, "markers"), text));
    json row = json::array({u.name()});
    report_cells(row, *f);
    rows.push_back(row);
  }
  if (traces.empty()) return std::nullopt;
  const std::string method = metrology::to_string(c.specs.flatness_method);
  return json{{"id", "flatness"},
              {"title", "Flatness (report 1.2)"},
              {"text", fmt::format("Every probe point's distance from the unit's fitted plane ({} plane, the specification's method): the "
                                   "plane is the 0 line, the flatness is the spread of the points above and below it.",
                                   method)},
              {"tables", json::array({table("Flatness per unit (flatness: " + method + ")", flatness_columns(), rows)})},
              {"figures", json::array({figure("flatness", "Table 1.1: probe points against the fitted plane", "probe point (file order)", false,
                                              json::array({panel("distance from the plane [um]", false, traces)}),
                                              "Markers: probe points (hover: x, y and the distance); 0: the fitted plane.")})}};
}

// results.json writes stiffness_N_per_um only when one of these is known.
bool has_stiffness(const UnitAnalysis& u) { return k1_of(u) || k_resonance_of(u) || k_oc_of(u); }

// The Prony creep table's columns: the fit's declared ones, then the record's own.
std::vector<std::string> creep_columns() {
  std::vector<std::string> columns{"record"};
  report_columns<ident::CreepFit>(columns);
  for (const char* c : {"instantaneous stiffness [N/um]", "rms residual [um]", "fit"}) columns.emplace_back(c);
  return columns;
}

std::optional<json> stiffness_section(const Campaign& c, const std::vector<UnitCurves>& units) {
  json traces = json::array(), rows = json::array(), creep_rows = json::array();
  for (const auto& u : units) {
    for (const bool open : {false, true}) {
      const std::optional<StiffnessCurves>& s = open ? u.stiffness_open : u.stiffness;
      if (!s) continue;
      const std::string name = u.name() + (open ? ", stacks open" : "");
      traces.push_back(trace(name, s->t, s->de_um, name));
      traces.push_back(trace(name + " creep fit", s->t, s->fit_um, name, true));
    }
    const UnitAnalysis& r = *u.result;
    if (has_stiffness(r)) {
      rows.push_back({u.name(), io::to_json(k1_of(r), kNPerUm), io::to_json(k2_of(r), kNPerUm), io::to_json(k1_of(r), kNPerUm),
                      io::to_json(k_oc_of(r), kNPerUm), io::to_json(k_resonance_of(r), kNPerUm),
                      r.stiffness_analysis ? json(r.stiffness_analysis->result.creep_on * kUm) : json(nullptr)});
    }
    for (const bool open : {false, true}) {
      const std::optional<StiffnessAnalysis>& a = open ? r.stiffness_open_analysis : r.stiffness_analysis;
      if (!a || !a->creep) continue;
      const ident::CreepFit& k = *a->creep;
      // The fit's declared report columns, then what only this record's units name (N in, m out).
      json row = json::array({u.name() + (open ? ", stacks open" : "")});
      report_cells(row, k);
      row.push_back(io::shown_json(k.gain != 0.0 ? -1.0 / k.gain : 0.0, core::shown::kNewtonPerMetreAsNPerUm.per_si));
      row.push_back(io::shown_json(k.rms_residual, core::shown::kMetreAsUm.per_si));
      row.push_back(core::to_string(k.quality.verdict));
      creep_rows.push_back(row);
    }
  }
  if (traces.empty() && rows.empty()) return std::nullopt;
  json figs = json::array();
  if (!traces.empty()) {
    figs.push_back(figure("stiffness", "Fig. 2.4: d_e during the added-mass test", "Time [s]", false,
                          json::array({panel("d_e [um]", false, traces)})));
  }
  json tables = json::array({table("Stiffness per unit [N/um]",
                                   {"unit", "k1", "k2", "k_sc", "k_oc", "from the resonance", "creep under load [um/decade]"}, rows)});
  if (!creep_rows.empty()) {
    tables.push_back(table("Creep, Prony series (d_e = offset + gain (F + sum c_j F_j), F the weight, F_j its "
                           "first-order lags of time constant tau_j)",
                           creep_columns(), creep_rows, "The model piezobench hysteresis creep fits (docs/hysteresis.md); a poor fit says the record's creep is not a "
                                       "sum of these exponentials."));
  }
  return json{{"id", "stiffness"},
              {"title", "Static stiffness (report 2.2)"},
              {"text", fmt::format("Added mass {:g} kg put on and taken off; dashed: the fitted logarithmic creep model. k_sc: the stacks "
                                   "short-circuited (actuators on the amplifier, sensor on the resistor), which is k1; k_oc: the same test "
                                   "with every stack open (report: about 2.3 and 1.7 N/um).",
                                   c.bench.added_mass)},
              {"tables", tables},
              {"figures", figs}};
}

std::optional<json> modes_section(const std::vector<UnitCurves>& units) {
  json traces = json::array();
  for (const auto& u : units) {
    if (u.hammer) traces.push_back(trace(u.name(), u.hammer->x, u.hammer->y, u.name()));
  }
  if (traces.empty()) return std::nullopt;
  return json{{"id", "modes"}, {"title", "Flexible modes, hammer test (report 1.4)"},
              {"figures", json::array({figure("hammer", "Fig. 1.7: force -> vibrometer velocity", "Frequency [Hz]", true,
                                              json::array({panel("|H| [m/s/N]", true, traces)}))})}};
}

// The batch's numbers as tables: the spread per quantity (in the order of the report, with its
// unit), the outliers and the FRF similarity, units by name.
json batch_tables(const CampaignResult& r) {
  const auto name_of = [&](int id) {
    for (const auto& u : r.units) {
      if (u.id == id) return u.name;
    }
    return std::to_string(id);
  };
  const BatchAnalysis& b = r.batch;
  json spread = json::array();
  for (const QuantitySpread& q : b.spread) {
    spread.push_back({fmt::format("{} [{}]", q.label, q.unit), q.units, q.min, q.median, q.max, finite_scaled(q.relative_spread, 100.0), q.mad});
  }
  json tables = json::array({table("Spread over the batch",
                                   {"quantity", "units measured", "minimum", "median", "maximum", "(max - min) / median [%]",
                                    "median absolute deviation"},
                                   spread, "Over the units analysed; a unit that could not be analysed is left out.")});
  if (!b.outliers.empty()) {
    json rows = json::array();
    for (const BatchOutlier& o : b.outliers) {
      std::string label = o.quantity;
      for (const QuantitySpread& q : b.spread) {
        if (q.quantity == o.quantity) label = fmt::format("{} [{}]", q.label, q.unit);
      }
      rows.push_back({name_of(o.unit), label, o.value, o.median, finite_scaled(o.robust_z, 1.0)});
    }
    tables.push_back(table("Batch outliers", {"unit", "quantity", "value", "batch median", "robust z-score"}, rows,
                           fmt::format("Robust z-score: (value - median) / (1.4826 median absolute deviation); an outlier beyond {:.1f} "
                                       "{} the unit when it is a capacitance or the stroke.",
                                       b.rule.threshold, b.rejects ? "rejects" : "would reject (reject_outliers is off)")));
  }
  if (b.similarity) {
    json rows = json::array();
    for (const auto& u : b.similarity->units) rows.push_back({name_of(u.unit), finite_scaled(u.de_rms_dB, 1.0), finite_scaled(u.vs_rms_dB, 1.0)});
    tables.push_back(table("Unit-to-unit similarity of the FRFs",
                           {"unit", "u -> d_e: rms distance from the batch median [dB]", "u -> Vs: rms distance from the batch median [dB]"},
                           rows,
                           fmt::format("|H| on 120 log-spaced frequencies from {:g} to {:g} Hz against the median |H| of the batch.",
                                       b.similarity->fmin_Hz, b.similarity->fmax_Hz)));
  }
  return tables;
}

// Bars with both limits of every spec.
json batch_section(const CampaignResult& result) {
  const Campaign& c = result.campaign;
  const std::vector<UnitAnalysis>& units = result.units;
  json names = json::array();
  for (const auto& u : units) names.push_back(u.name);
  const auto bars = [&](const std::string& name, const std::function<json(const UnitAnalysis&)>& value) {
    json y = json::array();
    for (const auto& u : units) y.push_back(value(u));
    return trace(name, names, y, "", false, "bars");
  };
  const auto limit = [&](const std::string& name, double v) {
    json y = json::array();
    for (std::size_t i = 0; i < names.size(); ++i) y.push_back(v);
    return trace(fmt::format("{} {:.3g}", name, v), names, y, "", true, "lines");
  };
  const auto range = [&](json& t, const std::string& what, const std::optional<metrology::Range>& r, double scale) {
    if (!r) return;
    t.push_back(limit(what + " minimum", r->min * scale));
    if (std::isfinite(r->max)) t.push_back(limit(what + " maximum", r->max * scale));
  };
  const auto capacitance = [](double CapacitanceAnalysis::*which) {
    return [which](const UnitAnalysis& u) { return u.capacitance_analysis ? json((*u.capacitance_analysis).*which * kUf) : json(nullptr); };
  };
  const auto stiffness = [](std::optional<double> (*which)(const UnitAnalysis&)) {
    return [which](const UnitAnalysis& u) { return has_stiffness(u) ? io::to_json(which(u), kNPerUm) : json(nullptr); };
  };
  json figs = json::array();
  std::vector<std::string> not_measured;
  // A figure only when a unit has a bar in it (its first traces are the bars, the limits follow).
  const auto add = [&](const json& traces, const std::string& what, json fig) {
    const bool measured = std::any_of(traces.begin(), traces.end(), [](const json& tr) {
      return tr["mode"] == "bars" && std::any_of(tr["y"].begin(), tr["y"].end(), [](const json& v) { return !v.is_null(); });
    });
    if (measured) {
      figs.push_back(std::move(fig));
    } else {
      not_measured.push_back(what);
    }
  };
  {
    json t = json::array({bars("sensor stack", capacitance(&CapacitanceAnalysis::sensor)),
                          bars("actuator stacks", capacitance(&CapacitanceAnalysis::actuator))});
    range(t, "sensor", c.specs.capacitance_sensor, kUf);
    range(t, "actuator", c.specs.capacitance_actuator, kUf);
    add(t, "capacitance", figure("batch-capacitance", "Capacitance (Table 1.2)", "", false, json::array({panel("C [uF]", false, t)})));
  }
  {
    json t = json::array({bars("k1", stiffness(&k1_of)), bars("k2", stiffness(&k2_of)), bars("k_oc", stiffness(&k_oc_of)),
                          bars("from the resonance", stiffness(&k_resonance_of))});
    range(t, "stiffness", c.specs.stiffness, kNPerUm);
    add(t, "stiffness", figure("batch-stiffness", "Stiffness (Table 2.1)", "", false, json::array({panel("k [N/um]", false, t)})));
  }
  {
    json t = json::array({bars("flatness", [](const UnitAnalysis& u) {
      return u.flatness_analysis ? json(u.flatness_analysis->flatness * kUm) : json(nullptr);
    })});
    if (c.specs.flatness_max) t.push_back(limit("flatness maximum", *c.specs.flatness_max * kUm));
    add(t, "flatness", figure("batch-flatness", "Flatness (Table 1.1, " + metrology::to_string(c.specs.flatness_method) + ")", "", false,
                          json::array({panel("flatness [um]", false, t)})));
  }
  {
    json t = json::array({bars("stroke", [](const UnitAnalysis& u) {
      return u.stroke_analysis ? json(u.stroke_analysis->result.stroke * kUm) : json(nullptr);
    })});
    if (c.specs.stroke_min) t.push_back(limit("stroke minimum", *c.specs.stroke_min * kUm));
    add(t, "stroke", figure("batch-stroke", "Stroke (Figure 1.4)", "", false, json::array({panel("stroke [um]", false, t)}),
                          "The specification gives a minimum stroke only."));
  }
  std::string text = "Dashed lines: the specification's limits (both where it has two).";
  if (!not_measured.empty()) text += fmt::format(" Not measured on any analysed unit, so not drawn: {}.", fmt::join(not_measured, ", "));
  return {{"id", "batch"}, {"title", "Batch comparison"},
          {"text", text},
          {"tables", batch_tables(result)},
          {"figures", figs}};
}

// Section 4: the super element (Figure 4.2): ga and gs tuned against the measurements, u -> d_e
// and u -> V_s, magnitude and phase, with the table of the tuned values.
json superelement_section(const CampaignResult& r, const std::vector<UnitCurves>& units) {
  json figs = json::array(), tables = json::array();
  std::string text;
  const auto& s = r.superelement;
  if (s && !s->failed && s->figure) {
    // Figure 4.2: the tuned model thinned as the unit's measured FRF (unit_curves).
    const SuperElementComparison::Response& m = *s->figure;
    const VectorXd& f = m.model.freq_Hz;
    json fm = json::array();
    std::vector<std::complex<double>> de, vs;
    if (f.size() > 1) {
      for (const Index k : log_indices(f, std::max(0.5, f(1)), std::min(2.0 * r.campaign.analysis.fmax_Hz, f(f.size() - 1)))) {
        fm.push_back(f(k));
        de.push_back(m.model.H[0](k));
        vs.push_back(m.model.H[1](k));
      }
    }
    const Bode se_de = model_lines(fm, de, kUmPerV), se_vs = model_lines(fm, vs, 1.0);
    json de_mag = json::array(), de_ph = json::array(), vs_mag = json::array(), vs_ph = json::array();
    for (const auto& u : units) {
      if (u.name() != m.name || !u.de) continue;
      const Bode &pd = *u.de, &pv = *u.vs;
      de_mag.push_back(trace(u.name() + " measured", pd.f, pd.abs, "measured"));
      de_ph.push_back(trace(u.name() + " measured", pd.f, pd.phase, "measured"));
      vs_mag.push_back(trace(u.name() + " measured", pv.f, pv.abs, "measured"));
      vs_ph.push_back(trace(u.name() + " measured", pv.f, pv.phase, "measured"));
      const auto [xd, yd] = on_branch(se_de.f, se_de.phase, pd.f, pd.phase);
      de_ph.push_back(trace("super element", xd, yd, "model", true));
      const auto [xv, yv] = on_branch(se_vs.f, se_vs.phase, pv.f, pv.phase);
      vs_ph.push_back(trace("super element", xv, yv, "model", true));
    }
    de_mag.push_back(trace("super element", se_de.f, se_de.abs, "model", true));
    vs_mag.push_back(trace("super element", se_vs.f, se_vs.abs, "model", true));
    text = fmt::format("The super element ({}, {} DOF) on the bench ({:.3g} kg on the moving interface), its sensitivities tuned "
                       "against each unit's measured FRFs (docs/apa300ml.md) and compared with eq. 4.1 for Table 4.1's "
                       "constants and the stacks' effective modulus {:.3g} GPa (Table 4.1: 48 GPa): ga {:.3g} N/V, gs {:.3g} V/um.",
                       s->source, s->dofs, s->moving_mass, s->stack_modulus * 1e-9, s->eq41_ga, s->eq41_gs * core::shown::kVoltPerMetreAsVPerUm.per_si);
    json rows = json::array();
    for (const SuperElementUnitFit& row : s->units) {
      json cells = json::array();
      report_cells(cells, row);
      rows.push_back(cells);
    }
    std::vector<std::string> columns;
    report_columns<SuperElementUnitFit>(columns);
    tables.push_back(table("ga and gs tuned per unit against eq. 4.1", columns,
                           rows,
                           "Errors: median |model / measured| in dB from the tuning band's start to 300 Hz. Signs: ga "
                           "and gs carry the signs that make the model's phases agree with the measurement in the super "
                           "element's own axes (ga > 0 with gs < 0, or the reverse); the 2-DoF model's convention is ga < 0, "
                           "gs > 0. The data fix only the sign of the product ga gs (negative in both), so the comparison with eq. 4.1 "
                           "is on |ga| and |gs|."));
    figs.push_back(figure("superelement", "Fig. 4.2: super element against the measurement of " + m.name + " (u -> d_e, u -> V_s)",
                          "Frequency [Hz]", true,
                          json::array({panel("|u -> d_e| [um/V]", true, de_mag), panel("d_e phase [deg]", false, de_ph),
                                       panel("|u -> V_s| [V/V]", true, vs_mag), panel("V_s phase [deg]", false, vs_ph)}),
                          "Solid: measured (Welch H1); dashed: the super element with the tuned ga and gs (no measurement "
                          "chain: high-pass, anti-aliasing and delays are not in the model)."));
  } else if (s && s->failed) {
    text = "The super element's comparison failed: " + *s->failed;
  } else {
    text = "Not part of this campaign: no super element was given. A [superelement] table in the campaign file (docs/campaign.md) "
           "adds the finite-element model's u -> d_e and u -> V_s against the measured FRFs here (report Figure 4.2).";
  }
  return {{"id", "superelement"}, {"title", "Super element (report 4)"}, {"text", text}, {"tables", tables}, {"figures", figs}};
}

}  // namespace

// A section of the report whose experiment no unit of the campaign lists (or none could be
// analysed): its title, and why it has no figure, instead of empty plots.
json not_run(const std::string& id, const std::string& title, const std::string& experiments) {
  return {{"id", id},
          {"title", title},
          {"text", "Not measured in this campaign: no analysed unit has " + experiments + ", so this section has no figure or table."},
          {"figures", json::array()}};
}

json report_document(const CampaignResult& result) {
  const Campaign& c = result.campaign;
  std::vector<UnitCurves> units;
  for (const auto& u : result.units) units.push_back(unit_curves(c, u));
  const auto any = [&](const std::function<bool(const UnitCurves&)>& has) { return std::any_of(units.begin(), units.end(), has); };
  json sections = json::array();
  const bool has_frf = any([](const UnitCurves& u) { return u.de.has_value(); });
  // Section 2.3: frequency responses (Figure 2.5), 2.4: the NMP zero (Figure 2.6).
  sections.push_back(has_frf ? frf_section(units) : not_run("frf", "Frequency responses (report 2.3)", "an FRF record (frf)"));
  if (any([](const UnitCurves& u) { return u.nmp.has_value(); })) {
    sections.push_back(nmp_section(units));
  } else {
    sections.push_back(not_run("nmp", "The non-minimum-phase zero (report 2.4)", "an anti-resonance in u -> Vs (frf)"));
  }
  // Section 2.5: the resistor (Figure 2.7); 2.6: IFF (Figures 2.8, 2.10).
  const auto add = [&](const std::optional<json>& section, const char* id, const char* title, const char* experiments) {
    sections.push_back(section ? *section : not_run(id, title, experiments));
  };
  add(resistor_section(c, units), "resistor", "The resistor across the force sensor (report 2.5)", "a record without the resistor (frf_without_resistor)");
  add(iff_section(units, result.iff), "iff", "Integral Force Feedback (report 2.6)", "an FRF record (frf) or IFF records (iff)");
  // Section 3: the 2-DoF model (Figure 3.4).
  if (any([](const UnitCurves& u) { return u.model_de.has_value(); })) {
    sections.push_back(model_section(units));
  } else {
    sections.push_back(not_run("model", "Two degrees-of-freedom model (report 3)", has_frf ? "a tuned 2-DoF model (the tuning failed: see each unit's failed list in results.json)" : "an FRF record (frf)"));
  }
  // Sections 2.1 and 1.3: hysteresis and stroke (Figures 2.3, 1.4b); 2.2: stiffness (Figure 2.4),
  // short and open circuit; 1.4: flexible modes (Figure 1.7).
  add(flatness_section(c, units), "flatness", "Flatness (report 1.2)", "a flatness record (flatness)");
  add(quasi_static_section(units), "quasi-static", "Stroke and hysteresis (report 1.3, 2.1)", "a stroke, hysteresis or tracking record");
  add(stiffness_section(c, units), "stiffness", "Static stiffness (report 2.2)", "a static stiffness record (stiffness, stiffness_open_circuit) or a resonance");
  add(modes_section(units), "modes", "Flexible modes, hammer test (report 1.4)", "a hammer test record (hammer)");
  sections.push_back(batch_section(result));
  sections.push_back(superelement_section(result, units));
  return {{"title", c.title},
          {"subtitle", fmt::format("{} — piezobench {}", c.file.filename().string(), kVersion)},
          {"results", results_json(result)},
          {"sections", sections}};
}

}  // namespace piezobench::campaign
