// Tests for src/lti/interconnect.cpp: series, parallel, scale, append, select, feedback.
#include "piezobench/lti/interconnect.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/lti/analysis.hpp"
#include "piezobench/lti/conversions.hpp"
#include "test_util.hpp"

namespace piezobench::lti {
namespace {

using test::all_near;
using test::kLightlyDamped;
using test::kRoundoff;
using test::near;
using test::Tolerance;

// H(s) = D + C (sI - A)^-1 B by a dense solve (independent of the library).
CMatrix evaluate_matrix(const StateSpace& sys, Complex s) {
  const CMatrix m = s * CMatrix::Identity(sys.states(), sys.states()) - sys.A.cast<Complex>();
  return sys.D.cast<Complex>() + sys.C.cast<Complex>() * m.partialPivLu().solve(sys.B.cast<Complex>());
}

StateSpace tf(std::initializer_list<double> num, std::initializer_list<double> den) {
  Vector n(static_cast<Index>(num.size())), d(static_cast<Index>(den.size()));
  Index k = 0;
  for (const double x : num) n(k++) = x;
  k = 0;
  for (const double x : den) d(k++) = x;
  return to_state_space(TransferFunction(n, d));
}

// A 2-input, 3-output system with feedthrough, from fixed numbers.
StateSpace mimo_plant() {
  Matrix a(3, 3), b(3, 2), c(3, 3), d(3, 2);
  a << -1.0, 2.0, 0.0, -2.0, -1.0, 0.5, 0.0, 0.3, -4.0;
  b << 1.0, 0.0, 0.5, 1.0, 0.0, 2.0;
  c << 1.0, 0.0, 1.0, 0.0, 1.0, -1.0, 0.2, 0.4, 0.0;
  d << 0.0, 0.1, 0.3, 0.0, 0.0, 0.0;
  return StateSpace(a, b, c, d);
}

const Complex kPoints[] = {{0.0, 0.3}, {0.0, 2.0}, {-0.5, 7.0}, {1.0, 40.0}};

TEST(Series, ProductOfTransferFunctions) {
  const StateSpace g1 = tf({1.0}, {1.0, 1.0});
  const StateSpace g2 = tf({2.0, 1.0}, {1.0, 3.0});
  const StateSpace s = series(g1, g2);
  for (const Complex p : kPoints) {
    EXPECT_TRUE(near(evaluate_matrix(s, p)(0, 0), evaluate_matrix(g2, p)(0, 0) * evaluate_matrix(g1, p)(0, 0), Tolerance{kRoundoff, 0.0}));
  }
}

TEST(Series, MimoOrderIsSecondTimesFirst) {
  const StateSpace g = mimo_plant();  // 3x2
  Matrix a(1, 1), b(1, 3), c(2, 1), d(2, 3);
  a << -5.0;
  b << 1.0, -1.0, 2.0;
  c << 1.0, 3.0;
  d << 0.5, 0.0, 1.0, 0.0, 0.2, 0.0;
  const StateSpace k(a, b, c, d);  // 2x3
  const StateSpace s = series(g, k);
  ASSERT_EQ(s.inputs(), 2);
  ASSERT_EQ(s.outputs(), 2);
  for (const Complex p : kPoints) {
    EXPECT_TRUE(all_near(evaluate_matrix(s, p), evaluate_matrix(k, p) * evaluate_matrix(g, p), Tolerance{kRoundoff, 1e-14}));
  }
  EXPECT_THROW(series(g, g), InputError);  // 3 outputs into 2 inputs
}

TEST(Series, SisoDelaysAdd) {
  StateSpace g1 = tf({1.0}, {1.0, 1.0});
  StateSpace g2 = tf({1.0}, {1.0, 2.0});
  g1.input_delay = Vector::Constant(1, 0.01);
  g1.output_delay = Vector::Constant(1, 0.002);
  g2.input_delay = Vector::Constant(1, 0.0003);
  EXPECT_TRUE(near(series(g1, g2).channel_delay(0, 0), 0.0123, kRoundoff));
}

TEST(Series, MimoInternalDelayIsInputErrorButOuterDelaysStay) {
  StateSpace g = mimo_plant();
  StateSpace k = StateSpace::gain(Matrix::Ones(1, 3));
  g.output_delay = Vector{{0.0, 0.1, 0.0}};
  try {
    series(g, k);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pade"), std::string::npos);
  }
  g.output_delay.resize(0);
  g.input_delay = Vector{{0.1, 0.2}};
  k.output_delay = Vector{{0.05}};
  const StateSpace s = series(g, k);
  EXPECT_EQ(s.channel_delay(0, 1), 0.25);
}

TEST(Parallel, SumOfTransferFunctions) {
  // 1/(s+1) + 1/(s+2) = (2 s + 3)/((s+1)(s+2))
  const StateSpace p = parallel(tf({1.0}, {1.0, 1.0}), tf({1.0}, {1.0, 2.0}));
  const Zpk z = to_zpk(p);
  EXPECT_TRUE(all_near(z.zeros, CVector::Constant(1, Complex(-1.5, 0.0)), Tolerance{kRoundoff, 0.0}));
  EXPECT_TRUE(near(z.gain, 2.0, kRoundoff));
  const StateSpace g = mimo_plant();
  const StateSpace gg = parallel(g, scale(g, -3.0));
  for (const Complex s : kPoints) {
    EXPECT_TRUE(all_near(evaluate_matrix(gg, s), -2.0 * evaluate_matrix(g, s), Tolerance{kRoundoff, 1e-14}));
  }
  EXPECT_THROW(parallel(g, tf({1.0}, {1.0, 1.0})), InputError);
}

TEST(Parallel, EqualDelaysFactorOutOthersThrow) {
  StateSpace a = tf({1.0}, {1.0, 1.0});
  StateSpace b = tf({1.0}, {1.0, 2.0});
  a.input_delay = Vector::Constant(1, 0.1);
  b.input_delay = Vector::Constant(1, 0.1);
  EXPECT_EQ(parallel(a, b).channel_delay(0, 0), 0.1);
  b.input_delay(0) = 0.2;
  EXPECT_THROW(parallel(a, b), InputError);
}

TEST(Append, BlockDiagonalWithDelays) {
  StateSpace a = tf({1.0}, {1.0, 1.0});
  a.input_delay = Vector::Constant(1, 0.3);
  const StateSpace g = mimo_plant();
  const StateSpace s = append(a, g);
  ASSERT_EQ(s.inputs(), 3);
  ASSERT_EQ(s.outputs(), 4);
  EXPECT_EQ(s.channel_delay(0, 0), 0.3);
  EXPECT_EQ(s.channel_delay(1, 1), 0.0);
  for (const Complex p : kPoints) {
    const CMatrix h = evaluate_matrix(s, p);
    EXPECT_TRUE(near(h(0, 0), evaluate_matrix(a, p)(0, 0), Tolerance{kRoundoff, 0.0}));
    EXPECT_TRUE(all_near(h.bottomRightCorner(3, 2), evaluate_matrix(g, p), Tolerance{kRoundoff, 1e-14}));
    EXPECT_TRUE(all_near(h.topRightCorner(1, 2), CMatrix::Zero(1, 2), Tolerance{0.0, 0.0}));
    EXPECT_TRUE(all_near(h.bottomLeftCorner(3, 1), CMatrix::Zero(3, 1), Tolerance{0.0, 0.0}));
  }
}

TEST(Select, ReordersChannels) {
  StateSpace g = mimo_plant();
  g.output_delay = Vector{{0.1, 0.2, 0.3}};
  const StateSpace s = select(g, {2, 0}, {1});
  ASSERT_EQ(s.outputs(), 2);
  ASSERT_EQ(s.inputs(), 1);
  EXPECT_EQ(s.channel_delay(0, 0), 0.3);
  for (const Complex p : kPoints) {
    const CMatrix h = evaluate_matrix(g, p);
    const CMatrix hs = evaluate_matrix(s, p);
    EXPECT_TRUE(near(hs(0, 0), h(2, 1), Tolerance{kRoundoff, 0.0}));
    EXPECT_TRUE(near(hs(1, 0), h(0, 1), Tolerance{kRoundoff, 0.0}));
  }
  try {
    select(g, {3}, {0});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "outputs[0]");
  }
}

TEST(Scale, OutputsScaled) {
  const StateSpace g = mimo_plant();
  const StateSpace s = scale(g, 2.5);
  EXPECT_TRUE(all_near(evaluate_matrix(s, kPoints[1]), 2.5 * evaluate_matrix(g, kPoints[1]), Tolerance{kRoundoff, 0.0}));
  EXPECT_THROW(scale(g, std::nan("")), InputError);
}

TEST(Feedback, SisoClosedLoopPolesAreRootsOfCharacteristicPolynomial) {
  // L = 1/(s (s+1)), unity negative feedback: s^2 + s + 1. Positive: s^2 + s - 1.
  const StateSpace g = tf({1.0}, {1.0, 1.0, 0.0});
  const StateSpace one = StateSpace::gain(Matrix::Ones(1, 1));
  EXPECT_TRUE(all_near(poles(feedback(g, one)), roots(Vector{{1.0, 1.0, 1.0}}), Tolerance{kRoundoff, 0.0}));
  EXPECT_TRUE(all_near(poles(feedback(g, one, FeedbackSign::kPositive)), roots(Vector{{1.0, 1.0, -1.0}}),
                       Tolerance{kRoundoff, 0.0}));
  // With a dynamic back path K/(s + 10), K = 30: s (s + 1)(s + 10) + 30.
  const StateSpace k = tf({30.0}, {1.0, 10.0});
  EXPECT_TRUE(all_near(poles(feedback(g, k)), roots(Vector{{1.0, 11.0, 10.0, 30.0}}), Tolerance{1e-12, 0.0}));
  // The closed-loop zeros are the forward zeros and the back-path poles.
  const StateSpace cl = feedback(tf({1.0, 2.0}, {1.0, 1.0, 0.0}), k);
  EXPECT_TRUE(all_near(zeros(cl), Vector{{-2.0, -10.0}}.cast<Complex>(), Tolerance{1e-12, 0.0}));
}

TEST(Feedback, IffLoopOfTheReportMatchesFormula) {
  // Lightly damped plant with feedthrough, controller with feedthrough: y/r = G / (1 + G K).
  const StateSpace g = to_state_space(Zpk(Vector{{0.0}}.cast<Complex>(), Vector{{-2.5}}.cast<Complex>(), 0.64));
  const StateSpace k = tf({-2.0, -1.0}, {1.0, 20.0});
  const StateSpace cl = feedback(g, k);
  for (const Complex s : kPoints) {
    const Complex gs = evaluate_matrix(g, s)(0, 0);
    const Complex ks = evaluate_matrix(k, s)(0, 0);
    EXPECT_TRUE(near(evaluate_matrix(cl, s)(0, 0), gs / (1.0 + gs * ks), Tolerance{kRoundoff, 0.0}));
  }
}

TEST(Feedback, MimoSubsetOfChannels) {
  // u[feedin] += sign * K(y[feedout]):  y = (I - sign G E K F)^-1 G r.
  const StateSpace g = mimo_plant();  // 3 outputs, 2 inputs
  Matrix a(2, 2), b(2, 2), c(1, 2), d(1, 2);
  a << -3.0, 1.0, 0.0, -6.0;
  b << 1.0, 0.0, 0.5, 1.0;
  c << 2.0, -1.0;
  d << 0.4, 0.0;
  const StateSpace k(a, b, c, d);  // takes y[2], y[0]; feeds u[1]
  const std::vector<Index> feedin{1};
  const std::vector<Index> feedout{2, 0};
  Matrix e = Matrix::Zero(2, 1);
  e(1, 0) = 1.0;
  Matrix f = Matrix::Zero(2, 3);
  f(0, 2) = 1.0;
  f(1, 0) = 1.0;
  for (const FeedbackSign sign : {FeedbackSign::kNegative, FeedbackSign::kPositive}) {
    const double sg = sign == FeedbackSign::kNegative ? -1.0 : 1.0;
    const StateSpace cl = feedback(g, k, feedin, feedout, sign);
    ASSERT_EQ(cl.inputs(), 2);
    ASSERT_EQ(cl.outputs(), 3);
    for (const Complex s : kPoints) {
      const CMatrix gs = evaluate_matrix(g, s);
      const CMatrix ks = evaluate_matrix(k, s);
      const CMatrix expected =
          (CMatrix::Identity(3, 3) - sg * gs * e.cast<Complex>() * ks * f.cast<Complex>()).partialPivLu().solve(gs);
      EXPECT_TRUE(all_near(evaluate_matrix(cl, s), expected, Tolerance{1e-12, 1e-14}));
    }
  }
}

TEST(Feedback, BadInputs) {
  const StateSpace g = tf({1.0}, {1.0, 1.0});
  const StateSpace one = StateSpace::gain(Matrix::Ones(1, 1));
  // Algebraic loop with no solution: D_f = 1, D_b = 1, positive feedback.
  EXPECT_THROW(feedback(one, one, FeedbackSign::kPositive), NumericalError);
  StateSpace delayed = g;
  delayed.input_delay = Vector::Constant(1, 1e-3);
  try {
    feedback(delayed, one);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pade"), std::string::npos);
  }
  EXPECT_THROW(feedback(mimo_plant(), one), InputError);  // back must be 2x3
  EXPECT_THROW(feedback(mimo_plant(), one, {0, 0}, {1}), InputError);
  EXPECT_THROW(feedback(mimo_plant(), one, {0}, {3}), InputError);
}

TEST(Interconnect, SampleTimesMustMatchExceptForStaticGains) {
  const StateSpace d1(Matrix::Constant(1, 1, 0.5), Matrix::Ones(1, 1), Matrix::Ones(1, 1), Matrix::Zero(1, 1), 1e-3);
  const StateSpace d2(Matrix::Constant(1, 1, 0.5), Matrix::Ones(1, 1), Matrix::Ones(1, 1), Matrix::Zero(1, 1), 2e-3);
  try {
    series(d1, d2);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "sample_time");
  }
  const StateSpace cl = feedback(d1, StateSpace::gain(Matrix::Constant(1, 1, 0.25)));
  EXPECT_EQ(cl.sample_time, 1e-3);
  // x+ = 0.5 x + u - 0.25 x  ->  pole 0.25
  EXPECT_TRUE(near(poles(cl)(0), Complex(0.25, 0.0), Tolerance{kRoundoff, 0.0}));
  EXPECT_THROW(parallel(d1, tf({1.0}, {1.0, 1.0})), InputError);
}

}  // namespace
}  // namespace piezobench::lti
