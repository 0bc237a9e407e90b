#include "piezobench/campaign/results_json.hpp"

#include <fmt/format.h>

#include "piezobench/core/units.hpp"
#include "piezobench/io/json.hpp"
#include "piezobench/version.hpp"

namespace piezobench::campaign {

using nlohmann::json;

namespace {

json num(double v) { return io::to_json(v); }

json provenance(const RecordProvenance& p) {
  json ch = json::object();
  for (const auto& [role, name] : p.channels) ch[role] = name;
  json out = {{"file", p.file}, {"key", p.key}, {"channels", ch}, {"samples", p.samples}, {"sample_rate_Hz", p.sample_rate_Hz}};
  if (!p.input.empty()) {
    out["input"] = p.input;
    out["outputs"] = p.outputs;
  }
  return out;
}

json welch(const dsp::FrfProvenance& p) {
  return {{"estimator", p.estimator}, {"window", p.window}, {"nfft", p.nfft}, {"overlap", p.overlap},
          {"detrend", p.detrend},     {"averages", p.averages}, {"resolution_Hz", p.sample_rate / static_cast<double>(p.nfft)}};
}

json flatness(const FlatnessAnalysis& f) {
  json per_interface = json::array();
  for (const auto& i : f.per_interface) per_interface.push_back({{"interface", i.id}, {"least_squares_um", i.least_squares * 1e6}});
  return {{"method", metrology::to_string(f.method)},
          {"least_squares_um", f.least_squares * 1e6},
          {"minimum_zone_um", io::to_json(f.minimum_zone, 1e6)},
          {"points", f.points},
          {"per_interface", per_interface},
          {"probe_accuracy_um", f.probe_accuracy * 1e6},
          {"provenance", provenance(f.provenance)}};
}

json stroke(const StrokeAnalysis& s) {
  return {{"va_min_V", s.result.va_min},
          {"va_max_V", s.result.va_max},
          {"sensitivity_um_per_V", s.result.sensitivity * 1e6},
          {"loop_width_um", s.result.loop_width * 1e6},
          {"provenance", provenance(s.provenance)}};
}

json hysteresis(const std::vector<HysteresisLoop>& loops) {
  json list = json::array();
  for (const auto& l : loops) {
    const auto& h = l.result;
    list.push_back({{"amplitude_V", h.amplitude},
                    {"offset_V", h.offset},
                    {"width_um", h.width * 1e6},
                    {"loop_stroke_um", h.loop_stroke * 1e6},
                    {"relative_width", h.relative_width},
                    {"periods", h.periods},
                    {"provenance", provenance(l.provenance)}});
  }
  return list;
}

std::string hysteresis_model_name(const ident::HysteresisModel& m) {
  return m.output.identity() ? "prandtl-ishlinskii" : "modified-prandtl-ishlinskii";
}

json hysteresis_model(const HysteresisModelFit& h) {
  const ident::HysteresisModel& m = h.fit.model;
  // Every model fitted (the chosen first), with its residual and verdict.
  json candidates = json::array();
  for (const ident::HysteresisFit* f : {&h.fit, h.alternative ? &*h.alternative : nullptr}) {
    if (f == nullptr) continue;
    candidates.push_back({{"model", hysteresis_model_name(f->model)},
                          {"chosen", f == &h.fit},
                          {"rms_residual_um", f->rms_residual * 1e6},
                          {"relative_residual", f->relative_residual},
                          {"quality", core::to_string(f->quality.verdict)}});
  }
  if (!h.alternative_error.empty()) candidates.push_back({{"model", "modified-prandtl-ishlinskii"}, {"chosen", false}, {"error", h.alternative_error}});
  json j = {{"model", hysteresis_model_name(m)},
            {"loop_asymmetry", h.asymmetry},
            {"candidates", candidates},
            {"amplitude_V", h.amplitude},
            {"operators", m.hysteresis.thresholds.size()},
            {"thresholds_V", m.hysteresis.thresholds},
            {"weights", m.hysteresis.weights},
            {"gain_um_per_V", m.gain * 1e6},
            {"offset_um", m.offset * 1e6},
            {"reference_slope", m.reference_slope},
            {"reference_intercept_V", m.reference_intercept},
            {"rms_residual_um", h.fit.rms_residual * 1e6},
            {"relative_residual", h.fit.relative_residual},
            {"hysteresis_width", h.width},
            {"model_hysteresis_width", h.model_width},
            {"quality", core::to_string(h.fit.quality.verdict)},
            {"quality_problems", h.fit.quality.problems},
            {"provenance", provenance(h.provenance)}};
  if (!m.output.identity()) {
    j["output_map"] = {{"x_V", m.output.x}, {"y_V", m.output.y}, {"slope_below", m.output.slope_below}, {"slope_above", m.output.slope_above}};
  }
  return j;
}

json tracking(const TrackingAnalysis& t) {
  const auto figures = [](const bench::TrackingFigures& f) {
    return json{{"width_open", num(f.width_open)},         {"width_ff", num(f.width_ff)},
                {"rms_open_um", num(f.rms_open * 1e6)},    {"rms_ff_um", num(f.rms_ff * 1e6)},
                {"rms_reduction", num(f.rms_reduction())}, {"stroke_open_um", num(f.stroke_open * 1e6)}};
  };
  return {{"amplitude_V", num(t.amplitude)}, {"feedforward", t.feedforward},         {"clamped_samples", num(t.clamped_samples)},
          {"sine", figures(t.sine)},         {"triangle", figures(t.triangle)},     {"provenance", provenance(t.provenance)}};
}

// The Prony creep of a stiffness record (input N, output m).
json creep(const ident::CreepFit& c) {
  return {{"time_constants_s", c.time_constants},
          {"coefficients", c.coefficients},
          {"compliance_um_per_N", num(c.gain * 1e6)},
          {"instantaneous_stiffness_N_per_um", num(c.gain != 0.0 ? -1e-6 / c.gain : 0.0)},
          {"creep_per_decade", num(c.creep_per_decade)},
          {"rms_residual_um", num(c.rms_residual * 1e6)},
          {"relative_residual", num(c.relative_residual)},
          {"quality", core::to_string(c.quality.verdict)},
          {"quality_problems", c.quality.problems}};
}

json stiffness(const StiffnessAnalysis& a) {
  const auto& s = a.result;
  const auto& o = a.options;
  json j = {{"k1_N_per_um", s.k1 * 1e-6},
          {"k2_N_per_um", s.k2 * 1e-6},
          {"t_on_s", s.t_on},
          {"t_off_s", s.t_off},
          {"readings_um", {{"before", s.d_before * 1e6}, {"loaded", s.d_loaded * 1e6}, {"after", s.d_after * 1e6}}},
          {"reading_windows_s",
           {{"before", {o.before_s[0], o.before_s[1]}}, {"loaded", {o.loaded_s[0], o.loaded_s[1]}}, {"after", {o.after_s[0], o.after_s[1]}}}},
          {"elastic_N_per_um", {{"on", s.k_elastic_on * 1e-6}, {"off", s.k_elastic_off * 1e-6}}},
          {"creep_um_per_decade", {{"on", s.creep_on * 1e6}, {"off", s.creep_off * 1e6}}},
          {"creep_time_constant_s", s.creep_time_constant},
          {"fit_rms_um", s.rms_residual * 1e6},
          {"added_mass_kg", o.added_mass},
          {"gravity_m_per_s2", o.gravity},
          {"mass_log", a.mass_log},
          {"provenance", provenance(a.provenance)}};
  if (a.creep) j["creep_prony"] = creep(*a.creep);
  return j;
}

json vector_fit(const VectorFitSummary& v) {
  return {{"order", v.order}, {"relative_rms_error", v.relative_rms_error}, {"converged", v.converged}};
}

json hpf(const HighPassCorner& h) {
  json out = json::object();
  if (h.first_order_fit_Hz) {
    out["first_order_fit_Hz"] = *h.first_order_fit_Hz;
    out["first_order_fit_points"] = h.first_order_fit_points;
  }
  if (h.r_c_Hz) out["R_C_Hz"] = *h.r_c_Hz;
  if (h.iff_plant_fit_Hz) {
    out["iff_plant_fit_Hz"] = *h.iff_plant_fit_Hz;
  } else if (h.iff_plant_fit_error) {
    out["iff_plant_fit_Hz"] = nullptr;
    out["iff_plant_fit_error"] = *h.iff_plant_fit_error;
  }
  out["method"] = h.method;
  if (!h.corner_Hz) out["observable_above_Hz"] = h.observable_above_Hz;
  return out;
}

json frf(const FrfAnalysis& f) {
  json out = {{"provenance", provenance(f.provenance)}, {"welch", welch(f.welch)}};
  if (f.fit_de) out["fit_de"] = vector_fit(*f.fit_de);
  if (f.fit_vs) out["fit_Vs"] = vector_fit(*f.fit_vs);
  if (f.static_gain_vs) out["static_gain_Vs_V_per_V"] = *f.static_gain_vs;
  if (f.static_gain_vector_fit) out["static_gain_vector_fit_um_per_V"] = *f.static_gain_vector_fit * 1e6;
  out["static_gain_um_per_V"] = io::to_json(f.static_gain, 1e6);
  if (!f.static_gain_source.empty()) out["static_gain_source"] = f.static_gain_source;
  if (f.de_plant) {
    const auto& p = *f.de_plant;
    out["de_plant_fit"] = {{"static_gain_um_per_V", p.static_gain * 1e6},
                           {"resonance_Hz", p.natural_frequency / kTwoPi},
                           {"damping", p.damping},
                           {"delay_s", p.delay},
                           {"relative_rms_error", p.relative_rms_error},
                           {"points", p.points},
                           {"uncertainty", io::to_json(p.uncertainty)}};
  }
  if (f.iff_plant) {
    const auto& p = *f.iff_plant;
    out["iff_plant_fit"] = {{"g0", p.g0},
                            {"wz_Hz", p.wz / kTwoPi},
                            {"xz", p.xz},
                            {"wp_Hz", p.wp / kTwoPi},
                            {"xp", p.xp},
                            {"w_hpf_Hz", p.w_hpf / kTwoPi},
                            {"w_hpf_from", f.iff_plant_w_hpf_measured ? "R C_sensor" : "fit"},
                            {"delay_s", p.delay},
                            {"band_Hz", {f.iff_plant_fmin_Hz, f.iff_plant_fmax_Hz}},
                            {"relative_rms_error", p.relative_rms_error},
                            {"points", p.points},
                            {"iterations", p.iterations},
                            {"uncertainty", io::to_json(p.uncertainty)}};
  }
  json nmp = json::object();
  if (f.nmp.zero) {
    const auto& z = *f.nmp.zero;
    nmp = {{"phase_verdict", ident::to_string(z.phase_verdict)},
           {"phase_change_deg", z.phase_change_deg},
           {"fitted_zero", io::to_json(z.fitted_zero)},
           {"fitted_zero_nonminimum_phase", z.fitted_zero_nonminimum_phase}};
  }
  if (f.nmp.iff_plant_fit_xz) nmp["iff_plant_fit_xz"] = *f.nmp.iff_plant_fit_xz;
  if (f.nmp.iff_plant_fit_xz_standard_error) nmp["iff_plant_fit_xz_standard_error"] = io::to_json(*f.nmp.iff_plant_fit_xz_standard_error);
  nmp["verdict_from"] = f.nmp.verdict_from;
  nmp["verdict_reason"] = f.nmp.verdict_reason;
  out["nmp_evidence"] = nmp;
  if (f.antiresonance_vector_fit_Hz) {
    out["antiresonance_vector_fit_Hz"] = *f.antiresonance_vector_fit_Hz;
    out["antiresonance_vector_fit_damping"] = *f.antiresonance_vector_fit_damping;
  }
  if (f.resonance_vector_fit_Hz) {
    out["resonance_vector_fit_Hz"] = *f.resonance_vector_fit_Hz;
    out["resonance_vector_fit_damping"] = *f.resonance_vector_fit_damping;
  }
  out["resonance_Hz"] = io::to_json(f.resonance_Hz);
  out["resonance_damping"] = io::to_json(f.resonance_damping);
  out["antiresonance_Hz"] = io::to_json(f.antiresonance_Hz);
  out["antiresonance_damping"] = io::to_json(f.antiresonance_damping);
  out["zero_is_nonminimum_phase"] = f.zero_is_nonminimum_phase ? json(*f.zero_is_nonminimum_phase) : json(nullptr);
  out["shell_stiffness_N_per_um"] = io::to_json(f.shell_stiffness, 1e-6);
  return out;
}

void model_2dof(const Model2DofFit& m, json& unit) {
  const apa::TwoDofTuning& t = m.tuning;
  json params = json::object();
  for (const auto& name : apa::TwoDofParams::names()) params[name] = t.params.get(name);
  unit["model_2dof"] = params;
  unit["model_2dof_fit"] = {{"status", apa::to_string(t.status)},
                            {"iterations", t.iterations},
                            {"relative_error_de", t.fit_error_de},
                            {"relative_error_Vs", t.fit_error_vs},
                            {"points", t.points},
                            {"delay_s", m.bench.delay},
                            {"band_Hz", {m.fmin_Hz, m.fmax_Hz}},
                            {"units", "SI: kg, N/m, N s/m, N/V, V/m"},
                            {"quality", core::to_string(t.quality.verdict)},
                            {"undetermined", t.undetermined},
                            {"uncertainty", io::to_json(t.uncertainty)}};
}

json damped_plants(const std::vector<DampedPlant>& plants) {
  json list = json::array();
  for (const DampedPlant& d : plants) {
    json entry = {{"gain", d.gain}, {"provenance", provenance(d.provenance)}, {"welch", welch(d.frf.provenance)},
                  {"delay_removed_s", d.delay_removed}, {"fit", nullptr}, {"second_order_fit", nullptr}};
    if (d.identified) {
      entry["fit"] = {{"frequency_Hz", d.identified->frequency_Hz()},
                      {"damping", d.identified->damping},
                      {"pole", io::to_json(d.identified->pole)},
                      {"order", d.identified_order},
                      {"relative_rms_error", d.identified->fit.relative_rms_error},
                      {"band_Hz", {d.fmin_Hz, d.fmax_Hz}},
                      {"method", "vector fitting, the dominant pole pair (the largest contribution to the data) in the band; delay of d_e removed"}};
    }
    if (d.second_order) {
      entry["second_order_fit"] = {{"frequency_Hz", d.second_order->natural_frequency / kTwoPi},
                                   {"damping", d.second_order->damping},
                                   {"pole", io::to_json(d.second_order->pole())},
                                   {"relative_rms_error", d.second_order->relative_rms_error},
                                   {"method", "the report's: k wn^2/(s^2 + 2 zeta wn s + wn^2), weighted Levenberg-Marquardt"}};
    }
    list.push_back(entry);
  }
  return list;
}

json low_frequency_vs(const LowFrequencyVs& v) {
  json out = {{"provenance", provenance(v.provenance)}, {"welch", welch(v.frf.provenance)}, {"lowest_line_Hz", v.lowest_line_Hz},
              {"band_Hz", {v.lowest_line_Hz, v.fmax_Hz}}, {"corner_Hz", nullptr}, {"observable", false}};
  if (v.fitted_corner_Hz) {
    out["observable"] = v.observable;
    out["fitted_corner_Hz"] = *v.fitted_corner_Hz;
    out["relative_rms_error"] = v.relative_rms_error;
    out["points"] = v.points;
    if (v.observable) {
      out["corner_Hz"] = *v.fitted_corner_Hz;
    } else {
      out["below_Hz"] = v.lowest_line_Hz / 3.0;
      out["note"] = fmt::format("not observable in this record: the fitted corner ({:.2g} Hz) is below a third of the lowest line "
                                "({:.3g} Hz)", *v.fitted_corner_Hz, v.lowest_line_Hz);
    }
  }
  return out;
}

json resistor(const ResistorComparison& r) {
  return {{"with_resistor", r.with_resistor ? low_frequency_vs(*r.with_resistor) : json(nullptr)},
          {"without_resistor", low_frequency_vs(r.without_resistor)},
          {"method", "first-order high-pass g s/(s + wc) fitted to u -> Vs below hpf_fmax_Hz (Welch, segments of half the record)"}};
}

json flexible_modes(const FlexibleModes& m) {
  json peaks = json::array(), modes = json::array();
  for (const auto& p : m.peak_picking) peaks.push_back({{"frequency_Hz", p.frequency_Hz}, {"damping", p.damping}});
  for (const auto& p : m.lscf) modes.push_back({{"frequency_Hz", p.frequency_Hz}, {"damping", p.damping}, {"stable_orders", p.stable_orders}});
  return {{"provenance", provenance(m.provenance)}, {"welch", welch(m.welch)}, {"peak_picking", peaks}, {"lscf", modes}};
}

json batch(const BatchAnalysis& b) {
  json outliers = json::array();
  for (const auto& o : b.outliers) {
    outliers.push_back({{"unit", o.unit}, {"quantity", o.quantity}, {"value", o.value}, {"median", o.median}, {"robust_z", num(o.robust_z)}});
  }
  json spread = json::object();
  for (const auto& s : b.spread) {
    spread[s.quantity] = {{"units", s.units}, {"min", s.min}, {"max", s.max}, {"median", s.median},
                          {"relative_spread", s.relative_spread}, {"mad", s.mad}};
  }
  json similarity = json::object();
  if (b.similarity) {
    const FrfSimilarity& s = *b.similarity;
    json per_unit = json::array();
    for (const auto& u : s.units) per_unit.push_back({{"unit", u.unit}, {"de_rms_dB", num(u.de_rms_dB)}, {"Vs_rms_dB", num(u.vs_rms_dB)}});
    similarity = {{"reference", "median |H| of the batch"}, {"band_Hz", {s.fmin_Hz, s.fmax_Hz}}, {"units", per_unit}, {"max_rms_dB", s.max_rms_dB}};
  }
  return {{"outliers", outliers}, {"spread", spread}, {"similarity", similarity},
          {"outlier_rule", {{"robust_z_threshold", b.rule.threshold}, {"min_relative_deviation", b.rule.min_relative_deviation},
                            {"rejects", b.rejects}}}};
}

json iff(const IffStudy& s) {
  if (s.failed) return {{"gains", json::array()}, {"damped_poles", json::array()}, {"optimal_gain", nullptr}, {"failed", *s.failed}};
  const control::IffControllerParams& k = s.controller;
  json out = {{"unit", s.unit ? json(*s.unit) : json(nullptr)}, {"gains", s.gains}, {"damped_poles", json::array()}, {"optimal_gain", io::to_json(s.optimal_gain)}};
  out["controller"] = {{"gain", k.gain}, {"hpf_Hz", k.w_hpf / kTwoPi}, {"lpf_Hz", k.w_lpf / kTwoPi}, {"robust_Hz", k.w_robust / kTwoPi},
                       {"formula", "K(s) = gain g s/(s + w_hpf) 1/(s + w_lpf) 1/(s + w_robust) (eq. 2.4)"}};
  if (!s.plant) {
    out["note"] = s.note;
    return out;
  }
  const ident::IffPlantFit& p = *s.plant;
  out["plant"] = {{"g0", p.g0}, {"wz_Hz", p.wz / kTwoPi}, {"xz", p.xz}, {"wp_Hz", p.wp / kTwoPi}, {"xp", p.xp},
                  {"w_hpf_Hz", p.w_hpf / kTwoPi}, {"delay_s", p.delay}, {"source", "IFF plant fit of unit " + std::to_string(*s.unit)}};
  out["max_damping"] = io::to_json(s.max_damping);
  out["optimal_pole"] = io::to_json(s.optimal_pole);
  out["locus_method"] = "closed-loop poles of 1 - g K G = 0 on 401 log-spaced gains around 1/|K G(j wp)| (plots), branch from the "
                        "resonance pole; maximum damping on the adaptive root locus from g = 0 refined by golden section "
                        "(lti::max_damping_on_branch, as `iff rlocus`; delay as a 6th-order Pade approximant)";
  for (const auto& pole : s.damped_poles) out["damped_poles"].push_back(io::to_json(pole));
  if (!s.damped_poles.empty()) {
    json model = json::array();
    for (const auto& pole : s.model_poles) model.push_back(io::to_json(pole));
    out["model_poles"] = model;
    out["relative_pole_distance"] = s.relative_pole_distance;
    out["max_relative_pole_distance"] = s.max_relative_pole_distance;
    out["pole_distance_tolerance"] = s.pole_distance_tolerance;
    if (s.warning) out["warning"] = *s.warning;
  }
  return out;
}

json superelement(const SuperElementComparison& s) {
  if (s.failed) return {{"failed", *s.failed}};
  json units = json::array();
  for (const auto& u : s.units) {
    units.push_back({{"unit", u.unit},
                     {"name", u.name},
                     {"ga_N_per_V", num(u.ga)},
                     {"gs_V_per_um", num(u.gs * 1e-6)},
                     {"ga_relative_to_eq41", num(u.ga_relative_to_eq41)},
                     {"gs_relative_to_eq41", num(u.gs_relative_to_eq41)},
                     {"band_Hz", {num(u.band_lo_Hz), num(u.band_hi_Hz)}},
                     {"resonance_Hz", num(u.resonance_Hz)},
                     {"antiresonance_Hz", io::to_json(u.antiresonance_Hz)},
                     {"measured_resonance_Hz", io::to_json(u.measured_resonance_Hz)},
                     {"measured_antiresonance_Hz", io::to_json(u.measured_antiresonance_Hz)},
                     {"de_error_dB", num(u.de_error_dB)},
                     {"vs_error_dB", num(u.vs_error_dB)}});
  }
  json out = {{"source", s.source},
              {"dofs", s.dofs},
              {"modes_Hz", s.modes_Hz},
              {"moving_mass_kg", num(s.moving_mass)},
              {"eq41", {{"ga_N_per_V", num(s.eq41_ga)}, {"gs_V_per_um", num(s.eq41_gs * 1e-6)}, {"stack_modulus_Pa", num(s.stack_modulus)}}},
              {"units", units},
              {"ga_N_per_V", io::to_json(s.ga)},
              {"gs_V_per_um", io::to_json(s.gs, 1e-6)},
              {"resonance_Hz", io::to_json(s.resonance_Hz)},
              {"measured_resonance_Hz", io::to_json(s.measured_resonance_Hz)},
              {"warnings", s.warnings}};
  if (s.resonance_Hz && s.measured_resonance_Hz) out["relative_difference"] = num(*s.resonance_Hz / *s.measured_resonance_Hz - 1.0);
  return out;
}

json range(const std::optional<metrology::Range>& r, double scale) {
  return r ? json({r->min * scale, r->max * scale}) : json(nullptr);
}

}  // namespace

json unit_json(const UnitAnalysis& u) {
  json r = {{"id", u.id},
            {"name", u.name},
            {"flatness_um", nullptr},
            {"capacitance_uF", nullptr},
            {"stroke_um", nullptr},
            {"stiffness_N_per_um", nullptr},
            {"frf", nullptr},
            {"hpf_corner_Hz", nullptr},
            {"model_2dof", nullptr}};
  if (u.flatness_analysis) {
    r["flatness_um"] = u.flatness_analysis->flatness * 1e6;
    r["flatness"] = flatness(*u.flatness_analysis);
  }
  if (u.capacitance_analysis) {
    const auto& c = *u.capacitance_analysis;
    r["capacitance_uF"] = {{"sensor", c.sensor * 1e6}, {"actuator", c.actuator * 1e6}};
    r["capacitance_provenance"] = c.provenance ? provenance(*c.provenance) : json({{"key", c.key}});
  }
  if (u.stroke_analysis) {
    r["stroke_um"] = u.stroke_analysis->result.stroke * 1e6;
    r["stroke"] = stroke(*u.stroke_analysis);
  }
  if (!u.hysteresis.empty()) r["hysteresis"] = hysteresis(u.hysteresis);
  if (u.hysteresis_model) r["hysteresis_model"] = hysteresis_model(*u.hysteresis_model);
  if (u.tracking) r["tracking"] = tracking(*u.tracking);
  if (u.stiffness_analysis) r["stiffness_static"] = stiffness(*u.stiffness_analysis);
  if (u.stiffness_open_analysis) r["stiffness_open_circuit"] = stiffness(*u.stiffness_open_analysis);
  if (u.frf_analysis) {
    r["frf"] = frf(*u.frf_analysis);
    r["hpf"] = hpf(u.frf_analysis->hpf);
    if (u.frf_analysis->hpf.corner_Hz) r["hpf_corner_Hz"] = *u.frf_analysis->hpf.corner_Hz;
  }
  if (u.model_2dof) model_2dof(*u.model_2dof, r);
  if (u.resistor) r["hpf_resistor"] = resistor(*u.resistor);
  if (u.k1 || u.k_resonance || u.k_oc) {
    // k_sc: the stacks short-circuited (on the amplifier, the sensor on R) = k1; k_oc: every stack
    // open, read the same way (report section 2.2).
    r["stiffness_N_per_um"] = {{"k1", io::to_json(u.k1, 1e-6)}, {"k2", io::to_json(u.k2, 1e-6)}, {"resonance", io::to_json(u.k_resonance, 1e-6)},
                               {"k_sc", io::to_json(u.k1, 1e-6)}, {"k_oc", io::to_json(u.k_oc, 1e-6)}};
  }
  if (!u.damped.empty()) r["iff_damped_plants"] = damped_plants(u.damped);
  if (u.flexible_modes) r["flexible_modes"] = flexible_modes(*u.flexible_modes);
  r["not_measured"] = u.not_measured;
  if (u.not_analysed) {
    r["not_analysed"] = {{"file", u.not_analysed->file}, {"key", u.not_analysed->key}, {"reason", u.not_analysed->reason}};
  }
  r["failed"] = u.failed;
  r["warnings"] = u.warnings;
  r["accepted"] = u.accepted;
  r["reasons"] = u.reasons;
  return r;
}

json results_json(const CampaignResult& r) {
  const Campaign& c = r.campaign;
  json units = json::array();
  for (const auto& u : r.units) units.push_back(unit_json(u));
  const auto& a = c.analysis;
  const Specs& sp = c.specs;
  json specs = {{"flatness_um", sp.flatness_max ? json(*sp.flatness_max * 1e6) : json(nullptr)},
                {"flatness_method", metrology::to_string(sp.flatness_method)},
                {"capacitance_sensor_uF", range(sp.capacitance_sensor, 1e6)},
                {"capacitance_actuator_uF", range(sp.capacitance_actuator, 1e6)},
                {"stroke_min_um", sp.stroke_min ? json(*sp.stroke_min * 1e6) : json(nullptr)},
                {"stiffness_N_per_um", range(sp.stiffness, 1e-6)},
                {"reject_outliers", sp.reject_outliers}};
  return {{"title", c.title},
          {"campaign", c.file.string()},
          {"generator", std::string("piezobench ") + kVersion},
          {"units", units},
          {"batch", batch(r.batch)},
          {"iff", iff(r.iff)},
          {"superelement", r.superelement ? superelement(*r.superelement) : json(nullptr)},
          {"specs", specs},
          {"summary", {{"units", r.units.size()}, {"accepted", r.accepted}, {"rejected", r.rejected}, {"not_analysed", r.not_analysed}}},
          {"provenance",
           {{"campaign", c.file.string()},
            {"window", dsp::to_string(a.window)},
            {"nfft", a.nfft == 0 ? json("auto (4 s, at most a quarter of the record)") : json(a.nfft)},
            {"overlap", a.overlap},
            {"detrend", "mean (per segment)"},
            {"estimator", "H1"},
            {"band_Hz", {a.fmin_Hz, a.fmax_Hz}},
            {"fit_order", a.fit_order},
            {"bench", {{"amplifier_gain", c.bench.amplifier_gain}, {"suspended_mass_kg", c.bench.suspended_mass},
                       {"added_mass_kg", c.bench.added_mass}, {"gravity_m_per_s2", c.bench.gravity},
                       {"hpf_resistance_ohm", io::to_json(c.bench.hpf_resistance)}, {"probe_accuracy_um", c.bench.probe_accuracy * 1e6}}},
            {"note", "per-analysis files, channels, window, nfft and averages are in each unit's provenance/welch entries"}}}};
}

}  // namespace piezobench::campaign
