#include "piezobench/ident/low_frequency_high_pass.hpp"

#include <gtest/gtest.h>

#include <complex>

#include "piezobench/core/error.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::ident::low_frequency_high_pass_test {
namespace {

// u -> Vs = g s / (s + w_c) on a Welch-like grid from 0 Hz in steps of df_Hz, coherence 1.
dsp::Frf high_pass(double corner_Hz, double gain, double df_Hz, long lines = 400) {
  dsp::Frf frf;
  frf.freq_Hz = Eigen::VectorXd::LinSpaced(lines, 0.0, df_Hz * static_cast<double>(lines - 1));
  frf.input = "u";
  frf.outputs = {"de", "Vs"};
  Eigen::VectorXcd h(lines);
  for (Eigen::Index k = 0; k < lines; ++k) {
    const std::complex<double> s(0.0, kTwoPi * frf.freq_Hz(k));
    h(k) = gain * s / (s + kTwoPi * corner_Hz);
  }
  frf.H = {Eigen::VectorXcd::Ones(lines), h};
  frf.coherence = {Eigen::VectorXd::Ones(lines), Eigen::VectorXd::Ones(lines)};
  return frf;
}

// A 0.5 Hz corner seen from 0.125 Hz lines: fitted exactly on the 40 lines of (0, 5] Hz, observable
// (0.5 Hz >= 0.125 / 3 Hz).
TEST(LowFrequencyHighPass, RecoversAKnownCorner) {
  LowFrequencyHighPassOptions o;
  o.fmax_Hz = 5.0;
  const LowFrequencyHighPass h = fit_low_frequency_high_pass(high_pass(0.5, -2.0, 0.125), o);
  EXPECT_DOUBLE_EQ(h.lowest_line_Hz, 0.125);
  EXPECT_DOUBLE_EQ(h.observable_above_Hz, 0.125 / 3.0);
  EXPECT_EQ(h.points, 40);
  ASSERT_TRUE(h.corner_Hz.has_value());
  EXPECT_NEAR(*h.corner_Hz, 0.5, 1e-6);
  EXPECT_NEAR(h.gain, -2.0, 1e-6);
  EXPECT_LT(h.relative_rms_error, 1e-6);
  EXPECT_TRUE(h.observable);
}

// A 0.01 Hz corner changes |H| at 0.125 Hz by 0.3 %: fitted, but below a third of the lowest line,
// so an upper bound only.
TEST(LowFrequencyHighPass, CornerBelowAThirdOfTheLowestLineIsNotObservable) {
  LowFrequencyHighPassOptions o;
  const LowFrequencyHighPass h = fit_low_frequency_high_pass(high_pass(0.01, 1.0, 0.125), o);
  ASSERT_TRUE(h.corner_Hz.has_value());
  EXPECT_NEAR(*h.corner_Hz, 0.01, 1e-6);
  EXPECT_FALSE(h.observable);
}

// Lines below min_coherence are left out; fewer than 3 lines in the band is no fit, not an error.
TEST(LowFrequencyHighPass, CoherenceAndTooFewLines) {
  dsp::Frf frf = high_pass(0.5, 1.0, 0.125);
  for (Eigen::Index k = 1; k <= 10; ++k) frf.coherence[1](k) = 0.2;
  LowFrequencyHighPassOptions o;
  o.min_coherence = 0.5;
  const LowFrequencyHighPass h = fit_low_frequency_high_pass(frf, o);
  EXPECT_EQ(h.points, 30);
  EXPECT_NEAR(*h.corner_Hz, 0.5, 1e-6);
  o.min_coherence = 0.0;
  o.fmax_Hz = 0.25;  // two lines: 0.125 and 0.25 Hz
  const LowFrequencyHighPass none = fit_low_frequency_high_pass(frf, o);
  EXPECT_FALSE(none.corner_Hz.has_value());
  EXPECT_EQ(none.points, 0);
  EXPECT_FALSE(none.observable);
  o.output = "V_s";
  EXPECT_THROW(fit_low_frequency_high_pass(frf, o), InputError);
}

}  // namespace
}  // namespace piezobench::ident::low_frequency_high_pass_test
