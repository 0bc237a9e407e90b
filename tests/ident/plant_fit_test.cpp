#include "piezobench/ident/plant_fit.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <unsupported/Eigen/FFT>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "piezobench/core/fit_covariance.hpp"
#include "piezobench/dsp/frf.hpp"
#include "piezobench/dsp/welch.hpp"
#include "piezobench/io/frf_file.hpp"
#include "piezobench/lti/freqresp.hpp"
#include "test_util.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::ident {
namespace {

using lti::Vector;
using test::near;

// The report's plant (section 2.6) with the zero mirrored or not and a 200 us delay.
IffPlantFit report_plant(double xz) {
  IffPlantFit p;
  p.g0 = 0.64;
  p.wz = kTwoPi * 42.7;
  p.xz = xz;
  p.wp = kTwoPi * 95.2;
  p.xp = 0.02;
  p.w_hpf = kTwoPi * 0.4;
  p.delay = 200e-6;
  return p;
}

// A Welch-like grid: 0.25 Hz steps up to 1 kHz.
Vector grid() {
  return Vector::LinSpaced(4000, 0.25, 1000.0) * kTwoPi;
}

void expect_recovered(const IffPlantFit& fit, const IffPlantFit& p, double tol) {
  EXPECT_TRUE(near(fit.g0, p.g0, tol));
  EXPECT_TRUE(near(fit.wz, p.wz, tol));
  EXPECT_TRUE(near(fit.xz, p.xz, tol * 10));
  EXPECT_TRUE(near(fit.wp, p.wp, tol));
  EXPECT_TRUE(near(fit.xp, p.xp, tol * 10));
  EXPECT_TRUE(near(fit.w_hpf, p.w_hpf, tol * 10));
  EXPECT_TRUE(near(fit.delay, p.delay, tol * 10));
}

// The model's response equals the transfer function's (an independent evaluation through lti).
TEST(IffPlantFit, ResponseMatchesTransferFunction) {
  const IffPlantFit p = report_plant(-0.004);
  const Vector w = Vector::LinSpaced(50, 1.0, 5000.0);
  const lti::CVector a = p.response(w);
  const lti::CVector b = lti::freqresp(p.transfer_function(), w);
  EXPECT_TRUE(test::all_near(a, b, {1e-10, 0.0}));
  EXPECT_TRUE(p.zero_is_nonminimum_phase());
}

// The NMP verdict (report section 2.4) on the report's plant with the demo's delay (400 us) and a
// zero as light as the demo units' (xz = -+0.003: 2 xz f_z = 0.26 Hz wide, about one 0.25 Hz Welch
// line), with additive noise of 0.5 % of g0 (the sensor's noise does not shrink in the dip). The
// data's phase change across the dip sits at 180 +- 4 deg in magnitude (seed 4: 178.3 deg built with
// g++ -O3, 176.4 deg with clang -O1: the band examined follows the fitted zero's damping, which
// the compilers' round-off moves), well inside the 20 deg ambiguity: the
// plant fit decides, and calls the mirrored zero non-minimum-phase for every seed and the
// minimum-phase one never. (At 0.7 % noise and |xz| <= 0.0025 the fitted xz collapses towards 0
// and can flip along with the phase: both read the same few lines at the dip.)
TEST(ZeroPhaseVerdict, AmbiguousPhaseChangeIsDecidedByThePlantFit) {
  const Vector w_all = grid();
  std::vector<Eigen::Index> keep;
  for (Eigen::Index k = 0; k < w_all.size(); ++k) {
    if (w_all(k) >= kTwoPi * 20.0 && w_all(k) <= kTwoPi * 500.0) keep.push_back(k);
  }
  for (const double xz : {-0.003, 0.003}) {
    IffPlantFit p = report_plant(xz);
    p.delay = 400e-6;
    for (const unsigned seed : {1u, 2u, 3u, 4u, 5u, 6u, 7u, 8u}) {
      lti::CVector h = p.response(w_all);
      std::mt19937 rng(seed);
      std::normal_distribution<double> n(0.0, 0.005 * p.g0 / std::sqrt(2.0));
      for (Eigen::Index k = 0; k < h.size(); ++k) h(k) += std::complex<double>(n(rng), n(rng));
      // The campaign's two analyses of u -> Vs: the features (vector fit, phase across the dip) in
      // the band, and the plant fit with the corner known.
      Vector w(static_cast<Eigen::Index>(keep.size()));
      lti::CVector hb(w.size());
      for (std::size_t i = 0; i < keep.size(); ++i) {
        w(static_cast<Eigen::Index>(i)) = w_all(keep[i]);
        hb(static_cast<Eigen::Index>(i)) = h(keep[i]);
      }
      FrfFeatureOptions fo;
      fo.fit.order = 6;
      fo.fit.fail_if_not_converged = false;
      const FrfFeatures f = frf_features(w, hb, fo);
      const AntiResonance* zero = nullptr;
      for (const AntiResonance& a : f.antiresonances) {
        if (std::abs(a.natural_frequency / p.wz - 1.0) < 0.01) zero = &a;
      }
      ASSERT_NE(zero, nullptr) << "xz " << xz << " seed " << seed;
      // Mirrored: 180 +- 4 deg; minimum-phase: the delay takes a few more degrees off.
      EXPECT_NEAR(std::abs(zero->phase_change_deg), 180.0, xz < 0.0 ? 4.0 : 10.0) << "xz " << xz << " seed " << seed;
      IffPlantFitOptions o;
      o.fmin_Hz = 20.0;
      o.fmax_Hz = 500.0;
      o.fixed_w_hpf = p.w_hpf;
      const IffPlantFit fit = fit_iff_plant(w_all, h, Vector(), o);
      const ZeroPhaseVerdict v = zero_phase_verdict(zero, &fit);
      ASSERT_TRUE(v.nonminimum_phase.has_value()) << "xz " << xz << " seed " << seed << ": " << v.reason;
      EXPECT_EQ(*v.nonminimum_phase, xz < 0.0) << "xz " << xz << " seed " << seed << ": " << v.reason;
      EXPECT_EQ(v.from, "iff-plant-fit") << v.reason;
      EXPECT_NE(v.reason.find("plant fit zero xz = "), std::string::npos) << v.reason;
      EXPECT_NE(v.reason.find("; phase change "), std::string::npos) << v.reason;
    }
  }
}

// u filtered by the continuous response G(j omega) exactly, as a circular convolution over the
// record (the FFT of u times G at each bin, conjugate for the negative frequencies): a stationary
// record whose FRF is G itself (a zero-order-hold simulation would not do: the feedthrough of a
// proper plant skips the half-sample lag of the rest and fills a lightly damped dip).
Eigen::VectorXd filtered(const Eigen::VectorXd& u, double fs, const IffPlantFit& g) {
  const auto n = static_cast<Eigen::Index>(u.size());
  Eigen::FFT<double> fft;
  std::vector<double> in(u.data(), u.data() + n), out;
  std::vector<std::complex<double>> spectrum;
  fft.fwd(spectrum, in);
  for (Eigen::Index k = 0; k < n; ++k) {
    const Eigen::Index m = k <= n / 2 ? k : n - k;
    const std::complex<double> h = m == 0 ? std::complex<double>(0.0) : g.response(Vector::Constant(1, kTwoPi * fs * static_cast<double>(m) / static_cast<double>(n)))(0);
    spectrum[static_cast<std::size_t>(k)] *= k <= n / 2 ? h : std::conj(h);
  }
  fft.inv(out, spectrum);
  return Eigen::Map<const Eigen::VectorXd>(out.data(), n);
}

// A held-out plant (not the report's: anti-resonance 61 Hz, resonance 133 Hz, xp 0.03, corner 0.8 Hz,
// delay 200 us) with a truly mirrored (xz = -0.006) or truly minimum-phase (+0.006) zero pair, its
// dip (0.7 Hz wide) narrower than a line: white noise u through the plant (60 s at 2 kHz), Gaussian
// noise on the output of 0.1 % to 2 % of its rms, H1 by Welch with 1 Hz lines, and the plant fit
// weighted by the FRF's variance. The verdict from the 95 % interval of xz is never the wrong one;
// at 0.1 % it is always given; a zero 12 times lighter
// (xz = -+0.0005) is hidden by 2 % noise: undetermined.
TEST(ZeroPhaseVerdict, HeldOutPlantsNeverTheWrongVerdictAtAnyNoise) {
  const double fs = 2e3;
  int decided_low = 0, cases_low = 0, undetermined_high = 0;
  for (const double xz : {-0.006, 0.006, -0.0005, 0.0005}) {
    IffPlantFit p;
    p.g0 = 0.4;
    p.wz = kTwoPi * 61.0;
    p.xz = xz;
    p.wp = kTwoPi * 133.0;
    p.xp = 0.03;
    p.w_hpf = kTwoPi * 0.8;
    p.delay = 200e-6;
    for (const double noise : {0.001, 0.003, 0.01, 0.02}) {
      for (const unsigned seed : {1u, 2u, 3u}) {
        std::mt19937_64 rng(seed);
        std::normal_distribution<double> n01;
        const Eigen::Index n = static_cast<Eigen::Index>(60.0 * fs);
        Eigen::VectorXd u(n);
        for (Eigen::Index i = 0; i < n; ++i) u(i) = n01(rng);
        Eigen::VectorXd y = filtered(u, fs, p);
        const double rms = std::sqrt(y.squaredNorm() / static_cast<double>(n));
        for (Eigen::Index i = 0; i < n; ++i) y(i) += noise * rms * n01(rng);
        dsp::WelchOptions wo;
        wo.nfft = 2000;
        wo.threads = 1;
        const dsp::Frf frf = dsp::estimate_frf(dsp::channel("u", u), {dsp::channel("Vs", y)}, fs, wo).frf;
        IffPlantFitOptions o;
        o.fmin_Hz = 20.0;
        o.fmax_Hz = 300.0;
        o.fixed_w_hpf = p.w_hpf;
        o.effective_averages = frf.provenance.effective_averages;
        const IffPlantFit fit = fit_iff_plant(kTwoPi * frf.freq_Hz, frf.H[0], frf.coherence[0], o);
        EXPECT_TRUE(fit.uncertainty.from_data_variance);
        const ZeroPhaseVerdict v = zero_phase_verdict(nullptr, &fit);
        const std::string what = fmt::format("xz {} noise {} seed {}: {}", xz, noise, seed, v.reason);
        EXPECT_EQ(v.from, "iff-plant-fit") << what;
        if (v.nonminimum_phase) {
          EXPECT_EQ(*v.nonminimum_phase, xz < 0.0) << what;
        }
        if (noise == 0.001 && std::abs(xz) > 0.001) {
          ++cases_low;
          decided_low += v.nonminimum_phase ? 1 : 0;
        }
        if (noise == 0.02 && std::abs(xz) < 0.001 && !v.nonminimum_phase) ++undetermined_high;
      }
    }
  }
  EXPECT_EQ(decided_low, cases_low);
  EXPECT_GT(undetermined_high, 0);
}

// An FRF that records no variance (no coherence, as many lab files): the plant fit estimates the
// noise from its own residuals (additive and proportional, dsp::estimate_frf_noise), weights a second
// fit with it and takes its standard errors from it. Before, the relative residual of the dip's lines,
// where the sensor's noise is as large as H, decided xz with the standard error of the average line:
// at 0.5-2 % noise 5-20 % of the seeds got a confident wrong verdict. The report's plant (400 us delay)
// and a held-out one (61/133 Hz, xp 0.03, 0.8 Hz corner, 200 us), each zero truly mirrored or not,
// complex Gaussian noise of 0.1 % to 2 % of g0 on every line: never the wrong verdict; every verdict
// given at 0.1 %; xz's 95 % interval covers the truth in at least 90 % of the cases.
TEST(ZeroPhaseVerdict, WithoutTheFrfsVarianceNeverTheWrongVerdict) {
  const Vector w_all = grid();
  int cases = 0, covered = 0, decided_low = 0, cases_low = 0, undetermined = 0;
  for (const bool held_out : {false, true}) {
    for (const double xz : {-0.006, 0.006, -0.0015, 0.0015}) {
      IffPlantFit p = report_plant(xz);
      p.delay = 400e-6;
      if (held_out) p.g0 = 0.4, p.wz = kTwoPi * 61.0, p.wp = kTwoPi * 133.0, p.xp = 0.03, p.w_hpf = kTwoPi * 0.8, p.delay = 200e-6;
      for (const double noise : {0.001, 0.005, 0.01, 0.02}) {
        for (const unsigned seed : {1u, 2u, 3u, 4u}) {
          lti::CVector h = p.response(w_all);
          std::mt19937 rng(seed);
          std::normal_distribution<double> n(0.0, noise * p.g0 / std::sqrt(2.0));
          for (Eigen::Index k = 0; k < h.size(); ++k) h(k) += std::complex<double>(n(rng), n(rng));
          IffPlantFitOptions o;
          o.fmin_Hz = 20.0;
          o.fmax_Hz = 500.0;
          o.fixed_w_hpf = p.w_hpf;
          const IffPlantFit fit = fit_iff_plant(w_all, h, Vector(), o);
          EXPECT_FALSE(fit.uncertainty.from_data_variance);
          const ZeroPhaseVerdict v = zero_phase_verdict(nullptr, &fit);
          const std::string what = fmt::format("held-out {} xz {} noise {} seed {}: {}", held_out, xz, noise, seed, v.reason);
          if (v.nonminimum_phase) {
            EXPECT_EQ(*v.nonminimum_phase, xz < 0.0) << what;
          } else {
            ++undetermined;
          }
          if (noise == 0.001) ++cases_low, decided_low += v.nonminimum_phase ? 1 : 0;
          ++cases;
          covered += std::abs(fit.xz - xz) <= core::kCoverage95 * v.xz_standard_error ? 1 : 0;
        }
      }
    }
  }
  EXPECT_EQ(decided_low, cases_low);
  EXPECT_GT(undetermined, 0);  // 2 % noise hides the lighter zeros
  EXPECT_GE(covered, 0.90 * cases) << covered << " of " << cases;
}

TEST(ZeroPhaseVerdict, ClearPhaseDecidesAndMissingEvidenceFallsBack) {
  AntiResonance a;
  a.root = {-1.0, 260.0};
  a.phase_change_deg = -120.0;  // a broad zero: far from +-180, not ambiguous
  a.phase_verdict = PhaseVerdict::kNonMinimumPhase;
  IffPlantFit plant = report_plant(0.004);  // says minimum-phase: the phase wins
  ZeroPhaseVerdict v = zero_phase_verdict(&a, &plant);
  EXPECT_EQ(v.nonminimum_phase, std::optional<bool>(true));
  EXPECT_EQ(v.from, "phase");
  // Ambiguous and no plant fit: the phase as counted, said so.
  a.phase_change_deg = 178.0;
  a.phase_verdict = PhaseVerdict::kMinimumPhase;
  v = zero_phase_verdict(&a, nullptr);
  EXPECT_EQ(v.nonminimum_phase, std::optional<bool>(false));
  EXPECT_EQ(v.from, "phase");
  EXPECT_NE(v.reason.find("no plant fit to decide"), std::string::npos) << v.reason;
  // Undetermined phase, no plant fit: the vector fit's zero (Re < 0: minimum-phase).
  a.phase_change_deg = 30.0;
  a.phase_verdict = PhaseVerdict::kUndetermined;
  v = zero_phase_verdict(&a, nullptr);
  EXPECT_EQ(v.nonminimum_phase, std::optional<bool>(false));
  EXPECT_EQ(v.from, "fitted-zero");
  // Nothing at all.
  v = zero_phase_verdict(nullptr, nullptr);
  EXPECT_FALSE(v.nonminimum_phase.has_value());
  EXPECT_EQ(v.from, "none");
  // A tighter ambiguity leaves 178 deg to the phase.
  a.phase_change_deg = -178.0;
  a.phase_verdict = PhaseVerdict::kNonMinimumPhase;
  v = zero_phase_verdict(&a, &plant, 1.0);
  EXPECT_EQ(v.from, "phase");
  EXPECT_EQ(v.nonminimum_phase, std::optional<bool>(true));
}

// Noise-free data of both zero kinds: all seven parameters come back.
TEST(IffPlantFit, RecoversTheReportPlantExactly) {
  for (const double xz : {0.004, -0.004}) {
    const IffPlantFit p = report_plant(xz);
    const Vector w = grid();
    const IffPlantFit fit = fit_iff_plant(w, p.response(w), Vector());
    expect_recovered(fit, p, 1e-6);
    EXPECT_EQ(fit.zero_is_nonminimum_phase(), xz < 0.0);
    EXPECT_LT(fit.relative_rms_error, 1e-6);
    EXPECT_EQ(fit.points, 4000);
  }
}

// 1 % complex noise; the high-pass corner fixed (as the campaign does with 1/(R C)).
TEST(IffPlantFit, NoisyDataWithKnownCorner) {
  const IffPlantFit p = report_plant(-0.004);
  const Vector w = grid();
  lti::CVector h = p.response(w);
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 0.01 / std::sqrt(2.0));
  for (Eigen::Index k = 0; k < h.size(); ++k) h(k) *= std::complex<double>(1.0 + n(rng), n(rng));
  IffPlantFitOptions o;
  o.fmin_Hz = 20.0;
  o.fmax_Hz = 500.0;
  o.fixed_w_hpf = p.w_hpf;
  const IffPlantFit fit = fit_iff_plant(w, h, Vector(), o);
  EXPECT_DOUBLE_EQ(fit.w_hpf, p.w_hpf);
  EXPECT_TRUE(near(fit.wz, p.wz, 1e-3));
  EXPECT_TRUE(near(fit.wp, p.wp, 1e-3));
  EXPECT_TRUE(near(fit.g0, p.g0, 5e-3));
  EXPECT_TRUE(near(fit.xp, p.xp, 0.03));
  EXPECT_TRUE(fit.zero_is_nonminimum_phase());
  EXPECT_TRUE(near(fit.delay, p.delay, 0.05));
  EXPECT_NEAR(fit.relative_rms_error, 0.01, 0.002);
}

// Points of low coherence are left out: garbage there changes nothing.
TEST(IffPlantFit, CoherenceSelectsPoints) {
  const IffPlantFit p = report_plant(0.004);
  const Vector w = grid();
  lti::CVector h = p.response(w);
  Vector coh = Vector::Ones(w.size());
  for (Eigen::Index k = 0; k < w.size(); k += 7) {
    h(k) *= 3.0;
    coh(k) = 0.1;
  }
  IffPlantFitOptions o;
  o.min_coherence = 0.5;
  expect_recovered(fit_iff_plant(w, h, coh, o), p, 1e-6);
}

TEST(DelayedSecondOrderFit, RecoversMassSpringDamperWithDelay) {
  DelayedSecondOrderFit p;
  p.static_gain = -16.8e-6;
  p.natural_frequency = kTwoPi * 95.4;
  p.damping = 0.006;
  p.delay = 232e-6;
  const Vector w = grid();
  IffPlantFitOptions o;
  o.fmin_Hz = 20.0;
  o.fmax_Hz = 500.0;
  const DelayedSecondOrderFit fit = fit_delayed_second_order(w, p.response(w), Vector(), o);
  EXPECT_TRUE(near(fit.static_gain, p.static_gain, 1e-8));
  EXPECT_TRUE(near(fit.natural_frequency, p.natural_frequency, 1e-8));
  EXPECT_TRUE(near(fit.damping, p.damping, 1e-6));
  EXPECT_TRUE(near(fit.delay, p.delay, 1e-6));
  const std::complex<double> pole = fit.pole();
  EXPECT_NEAR(pole.real(), -0.006 * kTwoPi * 95.4, 1e-6);
  EXPECT_GT(pole.imag(), 0.0);
  // Without the delay in the model, a delay-compensated record fits just as well.
  lti::CVector h = p.response(w);
  for (Eigen::Index k = 0; k < w.size(); ++k) h(k) *= std::exp(std::complex<double>(0.0, w(k) * p.delay));
  o.fit_delay = false;
  const DelayedSecondOrderFit nodelay = fit_delayed_second_order(w, h, Vector(), o);
  EXPECT_DOUBLE_EQ(nodelay.delay, 0.0);
  EXPECT_TRUE(near(nodelay.damping, p.damping, 1e-6));
}

TEST(IffPlantFit, BadInput) {
  const Vector w = grid();
  const lti::CVector h = report_plant(0.004).response(w);
  const std::string src = "campaign.toml: units[0].frf";
  EXPECT_TRUE(test::contains(test::input_error([&] { (void)fit_iff_plant(w.head(10), h, Vector(), {}, src); }, "H"), src));
  lti::CVector bad = h;
  bad(5) = std::complex<double>(std::nan(""), 0.0);
  EXPECT_TRUE(test::contains(test::input_error([&] { (void)fit_iff_plant(w, bad, Vector(), {}, src); }, "H"), "point 5"));
  test::input_error([&] { (void)fit_iff_plant(w, h, Vector::Ones(3), {}, src); }, "coherence");
  IffPlantFitOptions narrow;
  narrow.fmin_Hz = 200.0;
  narrow.fmax_Hz = 201.0;
  test::input_error([&] { (void)fit_iff_plant(w, h, Vector(), narrow, src); }, "H");
  IffPlantFitOptions o;
  o.fixed_w_hpf = -1.0;
  test::input_error([&] { (void)fit_iff_plant(w, h, Vector(), o); }, "fixed_w_hpf");
  // A band without a peak inside.
  IffPlantFitOptions edge;
  edge.fmin_Hz = 300.0;
  test::input_error([&] { (void)fit_delayed_second_order(w, h, Vector(), edge, src); }, "H");
}

// The Welch FRF of a 2-DoF actuator simulated by scipy (scripts/fixtures/make_two_dof_frf_fixtures.py):
// both plants as `run` and `model tune` fit them recover the simulation's resonance,
// anti-resonance, high-pass corner and delay.
TEST(ActuatorPlants, ScipyWelchFrfOfTheTwoDofModel) {
  const dsp::Frf frf = io::read_frf(test::fixture_path("ident/two_dof_welch_frf.csv"));
  const auto truth = nlohmann::json::parse(test::read_text(test::fixture_path("ident/two_dof_welch_truth.json")));
  const Vector w = kTwoPi * frf.freq_Hz;
  ActuatorPlantOptions o;  // 20 .. 500 Hz for d_e, 0 .. 500 Hz for Vs, coherence >= 0.5
  const ActuatorPlants p = fit_actuator_plants(w, frf.H[0], frf.coherence[0], frf.H[1], frf.coherence[1], o, "two_dof_welch_frf.csv");
  ASSERT_TRUE(p.failures.empty()) << p.failures.front();
  ASSERT_TRUE(p.de && p.vs);
  const double fr = truth["resonance_Hz"].get<double>();
  EXPECT_TRUE(near(p.de->natural_frequency / kTwoPi, fr, 0.005));
  EXPECT_TRUE(near(p.de->static_gain, truth["static_gain_de_m_per_V"].get<double>(), 0.01));
  EXPECT_TRUE(near(p.de->delay, truth["effective_delay_s"].get<double>(), 0.05));
  EXPECT_FALSE(p.de->quality.poor()) << p.de->quality.summary();
  EXPECT_TRUE(near(p.vs->wp / kTwoPi, fr, 0.005));
  // The IFF plant's zero pair is the mass on the shell alone, sqrt(k1 / m).
  EXPECT_TRUE(near(p.vs->wz / kTwoPi, truth["antiresonance_Hz"].get<double>(), 0.01));
  // (Its sign is not asserted: the sampled record's notch looks slightly non-minimum-phase, see the
  // fixture script.)
  EXPECT_TRUE(near(p.vs->w_hpf / kTwoPi, truth["hpf_corner_Hz"].get<double>(), 0.05));
  EXPECT_TRUE(near(p.vs->delay, truth["effective_delay_s"].get<double>(), 0.25));
  EXPECT_FALSE(p.vs->quality.poor()) << p.vs->quality.summary();
}

// A fit over data that do not hold the model (here the phase scrambled) is poor and says why.
TEST(IffPlantFit, PoorFitIsReportedNotHidden) {
  const IffPlantFit p = report_plant(0.004);
  const Vector w = grid();
  lti::CVector h = p.response(w);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> phase(-1.5, 1.5);
  for (Eigen::Index k = 0; k < h.size(); ++k) h(k) *= std::polar(1.0, phase(rng));
  const IffPlantFit fit = fit_iff_plant(w, h, Vector());
  EXPECT_TRUE(fit.quality.poor());
  EXPECT_TRUE(test::contains(fit.quality.summary(), "relative rms error")) << fit.quality.summary();
  EXPECT_FALSE(fit.quality.advice.empty());
  // The exact data fit well.
  EXPECT_FALSE(fit_iff_plant(w, p.response(w), Vector()).quality.poor());
}

}  // namespace
}  // namespace piezobench::ident
