#include "piezobench/metrology/stiffness.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "test_util.hpp"

namespace piezobench::metrology {
namespace {

using Eigen::VectorXd;
using test::near;

// The report's added-mass test on an APA of static stiffness k: 6.4 kg put on at 3 s and taken off
// at 13 s, logarithmic creep of `creep` per decade with time constant tau after each step, the
// return step `ret` times the first (hysteresis), a 65 Hz ringing after each step, encoder
// quantization 2.5 nm and 1 nm noise.
struct Record {
  VectorXd t, de, mass;
  double d_on = 0.0, d_off = 0.0;
};
Record record(double k, double creep, double tau, double ret, bool noisy = true) {
  const double fs = 1000.0, m = 6.4, g = 9.8, t_on = 3.0, t_off = 13.0;
  const Eigen::Index n = 20000;
  Record r;
  r.t = VectorXd::LinSpaced(n, 0.0, (n - 1) / fs);
  r.de.resize(n);
  r.mass.resize(n);
  r.d_on = -m * g / k;
  r.d_off = -ret * r.d_on;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 1e-9);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = r.t(i);
    double d = 2e-6;
    auto step = [&](double te, double amp) {
      if (t < te) return;
      const double s = t - te;
      d += amp * (1.0 + creep * std::log10(1.0 + s / tau)) - amp * std::exp(-s / 0.05) * std::cos(2 * M_PI * 65.0 * s);
    };
    step(t_on, r.d_on);
    step(t_off, r.d_off);
    if (noisy) d = 2.5e-9 * std::round((d + noise(rng)) / 2.5e-9);
    r.de(i) = d;
    r.mass(i) = t >= t_on && t < t_off ? m : 0.0;
  }
  return r;
}

// Mean of the noise-free record over [from, to).
double window(const Record& r, double from, double to) {
  double s = 0.0;
  int n = 0;
  for (Eigen::Index i = 0; i < r.t.size(); ++i) {
    if (r.t(i) >= from && r.t(i) < to) {
      s += r.de(i);
      ++n;
    }
  }
  return s / n;
}

TEST(StaticStiffness, ReadingsAndCreep) {
  const double k = 1.9e6, weight = 6.4 * 9.8;
  const Record r = record(k, 0.03, 0.1, 0.97);
  const Record clean = record(k, 0.03, 0.1, 0.97, /*noisy=*/false);
  const StaticStiffnessResult s = static_stiffness(r.t, r.de, r.mass);
  EXPECT_NEAR(s.t_on, 3.0, 1e-3);
  EXPECT_NEAR(s.t_off, 13.0, 1e-3);
  // The report's readings (windows [2, 2.9), [12, 12.9), [14, 15) s) on the noise-free record.
  const double before = window(clean, 2.0, 2.9), loaded = window(clean, 12.0, 12.9), after = window(clean, 14.0, 15.0);
  EXPECT_TRUE(near(s.k1, weight / (before - loaded), 1e-4));
  EXPECT_TRUE(near(s.k2, weight / (after - loaded), 1e-4));
  // Creep while loaded: 3 % per decade over log10(1 + 9.5 / 0.1) ~ 2 decades makes k1 ~ 6 % low.
  EXPECT_LT(s.k1, 0.95 * k);
  // The creep fit recovers the elastic steps (noise ~ 1 nm against 33 um).
  EXPECT_TRUE(near(s.deflection_on, r.d_on, 2e-3));
  EXPECT_TRUE(near(s.deflection_off, r.d_off, 2e-3));
  EXPECT_TRUE(near(s.k_elastic_on, k, 2e-3));
  EXPECT_TRUE(near(s.k_elastic_off, k / 0.97, 2e-3));
  EXPECT_TRUE(near(s.creep_on, 0.03 * r.d_on, 0.05));
  EXPECT_TRUE(near(s.creep_time_constant, 0.1, 0.2));
  EXPECT_LT(s.rms_residual, 3e-9);
  EXPECT_EQ(s.fit.size(), r.t.size());
}

TEST(StaticStiffness, EventsFromTheRecordOrGiven) {
  const double k = 1.7e6;
  const Record r = record(k, 0.02, 0.3, 1.0);
  const StaticStiffnessResult a = static_stiffness(r.t, r.de, VectorXd());
  EXPECT_NEAR(a.t_on, 3.0, 2e-3);
  EXPECT_NEAR(a.t_off, 13.0, 2e-3);
  EXPECT_TRUE(near(a.k_elastic_on, k, 3e-3));
  EXPECT_TRUE(near(a.k_elastic_off, k, 3e-3));
  StaticStiffnessOptions o;
  o.t_on = 3.0;
  o.t_off = 13.0;
  const StaticStiffnessResult b = static_stiffness(r.t, r.de, VectorXd(), o);
  EXPECT_TRUE(near(b.k_elastic_on, k, 2e-3));
  EXPECT_TRUE(near(b.k1, a.k1, 1e-3));
}

// Without creep and noise the fit and the readings agree with the exact value.
TEST(StaticStiffness, NoCreepNoNoise) {
  const Record r = record(2.0e6, 0.0, 0.1, 1.0, /*noisy=*/false);
  const StaticStiffnessResult s = static_stiffness(r.t, r.de, r.mass);
  // Left: the ringing exp(-20) one second after the steps.
  EXPECT_TRUE(near(s.k1, 2.0e6, 1e-8));
  EXPECT_TRUE(near(s.k2, 2.0e6, 1e-8));
  EXPECT_TRUE(near(s.k_elastic_on, 2.0e6, 1e-9));
  EXPECT_TRUE(near(s.k_elastic_off, 2.0e6, 1e-9));
  EXPECT_LT(std::abs(s.creep_on), 1e-9 * std::abs(s.deflection_on));
}

TEST(StaticStiffness, BadInput) {
  const Record r = record(2e6, 0.0, 0.1, 1.0, false);
  const std::string src = "apa4_stiffness.mat";
  EXPECT_TRUE(test::contains(test::input_error([&] { (void)static_stiffness(r.t, r.de.head(100), r.mass, {}, src); }, "de"), src));
  VectorXd t = r.t;
  t(50) = t(49);
  test::input_error([&] { (void)static_stiffness(t, r.de, r.mass, {}, src); }, "t");
  // The mass is never taken off.
  VectorXd on = r.mass;
  on.tail(8000).setConstant(6.4);
  test::input_error([&] { (void)static_stiffness(r.t, r.de, on, {}, src); }, "added_mass");
  // Too little record after the mass comes off for the reading after it.
  test::input_error([&] { (void)static_stiffness(r.t.head(14800), r.de.head(14800), r.mass.head(14800), {}, src); }, "t_off");
  // Too little before.
  test::input_error([&] { (void)static_stiffness(r.t.tail(17500), r.de.tail(17500), r.mass.tail(17500), {}, src); }, "t_on");
  StaticStiffnessOptions o;
  o.added_mass = 0.0;
  test::input_error([&] { (void)static_stiffness(r.t, r.de, r.mass, o); }, "added_mass");
  o = {};
  o.t_on = 5.0;
  test::input_error([&] { (void)static_stiffness(r.t, r.de, r.mass, o); }, "t_off");
  o = {};
  o.before_s = {-0.1, -1.0};
  test::input_error([&] { (void)static_stiffness(r.t, r.de, r.mass, o); }, "before_s");
}

TEST(ResonanceStiffness, ReportValue) {
  // 5.7 (2 pi 95)^2 = 2.031e6 N/m (REFERENCE.md: 2.03 N/um).
  EXPECT_TRUE(near(stiffness_from_resonance(5.7, 2 * M_PI * 95.0), 5.7 * std::pow(2 * M_PI * 95.0, 2), 1e-15));
  EXPECT_NEAR(stiffness_from_resonance(5.7, 2 * M_PI * 95.0) / 1e6, 2.03, 0.005);
  test::input_error([] { (void)stiffness_from_resonance(0.0, 100.0); }, "mass");
  test::input_error([] { (void)stiffness_from_resonance(5.7, std::nan("")); }, "resonance");
}

}  // namespace
}  // namespace piezobench::metrology
