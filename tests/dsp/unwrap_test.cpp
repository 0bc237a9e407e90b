// dsp::unwrap_phase against numpy.unwrap's definition on known sequences.
#include "piezobench/dsp/unwrap.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <limits>

namespace piezobench::dsp {
namespace {

TEST(UnwrapPhase, RecoversALinearPhaseFromItsWrappedValues) {
  // phi = -0.7 k rad, wrapped into (-pi, pi] by arg(): unwrapping gives the line back.
  std::vector<double> wrapped;
  for (int k = 0; k < 40; ++k) wrapped.push_back(std::arg(std::polar(1.0, -0.7 * k)));
  const std::vector<double> u = unwrap_phase(wrapped);
  for (int k = 0; k < 40; ++k) EXPECT_NEAR(u[static_cast<std::size_t>(k)], -0.7 * k, 1e-12) << k;
}

TEST(UnwrapPhase, DegreesWithAPeriodOf360) {
  const std::vector<double> u = unwrap_phase({170.0, -170.0, -150.0, 175.0}, 360.0);
  EXPECT_EQ(u, (std::vector<double>{170.0, 190.0, 210.0, 175.0}));
}

TEST(UnwrapPhase, NonFiniteValuesAreSkipped) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> u = unwrap_phase({3.0, nan, -3.0}, kTwoPi);
  EXPECT_EQ(u[0], 3.0);
  EXPECT_TRUE(std::isnan(u[1]));
  EXPECT_NEAR(u[2], -3.0 + kTwoPi, 1e-15);
  EXPECT_TRUE(unwrap_phase({}).empty());
}

}  // namespace
}  // namespace piezobench::dsp
