#include "piezobench/lti/discretize.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "piezobench/core/error.hpp"
#include "piezobench/lti/conversions.hpp"
#include "piezobench/lti/freqresp.hpp"
#include "piezobench/core/units.hpp"
#include "test_util.hpp"

namespace piezobench::lti {
namespace {

using test::all_near;
using test::kRoundoff;
using test::near;
using test::Tolerance;

Matrix m1(double v) { return Matrix::Constant(1, 1, v); }

// dx/dt = -a x + b u, y = c x.
StateSpace first_order(double a, double b = 1.0, double c = 1.0) { return StateSpace(m1(-a), m1(b), m1(c), m1(0.0)); }

TEST(ExpmTest, ZeroDiagonalAndEmpty) {
  EXPECT_TRUE(all_near(expm(Matrix::Zero(3, 3)), Matrix::Identity(3, 3), Tolerance{0.0, 0.0}));
  const Vector d = (Vector(3) << -3.0, 0.5, 7.0).finished();
  const Matrix e = expm(Matrix(d.asDiagonal()));
  EXPECT_TRUE(all_near(e, Matrix(d.array().exp().matrix().asDiagonal()), Tolerance{kRoundoff, 1e-15}));
  EXPECT_EQ(expm(Matrix(0, 0)).size(), 0);
}

// Rotations exercise every Pade degree (small angles) and the scaling and squaring (large ones).
class ExpmRotationTest : public ::testing::TestWithParam<double> {};

TEST_P(ExpmRotationTest, GeneratorOfRotation) {
  const double theta = GetParam();
  Matrix a(2, 2);
  a << 0.0, theta, -theta, 0.0;
  Matrix expected(2, 2);
  expected << std::cos(theta), std::sin(theta), -std::sin(theta), std::cos(theta);
  // Squaring s times amplifies round-off by about 2^s ~ |theta|.
  const double tol = kRoundoff * std::max(1.0, std::abs(theta));
  EXPECT_TRUE(all_near(expm(a), expected, Tolerance{0.0, tol}));
}

INSTANTIATE_TEST_SUITE_P(Angles, ExpmRotationTest,
                         ::testing::Values(1e-3, 0.1, 0.9, 2.0, 5.0, 30.0, 1000.0),
                         [](const ::testing::TestParamInfo<double>& param) {
                           return "theta_" + std::to_string(param.index);
                         });

TEST(ExpmTest, NilpotentAndJordanBlock) {
  // N^3 = 0: expm(t N) = I + t N + t^2 N^2 / 2 exactly.
  const double t = 40.0;
  Matrix n = Matrix::Zero(3, 3);
  n(0, 1) = 1.0;
  n(1, 2) = 1.0;
  const Matrix expected = Matrix::Identity(3, 3) + t * n + t * t / 2.0 * n * n;
  EXPECT_TRUE(all_near(expm(t * n), expected, Tolerance{kRoundoff, kRoundoff}));
  // Jordan block [l 1; 0 l]: exp(l) [1 1; 0 1].
  const double l = -2.5;
  Matrix j(2, 2);
  j << l, 1.0, 0.0, l;
  Matrix ej(2, 2);
  ej << std::exp(l), std::exp(l), 0.0, std::exp(l);
  EXPECT_TRUE(all_near(expm(j), ej, Tolerance{kRoundoff, 1e-16}));
}

TEST(ExpmTest, BadInput) {
  EXPECT_THROW((void)expm(Matrix::Zero(2, 3)), InputError);
  Matrix a = Matrix::Zero(2, 2);
  a(0, 1) = std::nan("");
  EXPECT_THROW((void)expm(a), InputError);
}

TEST(C2dTest, ZohFirstOrderMatchesExponential) {
  const double a = 30.0;
  const double b = 2.0;
  const double ts = 1e-2;
  const StateSpace d = c2d(first_order(a, b, 3.0), ts);
  EXPECT_EQ(d.sample_time, ts);
  EXPECT_TRUE(near(d.A(0, 0), std::exp(-a * ts), kRoundoff));
  EXPECT_TRUE(near(d.B(0, 0), b * (1.0 - std::exp(-a * ts)) / a, kRoundoff));
  EXPECT_EQ(d.C(0, 0), 3.0);
  EXPECT_EQ(d.D(0, 0), 0.0);
}

TEST(C2dTest, ZohDoubleIntegrator) {
  Matrix a = Matrix::Zero(2, 2);
  a(0, 1) = 1.0;
  Matrix b(2, 1);
  b << 0.0, 1.0;
  const double ts = 0.1;
  const StateSpace d = c2d(StateSpace(a, b, Matrix::Identity(2, 2), Matrix::Zero(2, 1)), ts);
  Matrix ad(2, 2);
  ad << 1.0, ts, 0.0, 1.0;
  Matrix bd(2, 1);
  bd << ts * ts / 2.0, ts;
  EXPECT_TRUE(all_near(d.A, ad, Tolerance{kRoundoff, 1e-16}));
  EXPECT_TRUE(all_near(d.B, bd, Tolerance{kRoundoff, 1e-16}));
}

TEST(C2dTest, TustinFrequencyWarpingAndPrewarp) {
  // H(s) = w0^2 / (s^2 + 2 z w0 s + w0^2), lightly damped.
  const double w0 = 2 * kPi * 95.2;
  const double z = 0.02;
  Matrix a(2, 2);
  a << 0.0, 1.0, -w0 * w0, -2 * z * w0;
  const StateSpace sys(a, (Matrix(2, 1) << 0.0, w0 * w0).finished(), (Matrix(1, 2) << 1.0, 0.0).finished(), m1(0.0));
  const double ts = 1e-3;
  // Without pre-warping: Hd(exp(j w Ts)) = Hc(j (2/Ts) tan(w Ts / 2)).
  DiscretizeOptions opt;
  opt.method = DiscretizationMethod::kTustin;
  const StateSpace d = c2d(sys, ts, opt);
  const Vector w = logspace(0, std::log10(0.9 * kPi / ts), 40);
  const FrequencyResponse hd = freqresp(d, w);
  for (Index k = 0; k < w.size(); ++k) {
    const double warped = 2.0 / ts * std::tan(w(k) * ts / 2.0);
    const CMatrix hc = FrequencyResponseEvaluator(sys).evaluate(Complex(0.0, warped));
    EXPECT_TRUE(near(hd.H[static_cast<size_t>(k)](0, 0), hc(0, 0), Tolerance{1e-11, 0.0})) << w(k);
  }
  // With pre-warping at w0: exact match at w0 (and not without it).
  opt.prewarp_frequency = w0;
  const StateSpace dp = c2d(sys, ts, opt);
  const Complex hc0 = FrequencyResponseEvaluator(sys).evaluate(Complex(0.0, w0))(0, 0);
  const Complex hd0 = FrequencyResponseEvaluator(dp).evaluate(std::polar(1.0, w0 * ts))(0, 0);
  EXPECT_TRUE(near(hd0, hc0, Tolerance{1e-11, 0.0}));
  const Complex hd_plain = FrequencyResponseEvaluator(d).evaluate(std::polar(1.0, w0 * ts))(0, 0);
  EXPECT_FALSE(near(hd_plain, hc0, Tolerance{1e-3, 0.0}));
  // Static gain is preserved by the bilinear map (z = 1 <-> s = 0).
  const Complex dc = FrequencyResponseEvaluator(dp).evaluate(Complex(1.0, 0.0))(0, 0);
  EXPECT_TRUE(near(dc, Complex(1.0, 0.0), Tolerance{kRoundoff, 0.0}));
}

TEST(C2dTest, TustinPoleAtTwoOverTsThrows) {
  const double ts = 0.01;
  DiscretizeOptions opt;
  opt.method = DiscretizationMethod::kTustin;
  EXPECT_THROW((void)c2d(first_order(-2.0 / ts), ts, opt), NumericalError);
}

TEST(C2dTest, TransferFunctionThroughStateSpace) {
  // 1/(s + a): ZOH gives (1 - e)/a / (z - e), e = exp(-a Ts).
  const double a = 5.0;
  const double ts = 0.02;
  const TransferFunction tf(Vector::Ones(1), (Vector(2) << 1.0, a).finished(), 0.0, 0.04);
  const TransferFunction d = c2d(tf, ts);
  EXPECT_EQ(d.sample_time, ts);
  EXPECT_EQ(d.delay, 0.04);
  const double e = std::exp(-a * ts);
  const Vector w = logspace(-1, 2, 20);
  const CVector h = freqresp(d, w);
  for (Index k = 0; k < w.size(); ++k) {
    const Complex z = std::polar(1.0, w(k) * ts);
    const Complex expected = (1.0 - e) / a / (z - e) * std::polar(1.0, -w(k) * 0.04);
    EXPECT_TRUE(near(h(k), expected, Tolerance{1e-10, 0.0})) << w(k);
  }
}

TEST(C2dTest, BadInput) {
  const StateSpace sys = first_order(1.0);
  EXPECT_THROW((void)c2d(sys, 0.0), InputError);
  EXPECT_THROW((void)c2d(sys, -1.0), InputError);
  EXPECT_THROW((void)c2d(sys, std::nan("")), InputError);
  DiscretizeOptions opt;
  opt.method = DiscretizationMethod::kTustin;
  opt.prewarp_frequency = kPi / 0.1;  // at Nyquist
  EXPECT_THROW((void)c2d(sys, 0.1, opt), InputError);
  opt.prewarp_frequency = -1.0;
  EXPECT_THROW((void)c2d(sys, 0.1, opt), InputError);
  const StateSpace d = c2d(sys, 0.1);
  EXPECT_THROW((void)c2d(d, 0.1), InputError);
  try {
    DiscretizeOptions bad;
    bad.prewarp_frequency = 1e9;
    bad.validate(0.1);
    FAIL() << "no exception";
  } catch (const InputError& err) {
    EXPECT_EQ(err.field(), "prewarp_frequency");
  }
}

TEST(DiscretizationMethodTest, StringsRoundTrip) {
  for (auto m : {DiscretizationMethod::kZoh, DiscretizationMethod::kTustin}) {
    EXPECT_EQ(discretization_method_from_string(to_string(m)), m);
  }
  EXPECT_EQ(to_string(DiscretizationMethod::kZoh), "zoh");
  EXPECT_EQ(to_string(DiscretizationMethod::kTustin), "tustin");
  EXPECT_THROW((void)discretization_method_from_string("foh"), InputError);
}

TEST(TimeResponseTest, StepOfDiscreteFirstOrder) {
  // x[k+1] = a x + b u, y = c x + d u: y[k] = d + c b (1 - a^k)/(1 - a).
  const double a = 0.8;
  const double b = 0.5;
  const double c = 2.0;
  const double dd = 0.25;
  const double ts = 0.01;
  const StateSpace sys(m1(a), m1(b), m1(c), m1(dd), ts);
  const TimeResponse r = step(sys, 0.0, 30);
  ASSERT_EQ(r.y.rows(), 30);
  ASSERT_EQ(r.x.rows(), 30);
  for (Index k = 0; k < 30; ++k) {
    EXPECT_TRUE(near(r.t(k), static_cast<double>(k) * ts, kRoundoff));
    const double expected = dd + c * b * (1.0 - std::pow(a, static_cast<double>(k))) / (1.0 - a);
    EXPECT_TRUE(near(r.y(k, 0), expected, kRoundoff)) << k;
  }
  EXPECT_THROW((void)step(sys, 0.02, 5), InputError);  // another sample time
}

TEST(TimeResponseTest, ContinuousStepIsExactAtSamplesAndImpulseHasUnitArea) {
  const double a = 20.0;
  const double ts = 1e-3;
  const StateSpace sys = first_order(a, a);  // a / (s + a), unit DC gain
  const TimeResponse s = step(sys, ts, 200);
  for (Index k = 0; k < 200; ++k) {
    EXPECT_TRUE(near(s.y(k, 0), 1.0 - std::exp(-a * ts * static_cast<double>(k)), Tolerance{kRoundoff, 1e-15}));
  }
  // Impulse: a pulse of height 1/Ts over the first sample: y[k] = (1 - e)/Ts e^(k-1), e = exp(-a Ts).
  const TimeResponse im = impulse(sys, ts, 200);
  const double e = std::exp(-a * ts);
  EXPECT_EQ(im.y(0, 0), 0.0);
  for (Index k = 1; k < 200; ++k) {
    EXPECT_TRUE(near(im.y(k, 0), (1.0 - e) / ts * std::pow(e, static_cast<double>(k - 1)), Tolerance{kRoundoff, 1e-15}));
  }
  // Discrete impulse is the unit sample: y[k] = c a^(k-1) b.
  const StateSpace dsys(m1(0.5), m1(1.0), m1(3.0), m1(0.0), 0.1);
  const TimeResponse di = impulse(dsys, 0.1, 6);
  for (Index k = 1; k < 6; ++k) EXPECT_TRUE(near(di.y(k, 0), 3.0 * std::pow(0.5, static_cast<double>(k - 1)), kRoundoff));
}

TEST(TimeResponseTest, LsimDelaysInitialStateAndBadInput) {
  const double ts = 0.1;
  StateSpace sys(m1(0.5), m1(1.0), m1(1.0), m1(1.0), ts);
  sys.input_delay = Vector::Constant(1, 2 * ts);
  sys.output_delay = Vector::Constant(1, ts);
  Matrix u = Matrix::Zero(8, 1);
  u(0, 0) = 1.0;
  const TimeResponse r = lsim(sys, u);
  // Undelayed impulse response 1, 1, 0.5, 0.25, ... shifted by 3 samples.
  const Vector expected = (Vector(8) << 0, 0, 0, 1.0, 1.0, 0.5, 0.25, 0.125).finished();
  EXPECT_TRUE(all_near(r.y.col(0), expected, Tolerance{kRoundoff, 0.0}));
  // Free response from x0.
  StateSpace plain(m1(0.5), m1(1.0), m1(1.0), m1(0.0), ts);
  const TimeResponse f = lsim(plain, Matrix::Zero(4, 1), Vector::Constant(1, 8.0));
  EXPECT_TRUE(all_near(f.y.col(0), (Vector(4) << 8.0, 4.0, 2.0, 1.0).finished(), Tolerance{kRoundoff, 0.0}));
  EXPECT_TRUE(all_near(f.x.col(0), (Vector(4) << 8.0, 4.0, 2.0, 1.0).finished(), Tolerance{kRoundoff, 0.0}));

  EXPECT_THROW((void)lsim(first_order(1.0), u), InputError);         // continuous
  EXPECT_THROW((void)lsim(plain, Matrix::Zero(4, 2)), InputError);   // columns
  EXPECT_THROW((void)lsim(plain, u, Vector::Zero(2)), InputError);   // x0 size
  Matrix bad = u;
  bad(2, 0) = std::nan("");
  EXPECT_THROW((void)lsim(plain, bad), InputError);
  StateSpace odd = plain;
  odd.input_delay = Vector::Constant(1, 0.15);
  EXPECT_THROW((void)lsim(odd, u), InputError);  // not a whole number of samples
  EXPECT_THROW((void)step(plain, 0.0, 5, 1), InputError);  // no input 1
  EXPECT_THROW((void)step(plain, 0.0, -1), InputError);
}

}  // namespace
}  // namespace piezobench::lti
