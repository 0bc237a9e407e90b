// Hysteresis and creep of the virtual bench's stacks (src/bench/nonlinear.hpp), against their
// closed forms.
#include "nonlinear.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
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

// Bouc-Wen, closed form: from rest, increasing v: h = h_max (1 - exp(-2 beta v)), h_max = a / (2 beta);
// after a reversal at the top h falls linearly (slope a: the branch's slope is 1) until it is 0,
// then exponentially towards -h_max.
TEST(BoucWenHysteresis, BranchesFollowTheClosedForm) {
  const double a = 1.0, beta = 0.02, hmax = a / (2.0 * beta);
  BoucWenHysteresis bw(a, beta);
  double top = 0.0;
  for (int k = 1; k <= 1000; ++k) top = bw.update(0.1 * k);  // 0 -> 100 V in 1000 steps
  const double h_top = hmax * (1.0 - std::exp(-2.0 * beta * 100.0));
  EXPECT_TRUE(near(top, a * 100.0 - h_top, 1e-12));
  // Down by 10 V: still the linear piece (h_top / a = 21.6 V of it): Va_eff = v + a v - h falls by
  // 10 V exactly, the extra term stays.
  EXPECT_TRUE(near(bw.update(90.0), top, 1e-12));
  // Down to 40 V: the linear piece ends at 100 - h_top / a, then the exponential.
  const double v0 = 100.0 - h_top / a;
  const double h = -hmax * (1.0 - std::exp(-2.0 * beta * (v0 - 40.0)));
  EXPECT_TRUE(near(bw.update(40.0), a * 40.0 - h, 1e-12));
  bw.reset();
  EXPECT_EQ(bw.update(0.0), 0.0);
}

// Rate independence: the same path in 1 step or in 1000 gives the same output.
TEST(BoucWenHysteresis, IsRateIndependent) {
  BoucWenHysteresis coarse(1.0, 0.02), fine(1.0, 0.02);
  const double path[] = {30.0, -10.0, 120.0, 60.0, 75.0, -20.0};
  double last = 0.0, yc = 0.0, yf = 0.0;
  for (double target : path) {
    yc = coarse.update(target);
    for (int i = 1; i <= 1000; ++i) yf = fine.update(last + (target - last) * i / 1000.0);
    last = target;
    EXPECT_TRUE(near(yc, yf, 1e-9)) << target;
  }
}

// The bench's second law at 80 V about 65 V: a loop about 18 % of its stroke wide (peak-to-peak
// deviation from the best line, the width the tracking experiment reports) and a large-signal gain
// above the small-signal one (1).
TEST(BoucWenHysteresis, BenchDefaultLoopAt80V) {
  BoucWenHysteresis bw = BoucWenHysteresis::bench_default(1.0);
  std::vector<double> v, y;
  for (int k = 0; k <= 1000; ++k) bw.update(65.0 * k / 1000.0);
  for (int k = 0; k <= 3000; ++k) {
    const double x = 65.0 + 80.0 * std::sin(2.0 * std::numbers::pi * k / 1000.0);
    const double e = x + bw.update(x);
    if (k >= 1000) {
      v.push_back(x);
      y.push_back(e);
    }
  }
  double sv = 0, sy = 0, svv = 0, svy = 0;
  const double n = static_cast<double>(v.size());
  for (std::size_t k = 0; k < v.size(); ++k) {
    sv += v[k];
    sy += y[k];
    svv += v[k] * v[k];
    svy += v[k] * y[k];
  }
  const double slope = (svy - sv * sy / n) / (svv - sv * sv / n), icpt = (sy - slope * sv) / n;
  double lo = 1e300, hi = -1e300, ylo = 1e300, yhi = -1e300;
  for (std::size_t k = 0; k < v.size(); ++k) {
    const double d = y[k] - slope * v[k] - icpt;
    lo = std::min(lo, d);
    hi = std::max(hi, d);
    ylo = std::min(ylo, y[k]);
    yhi = std::max(yhi, y[k]);
  }
  const double width = (hi - lo) / (yhi - ylo);
  EXPECT_GT(width, 0.16);
  EXPECT_LT(width, 0.20);
  EXPECT_GT((yhi - ylo) / 160.0, 1.5);
}

}  // namespace
}  // namespace piezobench::bench::detail
