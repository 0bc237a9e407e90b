// Tests of the private Parlett-Reinsch balancing: powers of two, and bounded on overflowed input.
#include "balance.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace piezobench::lti::detail {
namespace {

// The classic badly scaled matrix: balancing brings the off-diagonal norms within a factor of 2
// (radix) of each other, with exact powers of two.
TEST(Balance, ScalesArePowersOfTwoThatEqualizeRowAndColumnNorms) {
  Matrix a(2, 2);
  a << 1.0, 1e6, 1e-6, 1.0;
  const Vector d = balancing_scales(a);
  ASSERT_EQ(d.size(), 2);
  for (Index i = 0; i < 2; ++i) {
    int e = 0;
    EXPECT_EQ(std::frexp(d(i), &e), 0.5) << d(i);
  }
  const double off12 = a(0, 1) * d(1) / d(0);
  const double off21 = a(1, 0) * d(0) / d(1);
  EXPECT_LT(off12 / off21, 4.0);
  EXPECT_GT(off12 / off21, 0.25);
}

// Issue 21.3: num = [1e308, 0], den = [1, 2.5] gives C = -2.5e308 = -inf; the row sum overflowed
// and the inner loop never ended. Now a non-finite row or column is left alone.
TEST(Balance, OverflowedEntriesEndAtOnceAndStayUnscaled) {
  const double inf = std::numeric_limits<double>::infinity();
  Matrix a(1, 1), b(1, 1), c(1, 1);
  a << -2.5;
  b << 1.0;
  c << -inf;
  balance_realization(a, b, c);
  EXPECT_EQ(a(0, 0), -2.5);
  EXPECT_EQ(b(0, 0), 1.0);
  EXPECT_EQ(c(0, 0), -inf);
  Matrix big(2, 2);
  big << 0.0, 1e308, 1e-308, 0.0;  // scaling would overflow the scale itself: stays finite
  const Vector d = balancing_scales(big);
  EXPECT_TRUE(d.allFinite());
  EXPECT_GT(d.minCoeff(), 0.0);
}

}  // namespace
}  // namespace piezobench::lti::detail
