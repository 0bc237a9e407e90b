#include "piezobench/rt/timing.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "test_util.hpp"

namespace piezobench::rt {
namespace {

// Nearest-rank percentile of the sorted samples.
double exact_percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  const auto rank = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size()))));
  return v[rank - 1];
}

TEST(TimingHistogram, PercentilesWithinTheBinResolution) {
  std::mt19937_64 rng(3);
  std::lognormal_distribution<double> dist(std::log(2000.0), 0.8);  // ns: around 2 us, long tail
  TimingHistogram h;
  std::vector<double> v;
  for (int i = 0; i < 30000; ++i) {
    const double x = dist(rng);
    v.push_back(x);
    h.add(x);
  }
  EXPECT_EQ(h.count(), 30000u);
  EXPECT_EQ(h.max(), *std::max_element(v.begin(), v.end()));
  const double resolution = std::pow(10.0, 0.5 / 100.0) - 1.0;  // half a bin: 1.16 %
  for (double q : {0.5, 0.9, 0.99, 0.999}) {
    EXPECT_TRUE(test::near(h.percentile(q), exact_percentile(v, q), resolution + 1e-12)) << "q = " << q;
  }
  const TimingSummary s = h.summary_us();
  EXPECT_EQ(s.count, 30000u);
  EXPECT_TRUE(test::near(s.p50, exact_percentile(v, 0.5) * 1e-3, resolution + 1e-12));
  EXPECT_DOUBLE_EQ(s.max, h.max() * 1e-3);
  double sum = 0.0;
  for (double x : v) sum += x;
  EXPECT_TRUE(test::near(s.mean, sum / 30000.0 * 1e-3, 1e-12));
}

TEST(TimingHistogram, EdgeCases) {
  TimingHistogram h;
  EXPECT_EQ(h.percentile(0.5), 0.0);
  EXPECT_EQ(h.summary_us().max, 0.0);
  h.add(-5.0);
  h.add(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(h.count(), 2u);
  EXPECT_EQ(h.max(), 0.0);
  EXPECT_EQ(h.percentile(1.0), 0.0);  // never above the exact maximum
  h.add(1e12);                          // 1000 s: into the last bin, max kept exactly
  EXPECT_EQ(h.max(), 1e12);
  EXPECT_EQ(h.percentile(1.0), 1e12);
}

// clock_nanosleep with an absolute deadline never returns early.
TEST(Clock, SleepUntilNeverReturnsBeforeTheDeadline) {
  for (int i = 0; i < 20; ++i) {
    const std::int64_t deadline = monotonic_ns() + 200'000;  // 200 us ahead
    sleep_until_ns(deadline);
    ASSERT_GE(monotonic_ns(), deadline);
  }
  const std::int64_t before = monotonic_ns();
  sleep_until_ns(before - 1'000'000);  // a past deadline returns at once (and does not hang)
  EXPECT_GE(monotonic_ns(), before);
}

}  // namespace
}  // namespace piezobench::rt
