#include "piezobench/ident/dominant_pole.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "piezobench/core/error.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::ident {
namespace {

// A damped plant as IFF makes it: a well damped resonance (80 Hz, 25 %) that dominates, a lightly
// damped pair with a small residue (a controller pole near a zero, 150 Hz) and a real pole (20 Hz).
struct Plant {
  Complex p1 = Complex(-0.25 * kTwoPi * 80.0, kTwoPi * 80.0 * std::sqrt(1.0 - 0.0625));
  Complex p2 = Complex(-0.01 * kTwoPi * 150.0, kTwoPi * 150.0);
  double p3 = -kTwoPi * 20.0;
  Complex r1 = Complex(-3.0e-4, -5.0e-3), r2 = Complex(1.0e-6, 2.0e-6);
  double r3 = 2.0e-4;
  Complex operator()(double w) const {
    const Complex s(0.0, w);
    return r1 / (s - p1) + std::conj(r1) / (s - std::conj(p1)) + r2 / (s - p2) + std::conj(r2) / (s - std::conj(p2)) +
           r3 / (s - p3);
  }
};

Vector grid(double f0, double f1, Index n) {
  Vector w(n);
  for (Index k = 0; k < n; ++k) w(k) = kTwoPi * f0 * std::pow(f1 / f0, static_cast<double>(k) / static_cast<double>(n - 1));
  return w;
}

TEST(DominantPole, FindsTheDominantPairNotTheSpuriousOne) {
  const Plant g;
  const Vector w = grid(2.0, 1000.0, 400);
  CVector h(w.size());
  for (Index k = 0; k < w.size(); ++k) h(k) = g(w(k));
  DominantPoleOptions o;
  o.fit.order = 5;
  o.omega_min = kTwoPi * 20.0;
  o.omega_max = kTwoPi * 400.0;
  const DominantPole d = dominant_pole(w, h, o);
  EXPECT_LT(std::abs(d.pole - g.p1) / std::abs(g.p1), 1e-6);
  EXPECT_NEAR(d.damping, 0.25, 1e-6);
  EXPECT_NEAR(d.frequency_Hz(), 80.0, 1e-4);
  EXPECT_LT(d.fit.relative_rms_error, 1e-6);
}

TEST(DominantPole, WithinOnePercentOnNoisyData) {
  const Plant g;
  const Vector w = grid(2.0, 1000.0, 600);
  CVector h(w.size());
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 0.01);
  for (Index k = 0; k < w.size(); ++k) h(k) = g(w(k)) * Complex(1.0 + n(rng), n(rng));
  DominantPoleOptions o;
  o.omega_min = kTwoPi * 20.0;
  o.omega_max = kTwoPi * 400.0;
  const DominantPole d = dominant_pole(w, h, o);
  EXPECT_LT(std::abs(d.pole - g.p1) / std::abs(g.p1), 0.01);
}

// A pair the fit puts (almost) on the imaginary axis between two lines with a small residue: its
// |r| / |Re p| is 5 times the resonance's, yet on the data's frequencies it contributes 1/20 of it.
// The dominant pole is the resonance (the demo's damped plants showed such pairs, as noise has it).
TEST(DominantPole, APairOnTheAxisBetweenTwoLinesDoesNotDominate) {
  const Plant g;
  const Vector w = grid(2.0, 1000.0, 400);
  Index k = 0;
  while (w(k + 1) < kTwoPi * 150.0) ++k;
  const Complex p4(-0.05, 0.5 * (w(k) + w(k + 1)));  // damping 5e-5, midway between lines k and k + 1
  const Complex r4(1.0e-5, 0.0);
  CVector h(w.size());
  for (Index i = 0; i < w.size(); ++i) {
    const Complex s(0.0, w(i));
    h(i) = g(w(i)) + r4 / (s - p4) + std::conj(r4) / (s - std::conj(p4)) - g.r2 / (s - g.p2) - std::conj(g.r2) / (s - std::conj(g.p2));
  }
  DominantPoleOptions o;
  o.fit.order = 5;
  o.omega_min = kTwoPi * 20.0;
  o.omega_max = kTwoPi * 400.0;
  const DominantPole d = dominant_pole(w, h, o);
  // The fit has the axis pair (else this test shows nothing) ...
  bool has_axis_pair = false;
  for (Index j = 0; j < d.fit.poles.size(); ++j) has_axis_pair |= std::abs(d.fit.poles(j) - p4) < 1e-3 * std::abs(p4);
  EXPECT_TRUE(has_axis_pair);
  EXPECT_GT(std::abs(r4) / std::abs(p4.real()), 5.0 * std::abs(g.r1) / std::abs(g.p1.real()));
  // ... and the resonance is the dominant pole.
  EXPECT_LT(std::abs(d.pole - g.p1) / std::abs(g.p1), 1e-4);
}

TEST(DominantPole, NoPairInTheBandIsANumericalError) {
  const Plant g;
  const Vector w = grid(2.0, 1000.0, 200);
  CVector h(w.size());
  for (Index k = 0; k < w.size(); ++k) h(k) = g(w(k));
  DominantPoleOptions o;
  o.fit.order = 5;
  o.omega_min = kTwoPi * 300.0;
  o.omega_max = kTwoPi * 400.0;
  EXPECT_THROW(dominant_pole(w, h, o), NumericalError);
}

TEST(DominantPole, BadBandIsAnInputError) {
  DominantPoleOptions o;
  o.omega_min = 10.0;
  o.omega_max = 5.0;
  EXPECT_THROW(o.validate(), InputError);
  o.omega_max = std::nan("");
  EXPECT_THROW(o.validate(), InputError);
}

}  // namespace
}  // namespace piezobench::ident
