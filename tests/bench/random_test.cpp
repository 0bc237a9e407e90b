// The bench's random numbers (src/bench/random.hpp): the published reference outputs of
// xoshiro256** and splitmix64, reproducibility, and the moments of the normal approximation.
#include "random.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "test_util.hpp"

namespace piezobench::bench::detail {
namespace {

TEST(Xoshiro256, MatchesTheReferenceImplementation) {
  // xoshiro256** from the state {1, 2, 3, 4} (Blackman & Vigna's xoshiro256starstar.c).
  Xoshiro256 rng;
  rng.set_state(1, 2, 3, 4);
  const std::vector<std::uint64_t> expected = {11520ULL, 0ULL, 1509978240ULL, 1215971899390074240ULL,
                                               1216172134540287360ULL, 607988272756665600ULL};
  for (const std::uint64_t e : expected) EXPECT_EQ(rng.next(), e);
}

TEST(Splitmix64, MatchesTheReferenceImplementation) {
  // splitmix64.c from the seed 1234567 (also java.util.SplittableRandom's mixer).
  std::uint64_t state = 1234567;
  EXPECT_EQ(splitmix64(state), 6457827717110365317ULL);
  EXPECT_EQ(splitmix64(state), 3203168211198807973ULL);
  EXPECT_EQ(splitmix64(state), 9817491932198370423ULL);
}

TEST(Xoshiro256, SameSeedSameSequenceOtherSeedOtherSequence) {
  Xoshiro256 a(42), b(42), c(43);
  bool differs = false;
  for (int i = 0; i < 100; ++i) {
    const std::uint64_t x = a.next();
    EXPECT_EQ(x, b.next());
    differs = differs || x != c.next();
  }
  EXPECT_TRUE(differs);
  EXPECT_NE(derive_seed(42, 1), derive_seed(42, 2));
  EXPECT_NE(derive_seed(42, 1), derive_seed(43, 1));
  EXPECT_EQ(derive_seed(42, 1), derive_seed(42, 1));
}

TEST(Xoshiro256, UniformAndNormalMoments) {
  Xoshiro256 rng(7);
  const int n = 200000;
  double su = 0.0, su2 = 0.0, sn = 0.0, sn2 = 0.0, sn4 = 0.0, max_abs = 0.0;
  for (int i = 0; i < n; ++i) {
    const double u = rng.uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    su += u;
    su2 += u * u;
    const double g = rng.normal();
    sn += g;
    sn2 += g * g;
    sn4 += g * g * g * g;
    max_abs = std::max(max_abs, std::abs(g));
  }
  // Uniform: mean 1/2, variance 1/12; standard errors 6.5e-4 and 1.5e-4.
  EXPECT_NEAR(su / n, 0.5, 3e-3);
  EXPECT_NEAR(su2 / n - 0.25, 1.0 / 12.0, 1e-3);
  // Irwin-Hall of 4, standardized: mean 0, variance 1, kurtosis 3 - 6/(5*4) = 2.7, bounded by sqrt(12).
  EXPECT_NEAR(sn / n, 0.0, 1e-2);
  EXPECT_NEAR(sn2 / n, 1.0, 1e-2);
  EXPECT_NEAR(sn4 / n, 2.7, 5e-2);
  EXPECT_LE(max_abs, std::sqrt(12.0));
}

}  // namespace
}  // namespace piezobench::bench::detail
