#include "piezobench/ident/flexible_modes.hpp"

#include <gtest/gtest.h>

#include <complex>

#include "piezobench/core/error.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::ident::flexible_modes_test {
namespace {

// A mobility F -> v with two modes, sum_i a_i s / (s^2 + 2 zeta_i w_i s + w_i^2), on 1 Hz lines up
// to 3 kHz.
constexpr double kF1 = 400.0, kZ1 = 0.01, kF2 = 1200.0, kZ2 = 0.02;

dsp::Frf hammer() {
  const long lines = 3001;
  dsp::Frf frf;
  frf.freq_Hz = Eigen::VectorXd::LinSpaced(lines, 0.0, static_cast<double>(lines - 1));
  frf.input = "F";
  frf.outputs = {"v"};
  Eigen::VectorXcd h(lines);
  for (Eigen::Index k = 0; k < lines; ++k) {
    const std::complex<double> s(0.0, kTwoPi * frf.freq_Hz(k));
    const double w1 = kTwoPi * kF1, w2 = kTwoPi * kF2;
    h(k) = 1.0 * s / (s * s + 2.0 * kZ1 * w1 * s + w1 * w1) + 0.5 * s / (s * s + 2.0 * kZ2 * w2 * s + w2 * w2);
  }
  frf.H = {h};
  return frf;
}

FlexibleModeOptions options() {
  FlexibleModeOptions o;
  o.fmin_Hz = 100.0;
  o.fmax_Hz = 2000.0;
  o.source = "test";
  return o;
}

// LSCF recovers both modes (exact data, a rational model of the same form); peak picking finds
// them within its half-power approximations.
TEST(FlexibleModes, BothMethodsFindTheTwoModes) {
  const FlexibleModeAnalysis m = identify_flexible_modes(hammer(), options());
  EXPECT_TRUE(m.failed.empty());
  EXPECT_EQ(m.lines, 1901);
  ASSERT_EQ(m.lscf.size(), 2u);
  EXPECT_NEAR(m.lscf[0].frequency_Hz(), kF1, 1e-3 * kF1);
  EXPECT_NEAR(m.lscf[0].damping, kZ1, 0.02 * kZ1);
  EXPECT_NEAR(m.lscf[1].frequency_Hz(), kF2, 1e-3 * kF2);
  EXPECT_NEAR(m.lscf[1].damping, kZ2, 0.02 * kZ2);
  EXPECT_GE(m.lscf[0].stable_orders, 5);
  ASSERT_EQ(m.peak_picking.size(), 2u);
  EXPECT_NEAR(m.peak_picking[0].frequency_Hz(), kF1, 2e-3 * kF1);
  EXPECT_NEAR(m.peak_picking[0].damping, kZ1, 0.1 * kZ1);
  EXPECT_NEAR(m.peak_picking[1].frequency_Hz(), kF2, 2e-3 * kF2);
  EXPECT_NEAR(m.peak_picking[1].damping, kZ2, 0.1 * kZ2);
}

// The band decides what is searched: above 800 Hz only the second mode; max_peaks keeps the most
// prominent peak.
TEST(FlexibleModes, BandAndPeakCount) {
  FlexibleModeOptions o = options();
  o.fmin_Hz = 800.0;
  const FlexibleModeAnalysis upper = identify_flexible_modes(hammer(), o);
  ASSERT_EQ(upper.peak_picking.size(), 1u);
  EXPECT_NEAR(upper.peak_picking[0].frequency_Hz(), kF2, 2e-3 * kF2);
  o = options();
  o.max_peaks = 1;
  const FlexibleModeAnalysis one = identify_flexible_modes(hammer(), o);
  ASSERT_EQ(one.peak_picking.size(), 1u);
  EXPECT_NEAR(one.peak_picking[0].frequency_Hz(), kF1, 2e-3 * kF1);  // the taller peak
  o.fmax_Hz = 50.0;
  EXPECT_THROW(identify_flexible_modes(hammer(), o), InputError);
  o = options();
  o.output = "a";
  EXPECT_THROW(identify_flexible_modes(hammer(), o), InputError);
}

}  // namespace
}  // namespace piezobench::ident::flexible_modes_test
