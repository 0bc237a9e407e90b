#include "piezobench/station/measurements.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "piezobench/core/error.hpp"

namespace piezobench::station {

using campaign::Experiment;

std::string to_string(Verdict v) {
  switch (v) {
    case Verdict::kPass: return "pass";
    case Verdict::kMarginal: return "marginal";
    case Verdict::kFail: return "fail";
  }
  return "fail";
}

Verdict verdict_from_string(const std::string& s) {
  for (const Verdict v : {Verdict::kPass, Verdict::kMarginal, Verdict::kFail}) {
    if (to_string(v) == s) return v;
  }
  throw InputError("verdict", "verdict", "pass, marginal or fail", "'" + s + "'");
}

Verdict worst(Verdict a, Verdict b) { return static_cast<int>(a) >= static_cast<int>(b) ? a : b; }

const std::vector<MeasurementKind>& measurement_catalog() {
  static const std::vector<MeasurementKind> catalog = {
      {"flatness_um", "um", Experiment::kFlatness, "flatness of the interfaces by the campaign's method"},
      {"capacitance_sensor_uF", "uF", Experiment::kCapacitance, "capacitance of the sensor stack"},
      {"capacitance_actuator_uF", "uF", Experiment::kCapacitance, "capacitance of the actuator stacks"},
      {"stroke_um", "um", Experiment::kStroke, "stroke, max - min of d_e over the stack range"},
      {"sensitivity_um_per_V", "um/V", Experiment::kStroke, "slope of d_e against Va"},
      {"hysteresis_relative_width", "1", Experiment::kHysteresis, "loop width at the offset / loop stroke"},
      {"hysteresis_width_um", "um", Experiment::kHysteresis, "loop width at the offset"},
      {"k1_N_per_um", "N/um", Experiment::kStiffness, "static stiffness, mass put on"},
      {"k2_N_per_um", "N/um", Experiment::kStiffness, "static stiffness, mass taken off"},
      {"k_oc_N_per_um", "N/um", Experiment::kStiffnessOpen, "static stiffness with every stack open"},
      {"resonance_Hz", "Hz", Experiment::kFrf, "resonance of u -> d_e"},
      {"antiresonance_Hz", "Hz", Experiment::kFrf, "anti-resonance of u -> Vs"},
      {"resonance_damping", "1", Experiment::kFrf, "damping ratio of the resonance"},
      {"k_resonance_N_per_um", "N/um", Experiment::kFrf, "stiffness from the resonance, m_sus w^2"},
      {"static_gain_um_per_V", "um/V", Experiment::kFrf, "static gain u -> d_e"},
      {"hpf_corner_Hz", "Hz", Experiment::kFrf, "high-pass corner of the force sensor"},
      {"hpf_corner_without_resistor_Hz", "Hz", Experiment::kFrfNoResistor, "fitted corner without the resistor"},
      {"damped_damping", "1", Experiment::kIff, "damping ratio of the identified damped pole"},
      {"damped_frequency_Hz", "Hz", Experiment::kIff, "frequency of the identified damped pole"},
      {"first_mode_Hz", "Hz", Experiment::kHammer, "first flexible mode (LSCF, else peak picking)"},
      {"tracking_width_ff", "1", Experiment::kTracking, "hysteresis width of the 1 Hz sine with the feedforward"},
      {"tracking_rms_reduction", "1", Experiment::kTracking, "rms tracking error without / with the feedforward (sine)"},
  };
  return catalog;
}

const MeasurementKind* find_measurement(const std::string& name) {
  const auto& c = measurement_catalog();
  const auto it = std::find_if(c.begin(), c.end(), [&](const MeasurementKind& k) { return k.name == name; });
  return it == c.end() ? nullptr : &*it;
}

namespace {

constexpr double kMicro = 1e6;

std::optional<double> scaled(const std::optional<double>& v, double scale) {
  return v ? std::optional<double>(*v * scale) : std::nullopt;
}

std::optional<double> hysteresis_value(const campaign::UnitAnalysis& u, const std::string& name, const std::string& file) {
  for (const campaign::HysteresisLoop& h : u.hysteresis) {
    if (!file.empty() && h.provenance.file != file) continue;
    if (name == "hysteresis_relative_width") return h.result.relative_width;
    return h.result.width * kMicro;
  }
  return std::nullopt;
}

std::optional<double> damped_value(const campaign::UnitAnalysis& u, const std::string& name, const std::string& file) {
  for (const campaign::DampedPlant& d : u.damped) {
    if (!file.empty() && d.file != file) continue;
    if (!d.identified) return std::nullopt;
    return name == "damped_damping" ? d.identified->damping : d.identified->frequency_Hz();
  }
  return std::nullopt;
}

std::optional<double> frf_value(const campaign::UnitAnalysis& u, const std::string& name) {
  if (name == "resonance_Hz") return u.resonance_Hz;
  if (name == "antiresonance_Hz") return u.antiresonance_Hz;
  if (name == "k_resonance_N_per_um") return scaled(u.k_resonance, 1e-6);
  if (name == "static_gain_um_per_V") return scaled(u.static_gain, kMicro);
  if (!u.frf_analysis) return std::nullopt;
  if (name == "resonance_damping") return u.frf_analysis->resonance_damping;
  if (name == "hpf_corner_Hz") return u.frf_analysis->hpf.corner_Hz;
  return std::nullopt;
}

}  // namespace

std::optional<double> measured_value(const campaign::UnitAnalysis& u, const std::string& name, const std::string& file) {
  if (name == "flatness_um") return scaled(u.flatness, kMicro);
  if (name == "capacitance_sensor_uF") return scaled(u.capacitance_sensor, kMicro);
  if (name == "capacitance_actuator_uF") return scaled(u.capacitance_actuator, kMicro);
  if (name == "stroke_um") return scaled(u.stroke, kMicro);
  if (name == "sensitivity_um_per_V") {
    return u.stroke_analysis ? std::optional<double>(u.stroke_analysis->result.sensitivity * kMicro) : std::nullopt;
  }
  if (name.rfind("hysteresis_", 0) == 0) return hysteresis_value(u, name, file);
  if (name == "k1_N_per_um") return scaled(u.k1, 1e-6);
  if (name == "k2_N_per_um") return scaled(u.k2, 1e-6);
  if (name == "k_oc_N_per_um") return scaled(u.k_oc, 1e-6);
  if (name == "hpf_corner_without_resistor_Hz") {
    return u.resistor ? u.resistor->without_resistor.fitted_corner_Hz : std::nullopt;
  }
  if (name.rfind("damped_", 0) == 0) return damped_value(u, name, file);
  if (name == "first_mode_Hz") {
    if (!u.flexible_modes) return std::nullopt;
    const auto& m = u.flexible_modes->lscf.empty() ? u.flexible_modes->peak_picking : u.flexible_modes->lscf;
    return m.empty() ? std::nullopt : std::optional<double>(m.front().frequency_Hz);
  }
  if (name == "tracking_width_ff") return u.tracking ? std::optional<double>(u.tracking->sine.width_ff) : std::nullopt;
  if (name == "tracking_rms_reduction") {
    return u.tracking ? std::optional<double>(u.tracking->sine.rms_reduction()) : std::nullopt;
  }
  return frf_value(u, name);
}

MeasuredValue judge(const MeasurementKind& kind, std::optional<double> value, const Limit& limit, double margin_relative) {
  MeasuredValue m{kind.name, kind.unit, value, limit, Verdict::kPass, {}};
  if (!value) {
    m.verdict = Verdict::kFail;
    m.reason = fmt::format("{}: no value (the analysis gave none)", kind.name);
    return m;
  }
  const double v = *value;
  const auto check = [&](double bound, bool is_min) {
    const double u = margin_relative * std::abs(bound);
    const bool outside = is_min ? v < bound : v > bound;
    Verdict here = Verdict::kPass;
    if (std::abs(v - bound) <= u) {
      here = Verdict::kMarginal;
    } else if (outside) {
      here = Verdict::kFail;
    }
    if (static_cast<int>(here) > static_cast<int>(m.verdict)) {
      m.verdict = here;
      m.reason = fmt::format("{} {:.4g} {} {} {} {:.4g} {}{}", kind.description, v, kind.unit,
                             here == Verdict::kMarginal ? "within the margin of" : (is_min ? "below" : "above"),
                             is_min ? "the minimum" : "the maximum",
                             bound, kind.unit,
                             here == Verdict::kMarginal ? fmt::format(" (margin +-{:.3g} {})", u, kind.unit) : std::string());
    }
  };
  if (limit.min) check(*limit.min, true);
  if (limit.max) check(*limit.max, false);
  return m;
}

}  // namespace piezobench::station
