#include "piezobench/metrology/stroke.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "test_util.hpp"

namespace piezobench::metrology {
namespace {

using Eigen::VectorXd;
using test::near;

// A ramp -20 V -> 150 V -> -20 V (10 s each way, 0.5 s holds at the ends) at 1 kHz; d_e = s Va on
// the average with branches -+ h sin(pi (Va + 20) / 170) (rising below, falling above): the stroke
// is |s| 170 V, the widest gap 2 h at 65 V.
struct Ramp {
  VectorXd va, de;
};
Ramp ramp(double s, double h) {
  const double fs = 1000.0;
  std::vector<double> va, de;
  auto push = [&](double v, int dir) {
    va.push_back(v);
    de.push_back(s * v + dir * -h * std::sin(M_PI * (v + 20.0) / 170.0));
  };
  for (int k = 0; k < 500; ++k) push(-20.0, 1);
  for (int k = 0; k <= 10000; ++k) push(-20.0 + 170.0 * k / 10000.0, 1);
  for (int k = 0; k < 500; ++k) push(150.0, 1);
  for (int k = 0; k <= 10000; ++k) push(150.0 - 170.0 * k / 10000.0, -1);
  for (int k = 0; k < 500; ++k) push(-20.0, -1);
  (void)fs;
  return {Eigen::Map<VectorXd>(va.data(), static_cast<Eigen::Index>(va.size())),
          Eigen::Map<VectorXd>(de.data(), static_cast<Eigen::Index>(de.size()))};
}

TEST(Stroke, RampOfKnownStrokeAndLoop) {
  const double s = -1.5e-6, h = 4e-6;
  const Ramp r = ramp(s, h);
  const StrokeResult out = analyze_stroke(r.va, r.de, 1000.0);
  EXPECT_TRUE(near(out.stroke, 170.0 * 1.5e-6, 1e-9));
  EXPECT_DOUBLE_EQ(out.va_min, -20.0);
  EXPECT_DOUBLE_EQ(out.va_max, 150.0);
  EXPECT_TRUE(near(out.sensitivity, s, 1e-3));
  // Grid level 25 of 50 is exactly 65 V, where the gap is 2 h (smoothing changes a sine by (w/T)^2).
  EXPECT_TRUE(near(out.loop_width, 2 * h, 1e-4));
}

TEST(Stroke, NoiseDoesNotWidenTheStroke) {
  Ramp r = ramp(-1.5e-6, 0.0);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.2e-6);
  for (Eigen::Index k = 0; k < r.de.size(); ++k) r.de(k) += noise(rng);
  const double raw = r.de.maxCoeff() - r.de.minCoeff();
  const StrokeResult out = analyze_stroke(r.va, r.de, 1000.0);
  // Raw peak-to-peak is ~ 7 sigma too wide; the 20-sample average leaves ~ 1.5 sigma.
  EXPECT_GT(raw - 255e-6, 0.8e-6);
  EXPECT_TRUE(near<double>(out.stroke, 255e-6, {0.0, 0.4e-6}));
  // The noise per sample is found under the ramp (its second differences), for the stroke's budget.
  EXPECT_NEAR(out.noise / 0.2e-6, 1.0, 0.03);
  EXPECT_EQ(out.smoothing_samples, 20);
}

// Va = 65 + A sin(w t), d_e = s A sin(w t - phi): the loop is an ellipse, crossing the offset at
// d_e = -+ s A sin(phi), so width = 2 |s| A sin(phi), loop stroke 2 |s| A, relative width sin(phi).
TEST(Hysteresis, EllipseLoop) {
  const double fs = 1000.0, f = 1.0, amp = 20.0, s = -1.5e-6, phi = 0.1;
  const Eigen::Index n = 5000;
  VectorXd va(n), de(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double wt = 2 * M_PI * f * k / fs;
    va(k) = 65.0 + amp * std::sin(wt);
    de(k) = 3e-6 + s * amp * std::sin(wt - phi);
  }
  const HysteresisResult h = analyze_hysteresis(va, de);
  EXPECT_TRUE(near(h.offset, 65.0, 1e-9));
  EXPECT_TRUE(near(h.amplitude, amp, 1e-9));
  EXPECT_TRUE(near(h.width, 2 * std::abs(s) * amp * std::sin(phi), 1e-5));
  EXPECT_TRUE(near(h.loop_stroke, 2 * std::abs(s) * amp, 1e-5));
  EXPECT_TRUE(near(h.relative_width, std::sin(phi), 1e-5));
  // From the first maximum (0.25 s) to the last (4.25 s): 4 falling and 4 rising crossings.
  EXPECT_EQ(h.periods, 4);
  EXPECT_NEAR(static_cast<double>(h.first_sample), 205.0, 1.0);  // within 2 % of the range from the peak
}

// Noise on Va would make many false crossings without the Schmitt trigger.
TEST(Hysteresis, NoisyVoltageCrossesOncePerPeriod) {
  const double fs = 1000.0, amp = 4.0, s = -1.5e-6, phi = 0.05;
  const Eigen::Index n = 6000;
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.05);
  VectorXd va(n), de(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double wt = 2 * M_PI * k / fs;
    va(k) = 65.0 + amp * std::sin(wt) + noise(rng);
    de(k) = s * amp * std::sin(wt - phi);
  }
  const HysteresisResult h = analyze_hysteresis(va, de);
  EXPECT_EQ(h.periods, 5);
  // The noise moves each crossing by ~ sigma / slope; averaged over 5 periods.
  EXPECT_TRUE(near(h.relative_width, std::sin(phi), 0.1));
}

TEST(StrokeAndHysteresis, BadInput) {
  VectorXd va = VectorXd::LinSpaced(100, 0.0, 100.0), de = VectorXd::Zero(100);
  EXPECT_TRUE(test::contains(test::input_error([&] { (void)analyze_stroke(va, de.head(50), 1000.0, {}, "apa2_stroke.csv"); }, "de"), "apa2_stroke.csv"));
  de(7) = std::nan("");
  EXPECT_TRUE(test::contains(test::input_error([&] { (void)analyze_stroke(va, de, 1000.0); }, "de"), "sample 7"));
  de(7) = 0.0;
  test::input_error([&] { (void)analyze_stroke(va, de, 0.0); }, "sample rate");
  test::input_error([&] { (void)analyze_stroke(VectorXd::Constant(100, 65.0), de, 1000.0); }, "Va");
  // A ramp only rises: no periods for the hysteresis.
  test::input_error([&] { (void)analyze_hysteresis(va, de); }, "Va");
  // Ramps in and out (0 V -> 65 V -> sine -> 0 V) are left out: the offset is the sine's.
  {
    const double fs = 1000.0;
    std::vector<double> v, d;
    for (int k = 0; k < 1000; ++k) v.push_back(65.0 * 0.5 * (1 - std::cos(M_PI * k / 1000.0)));
    for (int k = 0; k < 3000; ++k) v.push_back(65.0 + 20.0 * std::sin(2 * M_PI * k / fs));
    for (int k = 0; k <= 1000; ++k) v.push_back(65.0 * 0.5 * (1 + std::cos(M_PI * k / 1000.0)));
    for (const double x : v) d.push_back(-1.5e-6 * x);
    const HysteresisResult h = analyze_hysteresis(Eigen::Map<VectorXd>(v.data(), static_cast<Eigen::Index>(v.size())),
                                                  Eigen::Map<VectorXd>(d.data(), static_cast<Eigen::Index>(d.size())));
    EXPECT_NEAR(h.offset, 65.0, 1e-6);
    EXPECT_NEAR(h.amplitude, 20.0, 1e-6);
    EXPECT_EQ(h.periods, 2);
    EXPECT_NEAR(h.width, 0.0, 1e-12);
  }
  HysteresisOptions o;
  o.skip_periods = -1;
  test::input_error([&] { (void)analyze_hysteresis(va, de, o); }, "skip_periods");
}

}  // namespace
}  // namespace piezobench::metrology
