// The 2-DoF actuator model against (1) the derived numbers of REFERENCE.md, (2) closed-form
// static gains and zeros, (3) a direct solve of the 2x2 complex dynamic-stiffness system at each
// frequency (independent of the state-space realization), (4) Octave's response of the same model
// (tests/fixtures/lti/apa_2dof.json, scripts/fixtures/make_lti_fixtures.m).
#include "piezobench/apa/two_dof.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/lti/analysis.hpp"
#include "piezobench/lti/freqresp.hpp"
#include "test_util.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::apa {
namespace {

using lti::Complex;
using lti::Index;
using test::kLightlyDamped;
using test::kReferenceTool;
using test::kRoundoff;
using test::near;
using test::Tolerance;

// REFERENCE.md quotes 4 significant digits of the derived values; the issue asks for 0.5 %.
constexpr double kReferenceDigits = 0.005;

// [d_e; Vs] per volt of f = ga Va... solved directly: unknowns [x, xn] of
//   [m s^2 + Z1 + Ze, -Ze; -Ze, Ze + Za] [x; xn] = [0; f],   d_e = x,  Vs = gs (x - xn),
// times the amplifier gain, the high-pass and the delay of the bench.
Eigen::Vector2cd direct_solve(const TwoDofParams& p, const TwoDofBench& b, double omega) {
  const Complex s(0.0, omega);
  const double m = b.moving_mass(p);
  Eigen::Matrix2cd K;
  const Complex z1 = p.k1 + p.c1 * s, ze = p.ke + p.ce * s, za = p.ka + p.ca * s;
  K << m * s * s + z1 + ze, -ze, -ze, ze + za;
  const Eigen::Vector2cd f(0.0, p.ga * b.amplifier_gain);
  const Eigen::Vector2cd x = K.fullPivLu().solve(f);
  Eigen::Vector2cd y(x(0), p.gs * (x(0) - x(1)));
  if (b.has_hpf()) y(1) *= s / (s + 1.0 / (b.hpf_resistance * b.hpf_capacitance));
  return y * std::exp(-s * b.delay);
}

TEST(TwoDof, ReferenceNumbersOfTable31) {
  const TwoDofParams p;
  const TwoDofCharacteristics c = characterize(p, TwoDofBench{});
  // REFERENCE.md, derived checks (amplifier 20 V/V, input u).
  EXPECT_TRUE(near(c.static_gain_de * 1e6, -16.81, kReferenceDigits));
  EXPECT_TRUE(near(c.static_gain_vs, 0.588, kReferenceDigits));
  EXPECT_TRUE(near(c.resonance / kTwoPi, 95.37, kReferenceDigits));
  EXPECT_TRUE(near(c.antiresonance / kTwoPi, 41.09, kReferenceDigits));
  EXPECT_EQ(c.static_gain_vs, c.static_gain_vs_actuator);
  EXPECT_EQ(c.poles.size(), 3);
  EXPECT_EQ(c.zeros_vs.size(), 2);

  // The closed forms of the header.
  const double ktot = p.k1 + p.ke * p.ka / (p.ke + p.ka);
  EXPECT_TRUE(near(p.total_stiffness(), ktot, kRoundoff));
  EXPECT_TRUE(near(c.static_gain_de, 20.0 * p.ga * p.ke / (p.ke + p.ka) / ktot, kLightlyDamped));
  EXPECT_TRUE(near(c.static_gain_vs, -20.0 * p.gs * p.ga * p.k1 / ((p.ke + p.ka) * ktot), kLightlyDamped));
  // Zeros of u -> Vs: m s^2 + c1 s + k1.
  EXPECT_TRUE(near(c.antiresonance, std::sqrt(p.k1 / p.m), kLightlyDamped));
  EXPECT_TRUE(near(c.antiresonance_damping, p.c1 / (2.0 * std::sqrt(p.k1 * p.m)), 1e-8));
  // The report's sign convention: more voltage lowers the APA, Vs rises.
  EXPECT_LT(c.static_gain_de, 0.0);
  EXPECT_GT(c.static_gain_vs, 0.0);
}

TEST(TwoDof, PolesSolveTheCharacteristicPolynomial) {
  // P(s) = (m s^2 + Z1)(Ze + Za) + Ze Za, a cubic whose roots are the poles.
  const TwoDofParams p;
  const lti::CVector poles = lti::poles(two_dof_actuator(p));
  ASSERT_EQ(poles.size(), 3);
  for (Index i = 0; i < 3; ++i) {
    const Complex s = poles(i);
    const Complex z1 = p.k1 + p.c1 * s, ze = p.ke + p.ce * s, za = p.ka + p.ca * s;
    const Complex P = (p.m * s * s + z1) * (ze + za) + ze * za;
    // Scale of the terms of P at |s|.
    const double scale = p.m * std::norm(s) * (p.ke + p.ka + (p.ce + p.ca) * std::abs(s));
    EXPECT_LT(std::abs(P), 1e-12 * scale) << "pole " << s;
  }
}

TEST(TwoDof, StateSpaceMatchesDirectSolveOfTheDynamicStiffness) {
  TwoDofParams p;
  p.c1 = 3.0;
  p.ce = 80.0;
  p.ca = 60.0;  // ce / ca != ke / ka: no pole-zero cancellation in d_e
  struct Case {
    const char* name;
    TwoDofBench bench;
  };
  TwoDofBench with_all;
  with_all.amplifier_gain = 15.0;
  with_all.added_mass = 6.4;
  with_all.hpf_resistance = 80.6e3;
  with_all.hpf_capacitance = 5e-6;
  with_all.delay = 200e-6;
  TwoDofBench suspended;
  suspended.suspended_mass = 3.0;
  const Case cases[] = {{"default", TwoDofBench{}}, {"hpf+delay+mass", with_all}, {"suspended", suspended}};
  const lti::Vector omega = kTwoPi * lti::logspace(-1.0, 4.0, 300);
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const lti::StateSpace sys = two_dof_bench(p, c.bench);
    EXPECT_EQ(sys.states(), c.bench.has_hpf() ? 4 : 3);
    const lti::FrequencyResponse fr = lti::freqresp(sys, omega);
    const lti::CMatrix closed = two_dof_response(p, c.bench, omega);
    for (Index k = 0; k < omega.size(); ++k) {
      const Eigen::Vector2cd e = direct_solve(p, c.bench, omega(k));
      for (Index o = 0; o < 2; ++o) {
        EXPECT_TRUE(near<Complex>(fr.H[static_cast<std::size_t>(k)](o, 0), e(o), Tolerance{kLightlyDamped, 0.0}))
            << "state space, output " << o << " at " << omega(k) << " rad/s";
        EXPECT_TRUE(near<Complex>(closed(k, o), e(o), Tolerance{kLightlyDamped, 0.0}))
            << "closed form, output " << o << " at " << omega(k) << " rad/s";
      }
    }
  }
}

TEST(TwoDof, ActuatorMatchesOctaveFixture) {
  const auto j = nlohmann::json::parse(test::read_text(test::fixture_path("lti/apa_2dof.json")));
  const lti::StateSpace sys = two_dof_actuator(TwoDofParams{});
  const auto& fr = j.at("freqresp");
  const auto& om = fr.at("omega");
  lti::Vector omega(static_cast<Index>(om.size()));
  for (std::size_t k = 0; k < om.size(); ++k) omega(static_cast<Index>(k)) = om[k].get<double>();
  const lti::FrequencyResponse ours = lti::freqresp(sys, omega);
  for (std::size_t k = 0; k < om.size(); ++k) {
    const auto& h = fr.at("H")[k];
    for (std::size_t o = 0; o < 2; ++o) {
      const Complex expected(h.at("re")[o].get<double>(), h.at("im")[o].get<double>());
      // Two of the fixture's frequencies sit exactly on the lightly damped pole (damping 0.56 %).
      EXPECT_TRUE(near<Complex>(ours.H[k](static_cast<Index>(o), 0), expected, Tolerance{kReferenceTool, 0.0}))
          << "output " << o << " at " << omega(static_cast<Index>(k)) << " rad/s";
    }
  }
  const auto& dc = j.at("dcgain").at("data");
  const lti::Matrix g = lti::dc_gain(sys);
  EXPECT_TRUE(near(g(0, 0), dc[0].get<double>(), kReferenceTool));
  EXPECT_TRUE(near(g(1, 0), dc[1].get<double>(), kReferenceTool));
}

TEST(TwoDof, BenchOptions) {
  const TwoDofParams p;
  TwoDofBench b;
  b.hpf_resistance = 80.6e3;
  b.hpf_capacitance = 5e-6;
  b.added_mass = 6.4;
  b.delay = 200e-6;
  const TwoDofCharacteristics c = characterize(p, b);
  EXPECT_EQ(c.poles.size(), 4);
  // The high-pass blocks Vs at DC and adds a zero at the origin and a pole at -1/(R C).
  EXPECT_EQ(c.static_gain_vs, 0.0);
  EXPECT_TRUE(near(c.static_gain_vs_actuator, 0.588, kReferenceDigits));
  bool has_origin_zero = false, has_hpf_pole = false;
  for (Index i = 0; i < c.zeros_vs.size(); ++i) has_origin_zero |= std::abs(c.zeros_vs(i)) < 1e-9;
  for (Index i = 0; i < c.poles.size(); ++i) has_hpf_pole |= near<Complex>(c.poles(i), -1.0 / (80.6e3 * 5e-6), Tolerance{1e-9, 0.0});
  EXPECT_TRUE(has_origin_zero);
  EXPECT_TRUE(has_hpf_pole);
  EXPECT_TRUE(near(b.hpf_corner() / kTwoPi, 0.395, 0.002));  // REFERENCE.md: 0.395 Hz
  // The added mass changes the dynamics, not the statics.
  EXPECT_TRUE(near(c.static_gain_de, 20.0 * p.ga * p.ke / (p.ke + p.ka) / p.total_stiffness(), kLightlyDamped));
  EXPECT_TRUE(near(c.antiresonance, std::sqrt(p.k1 / (p.m + 6.4)), kLightlyDamped));
  EXPECT_TRUE(near(c.resonance, std::sqrt(p.total_stiffness() / (p.m + 6.4)), 1e-3));
  // The delay is an input delay of the state space, exact in the response.
  const lti::StateSpace sys = two_dof_bench(p, b);
  ASSERT_EQ(sys.input_delay.size(), 1);
  EXPECT_EQ(sys.input_delay(0), 200e-6);
}

TEST(TwoDof, ParametersByName) {
  TwoDofParams p;
  EXPECT_EQ(TwoDofParams::names().size(), 9U);
  for (const auto& n : TwoDofParams::names()) p.set(n, p.get(n) * 2.0);
  EXPECT_EQ(p.k1, 0.76e6);
  EXPECT_EQ(p.ga, -5.16);
  const TwoDofParams q = two_dof_params_from_map({{"k1", 0.5e6}, {"gs", 1e6}}, "p.toml");
  EXPECT_EQ(q.k1, 0.5e6);
  EXPECT_EQ(q.gs, 1e6);
  EXPECT_EQ(q.ka, 2.5e6);  // default kept
  try {
    (void)two_dof_params_from_map({{"kk", 1.0}}, "p.toml");
    ADD_FAILURE() << "unknown key accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "kk");
    EXPECT_NE(std::string(e.what()).find("p.toml"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)p.get("nope"), InputError);
}

TEST(TwoDof, ValidationNamesTheField) {
  const struct {
    const char* field;
    double value;
  } bad[] = {{"m", 0.0},   {"k1", -1.0}, {"ke", 0.0},  {"ka", NAN}, {"c1", -1.0},
             {"ce", -1.0}, {"ca", -1.0}, {"ga", 0.0},  {"gs", 0.0}, {"gs", INFINITY}};
  for (const auto& b : bad) {
    TwoDofParams p;
    p.set(b.field, b.value);
    try {
      p.validate();
      ADD_FAILURE() << b.field << " = " << b.value << " accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), b.field);
    }
  }
  TwoDofParams no_damper;
  no_damper.ca = 0.0;
  no_damper.ce = 0.0;
  EXPECT_THROW(no_damper.validate(), InputError);
  no_damper.ce = 1.0;
  EXPECT_NO_THROW(no_damper.validate());

  const struct {
    const char* field;
    void (*apply)(TwoDofBench&);
  } bench_bad[] = {
      {"amplifier_gain", [](TwoDofBench& b) { b.amplifier_gain = 0.0; }},
      {"added_mass", [](TwoDofBench& b) { b.added_mass = -1.0; }},
      {"suspended_mass", [](TwoDofBench& b) { b.suspended_mass = NAN; }},
      {"hpf_capacitance", [](TwoDofBench& b) { b.hpf_resistance = 1e3; }},
      {"hpf_resistance", [](TwoDofBench& b) { b.hpf_capacitance = 1e-6; }},
      {"delay", [](TwoDofBench& b) { b.delay = -1e-3; }},
  };
  for (const auto& b : bench_bad) {
    TwoDofBench bench;
    b.apply(bench);
    try {
      bench.validate();
      ADD_FAILURE() << b.field << " accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), b.field);
    }
  }
}

}  // namespace
}  // namespace piezobench::apa
