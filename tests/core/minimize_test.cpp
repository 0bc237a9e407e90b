#include "piezobench/core/minimize.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "piezobench/core/error.hpp"

namespace piezobench::core {
namespace {

TEST(GoldenSection, FindsTheMinimumOfAParabolaAndOfCos) {
  const ScalarMinimum m = golden_section_minimize([](double x) { return (x - 0.3) * (x - 0.3) + 2.0; }, -1.0, 4.0);
  EXPECT_NEAR(m.x, 0.3, 1e-7);  // a parabola's minimum is found to sqrt(machine epsilon)
  EXPECT_DOUBLE_EQ(m.value, 2.0 + (m.x - 0.3) * (m.x - 0.3));
  EXPECT_LE(m.upper - m.lower, 1e-12);
  // cos has its minimum at pi on [2, 4]; the bracket shrinks by 0.618 per evaluation.
  GoldenSectionOptions o;
  o.tolerance = 1e-6;
  const ScalarMinimum c = golden_section_minimize([](double x) { return std::cos(x); }, 2.0, 4.0, o);
  EXPECT_NEAR(c.x, M_PI, 1e-6);
  EXPECT_LE(c.evaluations, 2 + static_cast<int>(std::ceil(std::log(1e-6 / 2.0) / std::log(0.618034))) + 1);
}

TEST(GoldenSection, NanCountsAsInfinityAndBadBracketsAreRefused) {
  const ScalarMinimum m = golden_section_minimize([](double x) { return x < 1.0 ? std::nan("") : (x - 2.0) * (x - 2.0); }, 0.0, 5.0);
  EXPECT_NEAR(m.x, 2.0, 1e-6);
  EXPECT_THROW(golden_section_minimize([](double x) { return x; }, 1.0, 1.0), InputError);
  GoldenSectionOptions o;
  o.tolerance = -1.0;
  EXPECT_THROW(golden_section_minimize([](double x) { return x; }, 0.0, 1.0, o), InputError);
}

}  // namespace
}  // namespace piezobench::core
