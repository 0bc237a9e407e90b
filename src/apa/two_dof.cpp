#include "piezobench/apa/two_dof.hpp"

#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <tuple>

#include "piezobench/core/complex_division.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/lti/analysis.hpp"
#include "piezobench/lti/interconnect.hpp"

namespace piezobench::apa {
namespace {

void require(bool ok, const std::string& source, const std::string& field, const std::string& expected, double found) {
  if (!ok) throw InputError(source, field, expected, format_number(found));
}

double TwoDofParams::* member(const std::string& name) {
  if (name == "m") return &TwoDofParams::m;
  if (name == "k1") return &TwoDofParams::k1;
  if (name == "c1") return &TwoDofParams::c1;
  if (name == "ke") return &TwoDofParams::ke;
  if (name == "ce") return &TwoDofParams::ce;
  if (name == "ka") return &TwoDofParams::ka;
  if (name == "ca") return &TwoDofParams::ca;
  if (name == "ga") return &TwoDofParams::ga;
  if (name == "gs") return &TwoDofParams::gs;
  return nullptr;
}

std::string known_names() {
  std::string s;
  for (const auto& n : TwoDofParams::names()) s += (s.empty() ? "" : ", ") + n;
  return s;
}

}  // namespace

const std::vector<std::string>& TwoDofParams::names() {
  static const std::vector<std::string> kNames = {"m", "k1", "c1", "ke", "ce", "ka", "ca", "ga", "gs"};
  return kNames;
}

double TwoDofParams::get(const std::string& name) const {
  const auto ptr = member(name);
  if (ptr == nullptr) throw InputError("", "parameter", "one of " + known_names(), "'" + name + "'");
  return this->*ptr;
}

void TwoDofParams::set(const std::string& name, double value, const std::string& source) {
  const auto ptr = member(name);
  if (ptr == nullptr) throw InputError(source, name, "a known key (" + known_names() + ")", "an unknown key");
  this->*ptr = value;
}

void TwoDofParams::validate(const std::string& source) const {
  const std::string src = source.empty() ? "2-DoF parameters" : source;
  for (const auto& n : names()) require(std::isfinite(get(n)), src, n, "a finite number", get(n));
  require(m > 0.0, src, "m", "a mass > 0 kg", m);
  require(k1 > 0.0, src, "k1", "a stiffness > 0 N/m", k1);
  require(ke > 0.0, src, "ke", "a stiffness > 0 N/m", ke);
  require(ka > 0.0, src, "ka", "a stiffness > 0 N/m", ka);
  require(c1 >= 0.0, src, "c1", "a damping >= 0 N s/m", c1);
  require(ce >= 0.0, src, "ce", "a damping >= 0 N s/m", ce);
  require(ca >= 0.0, src, "ca", "a damping >= 0 N s/m", ca);
  // Without any damper in the stack chain the massless node would follow the springs instantly
  // and the model would be a different (2-state) one; we keep one realization.
  require(ca + ce > 0.0, src, "ca", "ca + ce > 0 (a damper in the stack chain)", ca + ce);
  require(ga != 0.0, src, "ga", "a nonzero sensitivity in N/V", ga);
  require(gs != 0.0, src, "gs", "a nonzero sensitivity in V/m", gs);
}

double TwoDofParams::total_stiffness() const { return k1 + ke * ka / (ke + ka); }

TwoDofParams two_dof_params_from_map(const std::map<std::string, double>& values, const std::string& source,
                                     const TwoDofParams& base) {
  TwoDofParams p = base;
  for (const auto& [key, value] : values) p.set(key, value, source);
  p.validate(source);
  return p;
}

double TwoDofBench::hpf_corner() const { return has_hpf() ? 1.0 / (hpf_resistance * hpf_capacitance) : 0.0; }

double TwoDofBench::moving_mass(const TwoDofParams& p) const {
  return (suspended_mass > 0.0 ? suspended_mass : p.m) + added_mass;
}

void TwoDofBench::validate(const std::string& source) const {
  const std::string src = source.empty() ? "bench" : source;
  require(std::isfinite(amplifier_gain) && amplifier_gain != 0.0, src, "amplifier_gain", "a finite nonzero gain in V/V",
          amplifier_gain);
  require(std::isfinite(suspended_mass) && suspended_mass >= 0.0, src, "suspended_mass",
          "a mass >= 0 kg (0 = the model's m)", suspended_mass);
  require(std::isfinite(added_mass) && added_mass >= 0.0, src, "added_mass", "a mass >= 0 kg", added_mass);
  require(std::isfinite(hpf_resistance) && hpf_resistance >= 0.0, src, "hpf_resistance", "a resistance >= 0 Ohm",
          hpf_resistance);
  require(std::isfinite(hpf_capacitance) && hpf_capacitance >= 0.0, src, "hpf_capacitance",
          "a capacitance >= 0 F", hpf_capacitance);
  if (has_hpf()) {
    require(hpf_resistance > 0.0, src, "hpf_resistance", "a resistance > 0 Ohm when a capacitance is given",
            hpf_resistance);
    require(hpf_capacitance > 0.0, src, "hpf_capacitance", "a capacitance > 0 F when a resistance is given",
            hpf_capacitance);
    require(std::isfinite(hpf_corner()), src, "hpf_capacitance", "R C large enough for a finite corner",
            hpf_resistance * hpf_capacitance);
  }
  require(std::isfinite(delay) && delay >= 0.0, src, "delay", "a delay >= 0 s", delay);
}

namespace {

// Realization of the equations in the header with mass `mass` and input gain `gain` (Va = gain *
// input). States [x, x', xn].
lti::StateSpace realize(const TwoDofParams& p, double mass, double gain) {
  const double cn = p.ca + p.ce;
  // Node: xn' = rn . [x, x', xn] + bn f
  const Eigen::RowVector3d rn(p.ke / cn, p.ce / cn, -(p.ka + p.ke) / cn);
  const double bn = 1.0 / cn;
  // Sensor-stack force T = ke (x - xn) + ce (x' - xn') = rT . state + bT f
  const Eigen::RowVector3d rT = Eigen::RowVector3d(p.ke, p.ce, -p.ke) - p.ce * rn;
  const double bT = -p.ce * bn;

  lti::Matrix A = lti::Matrix::Zero(3, 3);
  A(0, 1) = 1.0;
  A.row(1) = (Eigen::RowVector3d(-p.k1, -p.c1, 0.0) - rT) / mass;
  A.row(2) = rn;
  lti::Matrix B(3, 1);
  B << 0.0, -bT / mass, bn;
  B *= p.ga * gain;  // f = ga Va = ga gain input
  lti::Matrix C(2, 3);
  C << 1.0, 0.0, 0.0,  //
      p.gs, 0.0, -p.gs;
  return lti::StateSpace(A, B, C, lti::Matrix::Zero(2, 1));
}

}  // namespace

lti::StateSpace two_dof_actuator(const TwoDofParams& p) {
  p.validate();
  return realize(p, p.m, 1.0);
}

lti::StateSpace two_dof_bench(const TwoDofParams& p, const TwoDofBench& bench) {
  p.validate();
  bench.validate();
  lti::StateSpace sys = realize(p, bench.moving_mass(p), bench.amplifier_gain);
  if (bench.has_hpf()) {
    // s/(s + wc) = 1 - wc/(s + wc): z' = -wc z + Vs_raw, Vs = Vs_raw - wc z (no feedthrough since
    // Vs_raw has none).
    const double wc = bench.hpf_corner();
    lti::Matrix A = lti::Matrix::Zero(4, 4);
    A.topLeftCorner(3, 3) = sys.A;
    A.block(3, 0, 1, 3) = sys.C.row(kOutputVs);
    A(3, 3) = -wc;
    lti::Matrix B = lti::Matrix::Zero(4, 1);
    B.topRows(3) = sys.B;
    lti::Matrix C = lti::Matrix::Zero(2, 4);
    C.leftCols(3) = sys.C;
    C(kOutputVs, 3) = -wc;
    sys = lti::StateSpace(A, B, C, lti::Matrix::Zero(2, 1));
  }
  if (bench.delay > 0.0) sys.input_delay = lti::Vector::Constant(1, bench.delay);
  return sys;
}

lti::CMatrix two_dof_response(const TwoDofParams& p, const TwoDofBench& bench, const lti::Vector& omega) {
  p.validate();
  bench.validate();
  const double mass = bench.moving_mass(p);
  const double wc = bench.hpf_corner();
  lti::CMatrix H(omega.size(), 2);
  for (lti::Index k = 0; k < omega.size(); ++k) {
    const lti::Complex s(0.0, omega(k));
    const lti::Complex z1 = p.k1 + p.c1 * s;
    const lti::Complex ze = p.ke + p.ce * s;
    const lti::Complex za = p.ka + p.ca * s;
    const lti::Complex top = mass * s * s + z1;  // the mass on the shell
    const lti::Complex den = top * (ze + za) + ze * za;
    lti::Complex f = p.ga * bench.amplifier_gain;
    if (bench.delay > 0.0) f *= core::delay_phasor(omega(k), bench.delay);
    H(k, kOutputDe) = core::divide(f * ze, den);  // core::divide: the library's bits, inline
    H(k, kOutputVs) = core::divide(-p.gs * f * top, den);
    if (wc > 0.0) H(k, kOutputVs) *= core::divide(s, s + wc);
  }
  return H;
}

namespace {

// Least damped complex root with positive imaginary part: (natural frequency, damping), or NaNs.
std::pair<double, double> least_damped_pair(const lti::CVector& roots) {
  double best_w = std::numeric_limits<double>::quiet_NaN();
  double best_z = std::numeric_limits<double>::quiet_NaN();
  for (lti::Index i = 0; i < roots.size(); ++i) {
    const lti::Complex r = roots(i);
    // A real root computed in floating point may carry a round-off imaginary part.
    if (r.imag() <= 1e-9 * std::abs(r)) continue;
    const lti::PoleInfo info = lti::pole_info(r);
    if (std::isnan(best_z) || std::abs(info.damping) < std::abs(best_z)) {
      best_w = info.natural_frequency;
      best_z = info.damping;
    }
  }
  return {best_w, best_z};
}

}  // namespace

TwoDofCharacteristics characterize(const TwoDofParams& p, const TwoDofBench& bench) {
  const lti::StateSpace sys = two_dof_bench(p, bench);
  TwoDofCharacteristics c;
  c.poles = lti::poles(sys);
  c.zeros_vs = lti::zeros(lti::select(sys, {kOutputVs}, {0}));
  const lti::Matrix g = lti::dc_gain(sys);
  c.static_gain_de = g(kOutputDe, 0);
  // The high-pass has an exact zero at s = 0; dc_gain would return its round-off (~1e-15).
  c.static_gain_vs = bench.has_hpf() ? 0.0 : g(kOutputVs, 0);
  TwoDofBench bare = bench;
  bare.hpf_resistance = 0.0;
  bare.hpf_capacitance = 0.0;
  c.static_gain_vs_actuator = lti::dc_gain(two_dof_bench(p, bare))(kOutputVs, 0);
  std::tie(c.resonance, c.resonance_damping) = least_damped_pair(c.poles);
  std::tie(c.antiresonance, c.antiresonance_damping) = least_damped_pair(c.zeros_vs);
  return c;
}

}  // namespace piezobench::apa
