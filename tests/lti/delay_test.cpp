#include "piezobench/lti/delay.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "piezobench/core/error.hpp"
#include "piezobench/lti/freqresp.hpp"
#include "test_util.hpp"

namespace piezobench::lti {
namespace {

using test::all_near;
using test::kRoundoff;
using test::near;
using test::Tolerance;

// Polynomial in descending powers at s (Horner).
Complex polyval(const Vector& p, Complex s) {
  Complex acc(0.0, 0.0);
  for (Index i = 0; i < p.size(); ++i) acc = acc * s + p(i);
  return acc;
}

Complex tf_at(const TransferFunction& tf, Complex s) { return polyval(tf.num, s) / polyval(tf.den, s); }

TEST(PadeTest, MatlabValuesForFirstAndSecondOrder) {
  // MATLAB: [n, d] = pade(0.1, 1) -> n = [-1 20], d = [1 20]; pade(0.1, 2) -> [1 -60 1200] / [1 60 1200].
  const TransferFunction p1 = pade(0.1, 1);
  EXPECT_TRUE(all_near(p1.num, (Vector(2) << -1.0, 20.0).finished(), Tolerance{kRoundoff, 0.0}));
  EXPECT_TRUE(all_near(p1.den, (Vector(2) << 1.0, 20.0).finished(), Tolerance{kRoundoff, 0.0}));
  const TransferFunction p2 = pade(0.1, 2);
  EXPECT_TRUE(all_near(p2.num, (Vector(3) << 1.0, -60.0, 1200.0).finished(), Tolerance{kRoundoff, 0.0}));
  EXPECT_TRUE(all_near(p2.den, (Vector(3) << 1.0, 60.0, 1200.0).finished(), Tolerance{kRoundoff, 0.0}));
  // Order 0 and zero delay: the constant 1.
  for (const TransferFunction& one : {pade(0.5, 0), pade(0.0, 3)}) {
    ASSERT_EQ(one.num.size(), 1);
    EXPECT_EQ(one.num(0), 1.0);
    EXPECT_EQ(one.den(0), 1.0);
  }
}

// The defining property of the [N/N] approximant: den(s) exp(-s T) - num(s) = O(s^(2N+1)), i.e. the
// Taylor coefficients of den(s) exp(-sT) up to s^(2N) are those of num (zero above s^N).
class PadeOrderTest : public ::testing::TestWithParam<int> {};

TEST_P(PadeOrderTest, TaylorMatchAllPassAndPhase) {
  const int n = GetParam();
  const double tau = 1.0;
  const TransferFunction p = pade(tau, n);
  ASSERT_EQ(p.num.size(), n + 1);
  ASSERT_EQ(p.den.size(), n + 1);
  EXPECT_EQ(p.den(0), 1.0);  // monic, as MATLAB
  // Ascending coefficients.
  std::vector<long double> num(n + 1);
  std::vector<long double> den(n + 1);
  for (int k = 0; k <= n; ++k) {
    num[static_cast<size_t>(k)] = p.num(n - k);
    den[static_cast<size_t>(k)] = p.den(n - k);
  }
  long double scale = 0.0L;
  for (long double v : den) scale = std::max(scale, std::abs(v));
  for (int k = 0; k <= 2 * n; ++k) {
    // coefficient of s^k in den(s) * sum_j (-tau s)^j / j!
    long double c = 0.0L;
    for (int i = 0; i <= std::min(k, n); ++i) {
      long double term = den[static_cast<size_t>(i)];
      for (int j = 1; j <= k - i; ++j) term *= -static_cast<long double>(tau) / j;
      c += term;
    }
    const long double expected = k <= n ? num[static_cast<size_t>(k)] : 0.0L;
    EXPECT_LE(std::abs(static_cast<double>(c - expected)), 1e-13 * static_cast<double>(scale)) << "s^" << k;
  }
  // All-pass with unit DC gain, and exp(-j w T) at low frequency.
  const double t = 2e-4;
  const TransferFunction q = pade(t, n);
  EXPECT_TRUE(near(tf_at(q, 0.0), Complex(1.0, 0.0), Tolerance{kRoundoff, 0.0}));
  for (double w : {1.0, 100.0, 1e3, 1e4, 1e5, 1e7}) {
    EXPECT_TRUE(near(std::abs(tf_at(q, Complex(0.0, w))), 1.0, 1e-12)) << w;
  }
  // Error of the [N/N] approximant ~ (N!)^2 / ((2N)! (2N+1)!) (w T)^(2N+1).
  for (double x : {0.01, 0.1, 0.5}) {
    const double w = x / t;
    double bound = std::pow(x, 2 * n + 1);
    for (int k = 1; k <= n; ++k) bound *= static_cast<double>(k) * k;
    for (int k = 1; k <= 2 * n; ++k) bound /= k;
    for (int k = 1; k <= 2 * n + 1; ++k) bound /= k;
    EXPECT_LE(std::abs(tf_at(q, Complex(0.0, w)) - std::polar(1.0, -x)), 2.0 * bound + 1e-13) << "w T = " << x;
  }
}

INSTANTIATE_TEST_SUITE_P(Orders, PadeOrderTest, ::testing::Values(1, 2, 3, 4, 6, 8),
                         [](const ::testing::TestParamInfo<int>& param) {
                           return "order_" + std::to_string(param.param);
                         });

TEST(PadeTest, StateSpaceDelaysBecomeApproximantsInSeries) {
  // 2 inputs, 2 outputs with different input and output delays.
  Matrix a(2, 2);
  a << -1.0, 30.0, -30.0, -1.0;
  Matrix b(2, 2);
  b << 1.0, 0.0, 0.5, 2.0;
  Matrix c(2, 2);
  c << 1.0, 0.0, 0.3, 1.0;
  Matrix d(2, 2);
  d << 0.0, 0.1, 0.2, 0.0;
  StateSpace sys(a, b, c, d);
  sys.input_delay = (Vector(2) << 2e-3, 0.0).finished();
  sys.output_delay = (Vector(2) << 0.0, 5e-3).finished();
  const int order = 3;
  const StateSpace approx = pade(sys, order);
  EXPECT_FALSE(approx.has_delay());
  EXPECT_EQ(approx.states(), 2 + 2 * order);  // one approximant per nonzero delay
  StateSpace undelayed = sys;
  undelayed.input_delay.resize(0);
  undelayed.output_delay.resize(0);
  const FrequencyResponseEvaluator plain(undelayed);
  const FrequencyResponseEvaluator eval(approx);
  const TransferFunction p_in = pade(2e-3, order);
  const TransferFunction p_out = pade(5e-3, order);
  for (double w : {0.1, 10.0, 30.0, 300.0, 3000.0}) {
    const Complex s(0.0, w);
    const CMatrix h0 = plain.evaluate(s);
    const CMatrix h = eval.evaluate(s);
    const Complex fi[2] = {tf_at(p_in, s), 1.0};
    const Complex fo[2] = {1.0, tf_at(p_out, s)};
    for (Index i = 0; i < 2; ++i) {
      for (Index j = 0; j < 2; ++j) {
        EXPECT_TRUE(near(h(i, j), fo[i] * h0(i, j) * fi[j], Tolerance{1e-11, 1e-14})) << w << " " << i << j;
      }
    }
  }
  // Order 0 simply drops the delays; a system without delays is returned as it is.
  EXPECT_EQ(pade(sys, 0).states(), 2);
  EXPECT_FALSE(pade(sys, 0).has_delay());
  EXPECT_EQ(pade(undelayed, 4).A, undelayed.A);
}

TEST(PadeTest, DiscreteDelaysAreExactUnitDelays) {
  const double ts = 1e-3;
  StateSpace sys(Matrix::Constant(1, 1, 0.9), Matrix::Ones(1, 1), Matrix::Ones(1, 1), Matrix::Constant(1, 1, 0.5), ts);
  sys.input_delay = Vector::Constant(1, 3 * ts);
  sys.output_delay = Vector::Constant(1, 2 * ts);
  const StateSpace approx = pade(sys, 7);  // order ignored
  EXPECT_EQ(approx.states(), 1 + 3 + 2);
  EXPECT_FALSE(approx.has_delay());
  const Vector w = logspace(0, 3, 30);
  const FrequencyResponse exact = freqresp(sys, w);
  const FrequencyResponse unit = freqresp(approx, w);
  for (Index k = 0; k < w.size(); ++k) {
    EXPECT_TRUE(near(unit.H[static_cast<size_t>(k)](0, 0), exact.H[static_cast<size_t>(k)](0, 0), Tolerance{1e-12, 0.0}));
  }
  StateSpace odd = sys;
  odd.input_delay = Vector::Constant(1, 1.5 * ts);
  EXPECT_THROW((void)pade(odd, 2), InputError);
}

TEST(PadeTest, BadInput) {
  EXPECT_THROW((void)pade(-1.0, 2), InputError);
  EXPECT_THROW((void)pade(std::nan(""), 2), InputError);
  EXPECT_THROW((void)pade(1.0, -1), InputError);
  StateSpace sys(Matrix::Constant(1, 1, -1.0), Matrix::Ones(1, 1), Matrix::Ones(1, 1), Matrix::Zero(1, 1));
  sys.input_delay = Vector::Constant(1, 0.1);
  EXPECT_THROW((void)pade(sys, -2), InputError);
}

}  // namespace
}  // namespace piezobench::lti
