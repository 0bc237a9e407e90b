#pragma once
// Measurement files with known answers for the campaign tests: records computed from analytic
// signals and exact discretizations (no virtual bench), written in the documented formats with
// channel names that differ from the bench's.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "piezobench/apa/two_dof.hpp"
#include "piezobench/io/timeseries.hpp"
#include "piezobench/lti/conversions.hpp"
#include "piezobench/lti/discretize.hpp"
#include "piezobench/lti/interconnect.hpp"
#include "test_util.hpp"

namespace piezobench::test::synthetic {

namespace fs = std::filesystem;
constexpr double kFs = 10e3;

inline io::TimeSeries series(const std::vector<std::string>& names, const Eigen::MatrixXd& data, double fs, bool with_t = true) {
  io::TimeSeries ts;
  ts.names = names;
  ts.data = data;
  ts.sample_rate = fs;
  if (with_t) ts.t = Eigen::VectorXd::LinSpaced(data.rows(), 0.0, static_cast<double>(data.rows() - 1) / fs);
  return ts;
}

// The 2-DoF model of Table 3.1 on the bench (20 V/V, R = 80.6 kOhm with C = 5 uF, 200 us delay),
// driven by white noise u (1 V rms) for `seconds`: channels "u_dac", "d_enc", "V_sensor".
inline apa::TwoDofBench frf_bench() {
  apa::TwoDofBench b;
  b.amplifier_gain = 20.0;
  b.hpf_resistance = 80.6e3;
  b.hpf_capacitance = 5e-6;
  b.delay = 200e-6;
  return b;
}

inline io::TimeSeries frf_record(double seconds, std::uint64_t seed = 1) {
  const lti::StateSpace sys = lti::c2d(apa::two_dof_bench(apa::TwoDofParams{}, frf_bench()), 1.0 / kFs);
  const auto n = static_cast<Eigen::Index>(seconds * kFs);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::MatrixXd u(n, 1);
  for (Eigen::Index k = 0; k < n; ++k) u(k, 0) = g(rng);
  const lti::TimeResponse r = lti::lsim(sys, u);
  Eigen::MatrixXd data(n, 3);
  data.col(0) = u.col(0);
  data.col(1) = r.y.col(0);
  data.col(2) = r.y.col(1);
  return series({"u_dac", "d_enc", "V_sensor"}, data, kFs);
}

// A damped plant u' -> d_e = k wn^2 / (s^2 + 2 zeta wn s + wn^2) with the bench's 200 us delay
// (as frf_record), noise input, with the controller gain in the record's settings.
inline io::TimeSeries damped_record(double wn, double zeta, double gain, double seconds) {
  lti::Vector num(1), den(3);
  num << -17e-6 * wn * wn;
  den << 1.0, 2.0 * zeta * wn, wn * wn;
  lti::StateSpace c = lti::to_state_space(lti::TransferFunction(num, den));
  c.input_delay = lti::Vector::Constant(1, 200e-6);
  const lti::StateSpace sys = lti::c2d(c, 1.0 / kFs);
  const auto n = static_cast<Eigen::Index>(seconds * kFs);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::MatrixXd u(n, 1);
  for (Eigen::Index k = 0; k < n; ++k) u(k, 0) = g(rng);
  const lti::TimeResponse r = lti::lsim(sys, u);
  Eigen::MatrixXd data(n, 2);
  data.col(0) = u.col(0);
  data.col(1) = r.y.col(0);
  io::TimeSeries ts = series({"u_prime", "de"}, data, kFs);
  ts.settings["gain"] = gain;
  return ts;
}

// Hammer test: impacts (1 ms half-sines every 2 s) on two modes (280 Hz and 412 Hz, 1 %).
inline io::TimeSeries hammer_record() {
  lti::StateSpace sys;
  bool first = true;
  for (const auto& [f, r] : {std::pair{280.0, 1e-3}, std::pair{412.0, 0.6e-3}}) {
    const double w = 2 * M_PI * f;
    lti::Vector num(2), den(3);
    num << r, 0.0;
    den << 1.0, 2.0 * 0.01 * w, w * w;
    const lti::StateSpace m = lti::to_state_space(lti::TransferFunction(num, den));
    sys = first ? m : lti::parallel(sys, m);
    first = false;
  }
  const lti::StateSpace d = lti::c2d(sys, 1.0 / kFs);
  const Eigen::Index n = 100000;
  Eigen::MatrixXd u = Eigen::MatrixXd::Zero(n, 1);
  for (int i = 0; i < 5; ++i) {
    for (int k = 0; k < 10; ++k) u(5000 + i * 20000 + k, 0) = 100.0 * std::sin(M_PI * (k + 0.5) / 10.0);
  }
  const lti::TimeResponse r = lti::lsim(d, u);
  Eigen::MatrixXd data(n, 2);
  data.col(0) = u.col(0);
  data.col(1) = r.y.col(0);
  return series({"F", "v"}, data, kFs);
}

// Slow ramp -20 -> 150 -> -20 V at 1 kHz, d_e = s Va (no loop): stroke = |s| 170 V.
inline io::TimeSeries stroke_record(double s) {
  std::vector<double> va;
  for (int k = 0; k < 500; ++k) va.push_back(-20.0);
  for (int k = 0; k <= 5000; ++k) va.push_back(-20.0 + 170.0 * k / 5000.0);
  for (int k = 0; k < 500; ++k) va.push_back(150.0);
  for (int k = 0; k <= 5000; ++k) va.push_back(150.0 - 170.0 * k / 5000.0);
  Eigen::MatrixXd data(static_cast<Eigen::Index>(va.size()), 2);
  for (std::size_t i = 0; i < va.size(); ++i) {
    data(static_cast<Eigen::Index>(i), 0) = va[i];
    data(static_cast<Eigen::Index>(i), 1) = s * va[i];
  }
  return series({"V_stack", "probe"}, data, 1000.0);
}

// Va = 65 + A sin(2 pi t), d_e = s A sin(2 pi t - phi): relative loop width sin(phi).
inline io::TimeSeries hysteresis_record(double amplitude, double phi) {
  const Eigen::Index n = 5000;
  Eigen::MatrixXd data(n, 2);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double wt = 2 * M_PI * k / 1000.0;
    data(k, 0) = 65.0 + amplitude * std::sin(wt);
    data(k, 1) = -1.5e-6 * amplitude * std::sin(wt - phi);
  }
  return series({"Va", "de"}, data, 1000.0);
}

// A tracking record (bench/tracking.hpp's layout: 1 s ramp, 3 + 3 periods, 1 s ramp; here the
// sine throughout) with known figures: c = 65 + 80 sin(2 pi t), channel "cmd"; de_open = the target
// line + h cos(2 pi t) (an ellipse about the line, which is its best line: width 2 h / stroke, rms
// error h / sqrt(2)); de_ff = the line plus h / 10 cos.
inline io::TimeSeries tracking_record(double h) {
  const Eigen::Index n = 8000;
  const double slope = -1.2e-6, intercept = 3e-6;
  Eigen::MatrixXd data(n, 3);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double wt = 2 * M_PI * k / 1000.0;
    data(k, 0) = 65.0 + 80.0 * std::sin(wt);
    data(k, 1) = slope * data(k, 0) + intercept + h * std::cos(wt);
    data(k, 2) = slope * data(k, 0) + intercept + 0.1 * h * std::cos(wt);
  }
  io::TimeSeries ts = series({"cmd", "de_open", "de_ff"}, data, 1000.0);
  ts.settings = {{"experiment", std::string("tracking")}, {"ramp_s", 1.0}, {"periods", 3.0}, {"frequency_Hz", 1.0},
                 {"amplitude_V", 80.0}, {"target_slope_m_per_V", slope}, {"target_intercept_m", intercept},
                 {"feedforward", std::string("given")}, {"clamped_samples", 0.0}};
  return ts;
}

// Added mass on at 3 s, off at 13 s, step deflections -m g / k (no creep): k1 = k2 = k.
inline io::TimeSeries stiffness_record(double k) {
  const Eigen::Index n = 20000;
  Eigen::MatrixXd data(n, 2);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / 1000.0;
    const bool on = t >= 3.0 && t < 13.0;
    data(i, 0) = on ? -6.4 * 9.8 / k : 0.0;
    data(i, 1) = on ? 6.4 : 0.0;
  }
  return series({"de", "added_mass"}, data, 1000.0);
}

// 8 probe points: a tilted plane plus a saddle +-d (orthogonal to 1, x, y): least-squares flatness 2 d.
inline void write_flatness_csv(const fs::path& file, double d) {
  std::ofstream out(file);
  out << "# sample_rate_Hz: 1\nx_pos [m],y_pos [m],height [m]\n";
  for (const double a : {0.01, 0.02}) {
    for (const auto& [sx, sy] : {std::pair{1, 1}, {1, -1}, {-1, 1}, {-1, -1}}) {
      const double x = sx * a, y = sy * a;
      out.precision(17);
      out << x << "," << y << "," << 1e-4 * x - 2e-4 * y + 0.05 + d * sx * sy << "\n";
    }
  }
}

}  // namespace piezobench::test::synthetic
