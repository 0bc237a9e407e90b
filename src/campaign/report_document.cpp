#include "piezobench/campaign/report_document.hpp"

#include <fmt/format.h>

#include "piezobench/version.hpp"

namespace piezobench::campaign {

using nlohmann::json;

namespace {

json trace(const std::string& name, const json& x, const json& y, const std::string& group = "", bool dash = false,
           const std::string& mode = "lines") {
  json t = {{"name", name}, {"x", x}, {"y", y}, {"mode", mode}, {"dash", dash}};
  if (!group.empty()) t["group"] = group;
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

bool has(const json& j, const char* key) { return j.is_object() && j.contains(key) && !j[key].is_null(); }

// FRF figure of one output ("de" or "Vs"), all units, with the model named by `model_key`.
json frf_figure(const std::vector<UnitAnalysis>& units, const std::string& out, const std::string& id, const std::string& title,
                const std::string& unit_label, const std::string& model_abs, const std::string& model_phase,
                const std::string& model_name, bool model_in_frf) {
  json mag = json::array(), phase = json::array(), coh = json::array();
  for (const auto& u : units) {
    if (!has(u.plots, "frf")) continue;
    const json& p = u.plots["frf"];
    mag.push_back(trace(u.name, p["f"], p[out + "_abs"], u.name));
    phase.push_back(trace(u.name, p["f"], p[out + "_phase"], u.name));
    coh.push_back(trace(u.name, p["f"], p[out + "_coh"], u.name));
    const json& m = model_in_frf ? p : (has(u.plots, "model") ? u.plots["model"] : json());
    if (has(m, model_abs.c_str())) {
      mag.push_back(trace(u.name + " " + model_name, m["f"], m[model_abs], u.name, true));
      phase.push_back(trace(u.name + " " + model_name, m["f"], m[model_phase], u.name, true));
    }
  }
  return figure(id, title, "Frequency [Hz]", true,
                json::array({panel("|H| [" + unit_label + "]", true, mag), panel("Phase [deg]", false, phase),
                             panel("Coherence", false, coh)}),
                "Solid: measured (Welch H1); dashed: " + model_name + ".");
}

}  // namespace

json report_document(const Campaign& c, const std::vector<UnitAnalysis>& units, const json& results, const json& extra) {
  json sections = json::array();
  // Frequency responses.
  {
    json figs = json::array();
    if (std::any_of(units.begin(), units.end(), [](const UnitAnalysis& u) { return has(u.plots, "frf"); })) {
      figs.push_back(frf_figure(units, "de", "frf-de", "u -> d_e", "um/V", "de_abs", "de_phase", "tuned 2-DoF model", false));
      figs.push_back(frf_figure(units, "Vs", "frf-vs", "u -> Vs", "V/V", "iff_fit_abs", "iff_fit_phase", "IFF plant fit (eq. 2.3)", true));
      json model = json::array();
      for (const auto& u : units) {
        if (has(u.plots, "model")) {
          model.push_back(trace(u.name + " model", u.plots["model"]["f"], u.plots["model"]["Vs_abs"], u.name, true));
          model.push_back(trace(u.name, u.plots["frf"]["f"], u.plots["frf"]["Vs_abs"], u.name));
        }
      }
      if (!model.empty()) {
        figs.push_back(figure("model-vs", "Tuned 2-DoF model against the measurement, u -> Vs", "Frequency [Hz]", true,
                              json::array({panel("|H| [V/V]", true, model)})));
      }
    }
    if (!figs.empty()) {
      sections.push_back({{"id", "frf"}, {"title", "Frequency responses"},
                          {"text", "FRFs from the DAC voltage u to the encoder d_e and to the force-sensor voltage Vs "
                                   "(report section 2.3), all units overlaid, with the coherence."},
                          {"figures", figs}});
    }
  }
  // Hysteresis, stroke, stiffness.
  {
    json figs = json::array();
    for (const auto& u : units) {
      if (!has(u.plots, "hysteresis") || u.plots["hysteresis"].empty()) continue;
      json traces = json::array();
      for (const auto& loop : u.plots["hysteresis"]) {
        traces.push_back(trace(fmt::format("{:g} V", loop["amplitude_V"].get<double>()), loop["Va"], loop["de_um"]));
      }
      figs.push_back(figure(fmt::format("hysteresis-{}", u.id), u.name + ": hysteresis loops", "Va [V]", false,
                            json::array({panel("d_e [um]", false, traces)})));
    }
    json stroke = json::array();
    for (const auto& u : units) {
      if (has(u.plots, "stroke")) stroke.push_back(trace(u.name, u.plots["stroke"]["Va"], u.plots["stroke"]["de_um"], u.name));
    }
    if (!stroke.empty()) {
      figs.push_back(figure("stroke", "Stroke: displacement against the stack voltage (slow ramp)", "Va [V]", false,
                            json::array({panel("d_e [um]", false, stroke)})));
    }
    if (!figs.empty()) sections.push_back({{"id", "quasi-static"}, {"title", "Stroke and hysteresis"}, {"figures", figs}});
  }
  {
    json traces = json::array();
    for (const auto& u : units) {
      if (!has(u.plots, "stiffness")) continue;
      traces.push_back(trace(u.name, u.plots["stiffness"]["t"], u.plots["stiffness"]["de_um"], u.name));
      traces.push_back(trace(u.name + " creep fit", u.plots["stiffness"]["t"], u.plots["stiffness"]["fit_um"], u.name, true));
    }
    if (!traces.empty()) {
      sections.push_back({{"id", "stiffness"},
                          {"title", "Static stiffness"},
                          {"text", fmt::format("Added mass {:g} kg put on and taken off (report section 2.2); dashed: the fitted "
                                               "logarithmic creep model.", c.bench.added_mass)},
                          {"figures", json::array({figure("stiffness", "d_e during the added-mass test", "Time [s]", false,
                                                          json::array({panel("d_e [um]", false, traces)}))})}});
    }
  }
  // IFF.
  {
    json figs = json::array();
    if (extra.contains("root_locus")) {
      const json& rl = extra["root_locus"];
      json traces = json::array();
      for (const auto& b : rl["branches"]) traces.push_back(trace("root locus (fitted plant, eq. 2.4)", b["re"], b["im"], "model"));
      json re = json::array(), im = json::array();
      for (const auto& d : rl["damped"]) {
        re.push_back(d["re"]);
        im.push_back(d["im"]);
      }
      if (!re.empty()) traces.push_back(trace("damped plants (2nd-order fits)", re, im, "", false, "markers"));
      traces.push_back(trace("open-loop resonance", json::array({rl["open_loop_pole"][0]}), json::array({rl["open_loop_pole"][1]}), "", false, "markers"));
      figs.push_back(figure("root-locus", fmt::format("Root locus, APA {}", rl["unit"].get<int>()), "Re [rad/s]", false,
                            json::array({panel("Im [rad/s]", false, traces)}),
                            "Closed-loop poles of 1 - g K(s) G(s) = 0 for the fitted plant G (eq. 2.3 with delay) and the "
                            "report's controller K (eq. 2.4), against the poles of the second-order fits of the measured damped plants."));
    }
    json damped = json::array();
    for (const auto& u : units) {
      if (!has(u.plots, "damped")) continue;
      for (const auto& d : u.plots["damped"]) {
        const std::string name = fmt::format("{} g = {:g}", u.name, d["gain"].get<double>());
        damped.push_back(trace(name, d["f"], d["abs"], name));
        damped.push_back(trace(name + " fit", d["f"], d["fit_abs"], name, true));
      }
    }
    if (!damped.empty()) {
      figs.push_back(figure("damped-plants", "Damped plants u' -> d_e", "Frequency [Hz]", true,
                            json::array({panel("|H| [um/V]", true, damped)}), "Solid: measured; dashed: second-order fits."));
    }
    if (!figs.empty()) sections.push_back({{"id", "iff"}, {"title", "Integral Force Feedback"}, {"figures", figs}});
  }
  // Flexible modes.
  {
    json traces = json::array();
    for (const auto& u : units) {
      if (has(u.plots, "hammer")) traces.push_back(trace(u.name, u.plots["hammer"]["f"], u.plots["hammer"]["abs"], u.name));
    }
    if (!traces.empty()) {
      sections.push_back({{"id", "modes"}, {"title", "Flexible modes (hammer test)"},
                          {"figures", json::array({figure("hammer", "Force -> vibrometer velocity", "Frequency [Hz]", true,
                                                          json::array({panel("|H| [m/s/N]", true, traces)}))})}});
    }
  }
  // Batch comparison.
  {
    json names = json::array();
    for (const auto& u : units) names.push_back(u.name);
    auto bars = [&](const std::string& name, const std::function<json(const json&)>& get) {
      json y = json::array();
      for (const auto& r : results["units"]) y.push_back(get(r));
      return trace(name, names, y, "", false, "bars");
    };
    auto at = [](const json& r, const char* a, const char* b = nullptr) -> json {
      if (!has(r, a)) return nullptr;
      if (!b) return r[a];
      return has(r[a], b) ? r[a][b] : json(nullptr);
    };
    auto limit = [&](const std::string& name, double v) {
      json y = json::array();
      for (std::size_t i = 0; i < names.size(); ++i) y.push_back(v);
      return trace(name, names, y, "", true, "lines");
    };
    json figs = json::array();
    {
      json t = json::array({bars("sensor stack", [&](const json& r) { return at(r, "capacitance_uF", "sensor"); }),
                            bars("actuator stacks", [&](const json& r) { return at(r, "capacitance_uF", "actuator"); })});
      if (c.specs.capacitance_sensor) t.push_back(limit("sensor minimum", c.specs.capacitance_sensor->min * 1e6));
      if (c.specs.capacitance_actuator) t.push_back(limit("actuator minimum", c.specs.capacitance_actuator->min * 1e6));
      figs.push_back(figure("batch-capacitance", "Capacitance", "", false, json::array({panel("C [uF]", false, t)})));
    }
    {
      json t = json::array({bars("k1", [&](const json& r) { return at(r, "stiffness_N_per_um", "k1"); }),
                            bars("k2", [&](const json& r) { return at(r, "stiffness_N_per_um", "k2"); }),
                            bars("from the resonance", [&](const json& r) { return at(r, "stiffness_N_per_um", "resonance"); })});
      figs.push_back(figure("batch-stiffness", "Stiffness", "", false, json::array({panel("k [N/um]", false, t)})));
    }
    {
      json t = json::array({bars("flatness", [&](const json& r) { return at(r, "flatness_um"); })});
      if (c.specs.flatness_max) t.push_back(limit("flatness limit", *c.specs.flatness_max * 1e6));
      figs.push_back(figure("batch-flatness", "Flatness (" + metrology::to_string(c.specs.flatness_method) + ")", "", false,
                            json::array({panel("flatness [um]", false, t)})));
    }
    {
      json t = json::array({bars("stroke", [&](const json& r) { return at(r, "stroke_um"); })});
      if (c.specs.stroke_min) t.push_back(limit("minimum stroke", *c.specs.stroke_min * 1e6));
      figs.push_back(figure("batch-stroke", "Stroke", "", false, json::array({panel("stroke [um]", false, t)})));
    }
    sections.push_back({{"id", "batch"}, {"title", "Batch comparison"}, {"figures", figs}});
  }
  if (extra.contains("superelement")) {
    json traces = json::array();
    for (const auto& u : units) {
      if (has(u.plots, "frf")) traces.push_back(trace(u.name, u.plots["frf"]["f"], u.plots["frf"]["de_abs"], u.name));
    }
    traces.push_back(trace("super element", extra["superelement"]["f"], extra["superelement"]["abs_um_per_V"], "", true));
    sections.push_back({{"id", "superelement"}, {"title", "Super element"},
                        {"figures", json::array({figure("superelement", "u -> d_e: super element against the measurements",
                                                        "Frequency [Hz]", true, json::array({panel("|H| [um/V]", true, traces)}))})}});
  }
  return {{"title", c.title},
          {"subtitle", fmt::format("{} — piezobench {}", c.file.filename().string(), kVersion)},
          {"results", results},
          {"sections", sections}};
}

}  // namespace piezobench::campaign
