#include "piezobench/ident/modal.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "piezobench/core/error.hpp"
#include "test_util.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::ident {
namespace {

using test::near;

// Hammer test of the APA300ML (report section 1.4): y-bending near 280 Hz and x-bending near
// 412 Hz. Accelerance (laser vibrometer differentiated), modal superposition of the two modes:
//   H(s) = sum_i s^2 a_i / (s^2 + 2 zeta_i w_i s + w_i^2).
struct Hammer {
  double f1 = 280.0, z1 = 0.01, a1 = 1.0;
  double f2 = 412.0, z2 = 0.015, a2 = 0.6;
  Complex at(Complex s) const {
    const double w1 = kTwoPi * f1, w2 = kTwoPi * f2;
    return s * s * a1 / (s * s + 2.0 * z1 * w1 * s + w1 * w1) + s * s * a2 / (s * s + 2.0 * z2 * w2 * s + w2 * w2);
  }
};

// df = 0.25 Hz up to 1 kHz, as a 4 s hammer record would give.
Vector hammer_grid() { return kTwoPi * Vector::LinSpaced(4000, 0.25, 1000.0); }

CMatrix hammer_frf(const Vector& omega, const Hammer& model, double noise, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, noise / std::sqrt(2.0));
  CMatrix h(omega.size(), 1);
  for (Index k = 0; k < omega.size(); ++k) {
    h(k, 0) = model.at(Complex(0.0, omega(k)));
    if (noise > 0.0) h(k, 0) *= Complex(1.0 + gauss(rng), gauss(rng));
  }
  return h;
}

TEST(PeakPicking, FindsTheTwoBendingModesWithHalfPowerDamping) {
  const Hammer model;
  const Vector omega = hammer_grid();
  const std::vector<Mode> modes = peak_picking(omega, hammer_frf(omega, model, 0.0, 0));
  ASSERT_EQ(modes.size(), 2u);
  // Half-power bandwidth is ~5.6 Hz and ~12 Hz, resolved by 0.25 Hz bins; the neighbouring mode and
  // the accelerance weighting (s^2, peak at wn / sqrt(1 - 2 zeta^2)) move the peak of |H| by up to
  // ~0.2 % from wn: the method's own bias, not round-off.
  constexpr double kPeakBias = 3e-3;
  EXPECT_TRUE(near(modes[0].frequency_Hz(), 280.0, kPeakBias));
  EXPECT_TRUE(near(modes[1].frequency_Hz(), 412.0, kPeakBias));
  EXPECT_TRUE(near(modes[0].damping, 0.01, 0.05));
  EXPECT_TRUE(near(modes[1].damping, 0.015, 0.05));
}

TEST(PeakPicking, ProminenceAndBandSelectModes) {
  const Hammer model;
  const Vector omega = hammer_grid();
  const CMatrix h = hammer_frf(omega, model, 0.0, 0);
  PeakPickingOptions o;
  o.max_modes = 1;
  std::vector<Mode> modes = peak_picking(omega, h, o);
  ASSERT_EQ(modes.size(), 1u);
  o = PeakPickingOptions{};
  o.min_omega = kTwoPi * 350.0;
  modes = peak_picking(omega, h, o);
  ASSERT_EQ(modes.size(), 1u);
  EXPECT_TRUE(near(modes[0].frequency_Hz(), 412.0, 3e-3));
  o = PeakPickingOptions{};
  o.min_prominence = 1e6;
  EXPECT_TRUE(peak_picking(omega, h, o).empty());
}

TEST(PeakPicking, NoisyDataStillGivesBothModes) {
  const Hammer model;
  const Vector omega = hammer_grid();
  const std::vector<Mode> modes = peak_picking(omega, hammer_frf(omega, model, 0.01, 3));
  // 1 % noise creates tiny local maxima; the prominence rule (6 dB) removes them.
  ASSERT_EQ(modes.size(), 2u);
  EXPECT_TRUE(near(modes[0].frequency_Hz(), 280.0, 4e-3));
  EXPECT_TRUE(near(modes[1].frequency_Hz(), 412.0, 4e-3));
  EXPECT_TRUE(near(modes[0].damping, 0.01, 0.15));
  EXPECT_TRUE(near(modes[1].damping, 0.015, 0.15));
}

TEST(Lscf, StabilizationDiagramGivesBothModes) {
  const Hammer model;
  const Vector omega = hammer_grid();
  LscfOptions o;
  o.min_omega = kTwoPi * 150.0;
  o.max_omega = kTwoPi * 600.0;
  o.max_order = 24;
  const LscfResult r = lscf(omega, hammer_frf(omega, model, 0.0, 0), o);
  ASSERT_EQ(r.modes.size(), 2u);
  EXPECT_TRUE(near(r.modes[0].frequency_Hz(), 280.0, 1e-4));
  EXPECT_TRUE(near(r.modes[1].frequency_Hz(), 412.0, 1e-4));
  EXPECT_TRUE(near(r.modes[0].damping, 0.01, 1e-2));
  EXPECT_TRUE(near(r.modes[1].damping, 0.015, 1e-2));
  EXPECT_GE(r.modes[0].stable_orders, o.min_stable_orders);
  EXPECT_FALSE(r.diagram.empty());
}

TEST(Lscf, NoisyDataAndSeveralOutputs) {
  const Hammer model;
  Hammer other = model;  // a second measurement point: other mode shapes, same poles
  other.a1 = 0.3;
  other.a2 = -1.2;
  const Vector omega = hammer_grid();
  CMatrix h(omega.size(), 2);
  h.col(0) = hammer_frf(omega, model, 0.01, 1).col(0);
  h.col(1) = hammer_frf(omega, other, 0.01, 2).col(0);
  LscfOptions o;
  o.min_omega = kTwoPi * 150.0;
  o.max_omega = kTwoPi * 600.0;
  o.max_order = 30;
  const LscfResult r = lscf(omega, h, o);
  ASSERT_EQ(r.modes.size(), 2u);
  EXPECT_TRUE(near(r.modes[0].frequency_Hz(), 280.0, 1e-3));
  EXPECT_TRUE(near(r.modes[1].frequency_Hz(), 412.0, 1e-3));
  EXPECT_TRUE(near(r.modes[0].damping, 0.01, 0.05));
  EXPECT_TRUE(near(r.modes[1].damping, 0.015, 0.05));
}

TEST(Lscf, BadInputAndOptions) {
  const Hammer model;
  const Vector omega = hammer_grid();
  const CMatrix h = hammer_frf(omega, model, 0.0, 0);
  LscfOptions o;
  o.min_omega = kTwoPi * 280.0;
  o.max_omega = kTwoPi * 285.0;  // 21 points for orders up to 40
  EXPECT_THROW((void)lscf(omega, h, o), InputError);
  o = LscfOptions{};
  o.max_order = 1;
  EXPECT_THROW(o.validate(), InputError);
  o = LscfOptions{};
  o.min_stable_orders = 100;
  EXPECT_THROW(o.validate(), InputError);
  CMatrix bad = h;
  bad(5, 0) = Complex(std::nan(""), 0.0);
  EXPECT_THROW((void)lscf(omega, bad), InputError);
  EXPECT_THROW((void)peak_picking(omega, h.topRows(10)), InputError);
  PeakPickingOptions p;
  p.min_prominence = 0.5;
  EXPECT_THROW(p.validate(), InputError);
}

}  // namespace
}  // namespace piezobench::ident
