#include "piezobench/rt/safety.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "test_util.hpp"

namespace piezobench::rt {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(ActuatorLimits, DefaultsAreTheApa300mlBehindA20VPerVAmplifier) {
  const ActuatorLimits l;
  EXPECT_NO_THROW(l.validate());
  EXPECT_DOUBLE_EQ(l.u_min(), -1.0);  // -20 V / 20
  EXPECT_DOUBLE_EQ(l.u_max(), 7.5);   // 150 V / 20
  EXPECT_DOUBLE_EQ(l.u_safe(), 0.0);
  EXPECT_DOUBLE_EQ(l.max_step(10e3), 0.5);  // 1e5 V/s / 20 V/V / 10 kHz
}

TEST(ActuatorLimits, ValidateNamesTheField) {
  auto bad = [](auto mutate, const std::string& field) {
    ActuatorLimits l;
    mutate(l);
    test::input_error([&] { l.validate(); }, field);
  };
  bad([](ActuatorLimits& l) { l.amplifier_gain = 0.0; }, "amplifier_gain");
  bad([](ActuatorLimits& l) { l.va_min = kNaN; }, "va_min");
  bad([](ActuatorLimits& l) { l.va_max = -30.0; }, "va_max");
  bad([](ActuatorLimits& l) { l.va_safe = 200.0; }, "va_safe");
  bad([](ActuatorLimits& l) { l.slew_rate = -1.0; }, "slew_rate");
  bad([](ActuatorLimits& l) { l.ramp_in = -0.1; }, "ramp_in");
  bad([](ActuatorLimits& l) { l.ramp_out = kNaN; }, "ramp_out");
  bad([](ActuatorLimits& l) { l.stale_cycles = -1; }, "stale_cycles");
  bad([](ActuatorLimits& l) { l.watchdog_timeout = 0.0; }, "watchdog_timeout");
  bad([](ActuatorLimits& l) { l.saturation_time = kNaN; }, "saturation_time");
  // Times and counts that become nanoseconds or cycles are range-checked, not converted first
  // (issue 35: a watchdog of 1e300 s tripped at t = 0).
  bad([](ActuatorLimits& l) { l.watchdog_timeout = 1e300; }, "watchdog_timeout");
  bad([](ActuatorLimits& l) { l.ramp_in = 1e300; }, "ramp_in");
  bad([](ActuatorLimits& l) { l.stale_cycles = 1001; }, "stale_cycles");
  bad([](ActuatorLimits& l) { l.stale_budget = 0.5; }, "stale_budget");
  bad([](ActuatorLimits& l) { l.de_range = 0.0; }, "de_range");
  const std::string what = test::input_error([] { SafetyGuard g(ActuatorLimits{}, 0.0); }, "sample_rate");
  EXPECT_TRUE(test::contains(what, "actuator limits")) << what;
}

// The saturation level: +1 per clamped sample, -1 per sample inside the range; saturation_time =
// 1 ms at 10 kHz is 10 samples.
TEST(SafetyGuard, SaturationLevelReachesTheTimeOnlyWhenMostSamplesAreClamped) {
  ActuatorLimits l;
  l.slew_rate = 1e12;
  l.saturation_time = 1e-3;
  SafetyGuard g(l, 10e3);
  for (int k = 0; k < 1000; ++k) {  // every other sample clamped: the level stays at 0 or 1
    (void)g.limit(k % 2 == 0 ? 100.0 : 1.0);
    ASSERT_FALSE(g.saturated_too_long()) << k;
  }
  int samples = 0;
  for (int k = 0; !g.saturated_too_long(); ++k, ++samples) (void)g.limit(k % 3 == 2 ? 1.0 : 100.0);
  // Two clamped, one inside: net +1 per 3 samples, from level 0 (the last sample above was inside):
  // after 8 triples the level is 8, the next two clamped samples bring it to 10.
  EXPECT_EQ(samples, 26);
  g.trip(Fault::kSaturation, 26);
  EXPECT_EQ(to_string(g.fault()), "output saturated");
}

TEST(SafetyGuard, ClampsToTheRangeAndCounts) {
  ActuatorLimits l;
  l.slew_rate = 1e12;  // slew limit out of the way
  SafetyGuard g(l, 10e3);
  auto o = g.limit(3.0);
  EXPECT_EQ(o.u, 3.0);
  EXPECT_FALSE(o.clamped);
  o = g.limit(9.0);
  EXPECT_EQ(o.u, 7.5);
  EXPECT_TRUE(o.clamped);
  o = g.limit(-4.0);
  EXPECT_EQ(o.u, -1.0);
  EXPECT_TRUE(o.clamped);
  o = g.limit(kNaN);  // a NaN request keeps the previous output and counts as clamped
  EXPECT_EQ(o.u, -1.0);
  EXPECT_TRUE(o.clamped);
  EXPECT_EQ(g.clamped_samples(), 3u);
  EXPECT_EQ(g.slew_limited_samples(), 0u);
}

TEST(SafetyGuard, LimitsTheSlewRateAndCounts) {
  SafetyGuard g(ActuatorLimits{}, 10e3);  // 0.5 V per sample at the DAC
  auto o = g.limit(2.0);
  EXPECT_DOUBLE_EQ(o.u, 0.5);
  EXPECT_TRUE(o.slew_limited);
  o = g.limit(2.0);
  EXPECT_DOUBLE_EQ(o.u, 1.0);
  o = g.limit(1.2);
  EXPECT_DOUBLE_EQ(o.u, 1.2);
  EXPECT_FALSE(o.slew_limited);
  o = g.limit(-5.0);  // clamped to -1 then slewed down by 0.5
  EXPECT_DOUBLE_EQ(o.u, 0.7);
  EXPECT_TRUE(o.clamped);
  EXPECT_TRUE(o.slew_limited);
  EXPECT_EQ(g.slew_limited_samples(), 3u);
  EXPECT_EQ(g.clamped_samples(), 1u);
}

// Whatever is requested, the output stays in the range and never steps more than the limit.
TEST(SafetyGuard, OutputNeverLeavesTheRangeNorExceedsTheSlewLimit) {
  const ActuatorLimits l;
  SafetyGuard g(l, 10e3);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> big(0.0, 50.0);
  double prev = g.last_output();
  for (int k = 0; k < 100000; ++k) {
    const double request = k % 1000 == 17 ? kNaN : big(rng);
    if (k == 60000) g.trip(Fault::kWatchdog, 60000);
    const double u = g.limit(request).u;
    ASSERT_GE(u, l.u_min());
    ASSERT_LE(u, l.u_max());
    ASSERT_LE(std::abs(u - prev), l.max_step(10e3) * (1.0 + 1e-12));
    prev = u;
  }
  EXPECT_GT(g.clamped_samples(), 50000u);
  EXPECT_GT(g.slew_limited_samples(), 50000u);
  EXPECT_EQ(prev, l.u_safe());  // in the safe state since sample 60000
}

TEST(SafetyGuard, SafeStateGoesToTheSafeValueAtTheSlewLimitAndLatches) {
  ActuatorLimits l;
  l.va_safe = 10.0;  // 0.5 V at the DAC
  SafetyGuard g(l, 10e3);
  EXPECT_DOUBLE_EQ(g.last_output(), 0.5);
  for (int k = 0; k < 20; ++k) g.limit(7.5);
  EXPECT_DOUBLE_EQ(g.last_output(), 7.5);
  g.trip(Fault::kNonFiniteSensor, 20);
  g.trip(Fault::kStaleSensor, 21);  // already safe: neither a new event nor a new reason
  EXPECT_TRUE(g.safe_state());
  EXPECT_EQ(g.fault(), Fault::kNonFiniteSensor);
  EXPECT_EQ(g.fault_cycle(), 20u);
  EXPECT_EQ(g.safe_state_events(), 1u);
  // 7.5 -> 0.5 at 0.5 V per sample: 14 samples, then it stays there whatever is requested.
  for (int k = 1; k <= 14; ++k) EXPECT_DOUBLE_EQ(g.limit(7.5).u, 7.5 - 0.5 * k);
  EXPECT_DOUBLE_EQ(g.limit(-3.0).u, 0.5);
  EXPECT_DOUBLE_EQ(g.limit(7.5).u, 0.5);
  EXPECT_EQ(to_string(g.fault()), "non-finite sensor");
}

TEST(SafetyGuard, DetectsNonFiniteAndStaleSamples) {
  ActuatorLimits l;
  l.stale_cycles = 2;
  SafetyGuard g(l, 10e3);
  SensorSample s;
  s.sequence = 1;
  EXPECT_EQ(g.check(s), Fault::kNone);
  s.sequence = 2;
  EXPECT_EQ(g.check(s), Fault::kNone);
  EXPECT_EQ(g.check(s), Fault::kNone);  // stale 1
  EXPECT_EQ(g.check(s), Fault::kNone);  // stale 2 (tolerated)
  EXPECT_EQ(g.check(s), Fault::kStaleSensor);  // stale 3
  EXPECT_EQ(g.stale_samples(), 3u);
  s.sequence = 3;  // fresh again: the run of stale reads restarts
  EXPECT_EQ(g.check(s), Fault::kNone);
  s.sequence = 4;
  s.de = std::numeric_limits<double>::infinity();
  EXPECT_EQ(g.check(s), Fault::kNonFiniteSensor);
  s.de = 0.0;
  s.vs = kNaN;
  EXPECT_EQ(g.check(s), Fault::kNonFiniteSensor);
  EXPECT_EQ(g.nonfinite_samples(), 2u);
  EXPECT_FALSE(g.safe_state());  // check() reports, trip() decides
}

TEST(SafetyGuard, AReadingOutsideTheSensorsRangeIsASensorFault) {
  const ActuatorLimits l;  // d_e within 1 mm, Vs within 100 V
  SafetyGuard g(l, 10e3);
  SensorSample s;
  s.sequence = 1;
  s.de = 300e-6;  // the APA300ML's full stroke
  s.vs = 20.0;
  EXPECT_EQ(g.check(s), Fault::kNone);
  s.sequence = 2;
  s.de = 1e300;  // a lying target (issue 35)
  EXPECT_EQ(g.check(s), Fault::kSensorOutOfRange);
  s.de = -1.001e-3;
  EXPECT_EQ(g.check(s), Fault::kSensorOutOfRange);
  s.de = 0.0;
  s.vs = -100.5;
  EXPECT_EQ(g.check(s), Fault::kSensorOutOfRange);
  EXPECT_EQ(to_string(Fault::kSensorOutOfRange), "sensor out of range");
}

TEST(ActuatorDatasheet, BoundsTheLimitsOfANamedActuator) {
  const auto d = actuator_datasheet("APA300ML");
  ASSERT_TRUE(d);
  EXPECT_DOUBLE_EQ(d->va_min, -20.0);
  EXPECT_DOUBLE_EQ(d->va_max, 150.0);
  EXPECT_NEAR(d->max_slew_rate(), 10.0 / 9.9e-6, 1e-6);  // 1.01e6 V/s: 10 A into 9.9 uF
  EXPECT_FALSE(actuator_datasheet("APA300M"));
  EXPECT_NO_THROW(check_plausible(ActuatorLimits{}, "b.toml"));
  auto refused = [](auto mutate, const std::string& field) {
    ActuatorLimits l;
    mutate(l);
    return test::input_error([&] { check_plausible(l, "b.toml"); }, field);
  };
  const std::string e = refused([](ActuatorLimits& l) { l.va_max = 1e308; }, "limits.va_max_V");
  EXPECT_TRUE(test::contains(e, "at most 150 V (APA300ML's datasheet)")) << e;
  refused([](ActuatorLimits& l) { l.va_min = -30.0; }, "limits.va_min_V");
  refused([](ActuatorLimits& l) { l.slew_rate = 1e308; }, "limits.slew_rate_V_per_s");
  refused([](ActuatorLimits& l) { l.de_range = 1.0; }, "limits.de_range_m");
  refused([](ActuatorLimits& l) { l.actuator = "APA300M"; }, "limits.actuator");
  // "custom": the physical bounds of any stack only.
  ActuatorLimits custom;
  custom.actuator = "custom";
  custom.va_max = 500.0;
  EXPECT_NO_THROW(check_plausible(custom, "b.toml"));
  custom.va_max = 1e308;
  test::input_error([&] { check_plausible(custom, "b.toml"); }, "limits.va_max_V");
}

}  // namespace
}  // namespace piezobench::rt
