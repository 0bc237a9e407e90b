// The linear part of the virtual bench (src/bench/plant.hpp): the coupled 2-DoF model against its
// closed form, the high-pass corner, the non-minimum-phase zero, and the exact discretizations.
#include "plant.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

#include "piezobench/lti/analysis.hpp"
#include "piezobench/lti/discretize.hpp"
#include "piezobench/lti/freqresp.hpp"
#include "piezobench/core/units.hpp"
#include "test_util.hpp"

namespace piezobench::bench::detail {
namespace {

using test::near;
using Complex = std::complex<double>;

Electrics report_electrics(double ground_resistance) {
  Electrics e;
  e.amplifier_bandwidth = 2 * kPi * 5000.0;
  e.hpf_resistance = 80.6e3;
  e.capacitance_sensor = 4.95e-6;
  e.capacitance_actuator = 9.87e-6;
  e.ground_resistance = ground_resistance;
  e.adc_bandwidth = 2 * kPi * 1000.0;
  return e;
}

lti::StateSpace u_to_de_vs(const ContinuousPlant& p, double gain) {
  lti::Matrix c(2, p.states()), d(2, 1);
  c.row(0) = p.C.row(kOutDe);
  c.row(1) = p.C.row(kOutVs);
  d << p.D(kOutDe, kInVa) * gain, p.D(kOutVs, kInVa) * gain;
  return lti::StateSpace(p.A, p.B.col(kInVa) * gain, c, d);
}

// The coupled model in closed form: the sensor stack's dynamic stiffness seen by the mechanics is
// ke_sc + ce s + gs^2 C_b s / (s + wb), wb = 1 / (R C_b), and Vs = gs s / (s + wb) e + kappa s Va
// seen through the ADC's anti-aliasing low-pass w_aa / (s + w_aa).
std::pair<Complex, Complex> closed_form(const apa::TwoDofParams& p, const Electrics& e, double gain, Complex s) {
  const double cb = blocked_capacitance(p, e.capacitance_sensor);
  const double wb = 1.0 / (e.hpf_resistance * cb);
  const double ke_sc = p.ke - p.gs * p.gs * cb;
  const Complex ze = ke_sc + p.ce * s + p.gs * p.gs * cb * s / (s + wb);
  const Complex za = p.ka + p.ca * s;
  const Complex shell = p.m * s * s + p.k1 + p.c1 * s;
  const Complex poly = shell * (ze + za) + ze * za;
  const Complex va = gain * e.amplifier_bandwidth / (s + e.amplifier_bandwidth);
  const Complex f = p.ga * va;
  const Complex x = ze / poly * f;
  const Complex ext = -shell / poly * f;
  const double kappa = -e.ground_resistance * e.capacitance_actuator;
  const Complex aa = e.adc_bandwidth / (s + e.adc_bandwidth);
  return {x, (p.gs * s / (s + wb) * ext + kappa * s * va) * aa};
}

TEST(TwoDofPlant, FrequencyResponseEqualsTheClosedForm) {
  const apa::TwoDofParams p;
  const Electrics e = report_electrics(0.16);
  const lti::StateSpace sys = u_to_de_vs(two_dof_plant(p, e), 20.0);
  const lti::Vector hz = lti::logspace(-2, 3.5, 200);
  const lti::FrequencyResponse r = lti::freqresp(sys, 2 * kPi * hz);
  for (lti::Index k = 0; k < hz.size(); ++k) {
    const auto [de, vs] = closed_form(p, e, 20.0, Complex(0.0, 2 * kPi * hz(k)));
    EXPECT_TRUE(near<Complex>(r.H[static_cast<std::size_t>(k)](0, 0), de, {1e-9, 0.0})) << hz(k) << " Hz";
    // |Vs| dips by 1e-3 at the anti-resonance: relative to the response's scale there.
    EXPECT_TRUE(near<Complex>(r.H[static_cast<std::size_t>(k)](1, 0), vs, {1e-9, 1e-9})) << hz(k) << " Hz";
  }
}

TEST(TwoDofPlant, HighPassCornerIsSetByTheInSituCapacitance) {
  const apa::TwoDofParams p;
  const Electrics e = report_electrics(0.16);
  const lti::CVector poles = lti::poles(u_to_de_vs(two_dof_plant(p, e), 20.0));
  // The slowest pole: the charge leaking through R, at 1/(R C) with C the LCR (in-situ) value, up
  // to the (0.4 Hz / 95 Hz)^2 coupling with the mechanics.
  EXPECT_NEAR(poles(0).imag(), 0.0, 1e-12);
  EXPECT_TRUE(near(-poles(0).real(), 1.0 / (80.6e3 * 4.95e-6), 1e-4));
}

TEST(TwoDofPlant, StaticStiffnessIsTheShortCircuitedSensorsAndStiffnessLineTheOpenOnes) {
  const apa::TwoDofParams p;
  const Electrics e = report_electrics(0.0);
  const ContinuousPlant plant = two_dof_plant(p, e);
  const lti::StateSpace sys(plant.A, plant.B, plant.C, plant.D);
  const lti::Matrix dc = lti::dc_gain(sys);
  const double cb = blocked_capacitance(p, e.capacitance_sensor);
  const double ke_sc = p.ke - p.gs * p.gs * cb;
  const double k_static = p.k1 + ke_sc * p.ka / (ke_sc + p.ka);
  // A weight on the mass: d_e = F / k with the sensor stack short-circuited through R.
  EXPECT_TRUE(near(dc(kOutDe, kInMass), 1.0 / k_static, 1e-10));
  // Its short-circuit stiffness is below the open-circuit ke of Table 3.1 (about 4.1 vs 5 N/um).
  EXPECT_GT(ke_sc, 3.9e6);
  EXPECT_LT(ke_sc, 4.3e6);
  // On the stiffness line (10 Hz, far above 0.4 Hz, far below 95 Hz) the sensor is open: the
  // report's -16.8 um/V within the (10/95)^2 = 1 % mass effect.
  const lti::FrequencyResponse r = lti::freqresp(u_to_de_vs(plant, 20.0), lti::Vector::Constant(1, 2 * kPi * 2.0));
  const double line = 20.0 * p.ga * p.ke / (p.ke + p.ka) / p.total_stiffness();
  EXPECT_TRUE(near(r.H[0](0, 0).real(), line, 2e-3));
}

TEST(TwoDofPlant, OpenCircuitActuatorStacksAreStifferByTheirCoupling) {
  // Every stack open (no resistor: a shunt of 1 TOhm): between the leaks (hours) and the
  // resonance a weight sees k1 + ke ka_oc / (ke + ka_oc), ka_oc = ka + ga^2 / C_ab (report section
  // 2.2: k_oc about 2.3 N/um against k_sc about 1.7 with creep, 1.94 without).
  const apa::TwoDofParams p;
  Electrics e = report_electrics(0.16);
  e.hpf_resistance = 1e12;
  e.actuator_open_circuit = true;
  const ContinuousPlant plant = two_dof_plant(p, e);
  const double cab = actuator_blocked_capacitance(p, e.capacitance_actuator);
  EXPECT_TRUE(near(cab, e.capacitance_actuator - p.ga * p.ga / (p.ka + p.ke * p.k1 / (p.ke + p.k1)), 1e-12));
  const double ka_oc = p.ka + p.ga * p.ga / cab;
  const double k_oc = p.k1 + p.ke * ka_oc / (p.ke + ka_oc);
  EXPECT_GT(k_oc * 1e-6, 2.3);
  EXPECT_LT(k_oc * 1e-6, 2.5);
  const lti::StateSpace sys(plant.A, plant.B, plant.C, plant.D);
  const lti::FrequencyResponse r = lti::freqresp(sys, lti::Vector::Constant(1, 2 * kPi * 0.5));
  EXPECT_TRUE(near(r.H[0](kOutDe, kInMass).real(), 1.0 / k_oc, 1e-3));
  // The stacks' voltage follows the node, Va = -ga xn / C_ab; the amplifier's command does nothing.
  EXPECT_EQ(plant.B(0, kInVa), 0.0);
  EXPECT_LT(std::abs(r.H[0](kOutVa, kInVa)), 1e-12);
  // A capacitance too small for the coupling is refused by name.
  e.capacitance_actuator = 1e-6;
  EXPECT_TRUE(test::contains(test::input_error([&] { (void)two_dof_plant(p, e); }, "capacitance_actuator"), "open-circuit"));
}

TEST(TwoDofPlant, GroundResistanceMakesTheAntiResonanceNonMinimumPhase) {
  const apa::TwoDofParams p;
  for (const double rg : {0.0, 0.16}) {
    const ContinuousPlant plant = two_dof_plant(p, report_electrics(rg));
    const lti::StateSpace vs(plant.A, plant.B.col(kInVa), plant.C.row(kOutVs), plant.D.block(kOutVs, kInVa, 1, 1));
    const lti::CVector z = lti::zeros(vs);
    Complex pair(0.0, 0.0);
    for (const Complex zi : z) {
      if (zi.imag() > 1.0 && std::abs(zi) < 2 * kPi * 100) pair = zi;
    }
    const double f = std::abs(pair) / (2 * kPi), zeta = -pair.real() / std::abs(pair);
    EXPECT_NEAR(f, std::sqrt(p.k1 / p.m) / (2 * kPi), 0.01) << "R_g " << rg;
    if (rg == 0.0) {
      EXPECT_TRUE(near(zeta, p.c1 / (2.0 * std::sqrt(p.k1 * p.m)), 0.02));  // the shell's damping
    } else {
      EXPECT_LT(zeta, -0.003);  // the report's NMP zero: a damping of a few -0.1 %
      EXPECT_GT(zeta, -0.005);
    }
  }
}

TEST(TwoDofPlant, RefusesASensorStackWithNoShortCircuitStiffness) {
  apa::TwoDofParams p;
  p.gs = 1e7;  // gs^2 C_b > ke
  const std::string message = test::input_error([&] { (void)two_dof_plant(p, report_electrics(0.0)); }, "gs");
  EXPECT_TRUE(test::contains(message, "short-circuit stiffness"));
}

// lti::c2d of the balanced realization, transformed back: an accurate reference for every entry
// (the exponential is accurate relative to the norm of its argument only).
lti::StateSpace accurate_c2d(const ContinuousPlant& plant, double ts) {
  const Eigen::Index n = plant.states(), m = plant.B.cols();
  lti::Matrix aug = lti::Matrix::Zero(n + m, n + m);
  aug.topLeftCorner(n, n) = plant.A;
  aug.topRightCorner(n, m) = plant.B;
  const lti::Vector d = balancing_scales(aug).head(n);
  const lti::StateSpace balanced(d.cwiseInverse().asDiagonal() * plant.A * d.asDiagonal(), d.cwiseInverse().asDiagonal() * plant.B,
                                 plant.C * d.asDiagonal(), plant.D);
  lti::StateSpace c = lti::c2d(balanced, ts);
  c.A = d.asDiagonal() * c.A * d.cwiseInverse().asDiagonal();
  c.B = d.asDiagonal() * c.B;
  c.C = c.C * d.cwiseInverse().asDiagonal();
  return c;
}

TEST(BalancingScales, EqualizesRowAndColumnNorms) {
  lti::Matrix a(3, 3);
  a << 1.0, 1e6, 0.0, 1e-6, 1.0, 1e3, 0.0, 1e-3, 1.0;
  const lti::Vector d = balancing_scales(a);
  const lti::Matrix b = d.cwiseInverse().asDiagonal() * a * d.asDiagonal();
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(std::log2(d(i)), std::round(std::log2(d(i))));  // powers of two: exact
    const double c = b.col(i).cwiseAbs().sum() - 1.0, r = b.row(i).cwiseAbs().sum() - 1.0;
    EXPECT_LT(std::max(c, r) / std::min(c, r), 4.1) << i;
  }
}

TEST(Discretize, WithoutFractionIsZeroOrderHold) {
  const ContinuousPlant plant = two_dof_plant(apa::TwoDofParams{}, report_electrics(0.16));
  const DiscretePlant d = discretize(plant, 1e-4, 0.0);
  const lti::StateSpace c = accurate_c2d(plant, 1e-4);
  EXPECT_TRUE(test::all_near(d.Phi, c.A, {1e-10, 1e-15}));
  EXPECT_TRUE(test::all_near(d.Gamma.col(kLate), c.B.col(kInVa), {1e-10, 1e-20}));
  EXPECT_TRUE(test::all_near(d.Gamma.col(kForce), c.B.col(kInForce), {1e-10, 1e-20}));
  EXPECT_TRUE(test::all_near(d.Gamma.col(kMass), c.B.col(kInMass), {1e-10, 1e-20}));
  EXPECT_EQ(d.Gamma.col(kEarly).norm(), 0.0);
}

TEST(Discretize, FractionalDelaySplitsTheHoldExactly) {
  // Half a sample of delay: over one period, the previous command for the first half and the new
  // one for the second. The same with ten sub-steps of a plain ZOH discretization.
  const ContinuousPlant plant = two_dof_plant(apa::TwoDofParams{}, report_electrics(0.16));
  const double ts = 1e-4;
  const DiscretePlant d = discretize(plant, ts, 0.5);
  const lti::StateSpace fine = accurate_c2d(plant, ts / 10);
  lti::Vector early = lti::Vector::Zero(plant.states()), late = early;
  for (int i = 0; i < 10; ++i) {
    early = fine.A * early + fine.B.col(kInVa) * (i < 5 ? 1.0 : 0.0);
    late = fine.A * late + fine.B.col(kInVa) * (i < 5 ? 0.0 : 1.0);
  }
  EXPECT_TRUE(test::all_near(d.Gamma.col(kEarly), early, {1e-9, 1e-20}));
  EXPECT_TRUE(test::all_near(d.Gamma.col(kLate), late, {1e-9, 1e-20}));
}

TEST(DiscretizeModal, SameInputOutputBehaviourAsTheDenseForm) {
  const ContinuousPlant plant = two_dof_plant(apa::TwoDofParams{}, report_electrics(0.16));
  const double ts = 1e-4;
  const DiscretePlant d = discretize(plant, ts, 0.5);
  const ModalPlant m = discretize_modal(plant, ts, 0.5);
  EXPECT_EQ(m.real_blocks + 2 * m.complex_blocks, plant.states());
  EXPECT_EQ(m.complex_blocks, 1);  // the resonance; the amplifier, node, and charge poles are real
  lti::Vector x = lti::Vector::Zero(plant.states()), z = x, zn = z;
  double prev = 0.0;
  double max_de = 0.0, max_err = 0.0;
  for (int k = 0; k < 3000; ++k) {
    const double va = std::sin(0.01 * k) + 0.3 * std::sin(0.37 * k);
    const lti::Vector in = (lti::Vector(4) << prev, va, 0.5 * std::cos(0.05 * k), -1.0).finished();
    x = d.Phi * x + d.Gamma * in;
    for (int i = 0; i < m.real_blocks; ++i) zn(i) = m.a[static_cast<std::size_t>(i)] * z(i);
    for (int j = 0; j < m.complex_blocks; ++j) {
      const int i = m.real_blocks + 2 * j;
      const double a = m.a[static_cast<std::size_t>(m.real_blocks + j)], b = m.b[static_cast<std::size_t>(m.real_blocks + j)];
      zn(i) = a * z(i) + b * z(i + 1);
      zn(i + 1) = -b * z(i) + a * z(i + 1);
    }
    z = zn + m.Gamma * in;
    prev = va;
    const double de_dense = (plant.C * x)(kOutDe);
    const double de_modal = (m.C * z)(kOutDe);
    max_de = std::max(max_de, std::abs(de_dense));
    max_err = std::max(max_err, std::abs(de_dense - de_modal));
    // Two exact methods, round-off apart (relative to the 0.5 V scale of Vs).
    ASSERT_TRUE(near<double>((plant.C * x)(kOutVs), (m.C * z)(kOutVs), {1e-6, 1e-8})) << k;
  }
  EXPECT_LT(max_err, 1e-9 * max_de);
}

}  // namespace
}  // namespace piezobench::bench::detail
