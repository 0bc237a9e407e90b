#pragma once
// A representative report document, built from closed-form curves (no piezobench analysis): the
// seed report's 7-unit batch with unit 3 rejected, Bode plots with 3 panels (magnitude, phase,
// coherence), model vs. measurement, a root locus, hysteresis loops, stiffness time series and
// batch bars. Used by html_report_test.cpp and by render_sample.cpp, whose output the headless
// Chromium test (render_check.js) opens. Strings include the characters an attacker would use.
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

namespace piezobench::test::report_sample {

using nlohmann::json;
using cplx = std::complex<double>;

inline constexpr int kUnits = 7;
inline constexpr int kRejectedUnit = 3;  // 1-based, as in the seed report

inline std::string unit_name(int u) {
  return "APA " + std::to_string(u);
}

inline std::vector<double> logspace(double a, double b, int n) {
  std::vector<double> v(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) v[static_cast<std::size_t>(i)] = a * std::pow(b / a, i / double(n - 1));
  return v;
}

inline std::vector<double> linspace(double a, double b, int n) {
  std::vector<double> v(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) v[static_cast<std::size_t>(i)] = a + (b - a) * i / double(n - 1);
  return v;
}

struct UnitTruth {
  double resonance_Hz, antiresonance_Hz, static_gain_um_per_V, k1, k2, c_sensor, c_actuator, stroke_um;
};

// Unit 3 has about half the capacitance and a short stroke, as in the seed report.
inline UnitTruth truth(int u) {
  const double d = 0.004 * (u - 4);
  UnitTruth t{95.0 * (1 + d), 40.0 * (1 + 0.5 * d), -0.31 * (1 - d), 1.75 * (1 + d),
              1.80 * (1 + d), 4.4 * (1 + d),        8.9 * (1 + d),   305.0 * (1 - d)};
  if (u == kRejectedUnit) {
    t.c_sensor = 2.3;
    t.c_actuator = 8.7;
    t.stroke_um = 183.0;
  }
  return t;
}

// u -> d_e: the static gain, the suspension mode, then a zero pair below a second mode.
inline cplx frf(const UnitTruth& t, double f) {
  const auto second_order = [](cplx s, double f0, double zeta) {
    return 1.0 + 2.0 * zeta * s / f0 + (s / f0) * (s / f0);
  };
  const cplx s(0.0, f);
  const double zero_Hz = 4.2 * t.resonance_Hz, second_mode_Hz = 7.4 * t.resonance_Hz;
  return t.static_gain_um_per_V * second_order(s, zero_Hz, 0.02) /
         (second_order(s, t.resonance_Hz, 0.03) * second_order(s, second_mode_Hz, 0.02));
}

inline json trace(const std::string& name, const std::vector<double>& x, const std::vector<double>& y,
                  const std::string& group = "", const std::string& mode = "lines", bool dash = false) {
  json t = {{"name", name}, {"x", x}, {"y", y}, {"mode", mode}, {"dash", dash}};
  if (!group.empty()) t["group"] = group;
  return t;
}

inline json bode_figure() {
  const auto f = logspace(5.0, 2000.0, 400);
  json mag = json::array(), phase = json::array(), coh = json::array();
  for (int u = 1; u <= kUnits; ++u) {
    const UnitTruth t = truth(u);
    std::vector<double> m, p, c;
    for (const double fi : f) {
      const cplx h = frf(t, fi);
      m.push_back(std::abs(h));
      p.push_back(std::arg(h) * 180.0 / std::numbers::pi);
      c.push_back(1.0 - 0.4 * std::exp(-std::pow((fi - 4.2 * t.resonance_Hz) / 8.0, 2)) - 0.05 * fi / 2000.0);
    }
    c[10] = std::numeric_limits<double>::quiet_NaN();  // a gap, as a NaN from the analysis
    mag.push_back(trace(unit_name(u), f, m, unit_name(u)));
    phase.push_back(trace(unit_name(u) + " phase", f, p, unit_name(u)));
    coh.push_back(trace(unit_name(u) + " coherence", f, c, unit_name(u)));
  }
  return {{"id", "frf-de"},
          {"title", "u -> d_e, all units"},
          {"text", "Welch H1 estimate, Hann window; coherence below."},
          {"x_label", "Frequency [Hz]"},
          {"x_log", true},
          {"panels",
           {{{"y_label", "|d_e/u| [um/V]"}, {"y_log", true}, {"traces", mag}},
            {{"y_label", "Phase [deg]"}, {"y_log", false}, {"traces", phase}},
            {{"y_label", "Coherence [-]"}, {"traces", coh}}}}};
}

inline json model_figure() {
  const auto f = logspace(5.0, 2000.0, 200);
  json mag = json::array(), phase = json::array();
  for (const int u : {1, 3}) {
    UnitTruth t = truth(u);
    UnitTruth model = t;
    model.resonance_Hz *= 1.01;
    for (const auto& [which, dash] : {std::pair{t, false}, std::pair{model, true}}) {
      std::vector<double> m, p;
      for (const double fi : f) {
        m.push_back(std::abs(frf(which, fi)));
        p.push_back(std::arg(frf(which, fi)) * 180.0 / std::numbers::pi);
      }
      const std::string label = unit_name(u) + (dash ? " 2-DoF model" : " measured");
      mag.push_back(trace(label, f, m, unit_name(u), "lines", dash));
      phase.push_back(trace(label, f, p, unit_name(u), "lines", dash));
    }
  }
  return {{"id", "model-vs-measurement"},
          {"title", "Tuned 2-DoF model (dashed) against the measurement"},
          {"x_label", "Frequency [Hz]"},
          {"x_log", true},
          {"panels",
           {{{"y_label", "|d_e/u| [um/V]"}, {"y_log", true}, {"traces", mag}},
            {{"y_label", "Phase [deg]"}, {"traces", phase}}}}};
}

// Roots of s^3 + a s^2 + b s + c (Durand-Kerner; the polynomial is well conditioned here).
inline std::vector<cplx> cubic_roots(double a, double b, double c) {
  std::vector<cplx> z{cplx(0.4, 0.9), cplx(0.4, 0.9) * cplx(0.4, 0.9),
                      cplx(0.4, 0.9) * cplx(0.4, 0.9) * cplx(0.4, 0.9)};
  const double scale = std::max({1.0, std::abs(a), std::sqrt(std::abs(b)), std::cbrt(std::abs(c))});
  for (auto& zi : z) zi *= scale;
  for (int it = 0; it < 500; ++it) {
    for (std::size_t i = 0; i < 3; ++i) {
      cplx den = 1.0;
      for (std::size_t j = 0; j < 3; ++j) {
        if (j != i) den *= z[i] - z[j];
      }
      z[i] -= (((z[i] + a) * z[i] + b) * z[i] + c) / den;
    }
  }
  return z;
}

// IFF: plant (s^2 + wz^2)/(s^2 + wp^2), controller g/s: s^3 + g s^2 + wp^2 s + g wz^2 = 0.
inline json root_locus_figure() {
  const double wz = 2 * std::numbers::pi * 40.0, wp = 2 * std::numbers::pi * 95.0;
  std::vector<double> re_up, im_up, re_lo, im_lo, re_real, im_real;
  for (const double g : logspace(1.0, 3000.0, 150)) {
    for (const cplx r : cubic_roots(g, wp * wp, g * wz * wz)) {
      if (std::abs(r.imag()) < 1e-6 * wp) {
        re_real.push_back(r.real());
        im_real.push_back(0.0);
      } else if (r.imag() > 0) {
        re_up.push_back(r.real());
        im_up.push_back(r.imag());
      } else {
        re_lo.push_back(r.real());
        im_lo.push_back(r.imag());
      }
    }
  }
  json traces = json::array();
  traces.push_back(trace("root locus (model)", re_up, im_up, "root locus (model)"));
  traces.push_back(trace("root locus (model), conjugate", re_lo, im_lo, "root locus (model)"));
  traces.push_back(trace("root locus (model), real branch", re_real, im_real, "root locus (model)", "markers"));
  for (int u = 1; u <= kUnits; ++u) {
    std::vector<double> re, im;
    for (const double g : {30.0, 100.0, 300.0}) {
      for (const cplx r : cubic_roots(g, wp * wp * (1 + 0.01 * u), g * wz * wz)) {
        if (r.imag() > 0) {
          re.push_back(r.real() * (1 + 0.02 * (u - 4)));
          im.push_back(r.imag());
        }
      }
    }
    traces.push_back(trace(unit_name(u) + " damped plant poles", re, im, unit_name(u), "markers"));
  }
  return {{"id", "root-locus"},
          {"title", "IFF root locus against the damped-plant poles"},
          {"x_label", "Real part [rad/s]"},
          {"panels", {{{"y_label", "Imaginary part [rad/s]"}, {"traces", traces}}}}};
}

inline json hysteresis_figure() {
  json traces = json::array();
  for (int u = 1; u <= kUnits; ++u) {
    const UnitTruth t = truth(u);
    std::vector<double> v, d;
    for (const double ph : linspace(0.0, 2 * std::numbers::pi, 240)) {
      const double volts = 75.0 * (1.0 - std::cos(ph));
      v.push_back(volts);
      d.push_back(-t.stroke_um * volts / 170.0 - 8.0 * std::sin(ph));
    }
    traces.push_back(trace(unit_name(u), v, d, unit_name(u)));
  }
  return {{"id", "hysteresis"},
          {"title", "Hysteresis loops at 150 V peak-to-peak"},
          {"x_label", "Stack voltage V_a [V]"},
          {"panels", {{{"y_label", "d_e [um]"}, {"traces", traces}}}}};
}

inline json stiffness_figure() {
  json force = json::array(), disp = json::array();
  const auto t = linspace(0.0, 30.0, 300);
  for (int u = 1; u <= kUnits; ++u) {
    const UnitTruth tr = truth(u);
    std::vector<double> fo, di;
    for (const double ti : t) {
      const double load = ti < 5 ? 0.0 : (ti < 20 ? 10.0 : 0.0);
      const double creep = ti < 5 ? 0.0 : (ti < 20 ? 0.3 * (1 - std::exp(-(ti - 5) / 3.0)) : 0.0);
      fo.push_back(load);
      di.push_back(load / tr.k1 + creep);
    }
    force.push_back(trace(unit_name(u) + " force", t, fo, unit_name(u)));
    disp.push_back(trace(unit_name(u) + " displacement", t, di, unit_name(u)));
  }
  return {{"id", "stiffness-series"},
          {"title", "Static stiffness: load steps and creep"},
          {"x_label", "Time [s]"},
          {"panels",
           {{{"y_label", "Force [N]"}, {"traces", force}}, {{"y_label", "Displacement [um]"}, {"traces", disp}}}}};
}

inline json batch_figure() {
  std::vector<std::string> names;
  std::vector<double> cs, ca, stroke;
  for (int u = 1; u <= kUnits; ++u) {
    names.push_back(unit_name(u));
    cs.push_back(truth(u).c_sensor);
    ca.push_back(truth(u).c_actuator);
    stroke.push_back(truth(u).stroke_um);
  }
  json cap = json::array({{{"name", "sensor stack"}, {"x", names}, {"y", cs}, {"mode", "bars"}},
                          {{"name", "actuator stack"}, {"x", names}, {"y", ca}, {"mode", "bars"}}});
  json str = json::array({{{"name", "stroke"}, {"x", names}, {"y", stroke}, {"mode", "bars"}},
                          {{"name", "minimum stroke <b>(spec)</b> & $x$ %{y}"},
                           {"x", names},
                           {"y", std::vector<double>(names.size(), 250.0)},
                           {"mode", "lines"},
                           {"dash", true}}});
  return {
      {"id", "batch-comparison"},
      {"title", "Batch comparison"},
      {"x_label", "Unit"},
      {"panels", {{{"y_label", "Capacitance [uF]"}, {"traces", cap}}, {{"y_label", "Stroke [um]"}, {"traces", str}}}}};
}

inline json results() {
  json units = json::array();
  for (int u = 1; u <= kUnits; ++u) {
    const UnitTruth t = truth(u);
    json unit = {{"id", unit_name(u)},
                 {"flatness_um", 4.0 + 0.1 * u},
                 {"capacitance_uF", {{"sensor", t.c_sensor}, {"actuator", t.c_actuator}}},
                 {"stroke_um", t.stroke_um},
                 {"stiffness_N_per_um", {{"k1", t.k1}, {"k2", t.k2}, {"resonance", 1.7 * (1 + 0.004 * (u - 4))}}},
                 {"frf",
                  {{"static_gain_um_per_V", t.static_gain_um_per_V},
                   {"resonance_Hz", t.resonance_Hz},
                   {"resonance_damping", 0.03},
                   {"antiresonance_Hz", t.antiresonance_Hz},
                   {"antiresonance_damping", 0.02},
                   {"zero_is_nonminimum_phase", true}}},
                 {"hpf_corner_Hz", 0.3},
                 {"accepted", u != kRejectedUnit},
                 {"reasons", json::array()}};
    if (u == kRejectedUnit) {
      unit["reasons"] = {"capacitance of the sensor stack 2.3 uF < 4.0 uF (spec 4.0 .. 5.0 uF)",
                         "stroke 183 um < 250 um (spec: at least 250 um)"};
    }
    if (u == 7) unit["stiffness_N_per_um"]["k2"] = nullptr;  // not measured
    units.push_back(unit);
  }
  return {{"units", units},
          {"batch",
           {{"outliers", {unit_name(kRejectedUnit)}},
            {"spread", {{"resonance_Hz", 1.2}, {"capacitance_sensor_uF", 0.75}}},
            {"note", "spread = standard deviation over the accepted units"}}},
          {"iff", {{"gains", {30.0, 100.0, 300.0}}, {"optimal_gain", 102.5}}}};
}

inline json document() {
  return {{"title", "APA300ML batch: acceptance report"},
          {"subtitle",
           "campaign \"demo</script><script>window.__pbInjected = 1; alert('injected')</script>.toml\", "
           "generated by the report test"},
          {"results", results()},
          {"sections",
           {{{"id", "frf"},
             {"title", "Frequency responses"},
             {"text", "u -> d_e for every unit & the fitted model <dashed>."},
             {"figures", {bode_figure(), model_figure()}}},
            {{"title", "Integral force feedback"}, {"figures", {root_locus_figure()}}},
            {{"title", "Quasi-static tests"}, {"figures", {hysteresis_figure(), stiffness_figure()}}},
            {{"title", "Batch"}, {"figures", {batch_figure()}}}}}};
}

// Figure ids of document(), in order.
inline std::vector<std::string> figure_ids() {
  return {"frf-de", "model-vs-measurement", "root-locus", "hysteresis", "stiffness-series", "batch-comparison"};
}

}  // namespace piezobench::test::report_sample
