// Tests for src/lti/conversions.cpp: roots, poly, tf <-> zpk <-> ss.
#include "piezobench/lti/conversions.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/lti/analysis.hpp"
#include "piezobench/core/units.hpp"
#include "lti/lti_test_util.hpp"
#include "test_util.hpp"

namespace piezobench::lti {
namespace {

using test::all_near;
using test::kLightlyDamped;
using test::kRoundoff;
using test::near;
using test::Tolerance;


using test::cvec;
using test::pair;

CVector concat(const CVector& a, const CVector& b) { return test::concat({a, b}); }

// H(s) = D + C (sI - A)^-1 B of a SISO system, by a dense solve (independent of the library).
Complex evaluate(const StateSpace& sys, Complex s) {
  const CMatrix m = s * CMatrix::Identity(sys.states(), sys.states()) - sys.A.cast<Complex>();
  const CMatrix x = m.partialPivLu().solve(sys.B.cast<Complex>());
  return sys.D(0, 0) + (sys.C.cast<Complex>() * x)(0, 0);
}

Complex evaluate(const Zpk& z, Complex s) {
  Complex h = z.gain;
  for (Index i = 0; i < z.zeros.size(); ++i) h *= s - z.zeros(i);
  for (Index i = 0; i < z.poles.size(); ++i) h /= s - z.poles(i);
  return h;
}

// Coefficients normalized so that den(0) = 1 (a transfer function is defined up to a factor).
struct Normalized {
  Vector num, den;
};
Normalized normalized(const TransferFunction& tf) {
  Vector num = Vector::Zero(tf.den.size());
  num.tail(tf.num.size()) = tf.num;  // pad as tfdata does
  return {num / tf.den(0), tf.den / tf.den(0)};
}

// The IFF plant of the report, eq. (2.3).
TransferFunction iff_plant() {
  const double wz = 2 * kPi * 42.7, xz = 0.004, wp = 2 * kPi * 95.2, xp = 0.02, wh = 2 * kPi * 0.4, g0 = 0.64;
  const Vector num = g0 * Vector{{1.0 / (wz * wz), 2.0 * xz / wz, 1.0, 0.0}};
  Vector den(4);
  den << 1.0 / (wp * wp), 2.0 * xp / wp + wh / (wp * wp), 1.0 + 2.0 * xp * wh / wp, wh;
  return TransferFunction(num, den);
}

// ---------------------------------------------------------------- roots / poly

TEST(Roots, CubicAndComplexPair) {
  // (s + 1)(s + 2)(s + 3)
  EXPECT_TRUE(all_near(roots(Vector{{1.0, 6.0, 11.0, 6.0}}), cvec({-1.0, -2.0, -3.0}), Tolerance{kRoundoff, 0.0}));
  // 2 (s^2 + 2 s + 5): -1 -+ 2j, negative imaginary part first
  EXPECT_TRUE(all_near(roots(Vector{{2.0, 4.0, 10.0}}), cvec({{-1.0, -2.0}, {-1.0, 2.0}}), Tolerance{kRoundoff, 0.0}));
}

TEST(Roots, LeadingAndTrailingZeros) {
  // 0 s^4 + s^3 - 3 s^2 + 2 s + 0 = s (s - 1)(s - 2); the root at 0 is exact.
  const CVector r = roots(Vector{{0.0, 1.0, -3.0, 2.0, 0.0}});
  ASSERT_EQ(r.size(), 3);
  EXPECT_EQ(r(0), Complex(0.0, 0.0));
  EXPECT_TRUE(all_near(r.tail(2), cvec({1.0, 2.0}), Tolerance{kRoundoff, 0.0}));
  EXPECT_EQ(roots(Vector{{0.0, 5.0}}).size(), 0);
  EXPECT_EQ(roots(Vector()).size(), 0);
  EXPECT_TRUE(all_near(roots(Vector{{4.0, 2.0}}), cvec({-0.5}), Tolerance{0.0, 0.0}));
}

TEST(Roots, WideSpreadOfMagnitudes) {
  // (s + 1e-3)(s + 1)(s + 1e3)(s + 1e6): balancing keeps every root to high relative accuracy.
  const CVector expected = cvec({-1e-3, -1.0, -1e3, -1e6});
  EXPECT_TRUE(all_near(roots(poly(expected)), expected, Tolerance{1e-9, 0.0}));
}

TEST(Roots, NonFiniteCoefficientIsInputError) {
  try {
    roots(Vector{{1.0, std::nan(""), 2.0}});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "coefficients(1)");
  }
}

TEST(Poly, FromRealAndComplexRoots) {
  // (s + 1)(s^2 + 2 s + 5) = s^3 + 3 s^2 + 7 s + 5
  EXPECT_TRUE(all_near(poly(cvec({{-1.0, 2.0}, -1.0, {-1.0, -2.0}})), Vector{{1.0, 3.0, 7.0, 5.0}},
                       Tolerance{kRoundoff, 0.0}));
  EXPECT_TRUE(all_near(poly(CVector()), Vector{{1.0}}, Tolerance{0.0, 0.0}));
}

TEST(Poly, UnpairedComplexRootIsInputError) {
  try {
    poly(cvec({{-1.0, 2.0}, -3.0}));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "roots(0)");
    EXPECT_NE(std::string(e.what()).find("conjugate"), std::string::npos);
  }
}

// ---------------------------------------------------------------- tf <-> zpk

TEST(TfZpk, KnownFactorization) {
  // (2 s + 4) / (s^2 + 3 s + 2) = 2 (s + 2) / ((s + 1)(s + 2))
  const Zpk z = to_zpk(TransferFunction(Vector{{0.0, 2.0, 4.0}}, Vector{{1.0, 3.0, 2.0}}, 0.0, 0.01));
  EXPECT_TRUE(all_near(z.zeros, cvec({-2.0}), Tolerance{kRoundoff, 0.0}));
  EXPECT_TRUE(all_near(z.poles, cvec({-1.0, -2.0}), Tolerance{kRoundoff, 0.0}));
  EXPECT_TRUE(near(z.gain, 2.0, kRoundoff));
  EXPECT_EQ(z.delay, 0.01);
  const TransferFunction back = to_transfer_function(z);
  EXPECT_TRUE(all_near(back.num, Vector{{0.0, 2.0, 4.0}}, Tolerance{kRoundoff, 1e-15}));
  EXPECT_TRUE(all_near(back.den, Vector{{1.0, 3.0, 2.0}}, Tolerance{kRoundoff, 0.0}));
  EXPECT_EQ(back.delay, 0.01);
}

TEST(TfZpk, ZeroNumeratorHasZeroGainAndNoZeros) {
  const Zpk z = to_zpk(TransferFunction(Vector{{0.0, 0.0}}, Vector{{1.0, 1.0}}));
  EXPECT_EQ(z.gain, 0.0);
  EXPECT_EQ(z.zeros.size(), 0);
  EXPECT_EQ(z.poles.size(), 1);
  const TransferFunction tf = to_transfer_function(z);
  EXPECT_TRUE(all_near(tf.num, Vector::Zero(2), Tolerance{0.0, 0.0}));
}

// ---------------------------------------------------------------- tf/zpk -> ss -> tf/zpk

TEST(RoundTrip, TfSsTfIffPlant) {
  const TransferFunction tf = iff_plant();
  const TransferFunction back = to_transfer_function(to_state_space(tf));
  const Normalized e = normalized(tf);
  const Normalized a = normalized(back);
  // The trailing numerator coefficient is 0 exactly (zero at s = 0); compare it absolutely, at the
  // round-off of the largest numerator coefficient.
  EXPECT_TRUE(all_near(a.num, e.num, Tolerance{kLightlyDamped, 1e-12 * e.num.cwiseAbs().maxCoeff()}));
  EXPECT_TRUE(all_near(a.den, e.den, Tolerance{kLightlyDamped, 0.0}));
}

TEST(RoundTrip, TfSsTfMassSpringAndDiscrete) {
  // 1 / (m s^2 + c s + k), m = 0.5 kg, c = 3 Ns/m, k = 2e6 N/m (0.15 % damping)
  const TransferFunction msd(Vector{{1.0}}, Vector{{0.5, 3.0, 2e6}});
  const Normalized e = normalized(msd);
  const Normalized a = normalized(to_transfer_function(to_state_space(msd)));
  EXPECT_TRUE(all_near(a.num, e.num, Tolerance{kLightlyDamped, 0.0}));
  EXPECT_TRUE(all_near(a.den, e.den, Tolerance{kLightlyDamped, 0.0}));
  // Discrete: (z - 0.5)(z + 0.2) / ((z - 0.9)(z^2 - 1.2 z + 0.85)), Ts = 1e-4 s, delay 3 samples.
  const TransferFunction d(poly(cvec({0.5, -0.2})) * 3.0, poly(cvec({0.9, {0.6, 0.7}, {0.6, -0.7}})), 1e-4, 3e-4);
  const StateSpace ds = to_state_space(d);
  EXPECT_EQ(ds.sample_time, 1e-4);
  EXPECT_EQ(ds.channel_delay(0, 0), 3e-4);
  const TransferFunction db = to_transfer_function(ds);
  EXPECT_EQ(db.sample_time, 1e-4);
  EXPECT_EQ(db.delay, 3e-4);
  const Normalized ed = normalized(d);
  const Normalized ad = normalized(db);
  EXPECT_TRUE(all_near(ad.num, ed.num, Tolerance{kLightlyDamped, 1e-15}));
  EXPECT_TRUE(all_near(ad.den, ed.den, Tolerance{kLightlyDamped, 0.0}));
}

TEST(RoundTrip, ZpkSsZpkLightlyDampedHighOrder) {
  // Ten lightly damped modes (0.1 %) and nine anti-resonances between them: a companion form of the
  // degree-20 denominator would lose these poles entirely; the cascade keeps every one.
  CVector p(0), z(0);
  for (int k = 0; k < 10; ++k) {
    p = concat(p, pair(2 * kPi * 50.0 * std::pow(1.6, k), 0.001));
    if (k < 9) z = concat(z, pair(2 * kPi * 50.0 * std::pow(1.6, k) * 1.25, 0.001));
  }
  const Zpk zpk(z, p, 3e4);
  const StateSpace sys = to_state_space(zpk);
  EXPECT_EQ(sys.states(), 20);
  const Zpk back = to_zpk(sys);
  EXPECT_TRUE(all_near(back.poles, poles(sys), Tolerance{0.0, 0.0}));
  CVector ps = p, zs = z;
  std::sort(ps.data(), ps.data() + ps.size(), [](Complex a, Complex b) {
    return std::abs(a) != std::abs(b) ? std::abs(a) < std::abs(b) : a.imag() < b.imag();
  });
  std::sort(zs.data(), zs.data() + zs.size(), [](Complex a, Complex b) {
    return std::abs(a) != std::abs(b) ? std::abs(a) < std::abs(b) : a.imag() < b.imag();
  });
  EXPECT_TRUE(all_near(back.poles, ps, Tolerance{kLightlyDamped, 0.0}));
  EXPECT_TRUE(all_near(back.zeros, zs, Tolerance{kLightlyDamped, 0.0}));
  EXPECT_TRUE(near(back.gain, 3e4, kLightlyDamped));
  // The realization reproduces H at every resonance and anti-resonance peak.
  for (Index i = 0; i < p.size(); ++i) {
    const Complex s(0.0, std::abs(p(i)));
    EXPECT_TRUE(near(evaluate(sys, s), evaluate(zpk, s), Tolerance{kLightlyDamped, 0.0})) << "pole " << i;
  }
}

TEST(RoundTrip, MoreComplexZeroPairsThanComplexPolePairs) {
  // Two zero pairs over four real poles and one pole pair: real poles are merged into a
  // second-order section to carry the second zero pair.
  const CVector z = concat(pair(5.0, 0.01), pair(40.0, 0.2));
  const CVector p = concat(cvec({-1.0, -3.0, -30.0, -100.0}), pair(20.0, 0.05));
  const Zpk zpk(z, p, 7.0);
  const StateSpace sys = to_state_space(zpk);
  for (const double w : {0.3, 5.0, 20.0, 77.0, 1e3}) {
    const Complex s(0.0, w);
    EXPECT_TRUE(near(evaluate(sys, s), evaluate(zpk, s), Tolerance{kLightlyDamped, 0.0})) << "w " << w;
  }
  EXPECT_TRUE(near(to_zpk(sys).gain, 7.0, kLightlyDamped));
}

TEST(RoundTrip, RealZerosAndBiproper) {
  // (s - 2)(s + 0.5)(s + 300) / ((s + 1)(s + 10)(s^2 + 2 s + 400)) and a biproper first order.
  const Zpk zpk(cvec({2.0, -0.5, -300.0}), concat(cvec({-1.0, -10.0}), pair(20.0, 0.05)), -4.0);
  const StateSpace sys = to_state_space(zpk);
  for (const double w : {0.0, 0.7, 20.0, 5e3}) {
    const Complex s(0.0, w);
    EXPECT_TRUE(near(evaluate(sys, s), evaluate(zpk, s), Tolerance{kRoundoff * 100, 0.0})) << "w " << w;
  }
  const Zpk first(cvec({-3.0}), cvec({-1.0}), 2.0);
  const StateSpace fs = to_state_space(first);
  EXPECT_TRUE(near(fs.D(0, 0), 2.0, kRoundoff));
  EXPECT_TRUE(near(evaluate(fs, Complex(0.0, 0.0)), Complex(6.0, 0.0), Tolerance{kRoundoff, 0.0}));
}

TEST(ToStateSpace, StaticGain) {
  const StateSpace g = to_state_space(Zpk(CVector(), CVector(), -2.5));
  EXPECT_EQ(g.states(), 0);
  EXPECT_EQ(g.D(0, 0), -2.5);
  const StateSpace t = to_state_space(TransferFunction(Vector{{3.0}}, Vector{{2.0}}));
  EXPECT_EQ(t.D(0, 0), 1.5);
}

// ---------------------------------------------------------------- ss -> zpk

TEST(SsZpk, MassSpringDamperFromPhysicalModel) {
  // m x'' + c x' + k x = F, output x: no zeros, gain 1/m.
  const double m = 0.5, c = 3.0, k = 2e6;
  Matrix a(2, 2), b(2, 1), cc(1, 2);
  a << 0.0, 1.0, -k / m, -c / m;
  b << 0.0, 1.0 / m;
  cc << 1.0, 0.0;
  const Zpk z = to_zpk(StateSpace(a, b, cc, Matrix::Zero(1, 1)));
  EXPECT_EQ(z.zeros.size(), 0);
  EXPECT_TRUE(near(z.gain, 1.0 / m, kRoundoff));
  EXPECT_TRUE(all_near(z.poles, roots(Vector{{m, c, k}}), Tolerance{kRoundoff, 0.0}));
  // Velocity output: a zero at the origin, same gain.
  cc << 0.0, 1.0;
  const Zpk zv = to_zpk(StateSpace(a, b, cc, Matrix::Zero(1, 1)));
  ASSERT_EQ(zv.zeros.size(), 1);
  EXPECT_LE(std::abs(zv.zeros(0)), 1e-12 * std::sqrt(k / m));
  EXPECT_TRUE(near(zv.gain, 1.0 / m, kRoundoff));
}

TEST(SsZpk, MimoChannelsDelaysAndZeroChannel) {
  // [1/(s+1), 0; 2(s+3)/(s+1), 0] with input delays [0.1, 0.2] and output delays [0, 0.05].
  Matrix a(1, 1), b(1, 2), c(2, 1), d = Matrix::Zero(2, 2);
  a << -1.0;
  b << 1.0, 0.0;
  c << 1.0, 4.0;
  d(1, 0) = 2.0;
  StateSpace sys(a, b, c, d);
  sys.input_delay = Vector{{0.1, 0.2}};
  sys.output_delay = Vector{{0.0, 0.05}};
  const Zpk z00 = to_zpk(sys, 0, 0);
  EXPECT_EQ(z00.zeros.size(), 0);
  EXPECT_TRUE(near(z00.gain, 1.0, kRoundoff));
  EXPECT_EQ(z00.delay, 0.1);
  const Zpk z10 = to_zpk(sys, 1, 0);
  EXPECT_TRUE(all_near(z10.zeros, cvec({-3.0}), Tolerance{kRoundoff, 0.0}));
  EXPECT_TRUE(near(z10.gain, 2.0, kRoundoff));
  EXPECT_TRUE(near(z10.delay, 0.15, kRoundoff));
  const Zpk z01 = to_zpk(sys, 0, 1);  // identically zero
  EXPECT_EQ(z01.gain, 0.0);
  EXPECT_EQ(z01.zeros.size(), 0);
  const TransferFunction t10 = to_transfer_function(sys, 1, 0);
  EXPECT_TRUE(all_near(t10.num, Vector{{2.0, 6.0}}, Tolerance{kRoundoff, 0.0}));
  EXPECT_TRUE(all_near(t10.den, Vector{{1.0, 1.0}}, Tolerance{kRoundoff, 0.0}));
  EXPECT_THROW(to_zpk(sys, 2, 0), InputError);
  EXPECT_THROW(to_zpk(sys, 0, -1), InputError);
}

TEST(SsZpk, GainOfDiscreteSystem) {
  const Zpk zpk(cvec({0.5, -0.9}), cvec({0.95, {0.7, 0.2}, {0.7, -0.2}}), 0.02, 1e-3);
  const Zpk back = to_zpk(to_state_space(zpk));
  EXPECT_TRUE(near(back.gain, 0.02, kLightlyDamped));
  EXPECT_EQ(back.sample_time, 1e-3);
}

}  // namespace
}  // namespace piezobench::lti
