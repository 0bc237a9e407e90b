#include "piezobench/campaign/results_json.hpp"

#include <fmt/format.h>

#include "piezobench/core/units.hpp"
#include "piezobench/io/fields_json.hpp"
#include "piezobench/io/json.hpp"
#include "piezobench/version.hpp"
#include "shown_units.hpp"

namespace piezobench::campaign {

using nlohmann::json;

namespace {

using namespace shown_units;

json num(double v) { return io::to_json(v); }

// The Welch settings with the line spacing they give.
json welch(const dsp::FrfProvenance& p) {
  json out = io::results_object(p);
  out["resolution_Hz"] = p.sample_rate / static_cast<double>(p.nfft);
  return out;
}

std::string hysteresis_model_name(const ident::HysteresisModel& m) {
  return m.output.identity() ? "prandtl-ishlinskii" : "modified-prandtl-ishlinskii";
}

// The declared view (fit, alternative, loop_asymmetry, ...) with the chosen model's name.
json hysteresis_model(const HysteresisModelFit& h) {
  json j = io::results_object(h);
  j["model"] = hysteresis_model_name(h.fit.model);
  if (h.alternative) j["alternative"]["name"] = hysteresis_model_name(h.alternative->model);
  return j;
}

json tracking(const TrackingAnalysis& t) {
  json out = io::results_object(t);
  out["sine"]["rms_reduction"] = num(t.sine.rms_reduction());
  out["triangle"]["rms_reduction"] = num(t.triangle.rms_reduction());
  return out;
}

// The Prony creep of a stiffness record: the declared view (SI: input N, output m), with the two
// figures that only this record's units give a name to.
json creep(const ident::CreepFit& c) {
  json j = io::results_object(c);
  j["compliance_um_per_N"] = io::shown_json(c.gain, core::shown::kMetrePerNewtonAsUmPerN.per_si);
  j["instantaneous_stiffness_N_per_um"] = io::shown_json(c.gain != 0.0 ? -1.0 / c.gain : 0.0, core::shown::kNewtonPerMetreAsNPerUm.per_si);
  return j;
}

json frf(const FrfAnalysis& f) {
  json out = io::results_object(f);
  out["welch"] = welch(f.welch);
  if (f.de_plant) out["de_plant_fit"] = io::results_object(*f.de_plant);
  if (f.iff_plant) {
    out["iff_plant_fit"] = io::results_object(*f.iff_plant);
    out["iff_plant_fit"]["w_hpf_from"] = f.iff_plant_w_hpf_measured ? "R C_sensor" : "fit";
    out["iff_plant_fit"]["band_Hz"] = {f.iff_plant_fmin_Hz, f.iff_plant_fmax_Hz};
  }
  return out;
}

void model_2dof(const Model2DofFit& m, json& unit) {
  const apa::TwoDofTuning& t = m.tuning;
  json params = json::object();
  for (const auto& name : apa::TwoDofParams::names()) params[name] = t.params.get(name);
  unit["model_2dof"] = params;
  // The tuning's declared view without its parameters (model_2dof above, in SI), with the chain and band.
  json fit = io::results_object(t);
  fit.erase("params");
  fit["delay_s"] = m.bench.delay;
  fit["band_Hz"] = {m.fmin_Hz, m.fmax_Hz};
  unit["model_2dof_fit"] = fit;
}

// Each damped plant's declared view (gain, provenance, fit, second_order_fit, delay_removed_s), with
// the Welch settings, the band and how each pole was found.
json damped_plants(const std::vector<DampedPlant>& plants) {
  json list = json::array();
  for (const DampedPlant& d : plants) {
    json entry = io::results_object(d);
    entry["welch"] = welch(d.frf.provenance);
    if (d.identified) {
      entry["fit"]["order"] = d.identified_order;
      entry["fit"]["band_Hz"] = {d.fmin_Hz, d.fmax_Hz};
      entry["fit"]["method"] = "vector fitting, the dominant pole pair (the largest contribution to the data) in the band; delay of d_e removed";
    }
    if (d.second_order) {
      entry["second_order_fit"]["method"] = "the report's: k wn^2/(s^2 + 2 zeta wn s + wn^2), weighted Levenberg-Marquardt";
    }
    list.push_back(entry);
  }
  return list;
}

// The declared view with the Welch settings, the band, and the corner the unit is given (null when
// the fitted one is not observable, with why).
json low_frequency_vs(const LowFrequencyVs& v) {
  json out = io::results_object(v);
  out["welch"] = welch(v.frf.provenance);
  out["band_Hz"] = {v.lowest_line_Hz, v.fmax_Hz};
  out["corner_Hz"] = v.fitted_corner_Hz && v.observable ? json(*v.fitted_corner_Hz) : json(nullptr);
  if (v.fitted_corner_Hz && !v.observable) {
    out["below_Hz"] = v.lowest_line_Hz / 3.0;
    out["note"] = fmt::format("not observable in this record: the fitted corner ({:.2g} Hz) is below a third of the lowest line "
                              "({:.3g} Hz)", *v.fitted_corner_Hz, v.lowest_line_Hz);
  }
  return out;
}

json resistor(const ResistorComparison& r) {
  return {{"with_resistor", r.with_resistor ? low_frequency_vs(*r.with_resistor) : json(nullptr)},
          {"without_resistor", low_frequency_vs(r.without_resistor)},
          {"method", "first-order high-pass g s/(s + wc) fitted to u -> Vs below hpf_fmax_Hz (Welch, segments of half the record)"}};
}

// The declared batch, its spreads keyed by quantity and the similarity's band and reference.
json batch(const BatchAnalysis& b) {
  json out = io::results_object(b);
  out["spread"] = json::object();
  for (const auto& s : b.spread) out["spread"][s.quantity] = io::results_object(s);
  out["similarity"] = json::object();
  if (b.similarity) {
    out["similarity"] = io::results_object(*b.similarity);
    out["similarity"]["reference"] = "median |H| of the batch";
    out["similarity"]["band_Hz"] = {b.similarity->fmin_Hz, b.similarity->fmax_Hz};
  }
  return out;
}

// The declared study, with how the locus was computed and what the controller and plant are.
json iff(const IffStudy& s) {
  json out = io::results_object(s);
  out["controller"]["formula"] = "K(s) = gain g s/(s + w_hpf) 1/(s + w_lpf) 1/(s + w_robust) (eq. 2.4)";
  if (s.plant && s.unit) out["plant"]["source"] = "IFF plant fit of unit " + std::to_string(*s.unit);
  if (s.plant && !s.failed) {
    out["locus_method"] = "closed-loop poles of 1 - g K G = 0 on 401 log-spaced gains around 1/|K G(j wp)| (plots), branch from the "
                          "resonance pole; maximum damping on the adaptive root locus from g = 0 refined by golden section "
                          "(lti::max_damping_on_branch, as `iff rlocus`; delay as a 6th-order Pade approximant)";
  }
  return out;
}

json superelement(const SuperElementComparison& s) {
  if (s.failed) return {{"failed", *s.failed}};
  json out = io::results_object(s);
  if (s.resonance_Hz && s.measured_resonance_Hz) out["relative_difference"] = num(*s.resonance_Hz / *s.measured_resonance_Hz - 1.0);
  return out;
}

json range(const std::optional<metrology::Range>& r, double scale) {
  return r ? json({r->min * scale, r->max * scale}) : json(nullptr);
}

}  // namespace

json unit_json(const UnitAnalysis& u) {
  json r = io::results_object(u);
  r["capacitance_provenance"] = nullptr;
  r["hpf"] = nullptr;
  r["model_2dof"] = nullptr;
  if (u.capacitance_analysis) {
    const auto& c = *u.capacitance_analysis;
    r["capacitance_provenance"] = c.provenance ? io::results_object(*c.provenance) : json({{"key", c.key}});
  }
  if (u.hysteresis_model) r["hysteresis_model"] = hysteresis_model(*u.hysteresis_model);
  if (u.tracking) r["tracking"] = tracking(*u.tracking);
  if (u.stiffness_analysis && u.stiffness_analysis->creep) r["stiffness_static"]["creep_prony"] = creep(*u.stiffness_analysis->creep);
  if (u.stiffness_open_analysis && u.stiffness_open_analysis->creep) {
    r["stiffness_open_circuit"]["creep_prony"] = creep(*u.stiffness_open_analysis->creep);
  }
  if (u.frf_analysis) {
    r["frf"] = frf(*u.frf_analysis);
    r["hpf"] = io::results_object(u.frf_analysis->hpf);
  }
  if (u.model_2dof) model_2dof(*u.model_2dof, r);
  if (u.resistor) r["hpf_resistor"] = resistor(*u.resistor);
  // k_sc: the stacks short-circuited (on the amplifier, the sensor on R) = k1 (report section 2.2).
  r["stiffness_N_per_um"]["k_sc"] = r["stiffness_N_per_um"]["k1"];
  // A group of numbers none of which was measured is null as a whole (as an analysis not run).
  if (!u.capacitance_analysis) r["capacitance_uF"] = nullptr;
  if (!k1_of(u) && !k_resonance_of(u) && !k_oc_of(u)) r["stiffness_N_per_um"] = nullptr;
  if (!u.damped.empty()) r["iff_damped_plants"] = damped_plants(u.damped);
  if (u.flexible_modes) r["flexible_modes"]["welch"] = welch(u.flexible_modes->welch);
  io::name_non_finite(r);
  return r;
}

json results_json(const CampaignResult& r) {
  const Campaign& c = r.campaign;
  json units = json::array();
  for (const auto& u : r.units) units.push_back(unit_json(u));
  const auto& a = c.analysis;
  const Specs& sp = c.specs;
  json specs = {{"flatness_um", sp.flatness_max ? json(*sp.flatness_max * kUm) : json(nullptr)},
                {"flatness_method", metrology::to_string(sp.flatness_method)},
                {"capacitance_sensor_uF", range(sp.capacitance_sensor, kUf)},
                {"capacitance_actuator_uF", range(sp.capacitance_actuator, kUf)},
                {"stroke_min_um", sp.stroke_min ? json(*sp.stroke_min * kUm) : json(nullptr)},
                {"stiffness_N_per_um", range(sp.stiffness, kNPerUm)},
                {"reject_outliers", sp.reject_outliers}};
  json doc = io::results_object(r);  // the declared view: the summary's counts
  doc.update(json{{"title", c.title},
          {"campaign", c.file.string()},
          {"generator", std::string("piezobench ") + kVersion},
          {"units", units},
          {"batch", batch(r.batch)},
          {"iff", iff(r.iff)},
          {"superelement", r.superelement ? superelement(*r.superelement) : json(nullptr)},
          {"specs", specs},
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
                       {"hpf_resistance_ohm", io::to_json(c.bench.hpf_resistance)}, {"probe_accuracy_um", c.bench.probe_accuracy * kUm},
                       {"added_mass_uncertainty_kg", c.bench.uncertainty.added_mass_kg},
                       {"gravity_uncertainty_m_per_s2", c.bench.uncertainty.gravity_m_per_s2},
                       {"suspended_mass_uncertainty_kg", c.bench.uncertainty.suspended_mass_kg},
                       {"encoder_resolution_um", c.bench.uncertainty.encoder_resolution_m * kUm},
                       {"capacitance_uncertainty_relative", c.bench.uncertainty.capacitance_relative},
                       {"displacement_scale_uncertainty_relative", c.bench.uncertainty.displacement_scale_relative}}},
            {"note", "per-analysis files, channels, window, nfft and averages are in each unit's provenance/welch entries"}}}});
  io::name_non_finite(doc);  // the one encoding of non-finite numbers (docs/formats.md)
  return doc;
}

}  // namespace piezobench::campaign
