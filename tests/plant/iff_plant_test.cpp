#include "piezobench/plant/iff_plant.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "piezobench/core/error.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/lti/freqresp.hpp"
#include "test_util.hpp"

namespace piezobench::plant {
namespace {

using lti::Complex;
using lti::CVector;
using lti::Vector;

// eq. 2.3 written out at s = j w, against the transfer function's own frequency response.
Complex equation_2_3(const IffPlantParams& p, double w) {
  const Complex s(0.0, w);
  return p.g0 * (1.0 + 2.0 * p.xz * s / p.wz + s * s / (p.wz * p.wz)) / (1.0 + 2.0 * p.xp * s / p.wp + s * s / (p.wp * p.wp)) *
         s / (p.w_hpf + s) * std::exp(-s * p.delay);
}

TEST(IffPlant, MatchesEquation23) {
  const IffPlantParams p;
  const lti::TransferFunction g = iff_plant(p);
  const Vector w = (Vector(4) << 1.0, kTwoPi * 42.7, kTwoPi * 95.2, kTwoPi * 1000).finished();
  const CVector h = lti::freqresp(g, w);
  for (Eigen::Index i = 0; i < w.size(); ++i) {
    EXPECT_TRUE(test::near(h(i), equation_2_3(p, w(i)), {test::kLightlyDamped, 0.0})) << "w = " << w(i);
  }
}

TEST(IffPlant, ResponseIncludesTheDelay) {
  IffPlantParams p;
  p.delay = 200e-6;  // the report's 200 us
  const Vector w = (Vector(3) << kTwoPi * 10.0, kTwoPi * 95.2, kTwoPi * 500.0).finished();
  const CVector h = iff_plant_response(p, w);
  for (Eigen::Index i = 0; i < w.size(); ++i) {
    EXPECT_TRUE(test::near(h(i), equation_2_3(p, w(i)), {1e-14, 0.0})) << "w = " << w(i);
    // The delay only turns the phase: -w * 200 us at w.
    const double lag = std::arg(h(i) / iff_plant_response(IffPlantParams{}, w(i)));
    EXPECT_NEAR(lag, std::remainder(-w(i) * 200e-6, kTwoPi), 1e-12);
  }
}

TEST(IffPlantParams, InvalidValuesNameTheField) {
  IffPlantParams p;
  p.xz = -0.1;  // a non-minimum-phase zero pair is a valid plant
  EXPECT_NO_THROW(iff_plant(p));
  p.xp = -0.1;
  try {
    (void)iff_plant(p);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "xp");
  }
  IffPlantParams q;
  q.w_hpf = 0.0;
  try {
    q.validate();
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "w_hpf");
  }
}

}  // namespace
}  // namespace piezobench::plant
