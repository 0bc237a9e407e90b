#include "piezobench/ident/actuator_frf.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <random>
#include <string>

#include "piezobench/core/error.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/plant/iff_plant.hpp"
#include "test_util.hpp"

namespace piezobench::ident {
namespace {

using test::near;

// The analytic plants: u -> d_e a mass-spring-damper k wn^2 / (s^2 + 2 zeta wn s + wn^2) with a
// 100 us delay; u -> Vs the report's eq. 2.3 (section 2.6) with a mirrored zero pair, a 0.4 Hz
// high-pass and a 200 us delay.
constexpr double kGain = 1.5e-6;            // m/V
constexpr double kResonanceHz = 95.2;
constexpr double kDamping = 0.02;
constexpr double kDeDelay = 100e-6;         // s
constexpr double kAntiResonanceHz = 42.7;
constexpr double kZeroDamping = -0.004;     // < 0: non-minimum phase
constexpr double kCornerHz = 0.4;
constexpr double kMass = 0.5;               // kg
constexpr double kResistance = 80.6e3;      // Ohm
const double kCapacitance = 1.0 / (kTwoPi * kCornerHz * kResistance);  // F: 1/(2 pi R C) = the corner

plant::IffPlantParams vs_plant() {
  plant::IffPlantParams p;
  p.wz = kTwoPi * kAntiResonanceHz;
  p.xz = kZeroDamping;
  p.wp = kTwoPi * kResonanceHz;
  p.xp = kDamping;
  p.w_hpf = kTwoPi * kCornerHz;
  p.delay = 200e-6;
  return p;
}

// Both FRFs on a Welch-like grid: 0.25 Hz lines up to 1 kHz (nfft 4 * fs at fs = 4 kHz), coherence 1.
dsp::Frf measured(long lines = 4001) {
  dsp::Frf frf;
  frf.freq_Hz = Eigen::VectorXd::LinSpaced(lines, 0.0, 0.25 * static_cast<double>(lines - 1));
  frf.input = "u";
  frf.outputs = {"de", "Vs"};
  const double wn = kTwoPi * kResonanceHz;
  Eigen::VectorXcd de(lines);
  for (Eigen::Index k = 0; k < lines; ++k) {
    const std::complex<double> s(0.0, kTwoPi * frf.freq_Hz(k));
    de(k) = kGain * wn * wn / (s * s + 2.0 * kDamping * wn * s + wn * wn) * std::exp(-s * kDeDelay);
  }
  frf.H = {de, plant::iff_plant_response(vs_plant(), kTwoPi * frf.freq_Hz)};
  frf.coherence = {Eigen::VectorXd::Ones(lines), Eigen::VectorXd::Ones(lines)};
  frf.provenance.sample_rate = 4000.0;
  frf.provenance.nfft = 16000;
  return frf;
}

ActuatorFrfOptions options() {
  ActuatorFrfOptions o;
  o.fmin_Hz = 20.0;
  o.fmax_Hz = 500.0;
  o.suspended_mass_kg = kMass;
  o.source = "test";
  return o;
}

// The features come from the plant fits, which recover the analytic plants; the vector fits agree
// as cross-checks; the zero pair is judged non-minimum-phase and signed so.
TEST(ActuatorFrf, FeaturesOfAnalyticPlants) {
  ActuatorFrfOptions o = options();
  o.hpf_resistance_ohm = kResistance;
  o.sensor_capacitance_F = kCapacitance;
  const ActuatorFrfResult r = analyze_actuator_frf(measured(), o);
  const ActuatorFrfAnalysis& a = r.analysis;
  EXPECT_TRUE(r.failed.empty()) << r.failed.front();
  EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();
  ASSERT_TRUE(a.de_plant && a.iff_plant && a.resonance_Hz && a.antiresonance_Hz && a.static_gain);
  EXPECT_EQ(a.static_gain_source, "second-order fit of u -> d_e with delay");
  EXPECT_TRUE(near(*a.static_gain, kGain, 1e-4));
  EXPECT_TRUE(near(*a.resonance_Hz, kResonanceHz, 1e-5));
  EXPECT_TRUE(near(*a.resonance_damping, kDamping, 1e-3));
  EXPECT_TRUE(near(a.de_plant->delay, kDeDelay, 1e-3));
  EXPECT_TRUE(near(*a.antiresonance_Hz, kAntiResonanceHz, 1e-5));
  EXPECT_TRUE(near(*a.antiresonance_damping, kZeroDamping, 1e-2));
  ASSERT_TRUE(a.zero_is_nonminimum_phase);
  EXPECT_TRUE(*a.zero_is_nonminimum_phase);
  // m_sus w_z^2 and the resonance in rad/s behind resonance_Hz.
  const double wz = kTwoPi * kAntiResonanceHz;
  EXPECT_TRUE(near(*a.shell_stiffness, kMass * wz * wz, 1e-4));
  ASSERT_TRUE(r.resonance_rad_s);
  EXPECT_EQ(*a.resonance_Hz, *r.resonance_rad_s / kTwoPi);
  // The vector fits (order 6) see the same resonance and zero within the cross-check tolerance.
  ASSERT_TRUE(a.resonance_vector_fit_Hz && a.antiresonance_vector_fit_Hz && a.fit_de && a.fit_vs);
  EXPECT_TRUE(near(*a.resonance_vector_fit_Hz, kResonanceHz, 1e-2));
  EXPECT_TRUE(near(*a.antiresonance_vector_fit_Hz, kAntiResonanceHz, 1e-2));
  EXPECT_EQ(a.fit_de->order, 6);
  EXPECT_TRUE(near(*a.static_gain_vector_fit, kGain, 1e-2));
  EXPECT_LT(a.fit_de->relative_rms_error, 1e-2);
  EXPECT_LT(a.fit_vs->relative_rms_error, 1e-2);
  ASSERT_TRUE(a.nmp.zero && a.nmp.iff_plant_fit_xz);
  EXPECT_EQ(a.nmp.zero->phase_verdict, PhaseVerdict::kNonMinimumPhase);
  EXPECT_TRUE(near(*a.nmp.iff_plant_fit_xz, kZeroDamping, 1e-2));
  EXPECT_EQ(a.nmp.verdict_from, "iff-plant-fit");
}

// The vector fits' features carry standard errors (vector_fit_uncertainty from the FRF's std_H):
// the analytic plants with complex Gaussian noise of 1 % of |H| per part, std_H set to it. Each
// standard error is positive and small (the feature known to a few per cent at most) and the features
// lie within 4 standard errors of the truth.
TEST(ActuatorFrf, VectorFitFeaturesCarryStandardErrors) {
  dsp::Frf frf = measured();
  std::mt19937 rng(3);
  std::normal_distribution<double> n01;
  frf.std_H.clear();
  for (Eigen::VectorXcd& h : frf.H) {
    Eigen::VectorXd sd = 0.01 * h.cwiseAbs();
    for (Eigen::Index k = 0; k < h.size(); ++k) h(k) += std::complex<double>(sd(k) * n01(rng), sd(k) * n01(rng));
    frf.std_H.push_back(sd);
  }
  const ActuatorFrfResult r = analyze_actuator_frf(frf, options());
  const ActuatorFrfAnalysis& a = r.analysis;
  ASSERT_TRUE(a.resonance_vector_fit_Hz && a.antiresonance_vector_fit_Hz && a.static_gain_vector_fit);
  ASSERT_TRUE(a.resonance_vector_fit_standard_error_Hz && a.resonance_vector_fit_damping_standard_error);
  ASSERT_TRUE(a.antiresonance_vector_fit_standard_error_Hz && a.antiresonance_vector_fit_damping_standard_error);
  ASSERT_TRUE(a.static_gain_vector_fit_standard_error);
  const auto within = [](double value, double se, double truth, double max_relative_se) {
    EXPECT_GT(se, 0.0);
    EXPECT_LT(se, max_relative_se * std::abs(truth));
    EXPECT_LT(std::abs(value - truth), 4.0 * se) << value << " +- " << se << " against " << truth;
  };
  within(*a.resonance_vector_fit_Hz, *a.resonance_vector_fit_standard_error_Hz, kResonanceHz, 0.01);
  within(*a.resonance_vector_fit_damping, *a.resonance_vector_fit_damping_standard_error, kDamping, 0.2);
  within(*a.antiresonance_vector_fit_Hz, *a.antiresonance_vector_fit_standard_error_Hz, kAntiResonanceHz, 0.01);
  within(*a.antiresonance_vector_fit_damping, *a.antiresonance_vector_fit_damping_standard_error, std::abs(kZeroDamping), 1.0);
  within(*a.static_gain_vector_fit, *a.static_gain_vector_fit_standard_error, kGain, 0.02);
  // Each fit's covariance summary: its conditioning, and its flagged pairs named by the model's
  // parameters ("p1/r0.1 -0.958").
  for (const auto& fit : {a.fit_de, a.fit_vs}) {
    ASSERT_TRUE(fit && fit->condition_number);
    EXPECT_GE(*fit->condition_number, 1.0);
    for (const std::string& c : fit->high_correlations) {
      EXPECT_NE(c.find('/'), std::string::npos) << c;
      EXPECT_GT(std::abs(std::stod(c.substr(c.rfind(' ') + 1))), 0.95) << c;
    }
  }
}

// With R and C_sensor known the corner is 1/(2 pi R C), fixed in the IFF plant fit; the free fit
// down to the lowest line and the first-order fit find the same corner.
TEST(ActuatorFrf, HighPassCornerFromResistorAndCapacitance) {
  ActuatorFrfOptions o = options();
  o.hpf_resistance_ohm = kResistance;
  o.sensor_capacitance_F = kCapacitance;
  const ActuatorFrfResult r = analyze_actuator_frf(measured(), o);
  const HighPassCorner& h = r.analysis.hpf;
  ASSERT_TRUE(h.corner_Hz && h.r_c_Hz && h.iff_plant_fit_Hz && h.first_order_fit_Hz);
  EXPECT_TRUE(near(*h.r_c_Hz, kCornerHz, 1e-12));
  EXPECT_EQ(*h.corner_Hz, *h.r_c_Hz);
  EXPECT_TRUE(r.analysis.iff_plant_w_hpf_measured);
  EXPECT_EQ(r.analysis.iff_plant->w_hpf, kTwoPi * *h.r_c_Hz);
  EXPECT_TRUE(near(*h.iff_plant_fit_Hz, kCornerHz, 1e-3));
  EXPECT_TRUE(near(*h.first_order_fit_Hz, kCornerHz, 5e-2));
  EXPECT_EQ(h.first_order_fit_points, 20);  // lines 0.25 .. 5 Hz
  EXPECT_EQ(h.observable_above_Hz, 0.25 / 3.0);
  EXPECT_EQ(h.method.rfind("1/(2 pi R C_sensor), R = 80600 Ohm from [bench]", 0), 0U) << h.method;
}

// Without the resistor's value the corner is the IFF plant fit's, observable above a third of the
// lowest line; a resistor 100 times too large puts 1/(2 pi R C) a factor 100 off the fits: warned.
TEST(ActuatorFrf, HighPassCornerFittedOrWarned) {
  const ActuatorFrfResult fitted = analyze_actuator_frf(measured(), options());
  const HighPassCorner& h = fitted.analysis.hpf;
  ASSERT_TRUE(h.corner_Hz && h.iff_plant_fit_Hz);
  EXPECT_FALSE(h.r_c_Hz);
  EXPECT_FALSE(fitted.analysis.iff_plant_w_hpf_measured);
  EXPECT_EQ(*h.corner_Hz, *h.iff_plant_fit_Hz);
  EXPECT_TRUE(near(*h.corner_Hz, kCornerHz, 1e-3));
  EXPECT_EQ(h.method.rfind("IFF plant fit (eq. 2.3)", 0), 0U) << h.method;

  ActuatorFrfOptions o = options();
  o.hpf_resistance_ohm = 100.0 * kResistance;
  o.sensor_capacitance_F = kCapacitance;
  const ActuatorFrfResult wrong = analyze_actuator_frf(measured(), o);
  ASSERT_TRUE(wrong.analysis.hpf.r_c_Hz);
  EXPECT_TRUE(near(*wrong.analysis.hpf.r_c_Hz, kCornerHz / 100.0, 1e-12));
  ASSERT_FALSE(wrong.warnings.empty());
  EXPECT_NE(wrong.warnings.front().find("high-pass corner: 1/(2 pi R C_sensor) = 0.004 Hz"), std::string::npos) << wrong.warnings.front();
}

// Too few lines in the band and an FRF without the named output are data problems.
TEST(ActuatorFrf, RefusesTooFewLinesOrAMissingOutput) {
  ActuatorFrfOptions o = options();
  o.field = "units[0].frf";
  o.fmax_Hz = 24.0;  // lines 20 .. 24 Hz: 17
  try {
    (void)analyze_actuator_frf(measured(), o);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "units[0].frf");
    EXPECT_NE(std::string(e.what()).find("at least 20 FRF points in [20, 24] Hz"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("17 (resolution 0.25 Hz)"), std::string::npos) << e.what();
  }
  o = options();
  o.vs_output = "V_s";
  EXPECT_THROW((void)analyze_actuator_frf(measured(), o), InputError);
}

}  // namespace
}  // namespace piezobench::ident
