#include "piezobench/ident/damped_plant.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "piezobench/core/error.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::ident::damped_plant_test {
namespace {

constexpr double kGain = 1.2e-6;     // m/V
constexpr double kPoleHz = 80.0;     // natural frequency of the damped pole
constexpr double kDamping = 0.15;    // the loop's damping
constexpr double kDelay = 150e-6;    // s, d_e's read-out delay

// u' -> d_e = k wn^2 / (s^2 + 2 zeta wn s + wn^2) e^{-s delay} on 0.25 Hz lines up to 1 kHz.
dsp::Frf damped(double delay_s = kDelay) {
  const long lines = 4001;
  dsp::Frf frf;
  frf.freq_Hz = Eigen::VectorXd::LinSpaced(lines, 0.0, 0.25 * static_cast<double>(lines - 1));
  frf.input = "u_prime";
  frf.outputs = {"de"};
  const double wn = kTwoPi * kPoleHz;
  Eigen::VectorXcd h(lines);
  for (Eigen::Index k = 0; k < lines; ++k) {
    const std::complex<double> s(0.0, kTwoPi * frf.freq_Hz(k));
    h(k) = kGain * wn * wn / (s * s + 2.0 * kDamping * wn * s + wn * wn) * std::exp(-s * delay_s);
  }
  frf.H = {h};
  frf.coherence = {Eigen::VectorXd::Ones(lines)};
  return frf;
}

DampedPlantOptions options() {
  DampedPlantOptions o;
  o.fmin_Hz = 20.0;
  o.fmax_Hz = 300.0;
  o.delay_s = kDelay;
  o.fit_order = 6;
  o.source = "test";
  return o;
}

// With d_e's delay removed, the dominant pole is the analytic -zeta wn + j wn sqrt(1 - zeta^2), and
// the second-order fit recovers k, wn, zeta.
TEST(DampedPlant, DominantPoleOfASecondOrderPlant) {
  const DampedPlantAnalysis a = analyze_damped_plant(damped(), options());
  EXPECT_TRUE(a.failed.empty());
  const double wn = kTwoPi * kPoleHz;
  const std::complex<double> pole(-kDamping * wn, wn * std::sqrt(1.0 - kDamping * kDamping));
  ASSERT_TRUE(a.dominant.has_value());
  EXPECT_LT(std::abs(a.dominant->pole - pole), 1e-6 * wn);
  EXPECT_NEAR(a.dominant->natural_frequency, wn, 1e-6 * wn);
  EXPECT_NEAR(a.dominant->damping, kDamping, 1e-6);
  EXPECT_EQ(a.dominant_fit_order, 6);
  ASSERT_TRUE(a.second_order.has_value()) << a.second_order_error;
  EXPECT_NEAR(a.second_order->natural_frequency, wn, 1e-6 * wn);
  EXPECT_NEAR(a.second_order->damping, kDamping, 1e-6);
  EXPECT_NEAR(a.second_order->static_gain, kGain, 1e-6 * kGain);
  EXPECT_DOUBLE_EQ(a.delay_removed_s, kDelay);
  EXPECT_EQ(a.lines, 1121);  // 20 to 300 Hz in 0.25 Hz steps
}

// The delay matters: left in, the second-order fit (delay fixed at 0) cannot follow the phase; the
// same plant without delay needs none removed.
TEST(DampedPlant, DelayIsRemovedBeforeTheFits) {
  DampedPlantOptions o = options();
  o.delay_s = 0.0;
  const DampedPlantAnalysis kept = analyze_damped_plant(damped(), o);
  ASSERT_TRUE(kept.second_order.has_value());
  EXPECT_GT(kept.second_order->relative_rms_error, 1e-3);
  const DampedPlantAnalysis none = analyze_damped_plant(damped(0.0), o);
  ASSERT_TRUE(none.dominant.has_value());
  EXPECT_NEAR(none.dominant->damping, kDamping, 1e-6);
}

TEST(DampedPlant, RefusesBadOptions) {
  DampedPlantOptions o = options();
  o.fmax_Hz = 10.0;
  EXPECT_THROW(analyze_damped_plant(damped(), o), InputError);
  o = options();
  o.delay_s = -1e-3;
  EXPECT_THROW(analyze_damped_plant(damped(), o), InputError);
  o = options();
  o.output = "Vs";
  EXPECT_THROW(analyze_damped_plant(damped(), o), InputError);
}

}  // namespace
}  // namespace piezobench::ident::damped_plant_test
