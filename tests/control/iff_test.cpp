#include "piezobench/control/iff.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <numbers>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/lti/analysis.hpp"
#include "piezobench/lti/conversions.hpp"
#include "piezobench/lti/freqresp.hpp"
#include "test_util.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::control {
namespace {

using lti::Complex;
using lti::CVector;
using lti::Vector;

Vector conv(const Vector& a, const Vector& b) {
  Vector c = Vector::Zero(a.size() + b.size() - 1);
  for (Eigen::Index i = 0; i < a.size(); ++i) c.segment(i, b.size()) += a(i) * b;
  return c;
}

// Roots of a polynomial (descending powers) computed independently of piezobench: eigenvalues of
// the companion matrix of the polynomial in x = s / w0 (the scaling keeps the coefficients of the
// report's loop within a few decades of each other).
CVector independent_roots(const Vector& p, double w0) {
  const Eigen::Index n = p.size() - 1;
  Vector q(p.size());
  for (Eigen::Index i = 0; i <= n; ++i) q(i) = p(i) * std::pow(w0, static_cast<double>(n - i));
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index j = 0; j < n; ++j) companion(0, j) = -q(j + 1) / q(0);
  for (Eigen::Index i = 1; i < n; ++i) companion(i, i - 1) = 1.0;
  return Eigen::EigenSolver<Eigen::MatrixXd>(companion).eigenvalues() * w0;
}

// [N/N] Pade approximant of exp(-s T): numerator and denominator from the textbook coefficients
// c_k = (2N - k)! N! / ((2N)! k! (N - k)!), numerator sum c_k (-sT)^k, denominator sum c_k (sT)^k.
std::pair<Vector, Vector> pade_polynomials(double delay, int order) {
  Vector num(order + 1), den(order + 1);
  for (int k = 0; k <= order; ++k) {
    const double c = std::tgamma(2 * order - k + 1) * std::tgamma(order + 1) /
                     (std::tgamma(2 * order + 1) * std::tgamma(k + 1) * std::tgamma(order - k + 1));
    num(order - k) = c * std::pow(-delay, k);
    den(order - k) = c * std::pow(delay, k);
  }
  return {num, den};
}

// Characteristic polynomial of the report's loop, 1 - g K0 G = 0, from the formulas of eq. 2.3/2.4,
// with the plant delayed by a Pade approximant when delay > 0.
Vector characteristic_polynomial(double g, double delay = 0.0, int pade_order = 6) {
  const IffPlantParams p;
  const Vector num_g = p.g0 * conv((Vector(3) << 1 / (p.wz * p.wz), 2 * p.xz / p.wz, 1).finished(), (Vector(2) << 1, 0).finished());
  const Vector den_g = conv((Vector(3) << 1 / (p.wp * p.wp), 2 * p.xp / p.wp, 1).finished(), (Vector(2) << 1, p.w_hpf).finished());
  const Vector num_k = (Vector(2) << -10.0, 0.0).finished();
  const Vector den_k = conv(conv((Vector(2) << 1, kTwoPi * 2).finished(), (Vector(2) << 1, kTwoPi * 20).finished()),
                            (Vector(2) << 1, kTwoPi * 2000).finished());
  Vector a = conv(den_g, den_k);
  Vector b = conv(num_g, num_k);
  if (delay > 0.0) {
    const auto [pn, pd] = pade_polynomials(delay, pade_order);
    a = conv(a, pd);
    b = conv(b, pn);
  }
  Vector c = a;
  c.tail(b.size()) -= g * b;
  return c;
}

// Every pole of `actual` has a distinct partner in `expected` within the relative tolerance.
::testing::AssertionResult same_set(CVector actual, CVector expected, double rel) {
  if (actual.size() != expected.size()) return ::testing::AssertionFailure() << "sizes differ";
  std::vector<bool> used(static_cast<std::size_t>(expected.size()), false);
  for (Eigen::Index i = 0; i < actual.size(); ++i) {
    Eigen::Index best = -1;
    for (Eigen::Index j = 0; j < expected.size(); ++j) {
      if (!used[static_cast<std::size_t>(j)] && (best < 0 || std::abs(actual(i) - expected(j)) < std::abs(actual(i) - expected(best)))) best = j;
    }
    used[static_cast<std::size_t>(best)] = true;
    if (!test::within(actual(i), expected(best), {rel, 0.0})) {
      return ::testing::AssertionFailure() << "pole " << actual(i) << " vs " << expected(best);
    }
  }
  return ::testing::AssertionSuccess();
}

TEST(IffController, MatchesEquation24) {
  const lti::Zpk k = iff_controller();
  const Vector w = (Vector(3) << 1.0, 100.0, 1e4).finished();
  const CVector h = lti::freqresp(k, w);
  for (Eigen::Index i = 0; i < w.size(); ++i) {
    const Complex s(0.0, w(i));
    const Complex expected = -10.0 * s / (s + kTwoPi * 2.0) / (s + kTwoPi * 20.0) / (s + kTwoPi * 2000.0);
    EXPECT_TRUE(test::near(h(i), expected, {test::kRoundoff, 0.0}));
  }
}

TEST(IffRootLocus, ClosedLoopPolesMatchTheCharacteristicPolynomial) {
  const std::vector<double> gains = {0.0, 1e3, 1e4, 1e5, 1e6};
  const IffRootLocus r = iff_root_locus(lti::to_state_space(iff_plant()), lti::to_state_space(iff_controller()), gains);
  ASSERT_EQ(r.locus.gains, gains);
  for (std::size_t i = 0; i < gains.size(); ++i) {
    EXPECT_TRUE(same_set(r.locus.poles[i], independent_roots(characteristic_polynomial(gains[i]), kTwoPi * 100), 1e-8))
        << "g = " << gains[i];
  }
  EXPECT_TRUE(test::near(std::abs(r.resonance_pole), kTwoPi * 95.2, 1e-12));
  EXPECT_TRUE(test::near(r.locus.poles[0](r.resonance_branch), r.resonance_pole, {1e-10, 0.0}));
}

struct ScanOptimum {
  double damping;
  double gain;
};

// Independent optimum: follow the branch from the 95.2 Hz pole over 40,000 log-spaced gains by
// nearest-pole continuation on the characteristic polynomial's roots.
ScanOptimum dense_scan(double delay) {
  const CVector open_loop = independent_roots(characteristic_polynomial(0.0, delay), kTwoPi * 100);
  Complex pole = open_loop(0);
  for (const Complex p : open_loop) {
    if (p.imag() > 0 && std::abs(std::abs(p) - kTwoPi * 95.2) < std::abs(std::abs(pole) - kTwoPi * 95.2)) pole = p;
  }
  ScanOptimum best{lti::pole_info(pole).damping, 0.0};
  const int n = 40000;
  for (int i = 0; i <= n; ++i) {
    const double g = std::pow(10.0, 1.0 + 6.0 * i / n);
    const CVector roots = independent_roots(characteristic_polynomial(g, delay), kTwoPi * 100);
    Complex next = roots(0);
    for (const Complex p : roots) {
      if (std::abs(p - pole) < std::abs(next - pole)) next = p;
    }
    pole = next;
    if (lti::pole_info(pole).damping > best.damping) best = {lti::pole_info(pole).damping, g};
  }
  return best;
}

TEST(IffRootLocus, OptimumMatchesADenseScanOfTheResonanceBranch) {
  const ScanOptimum scan = dense_scan(0.0);
  const double best_damping = scan.damping;
  const double best_gain = scan.gain;
  const IffRootLocus r = iff_root_locus(lti::to_state_space(iff_plant()), lti::to_state_space(iff_controller()), {});
  EXPECT_NEAR(best_damping, 0.40, 0.02);  // the report's loop: about 0.40
  EXPECT_TRUE(test::near(r.optimum.damping, best_damping, 1e-4));
  EXPECT_TRUE(test::near(r.optimum.gain, best_gain, 0.01));
  EXPECT_GT(r.locus.gains.size(), 50U);
}

TEST(IffRootLocus, DelayIsApproximatedByPadeAndMatchesADenseScan) {
  IffPlantParams with_delay;
  with_delay.delay = 200e-6;
  const auto controller = lti::to_state_space(iff_controller());
  const IffRootLocus r0 = iff_root_locus(lti::to_state_space(iff_plant()), controller, {1e4});
  const IffRootLocus r1 = iff_root_locus(lti::to_state_space(iff_plant(with_delay)), controller, {1e4});
  EXPECT_EQ(r1.locus.poles[0].size(), r0.locus.poles[0].size() + 6);  // Pade order 6 adds 6 states
  EXPECT_TRUE(same_set(r1.locus.poles[0], independent_roots(characteristic_polynomial(1e4, 200e-6), kTwoPi * 100), 1e-7));
  // The phase lag of 200 us moves the optimum (to about 0.44, as Octave's control package finds
  // with the same Pade approximant): the delayed loop must match its own dense scan.
  const ScanOptimum scan = dense_scan(200e-6);
  EXPECT_TRUE(test::near(r1.optimum.damping, scan.damping, 1e-4));
  EXPECT_TRUE(test::near(r1.optimum.gain, scan.gain, 0.01));
  EXPECT_GT(std::abs(r1.optimum.damping - r0.optimum.damping), 0.01);
}

TEST(IffParams, InvalidValuesNameTheField) {
  try {
    IffControllerParams k;
    k.w_lpf = 0.0;
    iff_controller(k);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "w_lpf");
  }
  IffLoopOptions o;
  o.pade_order = 0;
  EXPECT_THROW(o.validate(), InputError);
}

TEST(IffRootLocus, RejectsNonSisoAndRealOnlyPlants) {
  const auto controller = lti::to_state_space(iff_controller());
  lti::StateSpace mimo(Eigen::MatrixXd::Identity(2, 2) * -1.0, Eigen::MatrixXd::Identity(2, 2), Eigen::MatrixXd::Identity(2, 2),
                       Eigen::MatrixXd::Zero(2, 2));
  EXPECT_THROW(iff_root_locus(mimo, controller, {1.0}), InputError);
  lti::StateSpace first_order((Eigen::MatrixXd(1, 1) << -1.0).finished(), Eigen::MatrixXd::Ones(1, 1), Eigen::MatrixXd::Ones(1, 1),
                              Eigen::MatrixXd::Zero(1, 1));
  EXPECT_THROW(iff_root_locus(first_order, controller, {1.0}), InputError);
  EXPECT_THROW(iff_root_locus(lti::to_state_space(iff_plant()), controller, {-1.0}), InputError);
}

}  // namespace
}  // namespace piezobench::control
