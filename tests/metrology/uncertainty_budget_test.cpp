#include "piezobench/metrology/uncertainty_budget.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "piezobench/core/error.hpp"

namespace piezobench::metrology {
namespace {

TEST(UncertaintyBudget, CombineIsTheRootSumOfSquaresOfTheContributions) {
  const UncertaintyBudget b = combine("m", {{"a", "m", 3.0, 1.0, 0.0}, {"b", "kg", 2.0, -2.0, 0.0}});
  EXPECT_DOUBLE_EQ(b.components[1].contribution, 4.0);  // |c| u
  EXPECT_DOUBLE_EQ(b.combined, 5.0);                    // sqrt(3^2 + 4^2)
  EXPECT_DOUBLE_EQ(b.expanded, 10.0);                   // k = 2
  EXPECT_DOUBLE_EQ(combine("m", {{"a", "m", 3.0, 1.0, 0.0}}, 3.0).expanded, 9.0);
  EXPECT_THROW((void)combine("m", {{"a", "m", -1.0, 1.0, 0.0}}), InputError);
  EXPECT_THROW((void)combine("m", {{"a", "m", 1.0, NAN, 0.0}}), InputError);
  EXPECT_THROW((void)combine("m", {}, 0.0), InputError);
}

// k = m g / d: relative contributions u(m)/m, u(g)/g and u(d)/d (GUM 5.1.6, a product of powers).
TEST(UncertaintyBudget, StiffnessIsTheProductRule) {
  StaticTestUncertainties in;
  in.added_mass_kg = 0.0064;  // 0.1 %
  in.gravity_m_per_s2 = 0.0098;  // 0.1 %
  in.encoder_resolution_m = 0.0;
  in.displacement_scale_relative = 0.001;  // 0.1 %
  // d = 31.36 um (k = 2 N/um), readings of 9,000 samples with 9 nm noise: u(d) = sqrt(2) 9e-9 / sqrt(9000).
  const double d = 6.4 * 9.8 / 2e6;
  const UncertaintyBudget b = stiffness_budget(6.4, 9.8, d, 9e-9, 9000.0, in);
  const double u_d = std::sqrt(2.0) * 9e-9 / std::sqrt(9000.0);
  const double rel = std::sqrt(1e-6 + 1e-6 + std::pow(u_d / d, 2) + 1e-6);
  EXPECT_NEAR(b.combined, 2e6 * rel, 1e-9 * 2e6 * rel);
  EXPECT_EQ(b.unit, "N/m");
  ASSERT_EQ(b.components.size(), 4u);
  EXPECT_NEAR(b.components[2].standard_uncertainty, u_d, 1e-22);
}

// Monte Carlo of the added-mass test's readings: two windows of n samples of d_e, each with white
// noise and the encoder's quantization, a mass and g drawn from their uncertainties; the spread of
// k = m g / |mean1 - mean2| is the budget's u_c within 5 % (the noise, 1.5 counts, dithers the
// quantization; the budget's q^2 / 12 per reading is then conservative, and small here).
TEST(UncertaintyBudget, StiffnessBudgetPredictsTheSpreadOfSimulatedTests) {
  StaticTestUncertainties in;
  in.added_mass_kg = 0.01;
  in.gravity_m_per_s2 = 0.02;
  in.encoder_resolution_m = 20e-9;
  in.displacement_scale_relative = 0.0;  // the simulated sensor has an exact scale
  const double m = 6.4, g = 9.8, k_true = 2e6, s = 30e-9;
  const int n = 200;
  const double d = m * g / k_true;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> offset(0.0, 1.0);
  const auto reading = [&](double level) {
    double sum = 0.0;
    for (int i = 0; i < n; ++i) sum += in.encoder_resolution_m * std::round((level + s * normal(rng)) / in.encoder_resolution_m);
    return sum / n;
  };
  const int trials = 4000;
  double sum = 0.0, sum2 = 0.0;
  for (int t = 0; t < trials; ++t) {
    const double mt = m + in.added_mass_kg * normal(rng), gt = g + in.gravity_m_per_s2 * normal(rng);
    const double base = 1e-6 * offset(rng);  // where the level falls between encoder counts
    const double k = m * g / std::abs(reading(base) - reading(base - mt * gt / k_true));  // m, g as declared
    sum += k;
    sum2 += k * k;
  }
  const double mean = sum / trials, spread = std::sqrt(sum2 / trials - mean * mean);
  // k is computed with the declared m and g while the deflection follows the drawn ones: the spread
  // holds all three inputs' shares.
  const UncertaintyBudget b = stiffness_budget(m, g, d, s, n, in);
  EXPECT_NEAR(spread / b.combined, 1.0, 0.05) << spread << " vs " << b.combined;
  EXPECT_NEAR(mean / k_true, 1.0, 3.0 * b.combined / k_true / std::sqrt(trials) + 1e-4);
}

TEST(UncertaintyBudget, StrokeCapacitanceAndFlatness) {
  StaticTestUncertainties in;
  in.encoder_resolution_m = 12e-9;  // q^2 / 12 = (3.46 nm)^2
  in.displacement_scale_relative = 1e-4;
  const UncertaintyBudget s = stroke_budget(250e-6, 20e-9, 100.0, in);  // noise 2 nm after averaging 100; scale 25 nm
  EXPECT_NEAR(s.combined, std::sqrt(2.0 * (12e-9 * 12e-9 / 12.0 + 4e-18) + 25e-9 * 25e-9), 1e-20);
  in.capacitance_relative = 0.01;
  const UncertaintyBudget c = capacitance_budget(4.4e-6, 0.03e-6, 9.0, in);  // 1 % and 0.01 uF
  EXPECT_NEAR(c.combined, std::hypot(0.044e-6, 0.01e-6), 1e-15);
  EXPECT_NEAR(flatness_budget(0.5e-6).expanded, 2.0 * std::sqrt(2.0) * 0.5e-6, 1e-18);
  EXPECT_THROW((void)capacitance_budget(0.0, 0.0, 1.0, in), InputError);
  EXPECT_THROW((void)stroke_budget(250e-6, 1e-9, 0.5, in), InputError);
}

TEST(UncertaintyBudget, ResonanceStiffnessDoublesTheResonancesRelativeError) {
  StaticTestUncertainties in;
  in.suspended_mass_kg = 0.0;
  const double w = 2.0 * 3.141592653589793 * 95.0;
  const UncertaintyBudget b = resonance_stiffness_budget(5.7, w, 0.001 * w, in);  // 0.1 % on w
  EXPECT_NEAR(b.combined / (5.7 * w * w), 0.002, 1e-15);
  in.suspended_mass_kg = 0.057;  // 1 % on m
  EXPECT_NEAR(resonance_stiffness_budget(5.7, w, 0.0, in).combined / (5.7 * w * w), 0.01, 1e-15);
}

TEST(UncertaintyBudget, NoiseFromSecondDifferencesIgnoresARampAndFindsWhiteNoise) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal;
  std::vector<double> ramp, noisy;
  for (int i = 0; i < 20000; ++i) {
    ramp.push_back(1e-3 + 2e-8 * i);
    noisy.push_back(ramp.back() + 5e-9 * normal(rng));
  }
  EXPECT_NEAR(noise_from_second_differences(ramp), 0.0, 1e-15);
  EXPECT_NEAR(noise_from_second_differences(noisy) / 5e-9, 1.0, 0.02);
  EXPECT_EQ(noise_from_second_differences(std::vector<double>{1.0, 2.0}), 0.0);
}

}  // namespace
}  // namespace piezobench::metrology
