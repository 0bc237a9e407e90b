// Tuning the 2-DoF model on FRFs of a 2-DoF actuator whose parameters differ from Table 3.1,
// computed here by a direct solve of the 2x2 dynamic-stiffness system (not by the model code under
// test), with and without 1 % complex noise.
#include "piezobench/apa/tuning.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include <nlohmann/json.hpp>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/io/frf_file.hpp"
#include "piezobench/lti/freqresp.hpp"
#include "test_util.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::apa {
namespace {

using lti::Complex;
using lti::Index;
using test::near;

// The acceptance: stiffnesses and gains within 2 %, stack dampings within 10 % with 1 % noise.
constexpr double kStiffnessAndGain = 0.02;
constexpr double kStackDamping = 0.10;

// An actuator unlike Table 3.1: stiffer shell, ke = 2 ka but ce / ca = 3 (not 2), other gains.
TwoDofParams truth() {
  TwoDofParams p;
  p.m = 5.7;
  p.k1 = 0.45e6;
  p.c1 = 8.0;
  p.ka = 3.0e6;
  p.ke = 6.0e6;
  p.ca = 40.0;
  p.ce = 120.0;
  p.ga = -3.1;
  p.gs = 0.52e6;
  return p;
}

// The bench FRFs u -> [d_e, Vs] by direct solve; noise: H (1 + n), n complex Gaussian with
// E|n|^2 = noise^2.
dsp::Frf make_frf(const TwoDofParams& p, const TwoDofBench& b, const lti::Vector& f_Hz, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, noise / std::sqrt(2.0));
  dsp::Frf frf;
  frf.freq_Hz = f_Hz;
  frf.input = "u";
  frf.outputs = {"de", "Vs"};
  frf.H.assign(2, lti::CVector(f_Hz.size()));
  for (Index k = 0; k < f_Hz.size(); ++k) {
    const Complex s(0.0, kTwoPi * f_Hz(k));
    const Complex z1 = p.k1 + p.c1 * s, ze = p.ke + p.ce * s, za = p.ka + p.ca * s;
    Eigen::Matrix2cd K;
    K << p.m * s * s + z1 + ze, -ze, -ze, ze + za;
    const Eigen::Vector2cd x = K.fullPivLu().solve(Eigen::Vector2cd(0.0, p.ga * b.amplifier_gain));
    Complex de = x(0), vs = p.gs * (x(0) - x(1));
    if (b.has_hpf()) vs *= s / (s + 1.0 / (b.hpf_resistance * b.hpf_capacitance));
    de *= std::exp(-s * b.delay);
    vs *= std::exp(-s * b.delay);
    frf.H[0](k) = de * Complex(1.0 + gauss(rng), gauss(rng));
    frf.H[1](k) = vs * Complex(1.0 + gauss(rng), gauss(rng));
  }
  frf.provenance.source = "synthetic";
  return frf;
}

void expect_params(const TwoDofParams& got, const TwoDofParams& want, double stiff_gain_tol, double damping_tol) {
  for (const char* n : {"k1", "ke", "ka", "ga", "gs"}) {
    EXPECT_TRUE(near(got.get(n), want.get(n), stiff_gain_tol)) << n;
  }
  for (const char* n : {"ce", "ca"}) EXPECT_TRUE(near(got.get(n), want.get(n), damping_tol)) << n;
  EXPECT_EQ(got.m, want.m);
}

TEST(Tuning, NoiseFreeDataComeBackExactly) {
  const TwoDofParams p = truth();
  const dsp::Frf frf = make_frf(p, TwoDofBench{}, lti::logspace(0.0, std::log10(2000.0), 600), 0.0, 1);
  TuningOptions o;
  o.stack_damping_ratio = 0.0;  // the truth's ce / ca is 3
  const TwoDofTuning t = tune_two_dof(frf, o);
  EXPECT_EQ(t.status, TuningStatus::kConverged) << t.message;
  expect_params(t.params, p, 1e-6, 1e-5);
  EXPECT_TRUE(near(t.params.c1, p.c1, 1e-5));
  EXPECT_LT(t.fit_error_de, 1e-7);
  EXPECT_LT(t.fit_error_vs, 1e-7);
  EXPECT_LT(t.fit_error_vs, t.initial_fit_error_vs);
  EXPECT_EQ(t.points, 600);
  // The features of step 1: the resonance and the zero of Vs (exact: sqrt(k1 / m)).
  EXPECT_TRUE(near(t.features.antiresonance, std::sqrt(p.k1 / p.m), 0.01));
  EXPECT_TRUE(near(t.features.resonance, std::sqrt(p.total_stiffness() / p.m), 0.01));
  EXPECT_LT(t.features.static_gain_de, 0.0);
  EXPECT_GT(t.features.static_gain_vs, 0.0);
}

TEST(Tuning, OnePercentNoiseMeetsTheAcceptance) {
  const TwoDofParams p = truth();
  for (unsigned seed : {11U, 12U, 13U}) {
    SCOPED_TRACE(seed);
    const dsp::Frf frf = make_frf(p, TwoDofBench{}, lti::logspace(0.0, std::log10(2000.0), 600), 0.01, seed);
    TuningOptions o;
    o.stack_damping_ratio = 0.0;  // the truth's ce / ca is 3
    const TwoDofTuning t = tune_two_dof(frf, o);
    EXPECT_EQ(t.status, TuningStatus::kConverged) << t.message;
    expect_params(t.params, p, kStiffnessAndGain, kStackDamping);
    // The fit error is the noise: E|n| = 1 % rms.
    EXPECT_NEAR(t.fit_error_de, 0.01, 0.002);
    EXPECT_NEAR(t.fit_error_vs, 0.01, 0.002);
  }
}

TEST(Tuning, WelchLikeLinearGridWithTheBenchAroundIt) {
  // 1 Hz resolution up to 2 kHz as from a 1 s Welch segment at 10 kHz, through a 15 V/V amplifier,
  // the 0.4 Hz high-pass on Vs and a 100 us delay, all known to the tuning.
  const TwoDofParams p = truth();
  TwoDofBench b;
  b.amplifier_gain = 15.0;
  b.hpf_resistance = 80.6e3;
  b.hpf_capacitance = 5e-6;
  b.delay = 100e-6;
  lti::Vector f = lti::Vector::LinSpaced(2001, 0.0, 2000.0);  // includes 0 Hz, never used
  const dsp::Frf frf = make_frf(p, b, f, 0.01, 7);
  TuningOptions o;
  o.bench = b;
  o.stack_damping_ratio = 0.0;  // the truth's ce / ca is 3
  const TwoDofTuning t = tune_two_dof(frf, o);
  EXPECT_EQ(t.status, TuningStatus::kConverged) << t.message;
  EXPECT_EQ(t.points, 2000);
  expect_params(t.params, p, kStiffnessAndGain, kStackDamping);
}

TEST(Tuning, ReportProcedureAloneOnTable31) {
  // The model of Table 3.1 satisfies the procedure's assumptions (ke = 2 ka, ce = 2 ca): step 1
  // alone lands close, limited by reading the peak and the dip on a grid.
  const TwoDofParams p;
  const dsp::Frf frf = make_frf(p, TwoDofBench{}, lti::logspace(0.0, std::log10(2000.0), 2000), 0.0, 1);
  TuningOptions o;
  o.refine = false;
  o.stack_damping_ratio = 2.0;
  const TwoDofTuning t = tune_two_dof(frf, o);
  EXPECT_EQ(t.status, TuningStatus::kNotRefined);
  EXPECT_EQ(t.iterations, 0);
  for (const char* n : {"k1", "ke", "ka", "ga", "gs"}) EXPECT_TRUE(near(t.params.get(n), p.get(n), 0.01)) << n;
  EXPECT_TRUE(near(t.params.ke / t.params.ka, 2.0, 1e-12));
  EXPECT_TRUE(near(t.params.ce / t.params.ca, 2.0, 1e-12));
  // And the refinement keeps the imposed ratios.
  o.refine = true;
  const TwoDofTuning r = tune_two_dof(frf, o);
  EXPECT_TRUE(near(r.params.ce / r.params.ca, 2.0, 1e-12));
  for (const auto& n : TwoDofParams::names()) EXPECT_TRUE(near(r.params.get(n), p.get(n), 1e-6)) << n;
}

TEST(Tuning, FreeStiffnessRatio) {
  // ke free: the split ke / ka rests on the node relaxation (~8 kHz), so it needs clean data
  // reaching towards it; noise-free data up to 5 kHz suffice.
  TwoDofParams p = truth();
  p.ke = 4.5e6;  // ke / ka = 1.5, while the start assumes 2
  const dsp::Frf frf = make_frf(p, TwoDofBench{}, lti::logspace(0.0, std::log10(5000.0), 800), 0.0, 1);
  TuningOptions o;
  o.stack_stiffness_ratio = 0.0;
  o.stack_damping_ratio = 0.0;
  const TwoDofTuning t = tune_two_dof(frf, o);
  EXPECT_EQ(t.status, TuningStatus::kConverged) << t.message;
  expect_params(t.params, p, 1e-4, 1e-3);
}

// Issue 30's held-out check: an actuator with other mass, stiffnesses and dampings than the report's
// (and than truth()), ke / ka = ce / ca = 2, 1 % complex noise whose variance the FRF carries
// (coherence 1 / (1 + 2 n_d eps^2) with n_d = 40). Every tuned parameter is within 10 % of the truth
// or reported undetermined, by default and with the ratios freed; a parameter outside its 95 %
// interval by more than a factor 3 is never called good; the standard errors are there.
TEST(Tuning, HeldOutActuatorWithinTenPercentOrUndetermined) {
  TwoDofParams p;
  p.m = 3.2;
  p.k1 = 0.9e6;
  p.c1 = 25.0;
  p.ka = 6.0e6;
  p.ke = 12.0e6;
  p.ca = 65.0;
  p.ce = 130.0;
  p.ga = -4.2;
  p.gs = 0.3e6;
  const double noise = 0.01, n_d = 40.0;
  for (const bool free : {false, true}) {
    for (unsigned seed : {21U, 22U, 23U}) {
      SCOPED_TRACE(::testing::Message() << (free ? "ratios free" : "ratios 2") << ", seed " << seed);
      dsp::Frf frf = make_frf(p, TwoDofBench{}, lti::Vector::LinSpaced(2000, 1.0, 2000.0), noise, seed);
      const double eps = noise / std::sqrt(2.0);
      frf.coherence.assign(2, Eigen::VectorXd::Constant(frf.freq_Hz.size(), 1.0 / (1.0 + 2.0 * n_d * eps * eps)));
      frf.provenance.effective_averages = n_d;
      TuningOptions o;
      o.mass = p.m;  // known, as on the bench (the suspended mass)
      if (free) o.stack_stiffness_ratio = o.stack_damping_ratio = 0.0;
      const TwoDofTuning t = tune_two_dof(frf, o);
      ASSERT_FALSE(t.uncertainty.empty());
      EXPECT_TRUE(t.uncertainty.from_data_variance);
      for (const auto& name : TwoDofParams::names()) {
        if (name == "m") continue;
        const bool undetermined = std::find(t.undetermined.begin(), t.undetermined.end(), name) != t.undetermined.end();
        const double got = t.params.get(name), want = p.get(name), se = t.uncertainty.standard_error_of(name);
        if (!undetermined) EXPECT_TRUE(near(got, want, 0.10)) << name << " = " << got << " +- " << se << ", truth " << want;
        if (!t.quality.poor()) EXPECT_LE(std::abs(got - want), 3.0 * 1.96 * se) << name;
      }
      if (!t.undetermined.empty()) EXPECT_TRUE(t.quality.poor()) << t.quality.summary();
    }
  }
}

// Output noise (issue 30): the noise of a measured FRF is additive, std_H the same across the
// anti-resonance (the output noise over the input's spectrum), so the dip of |Vs| is where the relative
// noise is largest. The estimator must not be biased by it (the relative error H_model / H_data - 1
// was: E[1 / (h + n)] shrinks towards 0 where |h| ~ sigma, and the dampings came out c1 +54 %,
// ca -30 % on the virtual bench), and the intervals must cover: over 40 seeds, the mean of each
// parameter is within 0.5 standard errors of the truth (a bias of 1 standard error fails), and
// the mean of z^2 = ((value - truth) / se)^2 lies in [0.5, 2] (1 for a right standard error; one
// wrong by a factor 1.5 fails).
TEST(Tuning, AdditiveOutputNoiseNeitherBiasesNorMiscalibrates) {
  TwoDofParams p;  // a lightly damped shell: the dip of |Vs| (62 Hz) is 0.12 % of its mean level
  p.m = 4.0;
  p.k1 = 0.6e6;
  p.c1 = 12.0;
  p.ka = 4.0e6;
  p.ke = 8.0e6;
  p.ca = 45.0;
  p.ce = 90.0;
  p.ga = -3.0;
  p.gs = 0.4e6;
  const lti::Vector f = lti::Vector::LinSpaced(400, 20.0, 400.0);
  const dsp::Frf clean = make_frf(p, TwoDofBench{}, f, 0.0, 1);
  // sigma: 0.6 % of each output's mean |H| (a relative error of 5 at the dip, above 1 on its 5 lines;
  // the former estimator failed this at 0.3 %: ga's mean z +0.81, k1, c1, ka, ca +-0.46).
  const double rel = 0.006, n_d = 20.0;
  std::vector<double> sigma;
  for (const auto& h : clean.H) sigma.push_back(rel * h.cwiseAbs().mean());
  const std::vector<std::string> names = {"k1", "c1", "ka", "ca", "ga", "gs"};
  std::vector<double> z_sum(names.size(), 0.0), z2_sum(names.size(), 0.0);
  const int seeds = 40;
  for (int seed = 0; seed < seeds; ++seed) {
    std::mt19937 rng(100 + static_cast<unsigned>(seed));
    std::normal_distribution<double> gauss(0.0, 1.0);
    dsp::Frf frf = clean;
    frf.std_H.clear();
    frf.coherence.clear();
    frf.provenance.effective_averages = n_d;  // the coherence that gives the same std_H (a file's FRF)
    for (std::size_t o = 0; o < 2; ++o) {
      for (Index k = 0; k < f.size(); ++k) frf.H[o](k) += sigma[o] * Complex(gauss(rng), gauss(rng));
      frf.std_H.emplace_back(Eigen::VectorXd::Constant(f.size(), sigma[o]));
      const Eigen::VectorXd eps2 = (sigma[o] * clean.H[o].cwiseAbs().cwiseInverse()).array().square();
      frf.coherence.emplace_back((1.0 + 2.0 * n_d * eps2.array()).inverse());
    }
    TuningOptions o;
    o.mass = p.m;
    const TwoDofTuning t = tune_two_dof(frf, o);
    ASSERT_TRUE(t.uncertainty.from_data_variance);
    for (std::size_t i = 0; i < names.size(); ++i) {
      const double z = (t.params.get(names[i]) - p.get(names[i])) / t.uncertainty.standard_error_of(names[i]);
      z_sum[i] += z;
      z2_sum[i] += z * z;
    }
  }
  for (std::size_t i = 0; i < names.size(); ++i) {
    const double mean_z = z_sum[i] / seeds, mean_z2 = z2_sum[i] / seeds;
    EXPECT_LT(std::abs(mean_z), 0.5) << names[i];
    EXPECT_GT(mean_z2, 0.5) << names[i];
    EXPECT_LT(mean_z2, 2.0) << names[i];
  }
}

// The third step (apa/tuning.cpp, reweight_stiffnesses; docs/uncertainty.md, section 4): with the
// FRF's std_H and n_d k1, ka and gs are refitted with the model's variance as weights, the dampers
// and ga held. Without n_d (std_H alone) the first two passes see the same weights (from std_H) and
// there is no third step: the dampers and ga come out the same to round-off, k1, ka and gs move by a
// fraction of their standard error.
TEST(Tuning, ThirdStepRefitsTheStiffnessesAndGainsAndHoldsTheDampers) {
  const TwoDofParams p = truth();
  const lti::Vector f = lti::Vector::LinSpaced(400, 20.0, 400.0);
  dsp::Frf with_nd = make_frf(p, TwoDofBench{}, f, 0.0, 1);
  std::mt19937 rng(7);
  std::normal_distribution<double> gauss(0.0, 1.0);
  with_nd.std_H.clear();
  for (auto& h : with_nd.H) {
    const double sigma = 0.004 * h.cwiseAbs().mean();
    for (Index k = 0; k < f.size(); ++k) h(k) += sigma * Complex(gauss(rng), gauss(rng));
    with_nd.std_H.emplace_back(Eigen::VectorXd::Constant(f.size(), sigma));
  }
  dsp::Frf without_nd = with_nd;
  with_nd.provenance.effective_averages = 20.0;
  TuningOptions o;
  o.mass = p.m;
  const TwoDofTuning a = tune_two_dof(with_nd, o), b = tune_two_dof(without_nd, o);
  EXPECT_NE(a.message.find("weighted by the model's variance"), std::string::npos) << a.message;
  EXPECT_EQ(b.message.find("weighted by the model's variance"), std::string::npos) << b.message;
  for (const char* n : {"c1", "ca", "ce", "ga"}) EXPECT_TRUE(near(a.params.get(n), b.params.get(n), 1e-12)) << n;
  bool moved = false;
  for (const char* n : {"k1", "ka", "gs"}) {
    const double se = a.uncertainty.standard_error_of(n);
    ASSERT_TRUE(std::isfinite(se) && se > 0.0) << n;
    EXPECT_LT(std::abs(a.params.get(n) - b.params.get(n)), se) << n;
    moved = moved || a.params.get(n) != b.params.get(n);
    EXPECT_TRUE(near(a.params.get(n), p.get(n), kStiffnessAndGain)) << n;
  }
  EXPECT_TRUE(moved);
  EXPECT_NEAR(a.params.ke, 2.0 * a.params.ka, 1e-9 * a.params.ke);
}

TEST(Tuning, BadInput) {
  const TwoDofParams p = truth();
  dsp::Frf frf = make_frf(p, TwoDofBench{}, lti::logspace(0.0, 3.0, 100), 0.0, 1);
  TuningOptions o;
  o.vs_output = "Vsensor";
  EXPECT_THROW((void)tune_two_dof(frf, o), InputError);
  o = TuningOptions{};
  o.fmin_Hz = 500.0;
  o.fmax_Hz = 502.0;
  try {
    (void)tune_two_dof(frf, o);
    ADD_FAILURE() << "too few points accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "freq_Hz");
  }
  // A band above the resonance has no peak: a numerical failure that other settings may fix.
  o.fmin_Hz = 200.0;
  o.fmax_Hz = 0.0;
  try {
    (void)tune_two_dof(frf, o);
    ADD_FAILURE() << "no resonance accepted";
  } catch (const NumericalError& e) {
    EXPECT_TRUE(e.retry_may_help());
  }
  frf.H[1](10) = Complex(NAN, 0.0);
  EXPECT_THROW((void)tune_two_dof(frf), InputError);

  const struct {
    const char* field;
    void (*apply)(TuningOptions&);
  } bad[] = {
      {"mass", [](TuningOptions& t) { t.mass = 0.0; }},
      {"amplifier_gain", [](TuningOptions& t) { t.bench.amplifier_gain = 0.0; }},
      {"bench.suspended_mass", [](TuningOptions& t) { t.bench.added_mass = 1.0; }},
      {"fmax_Hz", [](TuningOptions& t) { t.fmin_Hz = 10.0, t.fmax_Hz = 5.0; }},
      {"min_coherence", [](TuningOptions& t) { t.min_coherence = 1.0; }},
      {"stack_stiffness_ratio", [](TuningOptions& t) { t.stack_stiffness_ratio = -2.0; }},
      {"max_iterations", [](TuningOptions& t) { t.max_iterations = 0; }},
  };
  for (const auto& b : bad) {
    TuningOptions t;
    b.apply(t);
    try {
      t.validate();
      ADD_FAILURE() << b.field << " accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), b.field);
    }
  }
}

// The scipy fixture's FRF, its plant fits and the campaign's tuning options (20-500 Hz, coherence 0.5).
struct ScipyFixture {
  dsp::Frf frf = io::read_frf(test::fixture_path("ident/two_dof_welch_frf.csv"));
  ident::ActuatorPlants plants = ident::fit_actuator_plants(2.0 * std::numbers::pi * frf.freq_Hz, frf.H[0], frf.coherence[0],
                                                            frf.H[1], frf.coherence[1]);
  TuningOptions options = [] {
    TuningOptions o;
    o.fmin_Hz = 20.0;
    o.fmax_Hz = 500.0;
    o.min_coherence = 0.5;
    return o;
  }();
};

// The campaign's procedure on a lab's Welch FRF (scripts/fixtures/make_two_dof_frf_fixtures.py: the
// 2-DoF model of Table 3.1 simulated by scipy with the bench's high-pass and delay): the chain
// found by the plant fits is removed and the stiffnesses and gains come back within 3 %; without
// removing it, the verdict says the tuning is not to be trusted as is.
TEST(Tuning, MeasuredProcedureOnAScipyWelchFrf) {
  const ScipyFixture f;
  const auto truth = nlohmann::json::parse(test::read_text(test::fixture_path("ident/two_dof_welch_truth.json")));
  ASSERT_TRUE(f.plants.de && f.plants.vs);
  const TwoDofTuning t = tune_two_dof_measured(f.frf, f.options, &*f.plants.de, &*f.plants.vs);
  for (const char* key : {"k1", "ke", "ka", "ga", "gs"}) {
    EXPECT_TRUE(test::near(t.params.get(key), truth[key].get<double>(), 0.03)) << key;
  }
  // The shell's damping c1 (5 N s/m against the stacks' 150) does not show in this FRF: the refinement
  // drives it towards 0, and it is reported undetermined (so the verdict is poor) rather than printed
  // as a value; every other parameter is within 10 % or undetermined too.
  for (const auto& key : TwoDofParams::names()) {
    const bool undetermined = std::find(t.undetermined.begin(), t.undetermined.end(), key) != t.undetermined.end();
    if (!undetermined) EXPECT_TRUE(test::near(t.params.get(key), truth[key].get<double>(), 0.10)) << key;
  }
  EXPECT_EQ(t.undetermined, std::vector<std::string>{"c1"});
  EXPECT_TRUE(t.quality.poor()) << t.quality.summary();
  EXPECT_NEAR(t.bench.delay, truth["effective_delay_s"].get<double>(), 0.05 * truth["effective_delay_s"].get<double>());
  EXPECT_NEAR(t.bench.hpf_corner() / (2.0 * std::numbers::pi), 0.39, 0.04);
}

// The refinement ends where the data put it, not where round-off does: on the scipy fixture the
// shell's damping c1 is not seen and ran towards exp(-2.8e8); with ||x|| that large the solver's step
// tolerance (relative to ||x||) stopped it while ce and ca still moved by per cents, so a change of
// the delay in its 13th digit moved ce from 105 to 110 N s/m (and out of 10 % of the truth). The
// parameters now stay within their bounds during the fit: the same data 1e-12 apart give the same
// tuning to 1e-6.
TEST(Tuning, RefinementDoesNotDependOnRoundOff) {
  const ScipyFixture f;
  ASSERT_TRUE(f.plants.de && f.plants.vs);
  const TwoDofTuning a = tune_two_dof_measured(f.frf, f.options, &*f.plants.de, &*f.plants.vs);
  ident::DelayedSecondOrderFit de = *f.plants.de;
  de.delay *= 1.0 + 1e-12;
  const TwoDofTuning b = tune_two_dof_measured(f.frf, f.options, &de, &*f.plants.vs);
  for (const auto& key : TwoDofParams::names()) {
    if (key == "c1") continue;  // undetermined, at its bound in both
    EXPECT_TRUE(test::near(a.params.get(key), b.params.get(key), 1e-6)) << key;
  }
}

TEST(Tuning, StatusNames) {
  for (const TuningStatus s :
       {TuningStatus::kConverged, TuningStatus::kMaxIterations, TuningStatus::kNoProgress, TuningStatus::kNotRefined}) {
    EXPECT_EQ(tuning_status_from_string(to_string(s)), s);
  }
  EXPECT_THROW((void)tuning_status_from_string("ok"), InputError);
}

}  // namespace
}  // namespace piezobench::apa
