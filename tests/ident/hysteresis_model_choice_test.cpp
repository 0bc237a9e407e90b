#include "piezobench/ident/hysteresis_model_choice.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "piezobench/core/error.hpp"

namespace piezobench::ident::hysteresis_model_choice_test {
namespace {

constexpr double kFs = 1000.0;  // Hz
constexpr std::size_t kRamp = 1000, kPeriod = 2000, kPeriods = 3;

// Va from rest: a ramp to 65 V, three periods of 65 + 80 sin, a ramp back to 0 (Va in [-15, 145] V).
std::vector<double> voltage() {
  std::vector<double> v;
  for (std::size_t k = 0; k < kRamp; ++k) v.push_back(65.0 * static_cast<double>(k) / kRamp);
  for (std::size_t k = 0; k < kPeriods * kPeriod; ++k) v.push_back(65.0 + 80.0 * std::sin(2.0 * std::numbers::pi * static_cast<double>(k) / kPeriod));
  for (std::size_t k = 0; k <= kRamp; ++k) v.push_back(65.0 - 65.0 * static_cast<double>(k) / kRamp);
  return v;
}

// A plain PI actuator on the fit's own default grid (10 thresholds (i + 1/2) 8 V: half the range
// of Va over 10), so that the plain fit is exact.
HysteresisModel truth() {
  HysteresisModel m;
  const double w[10] = {0.05, 0.2, 0.0, 0.12, 0.08, 0.0, 0.03, 0.01, 0.02, 0.0};
  for (int i = 0; i < 10; ++i) {
    m.hysteresis.thresholds.push_back((i + 0.5) * 8.0);
    m.hysteresis.weights.push_back(w[i]);
  }
  m.gain = -1.5e-6;
  m.offset = 3e-6;
  return m;
}

HysteresisModelChoiceOptions steady() {
  HysteresisModelChoiceOptions o;
  o.steady_first_sample = static_cast<long>(kRamp);
  o.steady_samples = static_cast<long>(kPeriods * kPeriod);
  return o;
}

// A PI record: the steady loop over whole periods is point-symmetric (asymmetry ~ 0), so only the
// plain PI is fitted; it is exact, so the model's loop width is the record's.
TEST(HysteresisModelChoice, SymmetricLoopKeepsThePlainPi) {
  const std::vector<double> va = voltage();
  const std::vector<double> de = truth().predict(va, kFs);
  const HysteresisModelChoice c = identify_hysteresis_model(va, de, kFs, steady());
  EXPECT_LT(c.asymmetry, 1e-3);
  EXPECT_FALSE(c.alternative.has_value());
  EXPECT_TRUE(c.fit.model.output.identity());
  EXPECT_LT(c.fit.relative_residual, 1e-9);
  EXPECT_GT(c.width, 0.05);
  EXPECT_NEAR(c.model_width, c.width, 1e-9);
  ASSERT_EQ(c.predicted_m.size(), va.size());
  EXPECT_NEAR(c.predicted_m[3000], de[3000], 1e-15);
}

// The same record bent (d_e + 0.3 (d_e - d_0)^2 / stroke: the loop is no longer point-symmetric):
// the modified PI is fitted too and, fitting the bend, is chosen; the plain PI is the alternative.
TEST(HysteresisModelChoice, AsymmetricLoopChoosesTheModifiedPi) {
  const std::vector<double> va = voltage();
  std::vector<double> de = truth().predict(va, kFs);
  const double d0 = de.front(), stroke = 1.5e-6 * 160.0;
  for (double& d : de) d += 0.3 * (d - d0) * (d - d0) / stroke;
  const HysteresisModelChoice c = identify_hysteresis_model(va, de, kFs, steady());
  EXPECT_GT(c.asymmetry, 0.01);
  ASSERT_TRUE(c.alternative.has_value()) << c.alternative_error;
  EXPECT_FALSE(c.fit.model.output.identity());
  EXPECT_TRUE(c.alternative->model.output.identity());
  EXPECT_LT(c.fit.relative_residual, c.alternative->relative_residual);
  // A limit above the asymmetry: the plain PI alone.
  HysteresisModelChoiceOptions o = steady();
  o.asymmetry_limit = 1.0;
  EXPECT_FALSE(identify_hysteresis_model(va, de, kFs, o).alternative.has_value());
}

TEST(HysteresisModelChoice, RefusesASteadyLoopOutsideTheRecord) {
  const std::vector<double> va = voltage();
  const std::vector<double> de = truth().predict(va, kFs);
  HysteresisModelChoiceOptions o = steady();
  o.steady_samples = static_cast<long>(va.size());
  EXPECT_THROW(identify_hysteresis_model(va, de, kFs, o), InputError);
  EXPECT_THROW(identify_hysteresis_model(va, std::vector<double>(10, 0.0), kFs, {}), InputError);
}

}  // namespace
}  // namespace piezobench::ident::hysteresis_model_choice_test
