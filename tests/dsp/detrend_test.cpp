#include "piezobench/dsp/detrend.hpp"

#include <gtest/gtest.h>

#include "piezobench/core/error.hpp"
#include "test_util.hpp"

namespace piezobench::dsp {
namespace {

using Eigen::VectorXd;

TEST(Detrend, NamesRoundTrip) {
  for (Detrend d : {Detrend::kNone, Detrend::kMean, Detrend::kLinear}) EXPECT_EQ(detrend_from_string(to_string(d)), d);
  EXPECT_THROW((void)detrend_from_string("constant"), InputError);
}

TEST(Detrend, LinearRemovesAnExactLineAndLeavesTheRestOrthogonal) {
  const Eigen::Index n = 37;
  const VectorXd t = VectorXd::LinSpaced(n, 0.0, static_cast<double>(n - 1));
  const VectorXd wiggle = (0.7 * t).array().sin();
  VectorXd x = (2.5 - 0.3 * t.array()).matrix() + wiggle;
  detrend_in_place(x, Detrend::kLinear);
  // The residual is the wiggle minus its own least-squares line: orthogonal to 1 and t.
  EXPECT_NEAR(x.sum(), 0.0, 1e-12);
  EXPECT_NEAR(x.dot(t), 0.0, 1e-10);
  VectorXd line = (2.5 - 0.3 * t.array()).matrix();
  detrend_in_place(line, Detrend::kLinear);
  EXPECT_LT(line.cwiseAbs().maxCoeff(), 1e-13);
}

TEST(Detrend, MeanAndNone) {
  VectorXd x(4);
  x << 1.0, 2.0, 3.0, 10.0;
  VectorXd y = x;
  detrend_in_place(y, Detrend::kNone);
  EXPECT_EQ(y, x);
  detrend_in_place(y, Detrend::kMean);
  VectorXd e(4);
  e << -3.0, -2.0, -1.0, 6.0;
  EXPECT_TRUE(test::all_near(y, e, test::Tolerance{0, 1e-15}));
  VectorXd one = VectorXd::Constant(1, 5.0);
  detrend_in_place(one, Detrend::kLinear);
  EXPECT_EQ(one(0), 0.0);
}

}  // namespace
}  // namespace piezobench::dsp
