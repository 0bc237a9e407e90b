#include "piezobench/ident/features.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/dsp/frf.hpp"
#include "test_util.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::ident {
namespace {

using test::near;

// The report's figures are given to 3 digits; issue 3 asks for 0.5 % on frequencies and 2 % on the
// static gain against them.
constexpr double kReportFrequency = 0.005;
constexpr double kReportGain = 0.02;
// Against the exact values of the model: the fit is of the exact order on noise-free data.
constexpr double kExactFit = 1e-6;

// The 2-DoF model of the APA300ML (report section 3, Table 3.1). Shell (k1, c1) from the base to
// the mass m; in parallel, from the base: actuator stacks (ka, ca, force ga Va) to a massless node
// y, then the sensor stack (ke, ce) from y to the mass x. Va = 20 u (amplifier), d_e = x,
// V_s = gs (x - y). With Ka = ka + ca s, Ke = ke + ce s, K1 = k1 + c1 s, M = m s^2:
//   node: Ka Y = F + Ke (X - Y);  mass: (M + K1) X = -Ke (X - Y)
//   => X / F = Ke / den,  (X - Y) / F = -(M + K1) / den,  den = (Ka + Ke)(M + K1) + Ka Ke.
struct TwoDof {
  double m = 5.7, k1 = 0.38e6, c1 = 5.0, ke = 5.0e6, ce = 100.0, ka = 2.5e6, ca = 50.0;
  double ga = -2.58, gs = 0.46e6, amplifier = 20.0;

  Complex den(Complex s) const {
    const Complex kA = ka + ca * s, kE = ke + ce * s, k1s = k1 + c1 * s, ms = m * s * s;
    return (kA + kE) * (ms + k1s) + kA * kE;
  }
  Complex de(Complex s) const { return amplifier * ga * (ke + ce * s) / den(s); }
  // mirror = true puts the shell's zero pair in the right half plane (m s^2 - c1 s + k1).
  Complex vs(Complex s, bool mirror = false) const {
    const Complex zero_poly = m * s * s + (mirror ? -c1 : c1) * s + k1;
    return -amplifier * ga * gs * zero_poly / den(s);
  }
  // Roots of den: the cubic A1 m s^3 + (A0 m + A1 c1 + ca ce) s^2 + (A0 c1 + A1 k1 + ka ce + ke ca) s
  // + A0 k1 + ka ke with A0 = ka + ke, A1 = ca + ce; returns the complex root with Im > 0.
  Complex resonance_pole() const {
    const double a0 = ka + ke, a1 = ca + ce;
    const double c3 = a1 * m, c2 = a0 * m + a1 * c1 + ca * ce, c1c = a0 * c1 + a1 * k1 + ka * ce + ke * ca,
                 c0 = a0 * k1 + ka * ke;
    Eigen::Matrix3d companion = Eigen::Matrix3d::Zero();
    companion(1, 0) = 1.0;
    companion(2, 1) = 1.0;
    companion(0, 2) = -c0 / c3;
    companion(1, 2) = -c1c / c3;
    companion(2, 2) = -c2 / c3;
    const Eigen::Vector3cd r = companion.eigenvalues();
    for (int i = 0; i < 3; ++i) {
      if (r(i).imag() > 0.0) return r(i);
    }
    return {};
  }
  double k_tot() const { return k1 + ke * ka / (ke + ka); }
  double static_gain_de() const { return amplifier * ga * ke / (ke + ka) / k_tot(); }
  double static_gain_vs() const { return -amplifier * ga * gs * k1 / den(0.0).real(); }
};

using test::log_grid;

template <typename F>
CVector response(const Vector& omega, F&& f) {
  CVector h(omega.size());
  for (Index k = 0; k < omega.size(); ++k) h(k) = f(Complex(0.0, omega(k)));
  return h;
}

CVector with_noise(const CVector& h, double level, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, level / std::sqrt(2.0));
  CVector out = h;
  for (Index k = 0; k < h.size(); ++k) out(k) *= Complex(1.0 + gauss(rng), gauss(rng));
  return out;
}

TEST(FrfFeatures, TwoDofDisplacementGivesResonanceAndStaticGain) {
  const TwoDof apa;
  const Vector omega = log_grid(1.0, 2000.0, 1000);
  FrfFeatureOptions o;
  o.fit.order = 3;  // the model's order: a pair and the real pole of the stacks' dampers
  const FrfFeatures f = frf_features(omega, response(omega, [&](Complex s) { return apa.de(s); }), o);
  ASSERT_EQ(f.resonances.size(), 1u);
  EXPECT_TRUE(near(f.resonances[0].frequency_Hz(), 95.4, kReportFrequency));
  const Complex p = apa.resonance_pole();
  EXPECT_TRUE(near(f.resonances[0].natural_frequency, std::abs(p), kExactFit));
  EXPECT_TRUE(near(f.resonances[0].damping, -p.real() / std::abs(p), kExactFit));
  EXPECT_TRUE(f.antiresonances.empty());  // d_e has only a real zero (-ke / ce)
  // The real pole nearly cancels that zero: its residue is ~1e-17 and it wanders at round-off
  // level; convergence is judged on the poles the data determine.
  EXPECT_EQ(f.fit.convergence, Convergence::kPolesSettled) << f.fit.brief_report();
  EXPECT_EQ(f.static_gain_source, StaticGainSource::kModelDcGain);
  EXPECT_TRUE(near(f.static_gain * 1e6, -16.8, kReportGain));  // um/V
  EXPECT_TRUE(near(f.static_gain, apa.static_gain_de(), kExactFit));
}

TEST(FrfFeatures, TwoDofSensorVoltageGivesAntiResonance) {
  const TwoDof apa;
  const Vector omega = log_grid(1.0, 2000.0, 1000);
  FrfFeatureOptions o;
  o.fit.order = 3;
  const FrfFeatures f = frf_features(omega, response(omega, [&](Complex s) { return apa.vs(s); }), o);
  ASSERT_EQ(f.resonances.size(), 1u);
  EXPECT_TRUE(near(f.resonances[0].frequency_Hz(), 95.4, kReportFrequency));
  ASSERT_EQ(f.antiresonances.size(), 1u);
  const AntiResonance& a = f.antiresonances[0];
  EXPECT_TRUE(near(a.frequency_Hz(), 41.1, kReportFrequency));
  EXPECT_TRUE(near(a.natural_frequency, std::sqrt(apa.k1 / apa.m), kExactFit));
  EXPECT_TRUE(near(a.damping, apa.c1 / (2.0 * std::sqrt(apa.k1 * apa.m)), 1e-5));
  EXPECT_FALSE(a.nonminimum_phase_model);
  EXPECT_EQ(a.phase_verdict, PhaseVerdict::kMinimumPhase);
  EXPECT_TRUE(near(a.phase_change_deg, 180.0, 0.05));
  EXPECT_TRUE(near(f.static_gain, apa.static_gain_vs(), kExactFit));
  EXPECT_TRUE(near(f.static_gain, 0.59, kReportGain));
}

TEST(FrfFeatures, MirroredZeroIsFlaggedNonMinimumPhaseByBothVerdicts) {
  const TwoDof apa;
  const Vector omega = log_grid(1.0, 2000.0, 1000);
  FrfFeatureOptions o;
  o.fit.order = 3;
  const FrfFeatures f = frf_features(omega, response(omega, [&](Complex s) { return apa.vs(s, true); }), o);
  ASSERT_EQ(f.antiresonances.size(), 1u);
  const AntiResonance& a = f.antiresonances[0];
  EXPECT_TRUE(near(a.frequency_Hz(), 41.1, kReportFrequency));
  EXPECT_TRUE(a.nonminimum_phase_model);
  EXPECT_GT(a.root.real(), 0.0);
  EXPECT_EQ(a.phase_verdict, PhaseVerdict::kNonMinimumPhase);
  EXPECT_TRUE(near(a.phase_change_deg, -180.0, 0.05));
}

TEST(FrfFeatures, NoisyOverParameterizedFitKeepsOnlyTheRealFeatures) {
  // 1 % noise and twice the needed order: spurious poles must not show up as resonances.
  const TwoDof apa;
  const Vector omega = log_grid(1.0, 2000.0, 1500);
  for (bool mirror : {false, true}) {
    const CVector h = with_noise(response(omega, [&](Complex s) { return apa.vs(s, mirror); }), 0.01, 11);
    FrfFeatureOptions o;
    o.fit.order = 6;
    o.fit.weighting = Weighting::kInverseMagnitude;
    const FrfFeatures f = frf_features(omega, h, o);
    ASSERT_EQ(f.resonances.size(), 1u) << "mirror " << mirror;
    ASSERT_EQ(f.antiresonances.size(), 1u) << "mirror " << mirror;
    EXPECT_TRUE(near(f.resonances[0].frequency_Hz(), 95.4, kReportFrequency));
    EXPECT_TRUE(near(f.antiresonances[0].frequency_Hz(), 41.1, kReportFrequency));
    EXPECT_EQ(f.antiresonances[0].nonminimum_phase_model, mirror);
    EXPECT_EQ(f.antiresonances[0].phase_verdict,
              mirror ? PhaseVerdict::kNonMinimumPhase : PhaseVerdict::kMinimumPhase);
    EXPECT_TRUE(near(f.static_gain, apa.static_gain_vs(), kReportGain));
  }
}

// A pole-zero pair that nearly cancels, 0.6 % above the resonance (what an order-6 fit of the demo's
// u -> d_e put there): the pair's zero is within the 2 % cancellation tolerance of the true pole
// too, but it cancels its own pole, the closest, and the resonance stays (the pairing is one to one).
TEST(FrfFeatures, SpuriousPairBesideTheResonanceLeavesTheResonance) {
  const TwoDof apa;
  const Vector omega = log_grid(1.0, 2000.0, 1000);
  const Complex p = apa.resonance_pole();
  const double wp = std::abs(p) * 1.006, wz = wp * 1.0002, zeta = 0.003;
  const auto pair = [&](Complex s) { return (s * s + 2.0 * zeta * wz * s + wz * wz) / (s * s + 2.0 * zeta * wp * s + wp * wp) * (wp * wp / (wz * wz)); };
  FrfFeatureOptions o;
  o.fit.order = 5;  // the 2-DoF model's 3 and the pair's 2
  const FrfFeatures f = frf_features(omega, response(omega, [&](Complex s) { return apa.de(s) * pair(s); }), o);
  ASSERT_EQ(f.resonances.size(), 1u) << f.fit.brief_report();
  EXPECT_TRUE(near(f.resonances[0].natural_frequency, std::abs(p), 1e-6));
  EXPECT_TRUE(near(f.resonances[0].damping, -p.real() / std::abs(p), 1e-5));
  EXPECT_TRUE(f.antiresonances.empty());  // the pair's zero went with its pole
}

TEST(FrfFeatures, HighPassedSensorVoltageReadsThePlateau) {
  // R = 80.6 kOhm across the C = 5 uF sensor stack: high-pass at 1 / (R C) (report section 2.5).
  const TwoDof apa;
  const double wc = 1.0 / (80.6e3 * 5e-6);
  const Vector omega = log_grid(0.02, 2000.0, 1500);
  const CVector h = response(omega, [&](Complex s) { return apa.vs(s) * s / (s + wc); });
  FrfFeatureOptions o;
  o.fit.order = 4;
  const FrfFeatures f = frf_features(omega, h, o);
  EXPECT_EQ(f.static_gain_source, StaticGainSource::kDataPlateau);
  EXPECT_TRUE(near(f.static_gain, apa.static_gain_vs(), kReportGain));
  ASSERT_EQ(f.antiresonances.size(), 1u);
  EXPECT_TRUE(near(f.antiresonances[0].frequency_Hz(), 41.1, kReportFrequency));

  const HighPassFit hp = fit_high_pass(omega, h, kTwoPi * 3.0);
  EXPECT_TRUE(near(hp.corner_Hz(), 0.39, 0.02));  // the report's 0.39 Hz (2 digits)
  EXPECT_TRUE(near(hp.corner, wc, 0.01));          // within 1 % of 1/(RC): the plant is not flat to 3 Hz
  EXPECT_TRUE(near(hp.gain, apa.static_gain_vs(), 0.01));
}

TEST(FrfFeatures, HighPassFitIsExactOnAPureHighPass) {
  const double wc = kTwoPi * 0.4;
  const Vector omega = log_grid(0.01, 50.0, 300);
  const CVector h = response(omega, [&](Complex s) { return -0.64 * s / (s + wc); });
  const HighPassFit hp = fit_high_pass(omega, h);
  EXPECT_TRUE(near(hp.corner, wc, 1e-9));
  EXPECT_TRUE(near(hp.gain, -0.64, 1e-9));
  EXPECT_LT(hp.relative_rms_error, 1e-9);
  EXPECT_THROW((void)fit_high_pass(omega, h, omega(0)), InputError);  // one point only
  EXPECT_THROW((void)fit_high_pass(omega, CVector::Zero(300)), InputError);
}

TEST(FrfFeatures, SecondOrderFitsRecoverDampedPlants) {
  for (double zeta : {0.02, 0.15, 0.6, 1.5}) {
    const double k = -16.8e-6, wn = kTwoPi * 80.0;
    const Vector omega = log_grid(1.0, 1000.0, 600);
    const CVector h = response(omega, [&](Complex s) { return k * wn * wn / (s * s + 2.0 * zeta * wn * s + wn * wn); });
    for (SecondOrderMethod method : {SecondOrderMethod::kNonlinearLeastSquares, SecondOrderMethod::kVectorFitting}) {
      SecondOrderFitOptions o;
      o.method = method;
      const SecondOrderFit f = fit_second_order(omega, h, o);
      const std::string what = to_string(method) + " zeta " + std::to_string(zeta);
      EXPECT_TRUE(near(f.natural_frequency, wn, 1e-8)) << what;
      EXPECT_TRUE(near(f.damping, zeta, 1e-8)) << what;
      EXPECT_TRUE(near(f.static_gain, k, 1e-8)) << what;
      ASSERT_EQ(f.poles.size(), 2);
      EXPECT_TRUE(near((f.poles(0) * f.poles(1)).real(), wn * wn, 1e-8)) << what;
    }
  }
}

TEST(FrfFeatures, SecondOrderFitWithNoise) {
  const double k = 2.0, wn = kTwoPi * 60.0, zeta = 0.1;
  const Vector omega = log_grid(1.0, 1000.0, 800);
  const CVector h = with_noise(
      response(omega, [&](Complex s) { return k * wn * wn / (s * s + 2.0 * zeta * wn * s + wn * wn); }), 0.01, 5);
  const SecondOrderFit f = fit_second_order(omega, h);
  EXPECT_TRUE(near(f.natural_frequency, wn, 2e-3));
  EXPECT_TRUE(near(f.damping, zeta, 2e-2));
  EXPECT_TRUE(near(f.static_gain, k, 5e-3));
}

TEST(FrfFeatures, FrfOverloadNamesSourceAndOutput) {
  const TwoDof apa;
  dsp::Frf frf;
  frf.freq_Hz = log_grid(1.0, 2000.0, 500) / kTwoPi;
  frf.input = "u";
  frf.outputs = {"de", "Vs"};
  frf.H = {response(kTwoPi * frf.freq_Hz, [&](Complex s) { return apa.de(s); }),
           response(kTwoPi * frf.freq_Hz, [&](Complex s) { return apa.vs(s); })};
  frf.provenance.source = "apa1.mat";
  FrfFeatureOptions o;
  o.fit.order = 3;
  const FrfFeatures f = frf_features(frf, "Vs", o);
  ASSERT_EQ(f.antiresonances.size(), 1u);
  try {
    (void)frf_features(frf, "Fs", o);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("apa1.mat"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("Vs"), std::string::npos) << e.what();
  }
  o.fit.order = 600;  // too many poles for 500 points
  try {
    (void)frf_features(frf, "de", o);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("apa1.mat"), std::string::npos) << e.what();
  }
}

TEST(FrfFeatures, OptionsValidateNamesTheField) {
  const auto field_of = [](const FrfFeatureOptions& o) {
    try {
      o.validate();
    } catch (const InputError& e) {
      return e.field();
    }
    return std::string("no error");
  };
  FrfFeatureOptions o;
  EXPECT_EQ(field_of(o), "no error");
  o.fit.asymptote = Asymptote::kConstantAndLinear;
  EXPECT_EQ(field_of(o), "fit.asymptote");
  o = FrfFeatureOptions{};
  o.max_damping = 1.5;
  EXPECT_EQ(field_of(o), "max_damping");
  o = FrfFeatureOptions{};
  o.phase_band = 0.0;
  EXPECT_EQ(field_of(o), "phase_band");
  o = FrfFeatureOptions{};
  o.fit.order = 0;
  EXPECT_EQ(field_of(o), "order");
  SecondOrderFitOptions so;
  so.max_iterations = 0;
  EXPECT_THROW(so.validate(), InputError);
}

TEST(FrfFeatures, EnumsRoundTripThroughStrings) {
  for (auto v : {StaticGainSource::kModelDcGain, StaticGainSource::kDataPlateau}) {
    EXPECT_EQ(static_gain_source_from_string(to_string(v)), v);
  }
  for (auto v : {PhaseVerdict::kMinimumPhase, PhaseVerdict::kNonMinimumPhase, PhaseVerdict::kUndetermined}) {
    EXPECT_EQ(phase_verdict_from_string(to_string(v)), v);
  }
  for (auto v : {SecondOrderMethod::kNonlinearLeastSquares, SecondOrderMethod::kVectorFitting}) {
    EXPECT_EQ(second_order_method_from_string(to_string(v)), v);
  }
  EXPECT_THROW((void)phase_verdict_from_string("nmp"), InputError);
}

}  // namespace
}  // namespace piezobench::ident
