#include "piezobench/dsp/frf_variance.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "piezobench/core/error.hpp"
#include "piezobench/dsp/welch.hpp"

namespace piezobench::dsp {
namespace {

using Eigen::Index;

TEST(FrfVariance, EffectiveAveragesMatchWelchsClosedForms) {
  // No overlap: the segments are independent whatever the window.
  EXPECT_DOUBLE_EQ(effective_averages(WindowType::kRectangular, 256, 0, 12), 12.0);
  EXPECT_DOUBLE_EQ(effective_averages(WindowType::kHannPeriodic, 256, 0, 12), 12.0);
  // Periodic hann at 50 %: rho(1) = (N/16) / (3N/8) = 1/6, so n_d = K / (1 + 2 (1 - 1/K) / 36).
  EXPECT_NEAR(effective_averages(WindowType::kHannPeriodic, 256, 128, 2), 72.0 / 37.0, 1e-12);
  EXPECT_NEAR(effective_averages(WindowType::kHannPeriodic, 1024, 512, 40), 40.0 / (1.0 + 2.0 * (39.0 / 40.0) / 36.0), 1e-12);
  // Rectangular at 50 %: rho(1) = 1/2, n_d = K / (1 + (1 - 1/K) / 2).
  EXPECT_NEAR(effective_averages(WindowType::kRectangular, 100, 50, 10), 10.0 / (1.0 + 0.9 / 2.0), 1e-12);
  EXPECT_THROW((void)effective_averages(WindowType::kHannPeriodic, 256, 256, 3), InputError);
  EXPECT_THROW((void)effective_averages(WindowType::kHannPeriodic, 256, 0, 0), InputError);
}

TEST(FrfVariance, RelativeStdIsBendatAndPiersolsFormula) {
  // sqrt((1 - g2) / (2 n_d g2)).
  EXPECT_NEAR(frf_relative_std(0.9, 10.0), std::sqrt(0.1 / 18.0), 1e-15);
  EXPECT_DOUBLE_EQ(frf_relative_std(1.0, 3.0), 0.0);
  EXPECT_TRUE(std::isfinite(frf_relative_std(0.0, 3.0)));
  EXPECT_THROW((void)frf_relative_std(0.5, 0.0), InputError);
  const Eigen::VectorXcd h = Eigen::VectorXcd::Constant(2, {3.0, -4.0});
  const Eigen::VectorXd s = frf_standard_deviation(h, Eigen::Vector2d(0.5, 0.8), 4.0);
  EXPECT_NEAR(s(0), 5.0 * std::sqrt(0.5 / 4.0), 1e-14);
  EXPECT_NEAR(s(1), 5.0 * std::sqrt(0.2 / 6.4), 1e-14);
  EXPECT_THROW((void)frf_standard_deviation(h, Eigen::VectorXd::Ones(3), 4.0), InputError);
}

// Monte Carlo against the closed forms: y(n) = a u(n - delay) + noise, u and the noise white, so the
// true H = a exp(-j w delay) (a phase that falls with frequency) and the true coherence
// gamma^2 = a^2 / (a^2 + sigma_n^2) at every line. Over many records the spread of |H_est| / |H| and of
// the phase error must be eps(gamma^2, n_d) with Welch's n_d, hann 50 %, and the std_H each record
// reports must predict it.
TEST(FrfVariance, MonteCarloSpreadMatchesTheClosedFormsPhaseSignIncluded) {
  const Index nfft = 128, segments = 15, delay = 3;
  const double a = 2.0, sigma_n = 1.0;  // gamma^2 = 0.8
  const Index n = nfft / 2 * (segments + 1);
  WelchOptions o;
  o.nfft = nfft;
  o.overlap = 0.5;
  o.threads = 1;
  const double n_d = effective_averages(WindowType::kHannPeriodic, nfft, nfft / 2, segments);
  const double eps = frf_relative_std(a * a / (a * a + sigma_n * sigma_n), n_d);
  std::mt19937_64 rng(30);
  std::normal_distribution<double> normal;
  const int records = 400;
  const Index lines = nfft / 2 + 1;
  Eigen::VectorXd sum_log2 = Eigen::VectorXd::Zero(lines), sum_ph = Eigen::VectorXd::Zero(lines),
                  sum_ph2 = Eigen::VectorXd::Zero(lines), sum_rel_std = Eigen::VectorXd::Zero(lines);
  for (int r = 0; r < records; ++r) {
    Eigen::VectorXd u(n + delay), y(n);
    for (Index i = 0; i < u.size(); ++i) u(i) = normal(rng);
    for (Index i = 0; i < n; ++i) y(i) = a * u(i) + sigma_n * normal(rng);
    const Eigen::VectorXd u_late = u.tail(n);  // y(i) = a u_late(i - delay)
    const FrfEstimate e = estimate_frf(channel("u", u_late), {channel("y", y)}, 1.0, o);
    ASSERT_EQ(e.frf.std_H.size(), 1u);
    EXPECT_NEAR(e.frf.provenance.effective_averages, n_d, 1e-12);
    for (Index k = 1; k < lines - 1; ++k) {
      const double w = 2.0 * std::numbers::pi * e.frf.freq_Hz(k);
      const std::complex<double> h_true = a * std::exp(std::complex<double>(0.0, -w * static_cast<double>(delay)));
      const std::complex<double> ratio = e.frf.H[0](k) / h_true;
      sum_log2(k) += std::pow(std::log(std::abs(ratio)), 2);
      sum_ph(k) += std::arg(ratio);
      sum_ph2(k) += std::pow(std::arg(ratio), 2);
      sum_rel_std(k) += e.frf.std_H[0](k) / std::abs(e.frf.H[0](k));
    }
  }
  // Averaged over the inner lines (each line's spread is itself known to ~4 % from 400 records).
  const Index inner = lines - 2;
  const double mag_spread = std::sqrt(sum_log2.segment(1, inner).sum() / (records * inner));
  const double phase_spread = std::sqrt(sum_ph2.segment(1, inner).sum() / (records * inner));
  const double phase_bias = sum_ph.segment(1, inner).sum() / (records * inner);
  const double predicted = sum_rel_std.segment(1, inner).sum() / (records * inner);
  EXPECT_NEAR(mag_spread / eps, 1.0, 0.08) << mag_spread << " vs " << eps;
  EXPECT_NEAR(phase_spread / eps, 1.0, 0.08) << phase_spread << " vs " << eps;
  // The phase error is centred on the true (falling) phase: a sign error in the phase convention
  // would put it at 2 w delay, i.e. at a mean far outside eps / sqrt(records * lines).
  EXPECT_NEAR(phase_bias, 0.0, 3.0 * eps / std::sqrt(static_cast<double>(records)));
  // What each record reports from its own coherence predicts the spread (the estimated coherence's
  // small upward bias at n_d = 14 makes it slightly optimistic).
  EXPECT_NEAR(predicted / eps, 1.0, 0.1) << predicted << " vs " << eps;
}

// The band H +- frf_band_factor(n_d) std_H, each record with its own estimated coherence, covers the
// true H at 95 % of the lines even with few averages (n_d = 4.8 here, where the Gaussian's 1.96
// covers only ~89 %): y = a u + noise as above, gamma^2 = 0.8.
TEST(FrfVariance, BandFactorCoversTheTrueResponseAtNinetyFivePercentWithFewAverages) {
  const Index nfft = 64, segments = 5;
  const double a = 2.0, sigma_n = 1.0;
  const Index n = nfft / 2 * (segments + 1);
  WelchOptions o;
  o.nfft = nfft;
  o.overlap = 0.5;
  o.threads = 1;
  const double n_d = effective_averages(WindowType::kHannPeriodic, nfft, nfft / 2, segments);
  const double k = frf_band_factor(n_d);
  std::mt19937_64 rng(31);
  std::normal_distribution<double> normal;
  long inside = 0, inside_gauss = 0, lines = 0;
  for (int r = 0; r < 1000; ++r) {
    Eigen::VectorXd u(n), y(n);
    for (Index i = 0; i < n; ++i) u(i) = normal(rng);
    for (Index i = 0; i < n; ++i) y(i) = a * u(i) + sigma_n * normal(rng);
    const FrfEstimate e = estimate_frf(channel("u", u), {channel("y", y)}, 1.0, o);
    for (Index l = 1; l < nfft / 2; ++l) {
      const double err = std::abs(std::abs(e.frf.H[0](l)) - a), s = e.frf.std_H[0](l);
      inside += err <= k * s ? 1 : 0;
      inside_gauss += err <= 1.959963984540054 * s ? 1 : 0;
      ++lines;
    }
  }
  const double coverage = static_cast<double>(inside) / static_cast<double>(lines);
  const double gauss = static_cast<double>(inside_gauss) / static_cast<double>(lines);
  EXPECT_NEAR(n_d, 5.0 / (1.0 + 2.0 * 0.8 / 36.0), 1e-12);  // rho(1) = 1/6 for hann at 50 %
  EXPECT_NEAR(coverage, 0.95, 0.01) << "factor " << k;  // 31,000 lines: the binomial sd is 0.13 %
  EXPECT_LT(gauss, 0.915);                                // what 1.96 would have claimed as 95 %
}

TEST(FrfVariance, BandFactorIsStudentsTWithTwoNdMinusTwoDegreesOfFreedom) {
  // scipy: sqrt(8.6 / 7.6) * stats.t.ppf(0.975, 15.2) = 2.2647487225643146
  EXPECT_NEAR(frf_band_factor(8.6), 2.2647487225643146, 1e-12);
  EXPECT_NEAR(frf_band_factor(1e6), 1.959964, 1e-5);  // many averages: the Gaussian's factor
  EXPECT_GT(frf_band_factor(8.6, 0.99), frf_band_factor(8.6));
  EXPECT_THROW((void)frf_band_factor(1.0), InputError);
  EXPECT_THROW((void)frf_band_factor(8.6, 1.0), InputError);
}

// The noise of an FRF that records no variance, from a model's residuals: 20,000 lines of a response
// spanning three decades with per-part noise sqrt(a^2 + (r |G|)^2) give back a and r within 3 %;
// noise of one kind only gives the other as (nearly) 0; an exact model gives 0 and 0; the relative
// standard deviation at each line is s_k / |G_k|.
TEST(FrfVariance, NoiseEstimateRecoversAdditiveAndProportionalParts) {
  const Index n = 20000;
  Eigen::VectorXcd g(n);
  for (Index k = 0; k < n; ++k) {
    const double f = std::pow(10.0, 3.0 * static_cast<double>(k) / static_cast<double>(n - 1));  // 1 to 1000
    g(k) = std::polar(10.0 / f, 0.3 * static_cast<double>(k));  // 10 down to 0.01
  }
  const auto noisy = [&](double a, double r, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> n01;
    Eigen::VectorXcd h = g;
    for (Index k = 0; k < n; ++k) {
      const double s = std::hypot(a, r * std::abs(g(k)));
      h(k) += std::complex<double>(s * n01(rng), s * n01(rng));
    }
    return h;
  };
  FrfNoiseEstimate e = estimate_frf_noise(noisy(0.002, 0.01, 1), g);
  EXPECT_NEAR(e.additive_std, 0.002, 0.03 * 0.002);
  EXPECT_NEAR(e.relative_std, 0.01, 0.03 * 0.01);
  const Eigen::VectorXd eps = e.relative_std_at(g);
  EXPECT_NEAR(eps(0), std::hypot(e.additive_std / 10.0, e.relative_std), 1e-15);
  EXPECT_NEAR(eps(n - 1), std::hypot(e.additive_std / 0.01, e.relative_std), 1e-12);
  e = estimate_frf_noise(noisy(0.003, 0.0, 2), g);
  EXPECT_NEAR(e.additive_std, 0.003, 0.03 * 0.003);
  EXPECT_LT(e.relative_std, 0.001);
  e = estimate_frf_noise(noisy(0.0, 0.02, 3), g);
  EXPECT_NEAR(e.relative_std, 0.02, 0.03 * 0.02);
  EXPECT_LT(e.additive_std, 0.02 * 0.01 * 0.1);  // a tenth of the noise at the smallest |G|
  e = estimate_frf_noise(g, g);
  EXPECT_EQ(e.additive_std, 0.0);
  EXPECT_EQ(e.relative_std, 0.0);
  EXPECT_THROW((void)estimate_frf_noise(g, g.head(10)), InputError);
  EXPECT_THROW((void)estimate_frf_noise(g.head(2), g.head(2)), InputError);
  Eigen::VectorXcd bad = g;
  bad(5) = std::complex<double>(NAN, 0.0);
  EXPECT_THROW((void)estimate_frf_noise(bad, g), NumericalError);
}

// The random part of a Welch estimate's std_k: 4,000 lines of a resonance (Q = 50) whose std_k^2 is the
// noise sqrt(a^2 + (r |G|)^2) squared times a chi-square of 2 n_d degrees of freedom over 2 n_d (what a
// coherence from n_d = 8.6 averages gives), plus the window's leakage |H|^2 (1/leakage - 1) / (2 n_d)
// over the peak: the noise model comes back within 5 %, at the peak std is the model (the leakage, there
// 28 times the noise, left out), and at a clean line too (the line's own chi-square scatter smoothed
// away). A noise 10 times larger over the upper half (coloured: the model does not fit it) keeps the
// measured std at clean lines and caps it by the model at the leaky ones; without 8 clean lines, std_H
// as it is.
TEST(FrfVariance, RandomStdLeavesTheLeakageOutAndSmoothsTheNoise) {
  const Index n = 4000, peak = 2000;
  const double nd = 8.6, a = 1e-4, r = 2e-3;
  Eigen::VectorXcd g(n);
  Eigen::VectorXd leakage(n), chi(n);
  std::mt19937 rng(5);
  std::chi_squared_distribution<double> chi2(2.0 * nd);
  for (Index k = 0; k < n; ++k) {
    const double x = static_cast<double>(k - peak) / 400.0;  // frequency over the resonance's, minus 1
    g(k) = 1.0 / std::complex<double>(1.0 - (1.0 + x) * (1.0 + x), 0.02 * (1.0 + x));
    leakage(k) = 1.0 - 0.05 * std::exp(-std::pow(static_cast<double>(k - peak) / 6.0, 2));
    chi(k) = chi2(rng) / (2.0 * nd);
  }
  const auto measured = [&](const Eigen::VectorXd& noise_var) {
    Eigen::VectorXd s(n);
    for (Index k = 0; k < n; ++k) s(k) = std::sqrt(noise_var(k) * chi(k) + std::norm(g(k)) * (1.0 / leakage(k) - 1.0) / (2.0 * nd));
    return s;
  };
  Eigen::VectorXd var(n);
  for (Index k = 0; k < n; ++k) var(k) = a * a + r * r * std::norm(g(k));
  const Eigen::VectorXd std_h = measured(var);
  RandomFrfStd out = random_frf_std(g, std_h, g, leakage, nd);
  ASSERT_TRUE(out.smooth_model);
  EXPECT_GT(out.clean_lines, 3900);
  EXPECT_NEAR(out.noise.additive_std, a, 0.05 * a);
  EXPECT_NEAR(out.noise.relative_std, r, 0.05 * r);
  EXPECT_GT(std_h(peak), 25.0 * std::sqrt(var(peak)));
  EXPECT_NEAR(out.std(peak), std::sqrt(var(peak)), 0.05 * std::sqrt(var(peak)));
  EXPECT_NEAR(out.std(100), std::sqrt(var(100)), 0.05 * std::sqrt(var(100)));

  Eigen::VectorXd coloured = var;
  coloured.tail(n / 2) *= 100.0;
  const Eigen::VectorXd std_c = measured(coloured);
  out = random_frf_std(g, std_c, g, leakage, nd);
  EXPECT_FALSE(out.smooth_model);
  EXPECT_EQ(out.std(100), std_c(100));
  EXPECT_EQ(out.std(3900), std_c(3900));
  const double capped = std::hypot(out.noise.additive_std, out.noise.relative_std * std::abs(g(peak)));
  EXPECT_LT(capped, 0.25 * std_c(peak));
  EXPECT_DOUBLE_EQ(out.std(peak), capped);

  out = random_frf_std(g, std_h, g, Eigen::VectorXd::Constant(n, 0.5), nd);
  EXPECT_FALSE(out.smooth_model);
  EXPECT_EQ(out.clean_lines, 0);
  EXPECT_EQ(out.std, std_h);
  EXPECT_THROW((void)random_frf_std(g, std_h.head(10), g, leakage, nd), InputError);
  EXPECT_THROW((void)random_frf_std(g, std_h, g, leakage, 0.0), InputError);
}

// The correlation of a Welch estimate's errors at neighbouring lines: without overlap only the
// window's own leakage, |sum w^2 e^(2 pi i n / N)|^2 / (sum w^2)^2 (periodic hann: (2/3)^2 = 4/9;
// rectangular: 0, its bins are orthogonal); hann at 50 % with 9 segments: 0.457 (scipy's csd/welch,
// 4,000 realizations, measured 0.434 +- 0.013 for H1, which also divides by the input's own estimate);
// from an FRF's provenance, and 0 when it does not say how the segments overlapped.
TEST(FrfVariance, AdjacentLineCorrelationMatchesTheWindowsLeakage) {
  EXPECT_NEAR(adjacent_line_correlation(WindowType::kHannPeriodic, 256, 0, 12), 4.0 / 9.0, 1e-12);
  EXPECT_NEAR(adjacent_line_correlation(WindowType::kRectangular, 256, 0, 12), 0.0, 1e-12);
  const double hann50 = adjacent_line_correlation(WindowType::kHannPeriodic, 256, 128, 9);
  EXPECT_NEAR(hann50, 0.4574, 5e-4);
  EXPECT_NEAR(hann50, 0.434, 2.0 * 0.013);
  FrfProvenance p;
  p.window = "hann-periodic";
  p.nfft = 256;
  p.overlap = 0.5;
  p.averages = 9;
  p.sample_rate = 1000.0;
  EXPECT_DOUBLE_EQ(adjacent_line_correlation(p), hann50);
  p.averages = 0;
  EXPECT_EQ(adjacent_line_correlation(p), 0.0);
  p.averages = 9;
  p.window = "kaiser-7";
  EXPECT_EQ(adjacent_line_correlation(p), 0.0);
  EXPECT_THROW((void)adjacent_line_correlation(WindowType::kHannPeriodic, 256, 256, 3), InputError);
}

TEST(FrfVariance, ValidateRejectsANegativeOrMisSizedStd) {
  Frf f;
  f.freq_Hz = Eigen::Vector2d(1.0, 2.0);
  f.outputs = {"y"};
  f.H = {Eigen::VectorXcd::Ones(2)};
  f.std_H = {Eigen::Vector2d(0.1, -0.1)};
  EXPECT_THROW(f.validate("x"), InputError);
  f.std_H = {Eigen::VectorXd::Ones(3)};
  EXPECT_THROW(f.validate("x"), InputError);
  f.std_H = {Eigen::Vector2d(0.1, 0.2)};
  EXPECT_NO_THROW(f.validate("x"));
  BandSelection b;
  b.fmin_Hz = 1.5;
  const Frf part = select_band(f, b);
  ASSERT_EQ(part.std_H.size(), 1u);
  EXPECT_DOUBLE_EQ(part.std_H[0](0), 0.2);
}

}  // namespace
}  // namespace piezobench::dsp
