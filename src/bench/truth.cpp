#include "piezobench/bench/truth.hpp"

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <utility>

#include "flatness.hpp"
#include "plant.hpp"
#include "piezobench/bench/experiments.hpp"
#include "piezobench/lti/analysis.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::bench {

namespace {

double mean_over(const io::TimeSeries& ts, const std::string& channel, double t0, double t1) {
  const auto c = ts.channel(channel);
  double sum = 0.0;
  Eigen::Index count = 0;
  for (Eigen::Index k = 0; k < ts.samples(); ++k) {
    const double t = static_cast<double>(k) / ts.sample_rate;
    if (t >= t0 && t < t1) {
      sum += c(k);
      ++count;
    }
  }
  return count > 0 ? sum / static_cast<double>(count) : std::numeric_limits<double>::quiet_NaN();
}

lti::StateSpace channel(const lti::StateSpace& sys, lti::Index output) {
  lti::StateSpace s(sys.A, sys.B, sys.C.row(output), sys.D.row(output));
  return s;
}

// Resonance: the lowest lightly damped complex pole pair (the 2-DoF model has one; a super
// element's modes all have the same modal damping, and the suspended mass's is the lowest).
lti::PoleInfo lowest_resonance(const lti::StateSpace& sys) {
  const std::vector<lti::PoleInfo> poles = lti::damp(sys);
  lti::PoleInfo res{};
  res.natural_frequency = std::numeric_limits<double>::infinity();
  for (const auto& pi : poles) {
    if (pi.pole.imag() > 0.0 && pi.damping < 0.2 && pi.natural_frequency < res.natural_frequency) res = pi;
  }
  return res;
}

// Anti-resonance: the lowest complex zero pair of u -> Vs. (The analysis of sampled files by
// scripts/analysis/check_simulate.py finds it within 0.0005 in damping.)
void add_antiresonance(const lti::StateSpace& sys, nlohmann::json& j) {
  lti::PoleInfo anti{};
  anti.natural_frequency = std::numeric_limits<double>::infinity();
  for (const auto z : lti::zeros(channel(sys, 1))) {
    if (z.imag() <= 1e-9 * std::abs(z)) continue;
    const lti::PoleInfo zi = lti::pole_info(z);
    if (zi.natural_frequency < anti.natural_frequency) anti = zi;
  }
  if (std::isfinite(anti.natural_frequency)) {
    j["antiresonance_Hz"] = anti.natural_frequency / kTwoPi;
    j["antiresonance_damping"] = anti.damping;
    j["zero_is_nonminimum_phase"] = anti.damping < 0.0;
    j["nmp_zero"] = {{"frequency_Hz", anti.natural_frequency / kTwoPi}, {"damping", anti.damping}};
  } else {
    j["antiresonance_Hz"] = nullptr;
    j["antiresonance_damping"] = nullptr;
    j["zero_is_nonminimum_phase"] = false;
    j["nmp_zero"] = nullptr;
  }
}

// The static figures of the model: gain d_e / u and Vs / u, total and static stiffness, and the
// open-circuit stiffness (2-DoF model only).
struct StaticFigures {
  double static_gain = 0.0, static_vs = 0.0, k_tot = 0.0, k_static = 0.0;  // m/V, V/V, N/m, N/m
  std::optional<double> k_open;                                             // N/m
};

StaticFigures static_figures(const UnitTruth& unit, const BenchOptions& options, bool two_dof, double resonance_rad_s, double dc_gain) {
  const apa::TwoDofParams& p = unit.model;
  const double g = options.amplifier_gain;
  StaticFigures s;
  s.static_gain = dc_gain;
  if (two_dof) {
    s.k_tot = p.total_stiffness();
    s.static_gain = g * p.ga * p.ke / (p.ke + p.ka) / s.k_tot;
    s.static_vs = -g * p.gs * p.ga * p.k1 / ((p.ke + p.ka) * s.k_tot);
    // The sensor stack short-circuited: ke_sc = ke - gs^2 C_b (virtual_bench.hpp).
    const double kk = p.ke + p.ka * p.k1 / (p.ka + p.k1);
    const double cb = unit.capacitance_sensor * kk / (kk + p.gs * p.gs * unit.capacitance_sensor);
    const double ke_sc = p.ke - p.gs * p.gs * cb;
    s.k_static = p.k1 + ke_sc * p.ka / (ke_sc + p.ka);
    // Every stack open: the sensor at ke, the actuators at ka + ga^2 / C_ab (virtual_bench.hpp).
    const double ka_oc = p.ka + p.ga * p.ga / detail::actuator_blocked_capacitance(p, unit.capacitance_actuator);
    s.k_open = p.k1 + p.ke * ka_oc / (p.ke + ka_oc);
  } else {
    // No electromechanical coupling in the super-element bench: one static stiffness, taken as
    // m_sus w^2 at the resonance (the report's eq. 2.2); no stiffness-line level of Vs is given.
    s.k_tot = options.suspended_mass * std::pow(resonance_rad_s, 2);
    s.k_static = s.k_tot;
    s.static_vs = std::numeric_limits<double>::quiet_NaN();
  }
  return s;
}

// k1 and k2 of a noise-free stiffness record, N/um.
std::pair<double, double> stiffness_readings(const UnitTruth& unit, const ExperimentOptions& e, double weight) {
  const io::TimeSeries stiff = simulate(Experiment::kStiffness, unit, e, 0);
  const double d_before = mean_over(stiff, "de", 2.0, 2.9);
  const double d_loaded = mean_over(stiff, "de", 12.0, 12.9);
  const double d_after = mean_over(stiff, "de", 14.0, 15.0);
  return std::pair{weight / (d_before - d_loaded) * 1e-6, weight / (d_after - d_loaded) * 1e-6};
}

// The stiffnesses (N/um) and the noise-free stroke (um) and flatness readings.
void add_readings(const UnitTruth& unit, const BenchOptions& options, bool two_dof, double resonance_rad_s, const StaticFigures& s,
                  nlohmann::json& j) {
  ExperimentOptions eo;
  eo.bench = options;
  eo.bench.noise = false;
  const double weight = options.added_mass * options.gravity;
  const auto [k1, k2] = stiffness_readings(unit, eo, weight);
  j["stiffness_N_per_um"] = {{"k_tot", s.k_tot * 1e-6},
                             {"static", s.k_static * 1e-6},
                             {"resonance", options.suspended_mass * std::pow(resonance_rad_s, 2) * 1e-6},
                             {"k1", k1},
                             {"k2", k2},
                             {"k_sc", k1},
                             {"k_oc", nullptr},
                             {"open_circuit", s.k_open ? nlohmann::json(*s.k_open * 1e-6) : nlohmann::json(nullptr)}};
  if (two_dof) {
    // The same test with every stack open: the actuators disconnected, no resistor on the sensor.
    ExperimentOptions open = eo;
    open.bench.actuator_open_circuit = true;
    open.bench.hpf_resistor = false;
    j["stiffness_N_per_um"]["k_oc"] = stiffness_readings(unit, open, weight).first;
  }
  j["stiffness_readings"] = {{"before_s", {2.0, 2.9}}, {"loaded_s", {12.0, 12.9}}, {"after_s", {14.0, 15.0}}};
  const io::TimeSeries stroke = simulate(Experiment::kStroke, unit, eo, 0);
  const auto de = stroke.channel("de");
  j["stroke_um"] = (de.maxCoeff() - de.minCoeff()) * 1e6;
  const Eigen::Matrix<double, 8, 3> layout = detail::probe_layout();
  j["flatness_um"] = detail::plane_flatness(layout.col(0), layout.col(1), detail::probe_heights(unit)) * 1e6;
}

}  // namespace

nlohmann::json truth_json(const UnitTruth& unit, const BenchOptions& options) {
  const VirtualBench bench(unit, options, 0);
  const lti::StateSpace sys = bench.linear_model();
  nlohmann::json j;
  j["id"] = unit.id;
  j["defective"] = unit.defective;
  j["defect"] = unit.defect;
  j["model"] = bench.model_name();
  j["delay_s"] = bench.effective_delay();
  const bool two_dof = bench.model_name() == "2dof";
  const apa::TwoDofParams& p = unit.model;
  if (two_dof) {
    j["model_2dof"] = {{"m", options.suspended_mass}, {"k1", p.k1}, {"c1", p.c1}, {"ke", p.ke}, {"ce", p.ce},
                       {"ka", p.ka},                  {"ca", p.ca}, {"ga", p.ga}, {"gs", p.gs}};
  } else {
    j["model_2dof"] = nullptr;
  }
  j["capacitance_uF"] = {{"sensor", unit.capacitance_sensor * 1e6}, {"actuator", unit.capacitance_actuator * 1e6}};
  j["hpf_corner_Hz"] = 1.0 / (kTwoPi * options.sensor_shunt_resistance() * unit.capacitance_sensor);
  j["hpf_corner_with_resistor_Hz"] = 1.0 / (kTwoPi * options.hpf_resistance * unit.capacitance_sensor);
  j["hpf_corner_without_resistor_Hz"] = 1.0 / (kTwoPi * options.adc_input_resistance * unit.capacitance_sensor);
  const lti::PoleInfo res = lowest_resonance(sys);
  j["resonance_Hz"] = res.natural_frequency / kTwoPi;
  j["resonance_damping"] = res.damping;
  add_antiresonance(sys, j);

  const lti::Matrix dc = lti::dc_gain(sys);
  const StaticFigures s = static_figures(unit, options, two_dof, res.natural_frequency, dc(0, 0));
  j["static_gain_um_per_V"] = s.static_gain * 1e6;
  j["dc_gain_um_per_V"] = dc(0, 0) * 1e6;
  j["static_gain_Vs_V_per_V"] = std::isfinite(s.static_vs) ? nlohmann::json(s.static_vs) : nlohmann::json(nullptr);
  add_readings(unit, options, two_dof, res.natural_frequency, s, j);
  j["bending_modes_Hz"] = {{"y", unit.mode_y_Hz}, {"x", unit.mode_x_Hz}};
  j["bending_damping"] = unit.mode_damping;
  j["stroke_factor"] = unit.stroke_factor;
  j["hysteresis_scale"] = unit.hysteresis_scale;
  j["creep_coefficient"] = unit.creep_coefficient;
  j["load_creep_coefficient"] = unit.load_creep_coefficient;
  return j;
}

}  // namespace piezobench::bench
