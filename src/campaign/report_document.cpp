#include "piezobench/campaign/report_document.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <optional>
#include <tuple>

#include "piezobench/apa/two_dof.hpp"
#include "piezobench/campaign/results_json.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/io/json.hpp"
#include "piezobench/version.hpp"

namespace piezobench::campaign {

using Eigen::Index;
using Eigen::VectorXd;
using nlohmann::json;

namespace {

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
  json out = json::array();
  double prev = 0.0, offset = 0.0;
  for (std::size_t i = 0; i < h.size(); ++i) {
    const double p = std::arg(h[i]) * 180.0 / std::numbers::pi;
    if (i > 0) {
      while (p + offset - prev > 180.0) offset -= 360.0;
      while (p + offset - prev < -180.0) offset += 360.0;
    }
    prev = p + offset;
    out.push_back(prev);
  }
  return out;
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

// |H|, coherence and unwrapped phase of one output at the indices `idx` (|H| times `scale`).
json frf_lines(const dsp::Frf& frf, Index output, const std::vector<Index>& idx, double scale) {
  const auto o = static_cast<std::size_t>(output);
  json p = {{"f", json::array()}, {"abs", json::array()}, {"coh", json::array()}};
  std::vector<std::complex<double>> h;
  for (const Index k : idx) {
    p["f"].push_back(frf.freq_hz(k));
    p["abs"].push_back(std::abs(frf.H[o](k)) * scale);
    p["coh"].push_back(frf.coherence[o].size() > 0 ? json(frf.coherence[o](k)) : json(nullptr));
    h.push_back(frf.H[o](k));
  }
  p["phase"] = unwrapped_degrees(h);
  return p;
}

json stiffness_curves(const StiffnessAnalysis& s) {
  return {{"t", values(s.de.x)}, {"de_um", values(s.de.y, 1e6)}, {"fit_um", values(s.fit.y, 1e6)}};
}

// The curves of one unit's analyses, under the keys the figures read.
json unit_plots(const Campaign& c, const UnitAnalysis& u) {
  json plots = json::object();
  if (u.flatness_analysis) plots["flatness_deviation_um"] = values(u.flatness_analysis->deviation, 1e6);
  if (u.stroke_analysis) {
    plots["stroke"] = {{"Va", values(u.stroke_analysis->de_vs_va.x)}, {"de_um", values(u.stroke_analysis->de_vs_va.y, 1e6)}};
  }
  if (!u.hysteresis.empty()) {
    json loops = json::array();
    for (const auto& h : u.hysteresis) {
      loops.push_back({{"amplitude_V", h.result.amplitude}, {"Va", values(h.loop.x)}, {"de_um", values(h.loop.y, 1e6)}});
    }
    plots["hysteresis"] = loops;
  }
  if (u.hysteresis_model) {
    const HysteresisModelFit& h = *u.hysteresis_model;
    plots["hysteresis_model"] = {{"Va", values(h.loop.x)}, {"de_um", values(h.loop.y, 1e6)}, {"model_um", values(h.model_loop.y, 1e6)}};
  }
  if (u.stiffness_analysis) plots["stiffness"] = stiffness_curves(*u.stiffness_analysis);
  if (u.stiffness_open_analysis) plots["stiffness_open"] = stiffness_curves(*u.stiffness_open_analysis);
  if (u.frf) {
    const dsp::Frf& frf = *u.frf;
    const VectorXd& f = frf.freq_hz;
    const std::vector<Index> idx = log_indices(f, std::max(0.5, f(1)), std::min(2.0 * c.analysis.fmax_hz, f(f.size() - 1)));
    VectorXd w(static_cast<Index>(idx.size()));
    for (std::size_t i = 0; i < idx.size(); ++i) w(static_cast<Index>(i)) = kTwoPi * f(idx[i]);
    if (u.model_2dof) {
      apa::TwoDofBench b = u.model_2dof->bench;
      const lti::CMatrix hm = apa::two_dof_response(u.model_2dof->tuning.params, b, w);
      json m = {{"f", json::array()}, {"de_abs", json::array()}, {"Vs_abs", json::array()}};
      std::vector<std::complex<double>> mde, mvs;
      for (Index k = 0; k < w.size(); ++k) {
        m["f"].push_back(w(k) / kTwoPi);
        m["de_abs"].push_back(std::abs(hm(k, 0)) * 1e6);
        m["Vs_abs"].push_back(std::abs(hm(k, 1)));
        mde.push_back(hm(k, 0));
        mvs.push_back(hm(k, 1));
      }
      m["de_phase"] = unwrapped_degrees(mde);
      m["Vs_phase"] = unwrapped_degrees(mvs);
      plots["model"] = m;
    }
    const json de = frf_lines(frf, 0, idx, 1e6), vs = frf_lines(frf, 1, idx, 1.0);
    json p = {{"f", de["f"]}, {"de_abs", de["abs"]}, {"de_coh", de["coh"]}, {"de_phase", de["phase"]},
              {"Vs_abs", vs["abs"]}, {"Vs_coh", vs["coh"]}, {"Vs_phase", vs["phase"]}};
    if (u.iff_plant) {
      const Eigen::VectorXcd g = u.iff_plant->response(w);
      p["iff_fit_abs"] = json::array();
      std::vector<std::complex<double>> hg;
      for (Index k = 0; k < g.size(); ++k) {
        p["iff_fit_abs"].push_back(std::abs(g(k)));
        hg.push_back(g(k));
      }
      p["iff_fit_phase"] = unwrapped_degrees(hg);
    }
    plots["frf"] = p;
    // Every line around the anti-resonance (report Figure 2.6: coherence and phase there).
    if (u.antiresonance_Hz) {
      const double fz = *u.antiresonance_Hz;
      std::vector<Index> near;
      for (Index k = 0; k < f.size(); ++k) {
        if (f(k) >= 0.7 * fz && f(k) <= 1.4 * fz) near.push_back(k);
      }
      json z = frf_lines(frf, 1, near, 1.0);
      z["antiresonance_Hz"] = fz;
      plots["nmp"] = z;
    }
  }
  if (u.resistor) {
    // Figure 2.7: up to 20 Hz.
    const auto lines = [](const LowFrequencyVs& v) {
      const VectorXd& f = v.frf.freq_hz;
      return frf_lines(v.frf, 0, log_indices(f, v.lowest_line_Hz, std::min(20.0, f(f.size() - 1)), 200), 1.0);
    };
    json r = json::object();
    if (u.resistor->with_resistor) r["with"] = lines(*u.resistor->with_resistor);
    r["without"] = lines(u.resistor->without_resistor);
    plots["resistor"] = r;
  }
  json damped = json::array();
  for (const DampedPlant& d : u.damped) {
    if (!d.identified) continue;
    const VectorXd& f = d.frf.freq_hz;
    const std::vector<Index> idx =
        log_indices(f, std::max(f(1), 0.5 * c.analysis.damped_fmin_hz), std::min(f(f.size() - 1), 2.0 * c.analysis.damped_fmax_hz), 300);
    VectorXd om(static_cast<Index>(idx.size()));
    for (std::size_t i = 0; i < idx.size(); ++i) om(static_cast<Index>(i)) = kTwoPi * f(idx[i]);
    // The fit (delay removed) with the delay put back, to sit on the measurement.
    const Eigen::MatrixXcd fit = d.identified->fit.evaluate(om);
    json p = {{"gain", d.gain}, {"f", json::array()}, {"abs", json::array()}, {"fit_abs", json::array()}};
    std::vector<std::complex<double>> hm, hf;
    for (std::size_t i = 0; i < idx.size(); ++i) {
      const auto k = static_cast<Index>(i);
      const std::complex<double> g = fit(k, 0) * std::exp(std::complex<double>(0.0, -om(k) * d.delay_removed));
      p["f"].push_back(f(idx[i]));
      p["abs"].push_back(std::abs(d.frf.H[0](idx[i])) * 1e6);
      p["fit_abs"].push_back(std::abs(g) * 1e6);
      hm.push_back(d.frf.H[0](idx[i]));
      hf.push_back(g);
    }
    p["phase"] = unwrapped_degrees(hm);
    p["fit_phase"] = unwrapped_degrees(hf);
    damped.push_back(p);
  }
  if (!u.damped.empty()) plots["damped"] = damped;
  if (u.flexible_modes) {
    const dsp::Frf& frf = u.flexible_modes->frf;
    json x = json::array(), y = json::array();
    for (const Index k : log_indices(frf.freq_hz, std::max(1.0, frf.freq_hz(1)), frf.freq_hz(frf.freq_hz.size() - 1), 500)) {
      x.push_back(frf.freq_hz(k));
      y.push_back(std::abs(frf.H[0](k)));
    }
    plots["hammer"] = {{"f", x}, {"abs", y}};
  }
  return plots;
}

// The batch-level curves: the root locus of the IFF study, the super element's u -> d_e.
json extra_plots(const CampaignResult& r) {
  json extra = json::object();
  const IffStudy& s = r.iff;
  if (s.plant && !s.failed) {
    const ident::IffPlantFit& p = *s.plant;
    const auto gain_label = [](double g) { return fmt::format("g = {:.3g}", g); };
    json branches = json::array();
    for (const auto& b : s.branches) {
      json text = json::array();
      for (const double g : b.gains) text.push_back(gain_label(g));
      branches.push_back({{"re", values(b.re_im.x)}, {"im", values(b.re_im.y)}, {"text", text}, {"resonance_branch", b.resonance_branch}});
    }
    json damped = json::array(), model = json::array();
    for (std::size_t i = 0; i < s.gains.size(); ++i) {
      damped.push_back({{"gain", s.gains[i]}, {"re", s.damped_poles[i].real()}, {"im", s.damped_poles[i].imag()}});
      model.push_back({{"gain", s.gains[i]}, {"re", s.model_poles[i].real()}, {"im", s.model_poles[i].imag()}});
    }
    extra["root_locus"] = {{"branches", branches},
                           {"open_loop_poles", {{"re", values(s.open_loop_poles.x)}, {"im", values(s.open_loop_poles.y)}}},
                           {"open_loop_zeros", {{"re", values(s.open_loop_zeros.x)}, {"im", values(s.open_loop_zeros.y)}}},
                           {"damped", damped},
                           {"model_at_gains", model},
                           {"optimum", {{"gain", s.optimal_gain.value_or(0.0)}, {"re", s.optimal_pole.real()}, {"im", s.optimal_pole.imag()},
                                        {"damping", s.max_damping.value_or(0.0)}}},
                           {"unit", *s.unit},
                           {"open_loop_pole", {p.wp * -p.xp, p.wp * std::sqrt(std::max(0.0, 1 - p.xp * p.xp))}}};
  }
  if (r.superelement && !r.superelement->failed && r.superelement->figure) {
    // Figure 4.2: the tuned model thinned as the unit's measured FRF (unit_plots).
    const SuperElementComparison::Response& m = *r.superelement->figure;
    const VectorXd& f = m.freq_Hz;
    json p = {{"unit", m.name}, {"f", json::array()}, {"de_abs", json::array()}, {"Vs_abs", json::array()}};
    std::vector<std::complex<double>> de, vs;
    if (f.size() > 1) {
      for (const Index k : log_indices(f, std::max(0.5, f(1)), std::min(2.0 * r.campaign.analysis.fmax_hz, f(f.size() - 1)))) {
        p["f"].push_back(f(k));
        p["de_abs"].push_back(std::abs(m.de(k)) * 1e6);
        p["Vs_abs"].push_back(std::abs(m.vs(k)));
        de.push_back(m.de(k));
        vs.push_back(m.vs(k));
      }
    }
    p["de_phase"] = unwrapped_degrees(de);
    p["Vs_phase"] = unwrapped_degrees(vs);
    extra["superelement"] = p;
  }
  return extra;
}

// What the figures read of a unit.
struct UnitPlots {
  int id = 0;
  std::string name;
  json plots;
};

// ------------------------------------------------------------------------------------ layout

json trace(const std::string& name, const json& x, const json& y, const std::string& group = "", bool dash = false,
           const std::string& mode = "lines") {
  json t = {{"name", name}, {"x", x}, {"y", y}, {"mode", mode}, {"dash", dash}};
  if (!group.empty()) t["group"] = group;
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

bool has(const json& j, const char* key) { return j.is_object() && j.contains(key) && !j[key].is_null(); }

// j[a][b]... or null.
json at(const json& j, std::initializer_list<const char*> path) {
  const json* v = &j;
  for (const char* k : path) {
    if (!has(*v, k)) return nullptr;
    v = &(*v)[k];
  }
  return *v;
}
json scaled(const json& v, double s) { return v.is_number() ? json(v.get<double>() * s) : json(nullptr); }

// A model's phase drawn on the measurement's branch: each model point is moved by the multiple of
// 360 degrees that brings it nearest to the measured phase at the nearest frequency (phases are
// defined modulo 360 degrees; unwrapped separately, a model and its measurement can sit one turn
// apart). Where that multiple changes (a model zero on the other side of the axis than the
// measured one), a gap is left rather than a vertical line.
std::pair<json, json> on_branch(const json& f_model, const json& ph_model, const json& f_ref, const json& ph_ref) {
  json x = json::array(), y = json::array();
  std::size_t j = 0;
  double last_shift = 0.0;
  bool first = true;
  for (std::size_t i = 0; i < f_model.size(); ++i) {
    if (!f_model[i].is_number() || !ph_model[i].is_number()) continue;
    const double f = f_model[i].get<double>(), ph = ph_model[i].get<double>();
    while (j + 1 < f_ref.size() && f_ref[j + 1].is_number() && std::abs(f_ref[j + 1].get<double>() - f) <= std::abs(f_ref[j].get<double>() - f)) ++j;
    double shift = last_shift;
    if (j < ph_ref.size() && ph_ref[j].is_number()) shift = 360.0 * std::round((ph_ref[j].get<double>() - ph) / 360.0);
    if (!first && shift != last_shift) {
      x.push_back(f);
      y.push_back(nullptr);
    }
    x.push_back(f);
    y.push_back(ph + shift);
    last_shift = shift;
    first = false;
  }
  return {x, y};
}

// Magnitude and phase (and coherence) of one output, all units, the measurement solid and a model
// dashed, the model's phase on the measurement's branch.
json frf_figure(const std::vector<UnitPlots>& units, const std::string& out, const std::string& id, const std::string& title,
                const std::string& unit_label, const std::string& model_key, const std::string& model_abs,
                const std::string& model_phase, const std::string& model_name, bool coherence, const std::string& text) {
  json mag = json::array(), phase = json::array(), coh = json::array();
  for (const auto& u : units) {
    if (!has(u.plots, "frf")) continue;
    const json& p = u.plots["frf"];
    mag.push_back(trace(u.name, p["f"], p[out + "_abs"], u.name));
    phase.push_back(trace(u.name, p["f"], p[out + "_phase"], u.name));
    if (coherence) coh.push_back(trace(u.name, p["f"], p[out + "_coh"], u.name));
    const json m = model_key.empty() ? p : at(u.plots, {model_key.c_str()});
    if (has(m, model_abs.c_str()) && has(m, model_phase.c_str())) {
      mag.push_back(trace(u.name + " " + model_name, m["f"], m[model_abs], u.name, true));
      const auto [x, y] = on_branch(m["f"], m[model_phase], p["f"], p[out + "_phase"]);
      phase.push_back(trace(u.name + " " + model_name, x, y, u.name, true));
    }
  }
  json panels = json::array({panel("|H| [" + unit_label + "]", true, mag), panel("Phase [deg]", false, phase)});
  if (coherence) panels.push_back(panel("Coherence", false, coh));
  return figure(id, title, "Frequency [Hz]", true, panels, text);
}

std::string amplitude_label(double a) { return fmt::format("{:.3g} V", a); }

// The document from the results.json document, the units' curves and the batch curves.
json document(const Campaign& c, const std::vector<UnitPlots>& units, const json& results, const json& extra) {
  json sections = json::array();
  const auto any = [&](const char* key) {
    return std::any_of(units.begin(), units.end(), [&](const UnitPlots& u) { return has(u.plots, key); });
  };
  const json& result_units = results["units"];
  const auto result_of = [&](const UnitPlots& u) -> json {
    for (const auto& r : result_units) {
      if (r.contains("id") && r["id"] == u.id) return r;
    }
    return json::object();
  };

  // ---- Section 2.3: frequency responses (Figure 2.5), 2.4: the NMP zero (Figure 2.6).
  if (any("frf")) {
    json figs = json::array();
    figs.push_back(frf_figure(units, "de", "frf-de", "Fig. 2.5a: u -> d_e", "um/V", "model", "de_abs", "de_phase", "2-DoF model", true,
                              "Solid: measured (Welch H1); dashed: the tuned 2-DoF model (section 3). The model's phase is drawn "
                              "on the measurement's branch (modulo 360 deg)."));
    figs.push_back(frf_figure(units, "Vs", "frf-vs", "Fig. 2.5b: u -> Vs", "V/V", "", "iff_fit_abs", "iff_fit_phase", "IFF plant fit", true,
                              "Solid: measured; dashed: the IFF plant fit (eq. 2.3 with delay). The phase falls by 180 deg at the "
                              "anti-resonance: a non-minimum-phase zero."));
    json rows = json::array();
    for (const auto& u : units) {
      const json r = result_of(u);
      if (!has(r, "frf")) continue;
      const json& f = r["frf"];
      const json verdict = at(f, {"zero_is_nonminimum_phase"});
      rows.push_back({u.name, at(f, {"static_gain_um_per_V"}), at(f, {"resonance_Hz"}), at(f, {"resonance_damping"}),
                      at(f, {"antiresonance_Hz"}), at(f, {"antiresonance_damping"}),
                      verdict.is_boolean() ? json(verdict.get<bool>() ? "non-minimum phase" : "minimum phase") : json(nullptr),
                      at(f, {"nmp_evidence", "phase_change_deg"}), at(f, {"shell_stiffness_N_per_um"}), at(r, {"hpf_corner_Hz"})});
    }
    json tables = json::array({table("FRF features per unit",
                                     {"unit", "static gain [um/V]", "resonance [Hz]", "damping", "anti-resonance [Hz]", "zero damping",
                                      "zero", "phase change at the zero [deg]", "k_shell [N/um]", "HPF corner [Hz]"},
                                     rows, "Zero damping < 0: the zero is in the right half plane.")});
    sections.push_back({{"id", "frf"}, {"title", "Frequency responses (report 2.3)"},
                        {"text", "FRFs from the DAC voltage u to the encoder d_e and to the force-sensor voltage Vs, all units "
                                 "overlaid, with the coherence."},
                        {"tables", tables}, {"figures", figs}});
  }
  if (any("nmp")) {
    json coh = json::array(), phase = json::array(), mag = json::array();
    json rows = json::array();
    for (const auto& u : units) {
      if (!has(u.plots, "nmp")) continue;
      const json& z = u.plots["nmp"];
      mag.push_back(trace(u.name, z["f"], z["abs"], u.name, false, "lines+markers"));
      coh.push_back(trace(u.name, z["f"], z["coh"], u.name, false, "lines+markers"));
      phase.push_back(trace(u.name, z["f"], z["phase"], u.name, false, "lines+markers"));
      const json r = result_of(u);
      rows.push_back({u.name, at(r, {"frf", "antiresonance_Hz"}), at(r, {"frf", "antiresonance_damping"}),
                      at(r, {"frf", "nmp_evidence", "phase_change_deg"}), at(r, {"frf", "nmp_evidence", "phase_verdict"}),
                      at(r, {"frf", "nmp_evidence", "verdict_from"})});
    }
    sections.push_back(
        {{"id", "nmp"}, {"title", "The non-minimum-phase zero (report 2.4)"},
         {"text", "u -> Vs around the anti-resonance, every frequency line. A minimum-phase zero pair raises the phase by 180 deg, "
                  "a non-minimum-phase one lowers it by 180 deg; the coherence says whether the data there can be trusted."},
         {"tables", json::array({table("Verdict per unit",
                                       {"unit", "anti-resonance [Hz]", "zero damping", "phase change [deg]", "verdict of the phase",
                                        "verdict from"},
                                       rows)})},
         {"figures", json::array({figure("nmp-zoom", "Fig. 2.6: u -> Vs at the anti-resonance", "Frequency [Hz]", false,
                                         json::array({panel("|H| [V/V]", true, mag), panel("Coherence", false, coh),
                                                      panel("Phase [deg]", false, phase)}))})}});
  }

  // ---- Section 2.5: the resistor (Figure 2.7).
  {
    json mag = json::array(), phase = json::array(), rows = json::array();
    for (const auto& u : units) {
      if (!has(u.plots, "resistor")) continue;
      for (const char* which : {"with", "without"}) {
        const json p = at(u.plots, {"resistor", which});
        if (p.is_null()) continue;
        const std::string name = u.name + (std::string(which) == "with" ? ", with R" : ", without R");
        mag.push_back(trace(name, p["f"], p["abs"], name));
        phase.push_back(trace(name, p["f"], p["phase"], name));
      }
      const json r = at(result_of(u), {"hpf_resistor"});
      const auto corner = [&](const char* which) -> json {
        const json w = at(r, {which});
        if (w.is_null()) return nullptr;
        if (has(w, "corner_Hz")) return w["corner_Hz"];
        return has(w, "below_Hz") ? json(fmt::format("below {:.2g} (not observable)", w["below_Hz"].get<double>())) : json(nullptr);
      };
      rows.push_back({u.name, corner("with_resistor"), corner("without_resistor"), at(r, {"without_resistor", "fitted_corner_Hz"}),
                      at(r, {"without_resistor", "lowest_line_Hz"}), at(result_of(u), {"hpf", "R_C_Hz"})});
    }
    if (!mag.empty()) {
      sections.push_back(
          {{"id", "resistor"}, {"title", "The resistor across the force sensor (report 2.5)"},
           {"text", fmt::format("u -> Vs at low frequency with and without the {:.3g} kOhm resistor in parallel with the sensor "
                                "stack: with it, a high-pass at 1/(2 pi R C).", c.bench.hpf_resistance * 1e-3)},
           {"tables", json::array({table("High-pass corner per unit",
                                         {"unit", "with R [Hz]", "without R [Hz]", "fitted without R [Hz]", "lowest line [Hz]",
                                          "1/(2 pi R C_sensor) [Hz]"},
                                         rows,
                                         "First-order high-pass fitted below the campaign's hpf_fmax_Hz. A corner below a third "
                                         "of the record's lowest line is reported as not observable.")})},
           {"figures", json::array({figure("resistor", "Fig. 2.7: u -> Vs with and without the resistor", "Frequency [Hz]", true,
                                           json::array({panel("|H| [V/V]", true, mag), panel("Phase [deg]", false, phase)}))})}});
    }
  }

  // ---- Section 2.6: IFF (Figures 2.8, 2.10).
  {
    json figs = json::array(), tables = json::array(), warnings = json::array();
    // Figure 2.8: the IFF plant of the IFF unit against its fit.
    const UnitPlots* iff_unit = nullptr;
    const json iff = at(results, {"iff"});
    for (const auto& u : units) {
      if (!iff_unit && has(u.plots, "frf") && has(u.plots["frf"], "iff_fit_abs") && (!has(iff, "unit") || iff["unit"] == u.id)) iff_unit = &u;
    }
    if (iff_unit) {
      const json& p = iff_unit->plots["frf"];
      const auto [x, y] = on_branch(p["f"], p["iff_fit_phase"], p["f"], p["Vs_phase"]);
      figs.push_back(figure("iff-plant", fmt::format("Fig. 2.8: IFF plant of {} and its fit (eq. 2.3)", iff_unit->name), "Frequency [Hz]", true,
                            json::array({panel("|H| [V/V]", true,
                                               json::array({trace("measured", p["f"], p["Vs_abs"], "measured"),
                                                            trace("fit (eq. 2.3 with delay)", p["f"], p["iff_fit_abs"], "fit", true)})),
                                         panel("Phase [deg]", false,
                                               json::array({trace("measured", p["f"], p["Vs_phase"], "measured"),
                                                            trace("fit (eq. 2.3 with delay)", x, y, "fit", true)})),
                                         panel("Coherence", false, json::array({trace("measured", p["f"], p["Vs_coh"], "measured")}))}),
                            "u -> Vs of the unit whose IFF data make the batch's IFF result, against the fitted plant model."));
    }
    json prow = json::array();
    for (const auto& u : units) {
      const json f = at(result_of(u), {"frf", "iff_plant_fit"});
      if (f.is_null()) continue;
      prow.push_back({u.name, f["g0"], f["wz_Hz"], f["xz"], f["wp_Hz"], f["xp"], f["w_hpf_Hz"], scaled(f["delay_s"], 1e6),
                      f["relative_rms_error"]});
    }
    if (!prow.empty()) {
      tables.push_back(table("IFF plant (eq. 2.3) per unit",
                             {"unit", "g0", "w_z [Hz]", "xi_z", "w_p [Hz]", "xi_p", "w_HPF [Hz]", "delay [us]", "relative rms error"}, prow,
                             "The report's hand-tuned values: g0 0.64, w_z 42.7 Hz, xi_z 0.4 %, w_p 95.2 Hz, xi_p 2 %, "
                             "w_HPF 0.4 Hz, 200 us."));
    }
    if (extra.contains("root_locus")) {
      const json& rl = extra["root_locus"];
      const auto gain_text = [](const json& list) {
        json re = json::array(), im = json::array(), text = json::array();
        for (const auto& d : list) {
          re.push_back(d["re"]);
          im.push_back(d["im"]);
          text.push_back(fmt::format("g = {:.3g}", d["gain"].get<double>()));
        }
        return std::tuple{re, im, text};
      };
      json traces = json::array();
      for (const auto& b : rl["branches"]) {
        traces.push_back(with_text(trace("root locus of the model", b["re"], b["im"], "root locus of the model"), b["text"]));
      }
      if (has(rl, "open_loop_poles")) {
        traces.push_back(trace("open-loop poles", rl["open_loop_poles"]["re"], rl["open_loop_poles"]["im"], "", false, "markers"));
      }
      if (has(rl, "open_loop_zeros")) {
        traces.push_back(trace("open-loop zeros", rl["open_loop_zeros"]["re"], rl["open_loop_zeros"]["im"], "", true, "markers"));
      }
      if (has(rl, "model_at_gains")) {
        const auto [re, im, text] = gain_text(rl["model_at_gains"]);
        traces.push_back(with_text(trace("model at the measured gains", re, im, "", true, "markers"), text));
      }
      {
        const auto [re, im, text] = gain_text(rl["damped"]);
        if (!re.empty()) traces.push_back(with_text(trace("identified damped poles", re, im, "", false, "markers"), text));
      }
      if (has(rl, "optimum")) {
        const json& o = rl["optimum"];
        traces.push_back(with_text(trace("optimum", json::array({o["re"]}), json::array({o["im"]}), "", false, "markers"),
                                   json::array({fmt::format("g = {:.3g}, damping {:.2f}", o["gain"].get<double>(), o["damping"].get<double>())})));
      }
      figs.push_back(figure("root-locus", fmt::format("Fig. 2.10b: root locus, APA {}", rl["unit"].get<int>()), "Re [rad/s]", false,
                            json::array({panel("Im [rad/s]", false, traces)}),
                            "Closed-loop poles of 1 - g K(s) G(s) = 0 for the fitted plant G (eq. 2.3 with delay) and the report's "
                            "controller K (eq. 2.4), every branch inside 3 w_p; open circles: the model's poles at the measured gains; "
                            "filled: the poles identified on the measured damped plants (dominant pair of a vector fit). Hover for "
                            "the gains."));
    }
    json mag = json::array(), phase = json::array();
    for (const auto& u : units) {
      if (!has(u.plots, "damped")) continue;
      for (const auto& d : u.plots["damped"]) {
        const std::string name = fmt::format("{} g = {:.3g}", u.name, d["gain"].get<double>());
        mag.push_back(trace(name, d["f"], d["abs"], name));
        mag.push_back(trace(name + " fit", d["f"], d["fit_abs"], name, true));
        if (has(d, "phase")) {
          phase.push_back(trace(name, d["f"], d["phase"], name));
          const auto [x, y] = on_branch(d["f"], d["fit_phase"], d["f"], d["phase"]);
          phase.push_back(trace(name + " fit", x, y, name, true));
        }
      }
    }
    if (!mag.empty()) {
      figs.push_back(figure("damped-plants", "Fig. 2.10a: damped plants u' -> d_e", "Frequency [Hz]", true,
                            json::array({panel("|H| [um/V]", true, mag), panel("Phase [deg]", false, phase)}),
                            "Solid: measured; dashed: the vector fits whose dominant pole is the identified damped pole."));
    }
    if (has(iff, "gains") && !iff["gains"].empty()) {
      json rows = json::array();
      const json distance = at(iff, {"relative_pole_distance"});
      for (std::size_t i = 0; i < iff["gains"].size(); ++i) {
        const auto info = [](const json& p) -> std::pair<json, json> {
          if (!p.is_array() || p.size() != 2 || !p[0].is_number()) return {nullptr, nullptr};
          const double re = p[0].get<double>(), im = p[1].get<double>(), w = std::hypot(re, im);
          return {w / kTwoPi, -re / w};
        };
        const auto [fi, zi] = info(iff["damped_poles"][i]);
        const auto [fm, zm] = has(iff, "model_poles") ? info(iff["model_poles"][i]) : std::pair<json, json>{nullptr, nullptr};
        rows.push_back({iff["gains"][i], fi, zi, fm, zm, distance.is_array() ? distance[i] : json(nullptr)});
      }
      tables.push_back(table("Damped poles against the model's root locus",
                             {"gain g", "identified [Hz]", "identified damping", "model [Hz]", "model damping", "relative distance"},
                             rows,
                             fmt::format("Optimal gain of the model {}, maximum damping {}.",
                                         has(iff, "optimal_gain") ? fmt::format("{:.3g}", iff["optimal_gain"].get<double>()) : "-",
                                         has(iff, "max_damping") ? fmt::format("{:.2f}", iff["max_damping"].get<double>()) : "-")));
    }
    if (has(iff, "warning")) warnings.push_back(iff["warning"]);
    if (!figs.empty() || !tables.empty()) {
      sections.push_back({{"id", "iff"}, {"title", "Integral Force Feedback (report 2.6)"}, {"warnings", warnings}, {"tables", tables},
                          {"figures", figs}});
    }
  }

  // ---- Section 3: the 2-DoF model (Figure 3.4).
  if (any("model")) {
    json figs = json::array();
    figs.push_back(frf_figure(units, "de", "model-de", "Fig. 3.4a: 2-DoF model against the measurement, u -> d_e", "um/V", "model", "de_abs",
                              "de_phase", "2-DoF model", false, "Solid: measured; dashed: the tuned 2-DoF model."));
    figs.push_back(frf_figure(units, "Vs", "model-vs", "Fig. 3.4b: 2-DoF model against the measurement, u -> Vs", "V/V", "model", "Vs_abs",
                              "Vs_phase", "2-DoF model", false,
                              "Solid: measured; dashed: the tuned 2-DoF model. Its zero is minimum phase: where the measured phase "
                              "falls through the anti-resonance, the model's (drawn on the measurement's branch) jumps by one turn."));
    json rows = json::array();
    for (const auto& u : units) {
      const json r = result_of(u);
      const json m = at(r, {"model_2dof"});
      if (m.is_null()) continue;
      rows.push_back({u.name, m["m"], scaled(m["k1"], 1e-6), m["c1"], scaled(m["ke"], 1e-6), m["ce"], scaled(m["ka"], 1e-6), m["ca"], m["ga"],
                      scaled(m["gs"], 1e-6), at(r, {"model_2dof_fit", "relative_error_de"}), at(r, {"model_2dof_fit", "relative_error_Vs"})});
    }
    sections.push_back({{"id", "model"}, {"title", "Two degrees-of-freedom model (report 3)"},
                        {"tables", json::array({table("2-DoF parameters per unit (Table 3.1)",
                                                      {"unit", "m [kg]", "k1 [N/um]", "c1 [Ns/m]", "ke [N/um]", "ce [Ns/m]", "ka [N/um]",
                                                       "ca [Ns/m]", "ga [N/V]", "gs [V/um]", "error d_e", "error Vs"},
                                                      rows, "Report: k1 0.38, c1 5, ke 5.0, ce 100, ka 2.5, ca 50, ga -2.58, gs 0.46.")})},
                        {"figures", figs}});
  }

  // ---- Section 2.1 and 1.3: hysteresis and stroke (Figures 2.3, 1.4b).
  {
    json figs = json::array(), rows = json::array();
    bool absolute = false;
    std::vector<double> amplitudes;
    for (const auto& u : units) {
      for (const auto& h : at(result_of(u), {"hysteresis"})) {
        const double a = std::round(h["amplitude_V"].get<double>() * 10.0) / 10.0;
        if (std::find(amplitudes.begin(), amplitudes.end(), a) == amplitudes.end()) amplitudes.push_back(a);
      }
    }
    std::sort(amplitudes.begin(), amplitudes.end());
    for (const auto& u : units) {
      if (!has(u.plots, "hysteresis") || u.plots["hysteresis"].empty()) continue;
      json loops = json::array(), normalized = json::array();
      for (const auto& loop : u.plots["hysteresis"]) {
        const std::string name = amplitude_label(loop["amplitude_V"].get<double>());
        loops.push_back(trace(name, loop["Va"], loop["de_um"], name));
        // (Va - middle) / half range against (d_e - middle) / half range: every loop fills [-1, 1].
        const auto norm = [](const json& v) {
          double lo = INFINITY, hi = -INFINITY;
          for (const auto& x : v) {
            if (x.is_number()) lo = std::min(lo, x.get<double>()), hi = std::max(hi, x.get<double>());
          }
          json out = json::array();
          for (const auto& x : v) out.push_back(x.is_number() && hi > lo ? json((2.0 * x.get<double>() - lo - hi) / (hi - lo)) : json(nullptr));
          return out;
        };
        normalized.push_back(trace(name, norm(loop["Va"]), norm(loop["de_um"]), name));
      }
      if (!absolute) {
        figs.push_back(figure("hysteresis", fmt::format("Fig. 2.3: {}, d_e against Va for each amplitude", u.name), "Va [V]", false,
                              json::array({panel("d_e [um]", false, loops)})));
        absolute = true;
      }
      figs.push_back(figure(fmt::format("hysteresis-{}", u.id), u.name + ": hysteresis loops, normalized", "(Va - mid) / half range", false,
                            json::array({panel("(d_e - mid) / half range", false, normalized)}),
                            "Each loop scaled to fill [-1, 1] on both axes, so the small ones can be told apart: the wider the "
                            "loop, the larger the hysteresis relative to the stroke."));
      json row = json::array({u.name});
      const json list = at(result_of(u), {"hysteresis"});
      for (const double a : amplitudes) {
        json cell = nullptr;
        for (const auto& h : list) {
          if (std::abs(h["amplitude_V"].get<double>() - a) < 0.05) cell = fmt::format("{:.3g} ({:.1f} %)", h["width_um"].get<double>(), 100.0 * h["relative_width"].get<double>());
        }
        row.push_back(cell);
      }
      rows.push_back(row);
    }
    json stroke = json::array();
    for (const auto& u : units) {
      if (has(u.plots, "stroke")) stroke.push_back(trace(u.name, u.plots["stroke"]["Va"], u.plots["stroke"]["de_um"], u.name));
    }
    if (!stroke.empty()) {
      figs.push_back(figure("stroke", "Fig. 1.4b: stroke, displacement against the stack voltage (slow ramp)", "Va [V]", false,
                            json::array({panel("d_e [um]", false, stroke)})));
    }
    json tables = json::array();
    if (!rows.empty()) {
      std::vector<std::string> columns = {"unit"};
      for (const double a : amplitudes) columns.push_back(fmt::format("width at {:.3g} V [um] (of the stroke)", a));
      tables.push_back(table("Hysteresis: loop width at the offset per amplitude", columns, rows));
    }
    // The Prandtl-Ishlinskii model of the largest loop (docs/hysteresis.md): its fit and the loop it draws.
    json model_rows = json::array();
    for (const auto& u : units) {
      const json m = at(result_of(u), {"hysteresis_model"});
      if (m.is_null()) continue;
      json weights = json::array();
      for (const auto& w : m["weights"]) weights.push_back(fmt::format("{:.3g}", w.get<double>()));
      model_rows.push_back(json::array({u.name, fmt::format("{:.3g}", m["amplitude_V"].get<double>()),
                                        fmt::format("{:.3g}", m["gain_um_per_V"].get<double>()), fmt::format("{}", fmt::join(weights, " ")),
                                        fmt::format("{:.3g} ({:.2f} %)", m["rms_residual_um"].get<double>(), 100.0 * m["relative_residual"].get<double>()),
                                        fmt::format("{:.1f} % / {:.1f} %", 100.0 * m["hysteresis_width"].get<double>(),
                                                    100.0 * m["model_hysteresis_width"].get<double>()),
                                        m["quality"].get<std::string>()}));
      if (has(u.plots, "hysteresis_model")) {
        const json& p = u.plots["hysteresis_model"];
        figs.push_back(figure(fmt::format("hysteresis-model-{}", u.id), u.name + ": hysteresis model against the record", "Va [V]", false,
                              json::array({panel("d_e [um]", false,
                                                 json::array({trace("record", p["Va"], p["de_um"], "record"),
                                                              trace("Prandtl-Ishlinskii model", p["Va"], p["model_um"], "model")}))}),
                              "The model's inverse is the feedforward of `rt --feedforward` and `measure tracking` "
                              "(docs/hysteresis.md)."));
      }
    }
    if (!model_rows.empty()) {
      tables.push_back(table("Hysteresis model (Prandtl-Ishlinskii, largest loop; thresholds (i - 1/2) R / n)",
                             {"unit", "amplitude [V]", "gain [um/V]", "weights", "rms residual [um] (of the stroke)",
                              "width: record / model", "fit"},
                             model_rows));
    }
    if (!figs.empty()) sections.push_back({{"id", "quasi-static"}, {"title", "Stroke and hysteresis (report 1.3, 2.1)"}, {"tables", tables}, {"figures", figs}});
  }

  // ---- Section 2.2: stiffness (Figure 2.4), short and open circuit.
  {
    json traces = json::array(), rows = json::array();
    for (const auto& u : units) {
      for (const char* key : {"stiffness", "stiffness_open"}) {
        if (!has(u.plots, key)) continue;
        const std::string name = u.name + (std::string(key) == "stiffness" ? "" : ", stacks open");
        traces.push_back(trace(name, u.plots[key]["t"], u.plots[key]["de_um"], name));
        traces.push_back(trace(name + " creep fit", u.plots[key]["t"], u.plots[key]["fit_um"], name, true));
      }
      const json k = at(result_of(u), {"stiffness_N_per_um"});
      if (!k.is_null()) {
        rows.push_back({u.name, at(k, {"k1"}), at(k, {"k2"}), at(k, {"k_sc"}), at(k, {"k_oc"}), at(k, {"resonance"}),
                        at(result_of(u), {"stiffness_static", "creep_um_per_decade", "on"})});
      }
    }
    if (!traces.empty() || !rows.empty()) {
      json figs = json::array();
      if (!traces.empty()) {
        figs.push_back(figure("stiffness", "Fig. 2.4: d_e during the added-mass test", "Time [s]", false,
                              json::array({panel("d_e [um]", false, traces)})));
      }
      sections.push_back(
          {{"id", "stiffness"},
           {"title", "Static stiffness (report 2.2)"},
           {"text", fmt::format("Added mass {:g} kg put on and taken off; dashed: the fitted logarithmic creep model. k_sc: the stacks "
                                "short-circuited (actuators on the amplifier, sensor on the resistor), which is k1; k_oc: the same test "
                                "with every stack open (report: about 2.3 and 1.7 N/um).",
                                c.bench.added_mass)},
           {"tables", json::array({table("Stiffness per unit [N/um]",
                                         {"unit", "k1", "k2", "k_sc", "k_oc", "from the resonance", "creep under load [um/decade]"}, rows)})},
           {"figures", figs}});
    }
  }

  // ---- Section 1.4: flexible modes (Figure 1.7).
  {
    json traces = json::array();
    for (const auto& u : units) {
      if (has(u.plots, "hammer")) traces.push_back(trace(u.name, u.plots["hammer"]["f"], u.plots["hammer"]["abs"], u.name));
    }
    if (!traces.empty()) {
      sections.push_back({{"id", "modes"}, {"title", "Flexible modes, hammer test (report 1.4)"},
                          {"figures", json::array({figure("hammer", "Fig. 1.7: force -> vibrometer velocity", "Frequency [Hz]", true,
                                                          json::array({panel("|H| [m/s/N]", true, traces)}))})}});
    }
  }

  // ---- Batch comparison: bars with both limits of every spec.
  {
    json names = json::array();
    for (const auto& u : units) names.push_back(u.name);
    auto bars = [&](const std::string& name, std::initializer_list<const char*> path) {
      json y = json::array();
      for (const auto& r : result_units) y.push_back(at(r, path));
      return trace(name, names, y, "", false, "bars");
    };
    auto limit = [&](const std::string& name, double v) {
      json y = json::array();
      for (std::size_t i = 0; i < names.size(); ++i) y.push_back(v);
      return trace(fmt::format("{} {:.3g}", name, v), names, y, "", true, "lines");
    };
    auto range = [&](json& t, const std::string& what, const std::optional<metrology::Range>& r, double scale) {
      if (!r) return;
      t.push_back(limit(what + " minimum", r->min * scale));
      if (std::isfinite(r->max)) t.push_back(limit(what + " maximum", r->max * scale));
    };
    json figs = json::array();
    {
      json t = json::array({bars("sensor stack", {"capacitance_uF", "sensor"}), bars("actuator stacks", {"capacitance_uF", "actuator"})});
      range(t, "sensor", c.specs.capacitance_sensor, 1e6);
      range(t, "actuator", c.specs.capacitance_actuator, 1e6);
      figs.push_back(figure("batch-capacitance", "Capacitance (Table 1.2)", "", false, json::array({panel("C [uF]", false, t)})));
    }
    {
      json t = json::array({bars("k1", {"stiffness_N_per_um", "k1"}), bars("k2", {"stiffness_N_per_um", "k2"}),
                            bars("k_oc", {"stiffness_N_per_um", "k_oc"}), bars("from the resonance", {"stiffness_N_per_um", "resonance"})});
      range(t, "stiffness", c.specs.stiffness, 1e-6);
      figs.push_back(figure("batch-stiffness", "Stiffness (Table 2.1)", "", false, json::array({panel("k [N/um]", false, t)})));
    }
    {
      json t = json::array({bars("flatness", {"flatness_um"})});
      if (c.specs.flatness_max) t.push_back(limit("flatness maximum", *c.specs.flatness_max * 1e6));
      figs.push_back(figure("batch-flatness", "Flatness (Table 1.1, " + metrology::to_string(c.specs.flatness_method) + ")", "", false,
                            json::array({panel("flatness [um]", false, t)})));
    }
    {
      json t = json::array({bars("stroke", {"stroke_um"})});
      if (c.specs.stroke_min) t.push_back(limit("stroke minimum", *c.specs.stroke_min * 1e6));
      figs.push_back(figure("batch-stroke", "Stroke (Figure 1.4)", "", false, json::array({panel("stroke [um]", false, t)}),
                            "The specification gives a minimum stroke only."));
    }
    sections.push_back({{"id", "batch"}, {"title", "Batch comparison"},
                        {"text", "Dashed lines: the specification's limits (both where it has two)."},
                        {"figures", figs}});
  }

  // ---- Section 4: the super element (Figure 4.2): ga and gs tuned against the measurements,
  // u -> d_e and u -> V_s, magnitude and phase, with the table of the tuned values.
  {
    json figs = json::array(), tables = json::array();
    std::string text;
    if (extra.contains("superelement")) {
      const json& se = extra["superelement"];
      const std::string name = se["unit"].get<std::string>();
      json de_mag = json::array(), de_ph = json::array(), vs_mag = json::array(), vs_ph = json::array();
      for (const auto& u : units) {
        if (u.name != name || !has(u.plots, "frf")) continue;
        const json& p = u.plots["frf"];
        de_mag.push_back(trace(u.name + " measured", p["f"], p["de_abs"], "measured"));
        de_ph.push_back(trace(u.name + " measured", p["f"], p["de_phase"], "measured"));
        vs_mag.push_back(trace(u.name + " measured", p["f"], p["Vs_abs"], "measured"));
        vs_ph.push_back(trace(u.name + " measured", p["f"], p["Vs_phase"], "measured"));
        const auto [xd, yd] = on_branch(se["f"], se["de_phase"], p["f"], p["de_phase"]);
        de_ph.push_back(trace("super element", xd, yd, "model", true));
        const auto [xv, yv] = on_branch(se["f"], se["Vs_phase"], p["f"], p["Vs_phase"]);
        vs_ph.push_back(trace("super element", xv, yv, "model", true));
      }
      de_mag.push_back(trace("super element", se["f"], se["de_abs"], "model", true));
      vs_mag.push_back(trace("super element", se["f"], se["Vs_abs"], "model", true));
      const json& sr = results["superelement"];
      text = fmt::format("The super element ({}, {} DOF) on the bench ({:.3g} kg on the moving interface), its sensitivities tuned "
                         "against each unit's measured FRFs (docs/apa300ml.md) and compared with eq. 4.1 for Table 4.1's "
                         "constants: ga {:.3g} N/V, gs {:.3g} V/um.",
                         sr["source"].get<std::string>(), sr["dofs"].get<long>(), sr["moving_mass_kg"].get<double>(),
                         sr["eq41"]["ga_N_per_V"].get<double>(), sr["eq41"]["gs_V_per_um"].get<double>());
      json rows = json::array();
      for (const auto& row : sr["units"]) {
        rows.push_back({row["name"], row["ga_N_per_V"], scaled(row["ga_relative_to_eq41"], 100.0), row["gs_V_per_um"],
                        scaled(row["gs_relative_to_eq41"], 100.0), row["resonance_Hz"], row["measured_resonance_Hz"],
                        row["antiresonance_Hz"], row["measured_antiresonance_Hz"], row["de_error_dB"], row["vs_error_dB"]});
      }
      tables.push_back(table("ga and gs tuned per unit against eq. 4.1",
                             {"unit", "ga [N/V]", "vs eq. 4.1 [%]", "gs [V/um]", "vs eq. 4.1 [%]", "resonance model [Hz]",
                              "resonance measured [Hz]", "anti-resonance model [Hz]", "anti-resonance measured [Hz]",
                              "u -> d_e error [dB]", "u -> V_s error [dB]"},
                             rows, "Errors: median |model / measured| in dB from the tuning band's start to twice the resonance."));
      figs.push_back(figure("superelement", "Fig. 4.2: super element against the measurement of " + name + " (u -> d_e, u -> V_s)",
                            "Frequency [Hz]", true,
                            json::array({panel("|u -> d_e| [um/V]", true, de_mag), panel("d_e phase [deg]", false, de_ph),
                                         panel("|u -> V_s| [V/V]", true, vs_mag), panel("V_s phase [deg]", false, vs_ph)}),
                            "Solid: measured (Welch H1); dashed: the super element with the tuned ga and gs (no measurement "
                            "chain: high-pass, anti-aliasing and delays are not in the model)."));
    } else if (has(results["superelement"], "failed")) {
      text = "The super element's comparison failed: " + results["superelement"]["failed"].get<std::string>();
    } else {
      text = "Not part of this campaign: no super element was given. A [superelement] table in the campaign file (docs/campaign.md) "
             "adds the finite-element model's u -> d_e and u -> V_s against the measured FRFs here (report Figure 4.2).";
    }
    sections.push_back({{"id", "superelement"}, {"title", "Super element (report 4)"}, {"text", text}, {"tables", tables}, {"figures", figs}});
  }
  return {{"title", c.title},
          {"subtitle", fmt::format("{} — piezobench {}", c.file.filename().string(), kVersion)},
          {"results", results},
          {"sections", sections}};
}

}  // namespace

json report_document(const CampaignResult& result) {
  std::vector<UnitPlots> units;
  for (const auto& u : result.units) units.push_back({u.id, u.name, unit_plots(result.campaign, u)});
  return document(result.campaign, units, results_json(result), extra_plots(result));
}

}  // namespace piezobench::campaign
