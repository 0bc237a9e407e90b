#include "piezobench/core/statistics.hpp"

#include <gtest/gtest.h>

#include "piezobench/core/error.hpp"

#include <cmath>
#include <numbers>

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

// scipy.special.betainc and scipy.stats.t.ppf (SciPy 1.10; scripts/fixtures/make_statistics_reference.py).
TEST(IncompleteBeta, MatchesScipy) {
  EXPECT_NEAR(incomplete_beta(0.5, 0.5, 0.3), 0.3690101195655454, 1e-14);
  EXPECT_NEAR(incomplete_beta(2.0, 3.0, 0.4), 0.5248, 1e-14);  // P(at least 2 of 4 draws of probability 0.4)
  EXPECT_NEAR(incomplete_beta(7.5, 0.5, 0.9), 0.2162483651372665, 1e-14);
  EXPECT_NEAR(incomplete_beta(50.0, 0.5, 0.99), 0.31730439787419623, 1e-13);
  EXPECT_DOUBLE_EQ(incomplete_beta(1.0, 1.0, 0.25), 0.25);  // the uniform distribution
  EXPECT_EQ(incomplete_beta(3.0, 2.0, 0.0), 0.0);
  EXPECT_EQ(incomplete_beta(3.0, 2.0, 1.0), 1.0);
}

TEST(IncompleteBeta, RefusesArgumentsOutsideItsDomain) {
  EXPECT_THROW((void)incomplete_beta(0.0, 1.0, 0.5), InputError);
  EXPECT_THROW((void)incomplete_beta(1.0, -1.0, 0.5), InputError);
  EXPECT_THROW((void)incomplete_beta(1.0, 1.0, 1.5), InputError);
  EXPECT_THROW((void)incomplete_beta(1.0, 1.0, std::nan("")), InputError);
}

TEST(StudentT, QuantilesMatchTheClosedFormsAndScipy) {
  // Closed forms: dof 1 (Cauchy) t = tan(pi (p - 1/2)); dof 2 t = (2p - 1) / sqrt(2 p (1 - p)).
  for (const double p : {0.6, 0.9, 0.975, 0.995, 0.025}) {
    EXPECT_NEAR(student_t_quantile(p, 1.0), std::tan(std::numbers::pi * (p - 0.5)), 1e-13 * std::abs(std::tan(std::numbers::pi * (p - 0.5))));
    const double t2 = (2.0 * p - 1.0) / std::sqrt(2.0 * p * (1.0 - p));
    EXPECT_NEAR(student_t_quantile(p, 2.0), t2, 1e-13 * std::abs(t2));
  }
  // scipy.stats.t.ppf (its stdtrit is good to ~1e-10 relative: at dof 1 it is 2e-11 off the tan).
  const struct {
    double p, dof, t;
  } cases[] = {{0.975, 15.15294, 2.129577363509327}, {0.975, 30.0, 2.0422724563012373},
               {0.995, 4.5, 4.272823993022849},    {0.9, 1000.0, 1.2823987214609247},
               {0.975, 1e6, 1.9599663568141066},   {0.025, 7.0, -2.3646242510103},
               {0.6, 3.0, 0.27667066230490933}};
  for (const auto& c : cases) EXPECT_NEAR(student_t_quantile(c.p, c.dof), c.t, 5e-10 * std::abs(c.t)) << c.p << " " << c.dof;
  EXPECT_EQ(student_t_quantile(0.5, 3.0), 0.0);
  EXPECT_THROW((void)student_t_quantile(1.0, 3.0), InputError);
  EXPECT_THROW((void)student_t_quantile(0.975, 0.0), InputError);
}

}  // namespace
}  // namespace piezobench::core
