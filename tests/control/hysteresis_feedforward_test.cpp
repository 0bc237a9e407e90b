#include "piezobench/control/hysteresis_feedforward.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "alloc_counter.hpp"
#include "piezobench/core/error.hpp"

namespace piezobench::control {
namespace {

ident::HysteresisModel model(bool creep, bool modified = false) {
  ident::HysteresisModel m;
  if (modified) m.output = {{-60.0, -10.0, 0.0, 30.0, 70.0}, {-45.0, -9.0, 0.0, 25.0, 50.0}, 0.5, 0.4};  // Kuhnen's S
  m.hysteresis = {1.0, {5.0, 15.0, 25.0, 35.0, 45.0}, {0.1, 0.25, 0.15, 0.1, 0.05}};
  if (creep) {
    m.creep_time_constants = {0.2, 2.0};
    m.creep_coefficients = {0.03, 0.02};
  }
  m.gain = -1.6e-6;
  m.offset = 2e-6;
  m.reference_slope = 1.5;
  m.reference_intercept = -12.0;
  return m;
}

// The model driven by the feedforward is the reference line, exactly (creep included).
TEST(HysteresisFeedforward, LinearizesItsModel) {
  for (const auto& [creep, modified] : {std::pair{false, false}, {true, false}, {false, true}, {true, true}}) {
    const ident::HysteresisModel m = model(creep, modified);
    const double fs = 1000.0;
    std::vector<double> c;
    for (int k = 0; k < 5000; ++k) {
      const double t = k / fs;
      c.push_back(40.0 + 50.0 * std::sin(2.0 * std::numbers::pi * t) + 20.0 * std::sin(2.0 * std::numbers::pi * 3.3 * t));
    }
    const std::vector<double> va = apply_feedforward(m, fs, c);
    const std::vector<double> de = m.predict(va, fs);
    for (std::size_t k = 0; k < c.size(); ++k) {
      const double expected = m.offset + m.gain * (m.reference_slope * c[k] + m.reference_intercept);
      ASSERT_NEAR(de[k], expected, 1e-9 * 1e-6 * 100.0) << k;
    }
  }
}

TEST(HysteresisFeedforward, StepAllocatesNothingAndHoldsOnNonFinite) {
  HysteresisFeedforward ff(model(true, true), 10e3);
  test::AllocationCounter count;
  double last = 0.0;
  for (int k = 0; k < 10000; ++k) last = ff.step(30.0 * std::sin(0.001 * k));
  EXPECT_EQ(count.allocations(), 0u);
  EXPECT_EQ(ff.step(std::nan("")), last);
  EXPECT_EQ(ff.step(INFINITY), last);
  ff.reset();
  EXPECT_DOUBLE_EQ(ff.step(0.0), ff.at_rest(0.0));
}

// The weighted step: c + w (stage - c), the stage stepping whatever w is (its memory follows the
// whole command): w = 0 gives c, w = 1 the stage's output, as an unweighted twin fed the same c.
TEST(HysteresisFeedforward, WeightedStepBlendsTheStage) {
  HysteresisFeedforward a(model(true, true), 10e3), b(model(true, true), 10e3);
  for (int k = 0; k < 3000; ++k) {
    const double c = 40.0 + 30.0 * std::sin(0.003 * k), w = k < 1000 ? 0.0 : k < 2000 ? 0.25 : 1.0;
    const double stage = b.step(c);
    ASSERT_NEAR(a.step(c, w), c + w * (stage - c), 1e-12) << k;
  }
}

TEST(HysteresisFeedforward, RefusesBadSettings) {
  EXPECT_THROW(HysteresisFeedforward(model(false), 0.0), InputError);
  ident::HysteresisModel m = model(false);
  m.hysteresis.weights[0] = -2.0;  // not invertible
  EXPECT_THROW(HysteresisFeedforward(m, 1e3), InputError);
}

}  // namespace
}  // namespace piezobench::control
