#include "piezobench/core/statistics.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace piezobench::core {
namespace {

TEST(Median, OddCountIsTheMiddleValueEvenCountTheMeanOfTheTwo) {
  EXPECT_EQ(median({3.0, -1.0, 7.0}), 3.0);
  EXPECT_EQ(median({4.0, 1.0, 10.0, 2.0}), 3.0);  // (2 + 4) / 2
  EXPECT_EQ(median({5.5}), 5.5);
  EXPECT_EQ(median({2.0, 2.0, 9.0, -3.0, 2.0}), 2.0);
  // An outlier moves the mean, not the median.
  EXPECT_EQ(median({1.0, 2.0, 3.0, 4.0, 1e9}), 3.0);
}

TEST(Median, NoValuesIsNan) { EXPECT_TRUE(std::isnan(median({}))); }

}  // namespace
}  // namespace piezobench::core
