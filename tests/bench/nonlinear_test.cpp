// Hysteresis and creep of the virtual bench's stacks (src/bench/nonlinear.hpp), against their
// closed forms.
#include "bench/nonlinear.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "test_util.hpp"

namespace piezobench::bench::detail {
namespace {

using test::near;

// Triangle wave between lo and hi (exact turning points), `periods` times, from `start`.
std::vector<double> triangle(double start, double lo, double hi, int periods, int per_leg) {
  std::vector<double> v;
  for (int i = 0; i <= per_leg; ++i) v.push_back(start + (lo - start) * i / per_leg);
  for (int p = 0; p < periods; ++p) {
    for (int i = 1; i <= per_leg; ++i) v.push_back(lo + (hi - lo) * i / per_leg);
    for (int i = 1; i <= per_leg; ++i) v.push_back(hi - (hi - lo) * i / per_leg);
  }
  return v;
}

TEST(PlayHysteresis, SingleOperatorIsABacklash) {
  std::array<double, PlayHysteresis::kOperators> r{}, w{};
  r[0] = 2.0;
  w[0] = 1.0;
  PlayHysteresis h(r, w);  // one active operator of threshold 2 (the others have weight 0)
  EXPECT_EQ(h.update(1.0), 0.0);   // inside the dead band: stuck at 0
  EXPECT_EQ(h.update(5.0), 3.0);   // pushed: v - r
  EXPECT_EQ(h.update(4.0), 3.0);   // reversal: stuck
  EXPECT_EQ(h.update(1.0), 3.0);   // still within 2 r of the turning point
  EXPECT_EQ(h.update(0.0), 2.0);   // pulled: v + r
  h.reset();
  EXPECT_EQ(h.update(-3.0), -1.0);
}

// Loop of amplitude a about `offset`: half range and width at the offset, from the closed forms
// of the header, against the operators driven by a triangle wave.
TEST(PlayHysteresis, LoopRangeAndWidthFollowTheClosedForm) {
  const PlayHysteresis model = PlayHysteresis::bench_default(1.0);
  for (const double a : {4.0, 20.0, 40.0, 80.0}) {
    PlayHysteresis h = model;
    const double offset = 65.0;
    const std::size_t leg = 4000;
    const std::vector<double> v = triangle(0.0, offset - a, offset + a, 3, static_cast<int>(leg));
    std::vector<double> y(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) y[i] = v[i] + h.update(v[i]);
    // Last period: rising leg then falling leg; the offset is crossed mid-leg.
    const std::size_t n = v.size();
    const std::size_t up_mid = n - 2 * leg + leg / 2 - 1;
    const std::size_t down_mid = n - leg + leg / 2 - 1;
    ASSERT_NEAR(v[up_mid], offset, 1e-9);
    ASSERT_NEAR(v[down_mid], offset, 1e-9);
    double half_range = a, width = 0.0;
    for (int i = 0; i < PlayHysteresis::kOperators; ++i) {
      const double ri = model.threshold(i);
      const double wi = model.weight(i);
      if (ri < a) {
        half_range += wi * (a - ri);
        width += 2.0 * wi * std::min(ri, a - ri);
      }
    }
    const double top = y[n - leg - 1], bottom = y[n - 2 * leg - 1];
    EXPECT_TRUE(near(top - bottom, 2.0 * half_range, 1e-12)) << "amplitude " << a;
    EXPECT_TRUE(near(y[down_mid] - y[up_mid], width, 1e-12)) << "amplitude " << a;
  }
}

TEST(PlayHysteresis, BenchDefaultWidensWithAmplitudeAndExceedsTheSmallSignalGain) {
  const PlayHysteresis h = PlayHysteresis::bench_default(1.0);
  const auto ratio = [&](double a) {
    double half = a, width = 0.0;
    for (int i = 0; i < PlayHysteresis::kOperators; ++i) {
      const double r = h.threshold(i), w = h.weight(i);
      if (r < a) {
        half += w * (a - r);
        width += 2.0 * w * std::min(r, a - r);
      }
    }
    return std::pair{width / (2.0 * half), half / a};
  };
  const auto [w4, g4] = ratio(4.0);
  const auto [w20, g20] = ratio(20.0);
  const auto [w80, g80] = ratio(80.0);
  EXPECT_EQ(w4, 0.0);  // below the first threshold: linear
  EXPECT_EQ(g4, 1.0);
  EXPECT_GT(w20, 0.04);
  EXPECT_LT(w20, 0.08);
  EXPECT_GT(w80, 0.14);
  EXPECT_LT(w80, 0.22);
  EXPECT_GT(g80, g20);
  // -20 V -> 150 V from rest: range 170 + sum w (170 - 2 r) (each operator spans 170 - 2 r).
  double stroke = 170.0;
  for (int i = 0; i < PlayHysteresis::kOperators; ++i) {
    stroke += h.weight(i) * std::max(0.0, 170.0 - 2.0 * h.threshold(i));
  }
  EXPECT_GT(stroke / 170.0, 1.6);
  EXPECT_LT(stroke / 170.0, 1.8);
}

TEST(Creep, VoltageStepFollowsTheExponentials) {
  const double ts = 1e-3;
  Creep c(0.01, 0.0, ts);
  const double f = 100.0;  // N of free-stroke force, held
  const int steps = 5000;  // 5 s
  for (int k = 0; k < steps; ++k) c.update(f, 0.0);
  double expected = 0.0;
  for (const double tau : Creep::kTimeConstants) expected += 0.01 * f * (1.0 - std::exp(-steps * ts / tau));
  EXPECT_TRUE(near(c.force(), expected, 1e-12));
  c.reset();
  EXPECT_EQ(c.force(), 0.0);
}

TEST(Creep, LoadCreepSettlesWhereTheElasticStrainDrivesIt) {
  // Held s_load and f_free: each state tends to load (s - F_c - f), so F_c -> 3 L (s - f) / (1 + 3 L).
  const double load = 0.1, s = -50.0, f = 10.0;
  Creep c(0.0, load, 1.0);  // 1 s samples: 10^4 s is many times the slowest time constant
  for (int k = 0; k < 10000; ++k) c.update(f, s);
  EXPECT_TRUE(near(c.force(), 3.0 * load * (s - f) / (1.0 + 3.0 * load), 1e-9));
}

}  // namespace
}  // namespace piezobench::bench::detail
