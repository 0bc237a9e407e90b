// Excitation signals: bounds, frequency content and reproducibility, all checked against what the
// signals are by construction.
#include "piezobench/dsp/excitation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "fft.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/units.hpp"
#include "test_util.hpp"

namespace piezobench::dsp {
namespace {

using Eigen::Index;
using Eigen::VectorXd;
using test::near;

double rms(const VectorXd& x) { return std::sqrt(x.squaredNorm() / static_cast<double>(x.size())); }

VectorXd magnitude_spectrum(const VectorXd& x) { return detail::rfft(x).cwiseAbs(); }

// ---- noise --------------------------------------------------------------------------------------

NoiseOptions noise_options() {
  NoiseOptions o;
  o.sample_rate = 1000.0;
  o.samples = 4000;
  o.f_low = 20.0;
  o.f_high = 200.0;
  o.rms = 0.5;
  o.offset = 2.0;
  o.seed = 42;
  return o;
}

TEST(Noise, PowerOnlyInsideTheBandWithTheRequestedRms) {
  const Excitation e = band_limited_noise(noise_options(), VoltageBounds{-10.0, 10.0});
  ASSERT_EQ(e.u.size(), 4000);
  EXPECT_FALSE(e.scaled);
  EXPECT_EQ(e.kind, "noise");
  const VectorXd v = e.u.array() - 2.0;
  EXPECT_TRUE(near(rms(v), 0.5, test::kRoundoff));
  EXPECT_NEAR(v.mean(), 0.0, 1e-14);
  const VectorXd mag = magnitude_spectrum(v);  // bin k = k * 0.25 Hz
  const double in_band = mag.segment(80, 721).maxCoeff();
  EXPECT_LT(mag.head(80).maxCoeff(), 1e-12 * in_band);
  EXPECT_LT(mag.tail(mag.size() - 801).maxCoeff(), 1e-12 * in_band);
  // White inside the band: every line carries power (no line below 1e-3 of the largest).
  EXPECT_GT(mag.segment(80, 721).minCoeff(), 1e-3 * in_band);
  EXPECT_DOUBLE_EQ(e.lines_Hz(0), 20.0);
  EXPECT_DOUBLE_EQ(e.lines_Hz(1), 200.0);
}

TEST(Noise, ReproducibleFromTheSeed) {
  const VoltageBounds b{-10.0, 10.0};
  const Excitation a = band_limited_noise(noise_options(), b);
  const Excitation again = band_limited_noise(noise_options(), b);
  EXPECT_EQ(a.u, again.u);
  NoiseOptions other = noise_options();
  other.seed = 43;
  EXPECT_GT((band_limited_noise(other, b).u - a.u).cwiseAbs().maxCoeff(), 0.1);
  EXPECT_EQ(a.seed, 42U);
}

// The generator draws the band's DFT lines as white Gaussian noise's DFT has them. A long record
// then shows white noise's statistics: Gaussian samples (skewness 0, kurtosis 3), equal mean power
// in every part of the band, nothing outside it, exactly the rms, the offset as mean.
TEST(Noise, LongRecordIsGaussianAndWhiteInsideTheBand) {
  NoiseOptions o;
  o.sample_rate = 1000.0;
  o.samples = Index{1} << 18;  // lines 1000 / 2^18 Hz apart
  o.f_low = 50.0;
  o.f_high = 450.0;
  o.rms = 0.3;
  o.offset = 1.0;
  o.seed = 7;
  const Excitation e = band_limited_noise(o, VoltageBounds{-10.0, 10.0});
  const VectorXd v = e.u.array() - 1.0;
  EXPECT_TRUE(near(rms(v), 0.3, test::kRoundoff));
  EXPECT_NEAR(e.u.mean(), 1.0, 1e-13);
  // Moments: with ~2e5 nearly independent samples the standard errors are sqrt(6/N) = 0.005 and
  // sqrt(24/N) = 0.01; the bounds are 6 to 8 of them (a uniform draw would give kurtosis 1.8).
  const double m2 = v.array().square().mean();
  const double skew = v.array().cube().mean() / std::pow(m2, 1.5);
  const double kurt = v.array().square().square().mean() / (m2 * m2);
  EXPECT_NEAR(skew, 0.0, 0.04);
  EXPECT_NEAR(kurt, 3.0, 0.06);
  // 1 sigma holds 68.27 % of the samples, 2 sigma 95.45 %.
  const double sigma = std::sqrt(m2);
  EXPECT_NEAR((v.array().abs() < sigma).cast<double>().mean(), 0.6827, 0.01);
  EXPECT_NEAR((v.array().abs() < 2.0 * sigma).cast<double>().mean(), 0.9545, 0.005);
  // Spectrum: zero outside the lines [50, 450] Hz, the same mean power in each quarter of the band
  // (each mean is over ~26,000 exponentially distributed line powers: 0.6 % standard error).
  const Eigen::VectorXd power = detail::rfft(v).cwiseAbs2();
  const double hz = static_cast<double>(o.samples) / o.sample_rate;  // lines per Hz
  const auto first = static_cast<Index>(std::ceil(50.0 * hz)), last = static_cast<Index>(std::floor(450.0 * hz));
  const double in_band = power.segment(first, last - first + 1).mean();
  EXPECT_LT(power.head(first).maxCoeff(), 1e-24 * in_band);
  EXPECT_LT(power.tail(power.size() - last - 1).maxCoeff(), 1e-24 * in_band);
  const Index quarter = (last - first + 1) / 4;
  for (Index q = 0; q < 4; ++q) {
    EXPECT_NEAR(power.segment(first + q * quarter, quarter).mean() / in_band, 1.0, 0.03) << "quarter " << q;
  }
}

// The Nyquist line of an even record is real and carries, on average, the power of any other line
// (white noise's DFT: X(n/2) = sum (-1)^j x_j has variance n, as E|X_k|^2 does). Averaged over many
// seeds of a short record; an odd record has no Nyquist line and its last line is complex.
TEST(Noise, NyquistLineCarriesTheSameMeanPower) {
  for (const Index n : {Index{64}, Index{63}}) {
    SCOPED_TRACE(n);
    NoiseOptions o;
    o.sample_rate = static_cast<double>(n);  // 1 Hz lines
    o.samples = n;
    o.f_low = 1.0;
    o.f_high = 0.5 * o.sample_rate;
    o.rms = 1.0;
    const Index bins = n / 2 + 1;
    VectorXd mean_power = VectorXd::Zero(bins);
    const int seeds = 4000;
    for (int s = 1; s <= seeds; ++s) {
      o.seed = static_cast<std::uint64_t>(s);
      mean_power += detail::rfft(band_limited_noise(o, VoltageBounds{-100.0, 100.0}).u).cwiseAbs2() / seeds;
    }
    EXPECT_LT(mean_power(0), 1e-20);  // DC: the offset (0) only
    const double interior = mean_power.segment(1, bins - 2).mean();
    // chi-square with 1 degree of freedom averaged over 4000 draws: 2.2 % standard error.
    EXPECT_NEAR(mean_power(bins - 1) / interior, 1.0, 0.1);
  }
}

TEST(Noise, SeedsGiveDifferentSignalsOfTheSameStatistics) {
  NoiseOptions o = noise_options();
  const VoltageBounds b{-10.0, 10.0};
  const VectorXd ua = band_limited_noise(o, b).u;
  const VectorXd a = ua.array() - 2.0;
  o.seed = 43;
  const VectorXd c = band_limited_noise(o, b).u.array() - 2.0;
  EXPECT_TRUE(near(rms(c), rms(a), test::kRoundoff));
  // Independent draws: the normalized correlation of the two records is of order 1/sqrt(lines).
  EXPECT_LT(std::abs(a.dot(c)) / (a.norm() * c.norm()), 0.2);
  o.seed = 42;
  EXPECT_EQ(band_limited_noise(o, b).u, ua);
}

TEST(Noise, ScaledIntoTheBoundsAndReported) {
  NoiseOptions o = noise_options();
  o.rms = 3.0;
  const VoltageBounds b{-1.0, 7.5};
  const Excitation e = band_limited_noise(o, b);
  EXPECT_TRUE(e.scaled);
  EXPECT_LT(e.scale, 1.0);
  EXPECT_GE(e.u.minCoeff(), -1.0);
  EXPECT_LE(e.u.maxCoeff(), 7.5);
  // Scaled, not clipped: the shape is the unbounded signal's times `scale`, and one side touches.
  const Excitation wide = band_limited_noise(o, VoltageBounds{-100.0, 100.0});
  EXPECT_TRUE(test::all_near((e.u.array() - 2.0).matrix(), ((wide.u.array() - 2.0) * e.scale).matrix(),
                             test::Tolerance{0, 1e-12}));
  EXPECT_TRUE(std::abs(e.u.minCoeff() + 1.0) < 1e-12 || std::abs(e.u.maxCoeff() - 7.5) < 1e-12);
}

TEST(Noise, ClipAndRejectPolicies) {
  NoiseOptions o = noise_options();
  o.rms = 3.0;
  const Excitation clipped = band_limited_noise(o, VoltageBounds{-1.0, 7.5, BoundsPolicy::kClip});
  EXPECT_FALSE(clipped.scaled);
  EXPECT_GT(clipped.clipped, 0);
  EXPECT_EQ(clipped.u.minCoeff(), -1.0);
  EXPECT_THROW((void)band_limited_noise(o, VoltageBounds{-1.0, 7.5, BoundsPolicy::kReject}), InputError);
  EXPECT_EQ(bounds_policy_from_string(to_string(BoundsPolicy::kClip)), BoundsPolicy::kClip);
}

TEST(Noise, BadOptionsNameTheField) {
  NoiseOptions o = noise_options();
  o.f_high = 600.0;  // above Nyquist
  try {
    (void)band_limited_noise(o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "f_high");
  }
  o = noise_options();
  o.offset = 9.0;  // outside -1..7.5
  try {
    (void)band_limited_noise(o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "offset");
  }
}

// ---- multisine ----------------------------------------------------------------------------------

MultisineOptions multisine_options(MultisinePhases phases) {
  MultisineOptions o;
  o.sample_rate = 1024.0;
  o.period_samples = 1024;  // 1 Hz lines
  o.periods = 3;
  for (int f = 10; f <= 300; f += 10) o.lines_Hz.push_back(f);
  o.rms = 0.2;
  o.offset = 1.0;
  o.phases = phases;
  o.seed = 9;
  return o;
}

TEST(Multisine, LinesAmplitudesAndPhasesAreExact) {
  for (MultisinePhases p : {MultisinePhases::kSchroeder, MultisinePhases::kRandom}) {
    const MultisineOptions o = multisine_options(p);
    const Excitation e = multisine(o, VoltageBounds{-5.0, 5.0});
    ASSERT_EQ(e.u.size(), 3 * 1024);
    EXPECT_FALSE(e.scaled);
    const VectorXd period = e.u.head(1024).array() - 1.0;
    EXPECT_EQ(e.u.segment(1024, 1024), e.u.head(1024));  // periodic
    EXPECT_TRUE(near(rms(period), 0.2, test::kRoundoff));
    const Eigen::VectorXcd X = detail::rfft(period);
    const Eigen::VectorXd phi = multisine_phases(o);
    const double a = 0.2 / std::sqrt(30 * 0.5);  // equal amplitudes: 30 A^2 / 2 = rms^2
    for (Index m = 0; m < X.size(); ++m) {
      if (m >= 10 && m <= 300 && m % 10 == 0) {
        const std::complex<double> expected = std::polar(512.0 * a, phi(m / 10 - 1));
        EXPECT_LT(std::abs(X(m) - expected), 1e-11) << "line " << m;
      } else {
        EXPECT_LT(std::abs(X(m)), 1e-11) << "bin " << m;
      }
    }
  }
}

TEST(Multisine, SchroederPhasesHaveTheClosedFormAndALowCrestFactor) {
  const MultisineOptions o = multisine_options(MultisinePhases::kSchroeder);
  const VectorXd phi = multisine_phases(o);
  const double F = 30.0;
  for (Index k = 1; k <= 30; ++k) {
    const double expected = std::remainder(-kPi * static_cast<double>(k) * static_cast<double>(k - 1) / F, 2 * kPi);
    EXPECT_NEAR(std::remainder(phi(k - 1) - expected, 2 * kPi), 0.0, 1e-12) << k;
  }
  // Crest factor (peak / rms) of Schroeder phases: about 1.7 for flat spectra; zero phases give
  // sqrt(2 F) = 7.7.
  const VectorXd v = multisine(o, VoltageBounds{-5.0, 5.0}).u.array() - 1.0;
  EXPECT_LT(v.cwiseAbs().maxCoeff() / rms(v), 2.0);
}

TEST(Multisine, RandomPhasesFollowTheSeed) {
  MultisineOptions o = multisine_options(MultisinePhases::kRandom);
  const VectorXd a = multisine_phases(o);
  EXPECT_EQ(a, multisine_phases(o));
  EXPECT_TRUE((a.array() >= 0.0).all() && (a.array() < 2 * kPi).all());
  o.seed = 10;
  EXPECT_GT((multisine_phases(o) - a).cwiseAbs().maxCoeff(), 0.1);
}

TEST(Multisine, OffGridLineIsRejected) {
  MultisineOptions o = multisine_options(MultisinePhases::kSchroeder);
  o.lines_Hz.push_back(10.5);
  try {
    (void)multisine(o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "lines_Hz");
  }
  EXPECT_EQ(multisine_phases_from_string("random"), MultisinePhases::kRandom);
}

// ---- sweeps -------------------------------------------------------------------------------------

TEST(Sweep, PhaseAndInstantaneousFrequency) {
  for (SweepType type : {SweepType::kLinear, SweepType::kLogarithmic}) {
    SweepOptions o;
    o.sample_rate = 2000.0;
    o.duration = 4.0;
    o.f_start = 5.0;
    o.f_end = 200.0;
    o.amplitude = 0.8;
    o.offset = 0.5;
    o.type = type;
    const Excitation e = sine_sweep(o, VoltageBounds{-2.0, 2.0});
    ASSERT_EQ(e.u.size(), 8000);
    EXPECT_EQ(e.kind, "sweep-" + to_string(type));
    // f(t) = dphi/dt / (2 pi): by central differences of the closed-form phase.
    const double T = 4.0;
    auto phase = [&](double t) {
      if (type == SweepType::kLinear) return 2 * kPi * (5.0 * t + 195.0 * t * t / (2 * T));
      const double r = std::log(40.0);
      return 2 * kPi * 5.0 * T / r * (std::exp(t * r / T) - 1.0);
    };
    for (double t : {0.5, 1.7, 3.2}) {
      const double h = 1e-5;
      EXPECT_TRUE(near((phase(t + h) - phase(t - h)) / (2 * h) / (2 * kPi), sweep_frequency(o, t), 1e-6));
      const auto k = static_cast<Index>(t * 2000.0);
      EXPECT_NEAR(e.u(k), 0.5 + 0.8 * std::sin(phase(static_cast<double>(k) / 2000.0)), 1e-9);
    }
    EXPECT_DOUBLE_EQ(sweep_frequency(o, 0.0), 5.0);
    EXPECT_NEAR(sweep_frequency(o, 4.0), 200.0, 1e-9);
    if (type == SweepType::kLogarithmic) {
      EXPECT_NEAR(sweep_frequency(o, 2.0), std::sqrt(5.0 * 200.0), 1e-9);
    }
  }
  EXPECT_EQ(sweep_type_from_string("log"), SweepType::kLogarithmic);
}

TEST(Sweep, RampsStartAndEndAtTheOffsetAndBoundsScaleTheAmplitude) {
  SweepOptions o;
  o.sample_rate = 1000.0;
  o.duration = 2.0;
  o.f_start = 1.0;
  o.f_end = 50.0;
  o.amplitude = 5.0;
  o.offset = 3.0;
  o.ramp_time = 0.2;
  const Excitation e = sine_sweep(o);  // default bounds -1..7.5: amplitude 5 around 3 does not fit
  EXPECT_TRUE(e.scaled);
  // Room below the offset: 4 V; the sampled troughs may fall just short of the continuous -5 V.
  EXPECT_GE(e.scale, 0.8);
  EXPECT_LT(e.scale, 0.81);
  EXPECT_NEAR(e.u.minCoeff(), -1.0, 1e-12);  // the deepest sampled trough touches the bound
  EXPECT_LE(e.u.maxCoeff(), 7.5);
  EXPECT_DOUBLE_EQ(e.u(0), 3.0);
  EXPECT_NEAR(e.u(e.u.size() - 1), 3.0, 1e-4);
}

// ---- quasi-static offset sine -------------------------------------------------------------------

TEST(OffsetSine, StartsAndEndsAtRestAndOscillatesAroundTheOffset) {
  OffsetSineOptions o;
  o.sample_rate = 1000.0;
  o.rest = 0.0;
  o.offset = 3.0;
  o.amplitude = 2.0;
  o.frequency = 0.5;
  o.cycles = 2.0;
  o.ramp_time = 1.0;
  const Excitation e = offset_sine(o);
  ASSERT_EQ(e.u.size(), 6001);  // 2 s of ramps + 4 s of cycles + the final sample
  EXPECT_FALSE(e.scaled);
  EXPECT_EQ(e.u(0), 0.0);
  EXPECT_NEAR(e.u(6000), 0.0, 1e-12);
  for (Index k = 1000; k <= 5000; k += 125) {
    const double t = static_cast<double>(k) / 1000.0;
    EXPECT_NEAR(e.u(k), 3.0 + 2.0 * std::sin(2 * kPi * 0.5 * (t - 1.0)), 1e-12) << k;
  }
  EXPECT_NEAR(e.u.maxCoeff(), 5.0, 1e-9);
  EXPECT_NEAR(e.u.minCoeff(), 0.0, 1e-12);  // the first trough of the sine at 1 V is above 0
  // Smooth: the largest step between samples is the sine's slope 2 pi f A / fs, not a jump.
  const VectorXd du = e.u.tail(6000) - e.u.head(6000);
  EXPECT_LT(du.cwiseAbs().maxCoeff(), 1.05 * 2 * kPi * 0.5 * 2.0 / 1000.0 + 3.0 * kPi / 2 / 1000.0);
}

TEST(OffsetSine, AmplitudeScaledToTheRoomAroundTheOffset) {
  OffsetSineOptions o;
  o.sample_rate = 200.0;
  o.offset = 6.0;
  o.amplitude = 3.0;
  o.frequency = 1.0;
  o.cycles = 3.0;
  o.ramp_time = 0.5;
  const Excitation e = offset_sine(o);  // room above 6 V: 1.5 V
  EXPECT_TRUE(e.scaled);
  EXPECT_NEAR(e.scale, 0.5, 1e-3);
  EXPECT_LE(e.u.maxCoeff(), 7.5);
  o.offset = 8.0;
  EXPECT_THROW((void)offset_sine(o), InputError);
}

// ---- steps --------------------------------------------------------------------------------------

TEST(Steps, LevelsHoldsAndLinearRamps) {
  StepOptions o;
  o.sample_rate = 100.0;
  o.rest = 0.0;
  o.levels = {1.0, 4.0, -0.5};
  o.hold_time = 0.5;   // 50 samples
  o.ramp_time = 0.1;   // 10 samples
  const Excitation e = steps(o);
  ASSERT_EQ(e.u.size(), 50 + 4 * 60);
  EXPECT_FALSE(e.scaled);
  EXPECT_TRUE((e.u.head(50).array() == 0.0).all());
  EXPECT_EQ(e.u(54), 0.5);                              // half way up the first ramp
  EXPECT_TRUE((e.u.segment(59, 51).array() == 1.0).all());  // first level (last ramp sample + hold)
  EXPECT_EQ(e.u(114), 2.5);
  EXPECT_TRUE((e.u.segment(120, 50).array() == 4.0).all());
  EXPECT_TRUE((e.u.segment(180, 50).array() == -0.5).all());
  EXPECT_TRUE((e.u.tail(50).array() == 0.0).all());
  // Slew limited: the largest step between samples is the steepest ramp, 3 V in 10 samples.
  EXPECT_NEAR((e.u.tail(e.u.size() - 1) - e.u.head(e.u.size() - 1)).cwiseAbs().maxCoeff(), 0.45, 1e-12);
}

TEST(Steps, OutOfRangeLevelsScaleAboutRest) {
  StepOptions o;
  o.sample_rate = 100.0;
  o.levels = {15.0};
  const Excitation e = steps(o);
  EXPECT_TRUE(e.scaled);
  EXPECT_NEAR(e.scale, 7.5 / 15.0, 1e-15);
  EXPECT_DOUBLE_EQ(e.u.maxCoeff(), 7.5);
  o.levels.clear();
  EXPECT_THROW((void)steps(o), InputError);
}

}  // namespace
}  // namespace piezobench::dsp
