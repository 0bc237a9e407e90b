#include "piezobench/control/discrete_iff.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "alloc_counter.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/lti/conversions.hpp"
#include "piezobench/lti/discretize.hpp"
#include "piezobench/lti/freqresp.hpp"
#include "test_util.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::control {
namespace {

using lti::Complex;
using lti::Matrix;
using lti::Vector;
constexpr double kFs = 10e3;
constexpr double kPrewarp = kTwoPi * 95.2;

// A broadband test input: a sum of sines from 1 Hz to 3 kHz plus a step, N samples at kFs.
Vector test_input(lti::Index n) {
  Vector u(n);
  for (lti::Index k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / kFs;
    u(k) = 0.3 + std::sin(kTwoPi * 1.0 * t) + 0.5 * std::sin(kTwoPi * 95.2 * t + 0.3) +
           0.2 * std::sin(kTwoPi * 700.0 * t) + 0.1 * std::sin(kTwoPi * 3000.0 * t + 1.0);
  }
  return u;
}

lti::StateSpace reference_discrete(const IffControllerParams& params = {}, double prewarp = kPrewarp) {
  lti::DiscretizeOptions opt;
  opt.method = lti::DiscretizationMethod::kTustin;
  opt.prewarp_frequency = prewarp;
  return lti::c2d(lti::to_state_space(iff_controller(params)), 1.0 / kFs, opt);
}

TEST(DiscreteIffOptions, ValidateNamesTheField) {
  DiscreteIffOptions o;
  o.sample_rate = 0.0;
  test::input_error([&] { o.validate(); }, "sample_rate");
  o = {};
  o.sample_rate = std::numeric_limits<double>::quiet_NaN();
  test::input_error([&] { o.validate(); }, "sample_rate");
  o = {};
  o.prewarp = std::numbers::pi * o.sample_rate;  // at Nyquist: tan blows up
  test::input_error([&] { o.validate(); }, "prewarp");
  o = {};
  o.prewarp = -1.0;
  test::input_error([&] { o.validate(); }, "prewarp");
  o = {};
  o.antiwindup_gain = 1.5;
  test::input_error([&] { o.validate(); }, "antiwindup_gain");
  test::input_error([] { DiscreteIff(IffControllerParams{}, DiscreteIffOptions{}, std::nan("")); }, "gain");
  IffControllerParams p;
  p.w_lpf = -1.0;
  test::input_error([&] { DiscreteIff c(p); }, "w_lpf");
}

// The sections reproduce lti::c2d (Tustin, pre-warped) of the continuous controller to round-off,
// sample by sample, at a non-unit gain.
TEST(DiscreteIff, TimeResponseEqualsC2dOfTheContinuousController) {
  for (const double prewarp : {kPrewarp, 0.0}) {
    const double g = 280000.0;
    DiscreteIffOptions o;
    o.prewarp = prewarp;
    DiscreteIff iff({}, o, g);
    const Vector u = test_input(20000);
    const Matrix y_ref = lti::lsim(reference_discrete({}, prewarp), u).y * g;
    Vector y(u.size());
    for (lti::Index k = 0; k < u.size(); ++k) y(k) = iff.step(u(k));
    const double scale = y_ref.cwiseAbs().maxCoeff();
    ASSERT_GT(scale, 0.1);
    EXPECT_TRUE(test::all_near(y, y_ref.col(0), test::Tolerance{0.0, 1e-12 * scale})) << "prewarp " << prewarp;
  }
}

// Tustin with pre-warping: H_d(exp(j w Ts)) = H_c(j c tan(w Ts / 2)), c = w0 / tan(w0 Ts / 2); in
// particular H_d = H_c exactly at w0. Checked against the continuous zpk (an independent path).
TEST(DiscreteIff, FrequencyResponseIsTheWarpedContinuousOne) {
  const DiscreteIff iff;
  const lti::StateSpace model = iff.model();
  EXPECT_DOUBLE_EQ(model.sample_time, 1.0 / kFs);
  const double ts = 1.0 / kFs;
  const double c = kPrewarp / std::tan(kPrewarp * ts / 2.0);
  Vector w(7);
  w << kPrewarp, kTwoPi * 1.0, kTwoPi * 20.0, kTwoPi * 300.0, kTwoPi * 1000.0, kTwoPi * 2000.0, kTwoPi * 4000.0;
  Vector w_warped(w.size());
  for (lti::Index i = 0; i < w.size(); ++i) w_warped(i) = c * std::tan(w(i) * ts / 2.0);
  const lti::CVector hd = lti::freqresp(model, w).channel(0, 0);
  const lti::CVector hc_warped = lti::freqresp(iff_controller(), w_warped);
  EXPECT_TRUE(test::all_near(hd, hc_warped, test::Tolerance{test::kLightlyDamped, 0.0}));
  // At the pre-warping frequency the discrete and the continuous responses coincide.
  const lti::CVector hc = lti::freqresp(iff_controller(), w);
  EXPECT_TRUE(test::near(hd(0), hc(0), test::Tolerance{test::kLightlyDamped, 0.0}));
  // ... and away from it they do not (the check above could not pass by accident): at 4 kHz the
  // warping moves the response by more than 10 %.
  EXPECT_GT(std::abs(hd(6) - hc(6)), 0.1 * std::abs(hc(6)));
}

// Against scipy (scripts/fixtures/make_control_fixtures.py): bilinear_zpk with the pre-warped
// constant and sosfilt, an implementation independent of piezobench's lti::c2d.
TEST(DiscreteIff, MatchesScipySosfilt) {
  const auto j = nlohmann::json::parse(test::read_text(test::fixture_path("control/discrete_iff_scipy.json")));
  DiscreteIffOptions o;
  o.sample_rate = j["fs"].get<double>();
  o.prewarp = j["prewarp_rad_s"].get<double>();
  DiscreteIff iff({}, o, j["gain"].get<double>());
  const auto& u = j["u"];
  const auto& y = j["y"];
  ASSERT_EQ(u.size(), 2000u);
  double scale = 0.0;
  for (const auto& v : y) scale = std::max(scale, std::abs(v.get<double>()));
  for (std::size_t k = 0; k < u.size(); ++k) {
    ASSERT_TRUE(test::near(iff.step(u[k].get<double>()), y[k].get<double>(), test::Tolerance{0.0, test::kReferenceTool * scale}))
        << "sample " << k;
  }
}

// The gain multiplies the input of the sections: the controller with a gain schedule is the fixed
// model driven by g[k] Vs[k] (so the states, hence the output, stay continuous), and the output
// jump at the switch is far below the jump of a gain applied at the output.
TEST(DiscreteIff, GainChangeIsBumpless) {
  const Vector u = test_input(4000);
  DiscreteIff iff({}, {}, 1000.0);
  Vector gu(u.size()), y(u.size());
  for (lti::Index k = 0; k < u.size(); ++k) {
    if (k == 2000) {
      ASSERT_TRUE(iff.set_gain(3000.0));
    }
    gu(k) = iff.gain() * u(k);
    y(k) = iff.step(u(k));
  }
  EXPECT_EQ(iff.gain(), 3000.0);
  const Matrix y_ref = lti::lsim(iff.model(), gu).y;
  const double scale = y_ref.cwiseAbs().maxCoeff();
  EXPECT_TRUE(test::all_near(y, y_ref.col(0), test::Tolerance{0.0, 1e-12 * scale}));
  // Jump at the switch vs the largest sample-to-sample change before it.
  double max_step = 0.0;
  for (lti::Index k = 1000; k < 2000; ++k) max_step = std::max(max_step, std::abs(y(k) - y(k - 1)));
  const double jump = std::abs(y(2000) - y(1999));
  const double output_scaling_jump = std::abs(2.0 * y(1999));  // (3000/1000 - 1) * y
  EXPECT_LT(jump, 2.0 * max_step);
  EXPECT_GT(output_scaling_jump, 20.0 * jump);
  // A non-finite gain is rejected and the gain kept.
  EXPECT_FALSE(iff.set_gain(std::numeric_limits<double>::infinity()));
  EXPECT_EQ(iff.gain(), 3000.0);
}

TEST(DiscreteIff, StepAllocatesNothing) {
  DiscreteIff iff({}, {}, 280000.0);
  const Vector u = test_input(1000);
  double sink = 0.0;
  test::AllocationCounter count;
  for (lti::Index k = 0; k < u.size(); ++k) {
    sink += iff.step(u(k));
    iff.applied(0.5 * sink);
    if (k == 500) iff.set_gain(1000.0);
  }
  iff.step(std::nan(""));
  iff.reset();
  EXPECT_EQ(count.allocations(), 0u);
  EXPECT_TRUE(std::isfinite(sink));
}

// A NaN or infinite input resets the controller to rest and returns 0; the states are not
// poisoned: afterwards the controller behaves exactly as a fresh one.
TEST(DiscreteIff, NonFiniteInputResetsAndIsCounted) {
  DiscreteIff iff({}, {}, 280000.0);
  const Vector u = test_input(600);
  for (lti::Index k = 0; k < 300; ++k) iff.step(u(k));
  EXPECT_EQ(iff.nonfinite_inputs(), 0u);
  EXPECT_EQ(iff.step(std::numeric_limits<double>::quiet_NaN()), 0.0);
  EXPECT_EQ(iff.step(std::numeric_limits<double>::infinity()), 0.0);
  EXPECT_EQ(iff.nonfinite_inputs(), 2u);
  EXPECT_EQ(iff.gain(), 280000.0);
  DiscreteIff fresh({}, {}, 280000.0);
  for (lti::Index k = 300; k < 600; ++k) {
    const double a = iff.step(u(k));
    const double b = fresh.step(u(k));
    ASSERT_TRUE(std::isfinite(a));
    ASSERT_EQ(a, b) << "sample " << k;
  }
  // A gain so large that the output overflows: also reset, counted, 0 returned.
  DiscreteIff huge({}, {}, 1e307);
  double y = 0.0;
  for (int k = 0; k < 10; ++k) y = huge.step(1e10);
  EXPECT_EQ(y, 0.0);
  EXPECT_GE(huge.nonfinite_inputs(), 1u);
}

TEST(DiscreteIff, ResetReturnsToRest) {
  DiscreteIff iff({}, {}, 1000.0);
  const Vector u = test_input(500);
  for (lti::Index k = 0; k < u.size(); ++k) iff.step(u(k));
  iff.reset();
  EXPECT_EQ(iff.step(0.0), 0.0);
  EXPECT_EQ(iff.step(0.0), 0.0);
}

// Reporting the value step() returned changes nothing.
TEST(DiscreteIff, AppliedUnchangedOutputIsANoOp) {
  DiscreteIff a({}, {}, 5000.0), b({}, {}, 5000.0);
  const Vector u = test_input(2000);
  for (lti::Index k = 0; k < u.size(); ++k) {
    const double ya = a.step(u(k));
    a.applied(ya);
    ASSERT_EQ(ya, b.step(u(k)));
  }
}

// With the output clamped at +-L and the clamp reported, the integral action does not wind up:
// the computed output stays near the limit and follows the input's sign changes at once; without
// anti-windup it runs far beyond the limit.
TEST(DiscreteIff, AntiwindupKeepsTheOutputNearTheLimit) {
  auto run = [](double aw_gain) {
    DiscreteIffOptions o;
    o.antiwindup_gain = aw_gain;
    DiscreteIff iff({}, o, 1e6);
    const double limit = 1.0;
    double max_abs = 0.0;
    for (int k = 0; k < 5000; ++k) {
      const double t = k / kFs;
      const double y = iff.step(std::sin(kTwoPi * 10.0 * t));
      const double applied = std::clamp(y, -limit, limit);
      if (applied != y) iff.applied(applied);
      if (k > 1000) max_abs = std::max(max_abs, std::abs(y));
    }
    return max_abs;
  };
  // Unclamped amplitude: |K0(j 2 pi 10)| * 1e6 ~ 1e6 * 10 * 62.8 / (63.3 * 140 * 12566) ~ 5.6.
  const double with_aw = run(1.0), without_aw = run(0.0);
  EXPECT_GT(without_aw, 4.0);
  EXPECT_LT(with_aw, 1.5) << "without " << without_aw;
}

}  // namespace
}  // namespace piezobench::control
