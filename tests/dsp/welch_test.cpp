// Welch spectra, H1/H2 and coherence: against scipy.signal and Octave's signal package (fixtures
// from scripts/fixtures/make_dsp_fixtures.py / .m) and against results known by construction.
#include "piezobench/dsp/welch.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>

#include "piezobench/core/error.hpp"
#include "test_util.hpp"

namespace piezobench::dsp {
namespace {

using Eigen::Index;
using Eigen::VectorXcd;
using Eigen::VectorXd;
using test::all_near;
using test::near;
using test::Tolerance;

// The acceptance bound: our spectra equal scipy's and Octave's to 1e-10 relative. They
// differ in FFT round-off only (measured ~1e-13 worst case on a complex CSD entry).
constexpr Tolerance kReference{1e-10, 0.0};

nlohmann::json load(const std::string& name) {
  return nlohmann::json::parse(test::read_text(test::fixture_path("dsp/" + name)));
}

VectorXd vec(const nlohmann::json& j) {
  const auto v = j.get<std::vector<double>>();
  return Eigen::Map<const VectorXd>(v.data(), static_cast<Index>(v.size()));
}

VectorXcd cvec(const nlohmann::json& re, const nlohmann::json& im) {
  VectorXcd z(static_cast<Index>(re.size()));
  z.real() = vec(re);
  z.imag() = vec(im);
  return z;
}

struct Signals {
  double fs = 0.0;
  VectorXd u, y1, y2;
  nlohmann::json cases;
};

const Signals& signals() {
  static const Signals s = [] {
    const auto j = load("welch_signals.json");
    Signals r;
    r.fs = j.at("fs").get<double>();
    r.u = vec(j.at("u"));
    r.y1 = vec(j.at("y1"));
    r.y2 = vec(j.at("y2"));
    r.cases = j.at("cases");
    return r;
  }();
  return s;
}

WelchOptions options_of(const nlohmann::json& c) {
  WelchOptions o;
  o.window = window_type_from_string(c.at("window").get<std::string>());
  o.nfft = c.at("nfft").get<Index>();
  o.overlap = c.at("overlap").get<double>();
  o.detrend = detrend_from_string(c.at("detrend").get<std::string>());
  return o;
}

FrfEstimate estimate_case(const nlohmann::json& c, FrfEstimator estimator = FrfEstimator::kH1) {
  const auto& s = signals();
  WelchOptions o = options_of(c);
  o.estimator = estimator;
  return estimate_frf(channel("u", s.u), {channel("y1", s.y1), channel("y2", s.y2)}, s.fs, o, "fixture");
}

TEST(Welch, RecordSettingsAreTheCampaignsDefaults) {
  // 4 s segments (0.25 Hz bins) when the record holds 16 s or more; else a quarter of the record;
  // never below 256 samples; mean removed; H1, hann-periodic, 50 %.
  EXPECT_EQ(segment_length_for_record(600000, 10000.0), 40000);
  EXPECT_EQ(segment_length_for_record(100000, 10000.0), 25000);
  EXPECT_EQ(segment_length_for_record(600000, 10000.0, 1.0), 10000);
  EXPECT_EQ(segment_length_for_record(800, 10000.0), 256);
  const WelchOptions o = welch_options_for_record(600000, 10000.0);
  EXPECT_EQ(o.nfft, 40000);
  EXPECT_EQ(o.detrend, Detrend::kMean);
  EXPECT_EQ(o.window, WindowType::kHannPeriodic);
  EXPECT_EQ(o.estimator, FrfEstimator::kH1);
  EXPECT_DOUBLE_EQ(o.overlap, 0.5);
  EXPECT_THROW((void)segment_length_for_record(1000, 0.0), InputError);
  EXPECT_THROW((void)segment_length_for_record(1000, 100.0, -1.0), InputError);
}

TEST(Welch, NoverlapIsOctavesFloorOfTheFraction) {
  for (const auto& c : signals().cases) {
    EXPECT_EQ(options_of(c).noverlap(), c.at("noverlap").get<Index>()) << c.at("name");
  }
  WelchOptions o;
  o.nfft = 10;
  o.overlap = 0.25;
  EXPECT_EQ(o.noverlap(), 2);
}

TEST(Welch, EqualsScipyCsdWelchCoherence) {
  const auto scipy = load("welch_scipy.json").at("cases");
  ASSERT_EQ(scipy.size(), signals().cases.size());
  for (std::size_t i = 0; i < scipy.size(); ++i) {
    const auto& ref = scipy[i];
    SCOPED_TRACE(ref.at("name").get<std::string>());
    const FrfEstimate e = estimate_case(signals().cases[i]);
    const CrossSpectra& sp = e.spectra;
    EXPECT_TRUE(all_near(sp.freq_Hz, vec(ref.at("freq_Hz")), kReference));
    EXPECT_TRUE(all_near(sp.Suu, vec(ref.at("Suu")), kReference));
    const char* labels[2] = {"y1", "y2"};
    for (std::size_t o = 0; o < 2; ++o) {
      const std::string y = labels[o];
      EXPECT_TRUE(all_near(sp.Syy[o], vec(ref.at("Syy_" + y)), kReference)) << y;
      EXPECT_TRUE(all_near(sp.Suy[o], cvec(ref.at("Suy_" + y + "_re"), ref.at("Suy_" + y + "_im")), kReference)) << y;
      EXPECT_TRUE(all_near(e.frf.coherence[o], vec(ref.at("coherence_" + y)), kReference)) << y;
      // H1 = csd(u, y) / welch(u) with scipy's own numbers.
      const VectorXcd h1 = cvec(ref.at("Suy_" + y + "_re"), ref.at("Suy_" + y + "_im")).array() /
                           vec(ref.at("Suu")).array().cast<std::complex<double>>();
      EXPECT_TRUE(all_near(e.frf.H[o], h1, kReference)) << y;
    }
  }
}

TEST(Welch, EqualsOctaveCpsdTfestimateMscohere) {
  const auto octave = load("welch_octave.json").at("cases");
  ASSERT_EQ(octave.size(), signals().cases.size());
  int compared = 0;
  for (std::size_t i = 0; i < octave.size(); ++i) {
    const auto& ref = octave[i];
    if (ref.contains("skipped")) continue;  // flat-top: Octave's pwelch refuses negative windows
    ++compared;
    SCOPED_TRACE(ref.at("name").get<std::string>());
    const FrfEstimate e = estimate_case(signals().cases[i]);
    EXPECT_TRUE(all_near(e.spectra.freq_Hz, vec(ref.at("freq_Hz")), kReference));
    EXPECT_TRUE(all_near(e.spectra.Suu, vec(ref.at("Suu")), kReference));
    const char* labels[2] = {"y1", "y2"};
    for (std::size_t o = 0; o < 2; ++o) {
      const std::string y = labels[o];
      EXPECT_TRUE(all_near(e.spectra.Suy[o], cvec(ref.at("Suy_" + y + "_re"), ref.at("Suy_" + y + "_im")), kReference));
      EXPECT_TRUE(all_near(e.frf.H[o], cvec(ref.at("H1_" + y + "_re"), ref.at("H1_" + y + "_im")), kReference));
      EXPECT_TRUE(all_near(e.frf.coherence[o], vec(ref.at("coherence_" + y)), kReference));
    }
  }
  EXPECT_EQ(compared, 5);
}

TEST(Welch, H2IsSyyOverConjugateOfSuy) {
  const auto& c = signals().cases[0];
  const FrfEstimate e = estimate_case(c, FrfEstimator::kH2);
  EXPECT_EQ(e.frf.provenance.estimator, "H2");
  for (std::size_t o = 0; o < 2; ++o) {
    const VectorXcd expected =
        e.spectra.Syy[o].array().cast<std::complex<double>>() / e.spectra.Suy[o].conjugate().array();
    EXPECT_TRUE(all_near(e.frf.H[o], expected, Tolerance{test::kRoundoff, 0.0}));
    // H1 / H2 = coherence (Bendat & Piersol eq. 9.71): |Suy|^2 / (Suu Syy).
    const FrfEstimate e1 = estimate_case(c, FrfEstimator::kH1);
    const VectorXcd ratio = e1.frf.H[o].array() / e.frf.H[o].array();
    EXPECT_TRUE(all_near(ratio, e.frf.coherence[o].cast<std::complex<double>>(), Tolerance{1e-12, 0.0}));
  }
}

TEST(Welch, ProvenanceDescribesTheEstimate) {
  const FrfEstimate e = estimate_case(signals().cases[1]);  // hamming-symmetric, 127, 0.3
  EXPECT_EQ(e.frf.provenance.window, "hamming-symmetric");
  EXPECT_EQ(e.frf.provenance.nfft, 127);
  EXPECT_EQ(e.frf.provenance.overlap, 0.3);
  EXPECT_EQ(e.frf.provenance.detrend, "none");
  EXPECT_EQ(e.frf.provenance.averages, (2400 - 127) / (127 - 38) + 1);
  EXPECT_EQ(e.frf.provenance.sample_rate, 1000.0);
  EXPECT_EQ(e.frf.provenance.source, "fixture");
  EXPECT_EQ(e.frf.input, "u");
  EXPECT_EQ(e.frf.outputs, (std::vector<std::string>{"y1", "y2"}));
  EXPECT_EQ(e.frf.freq_Hz.size(), 64);
  EXPECT_NO_THROW(e.frf.validate());
}

// Parseval: with a rectangular window and no overlap, the one-sided density integrates to the mean
// square of the samples used, exactly (DC and Nyquist counted once, the rest twice).
TEST(Welch, RectangularDensityIntegratesToMeanSquare) {
  for (Index nfft : {64, 97}) {
    std::mt19937_64 rng(7);
    std::normal_distribution<double> normal;
    VectorXd x(1000);
    for (Index i = 0; i < x.size(); ++i) x(i) = 0.3 + normal(rng);
    WelchOptions o;
    o.window = WindowType::kRectangular;
    o.nfft = nfft;
    o.overlap = 0.0;
    const double fs = 50.0;
    const VectorXd p = welch_psd(x, fs, o);
    const Index used = (x.size() / nfft) * nfft;
    EXPECT_TRUE(near(p.sum() * fs / static_cast<double>(nfft), x.head(used).squaredNorm() / static_cast<double>(used),
                     test::kRoundoff))
        << "nfft " << nfft;
  }
}

// y = g u + c: with mean detrending every estimate is exact: H1 = H2 = g, coherence 1.
TEST(Welch, ScaledCopyGivesExactGainAndUnitCoherence) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal;
  VectorXd u(5000);
  for (Index i = 0; i < u.size(); ++i) u(i) = normal(rng);
  const VectorXd y = (-2.5 * u).array() + 4.0;
  WelchOptions o;
  o.nfft = 500;
  o.detrend = Detrend::kMean;
  for (FrfEstimator est : {FrfEstimator::kH1, FrfEstimator::kH2}) {
    o.estimator = est;
    const FrfEstimate e = estimate_frf(channel("u", u), {channel("y", y)}, 1e3, o);
    EXPECT_TRUE(all_near(e.frf.H[0].tail(250), VectorXcd::Constant(250, -2.5), Tolerance{1e-12, 0.0}));
    EXPECT_TRUE(all_near(e.frf.coherence[0].tail(250), VectorXd::Ones(250), Tolerance{1e-12, 0.0}));
  }
}

// y = g u + n with independent noise of variance r g^2 var(u): H1 -> g (unbiased), H2 -> g (1 + r),
// coherence -> 1 / (1 + r). Averaged over 500 bins of 400 segments the estimates are within ~0.3 %.
TEST(Welch, OutputNoiseBiasesH2ButNotH1) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  const Index n = 400 * 1000;
  VectorXd u(n), y(n);
  const double g = 3.0, r = 0.25;
  for (Index i = 0; i < n; ++i) {
    u(i) = normal(rng);
    y(i) = g * u(i) + std::sqrt(r) * g * normal(rng);
  }
  WelchOptions o;
  o.nfft = 1000;
  o.overlap = 0.0;
  const FrfEstimate h1 = estimate_frf(channel("u", u), {channel("y", y)}, 1.0, o);
  o.estimator = FrfEstimator::kH2;
  const FrfEstimate h2 = estimate_frf(channel("u", u), {channel("y", y)}, 1.0, o);
  const Index bins = h1.frf.freq_Hz.size();
  EXPECT_TRUE(near(h1.frf.H[0].real().mean(), g, 3e-3));
  EXPECT_TRUE(near(h2.frf.H[0].real().mean(), g * (1 + r), 3e-3));
  EXPECT_TRUE(near(h1.frf.coherence[0].mean(), 1.0 / (1 + r), 3e-3));
  EXPECT_LT(std::abs(h1.frf.H[0].imag().mean()), 3e-3 * g);
  EXPECT_EQ(bins, 501);
}

TEST(Welch, ResultDoesNotDependOnTheThreadCount) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  VectorXd u(200000), y(200000);
  for (Index i = 0; i < u.size(); ++i) {
    u(i) = normal(rng);
    y(i) = 0.5 * u(i) + normal(rng);
  }
  WelchOptions o;
  o.nfft = 1000;
  o.threads = 1;
  const CrossSpectra one = cross_spectra(channel("u", u), {channel("y", y)}, 1e3, o);
  o.threads = 2;
  const CrossSpectra two = cross_spectra(channel("u", u), {channel("y", y)}, 1e3, o);
  o.threads = 5;
  const CrossSpectra five = cross_spectra(channel("u", u), {channel("y", y)}, 1e3, o);
  EXPECT_TRUE(one.Suu == two.Suu && one.Suu == five.Suu);
  EXPECT_TRUE(one.Suy[0] == two.Suy[0] && one.Suy[0] == five.Suy[0]);
  EXPECT_TRUE(one.Syy[0] == two.Syy[0]);
}

TEST(Welch, SineOnABinShowsItsPowerAtThatBin) {
  // A sine of amplitude A at bin m, Hann window: the one-sided PSD at bin m is
  // A^2 / 2 * (sum w / 2)^2 ... normalised: P(m) = A^2 (sum w)^2 / (8 fs sum w^2) * 2 (one-sided).
  const Index nfft = 240, m = 30;
  const double fs = 480.0, A = 1.7;
  VectorXd x(nfft * 10);
  for (Index i = 0; i < x.size(); ++i) x(i) = A * std::sin(2 * std::numbers::pi * static_cast<double>(m) * static_cast<double>(i) / nfft + 0.3);
  WelchOptions o;
  o.nfft = nfft;
  const VectorXd w = make_window(o.window, nfft);
  const VectorXd p = welch_psd(x, fs, o);
  const double expected = 2.0 * std::pow(A * w.sum() / 2.0, 2) / (fs * w.squaredNorm());
  EXPECT_TRUE(near(p(m), expected, test::kRoundoff));
  EXPECT_TRUE(near(p(m - 1), expected / 4.0, test::kRoundoff));  // periodic Hann: neighbours at -6 dB
  EXPECT_LT(p(m + 5), 1e-20 * expected);
}

// --- bad input ---------------------------------------------------------------------------------

TEST(WelchErrors, OptionsNameTheBadField) {
  WelchOptions o;
  o.nfft = 1;
  try {
    o.validate("run.mat");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "nfft");
    EXPECT_NE(std::string(e.what()).find("run.mat"), std::string::npos);
  }
  o.nfft = 8;
  for (double bad : {-0.1, 1.0, std::nan("")}) {
    o.overlap = bad;
    try {
      o.validate();
      FAIL() << bad;
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), "overlap");
    }
  }
  o.overlap = 0.5;
  o.threads = -1;
  EXPECT_THROW(o.validate(), InputError);
}

TEST(WelchErrors, NanIsReportedWithItsChannelAndIndex) {
  VectorXd u = VectorXd::LinSpaced(100, 0.0, 1.0);
  VectorXd y = u;
  y(42) = std::nan("");
  WelchOptions o;
  o.nfft = 16;
  try {
    (void)estimate_frf(channel("u", u), {channel("force", y)}, 1e3, o, "bench.mat");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "force");
    const std::string what = e.what();
    EXPECT_NE(what.find("bench.mat"), std::string::npos) << what;
    EXPECT_NE(what.find("NaN at sample 42"), std::string::npos) << what;
  }
}

// Non-finite samples are not checked in a pass of their own: the samples after the last segment
// are checked up front and the spectral sums at the end, and only then are the channels scanned,
// in order (input first), for the message. These records have 200,000 samples; nfft = 30000 with
// 50 % overlap gives 12 segments covering samples [0, 195000).
struct LongRecord {
  static constexpr Index kN = 200000;
  static constexpr Index kCovered = 195000;
  VectorXd u, y1, y2;
  WelchOptions options;
  LongRecord() : u(kN), y1(kN), y2(kN) {
    for (Index k = 0; k < kN; ++k) {
      const double x = static_cast<double>(k);
      u(k) = std::sin(0.013 * x) + 0.3 * std::cos(0.071 * x);
      y1(k) = 0.5 * std::sin(0.013 * x + 0.2);
      y2(k) = std::cos(0.0031 * x);
    }
    options.nfft = 30000;
    options.overlap = 0.5;
  }
  // The InputError message of estimate_frf on (u; y1, y2), which must name `field`.
  std::string error(const std::string& field) const {
    return test::input_error(
        [&] { (void)estimate_frf(channel("u", u), {channel("y1", y1), channel("y2", y2)}, 1e4, options, "rec.mat"); },
        field);
  }
};

TEST(WelchErrors, NonFiniteSamplesAfterTheLastSegmentAreReported) {
  LongRecord r;
  ASSERT_EQ((LongRecord::kN - r.options.nfft) / (r.options.nfft - r.options.noverlap()) + 1, 12);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  r.y2(LongRecord::kCovered) = nan;  // first sample no segment reaches
  EXPECT_EQ(r.error("y2"), "rec.mat: y2: expected finite samples, found NaN at sample 195000 (0-based)");
  r.y2(LongRecord::kCovered) = 0.0;
  r.y1(LongRecord::kN - 1) = -std::numeric_limits<double>::infinity();  // the very last sample
  EXPECT_EQ(r.error("y1"), "rec.mat: y1: expected finite samples, found -Inf at sample 199999 (0-based)");
  r.u(LongRecord::kN - 2) = nan;  // the input is reported first
  EXPECT_EQ(r.error("u"), "rec.mat: u: expected finite samples, found NaN at sample 199998 (0-based)");
  // welch_psd (no outputs) checks its tail as well.
  VectorXd x = r.u;
  x(LongRecord::kN - 2) = 0.0;
  x(LongRecord::kCovered + 7) = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(test::contains(test::input_error([&] { (void)welch_psd(x, 1e4, r.options); }, "x"),
                             "Inf at sample 195007 (0-based)"));
}

TEST(WelchErrors, NonFiniteSamplesInsideSegmentsNameTheChannelInputFirst) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (Detrend detrend : {Detrend::kNone, Detrend::kMean, Detrend::kLinear}) {
    for (int threads : {1, 2}) {
      SCOPED_TRACE(to_string(detrend) + ", " + std::to_string(threads) + " thread(s)");
      LongRecord r;
      r.options.detrend = detrend;
      r.options.threads = threads;
      // Each bad sample alone (only the spectral sums can reveal it): that channel and sample.
      const auto alone = [&](VectorXd LongRecord::*channel_of, const std::string& name, Index k, double value,
                             const std::string& found) {
        LongRecord bad = r;
        (bad.*channel_of)(k) = value;
        EXPECT_EQ(bad.error(name), "rec.mat: " + name + ": expected finite samples, found " + found + " at sample " +
                                       std::to_string(k) + " (0-based)");
      };
      alone(&LongRecord::y2, "y2", 1000, inf, "Inf");
      alone(&LongRecord::y1, "y1", 150000, nan, "NaN");
      alone(&LongRecord::u, "u", 194999, nan, "NaN");  // the last sample of the last segment
      // Sample 0 is in one segment only, where the periodic Hann window is exactly 0.
      alone(&LongRecord::u, "u", 0, -inf, "-Inf");  // the sign kept, as the readers do
      alone(&LongRecord::y1, "y1", 0, nan, "NaN");
      // Several bad channels: the input first, then the outputs in order, whatever the indices.
      r.y2(1000) = inf;
      r.y1(150000) = nan;
      EXPECT_EQ(r.error("y1"), "rec.mat: y1: expected finite samples, found NaN at sample 150000 (0-based)");
      r.u(194999) = nan;
      EXPECT_EQ(r.error("u"), "rec.mat: u: expected finite samples, found NaN at sample 194999 (0-based)");
    }
  }
}

// Finite samples whose spectral sums overflow (|x| ~ 1e200: |X|^2 > DBL_MAX) are valid input:
// cross_spectra does not report them as non-finite samples (welch.cpp returns the sums as they
// are), so the densities hold +Inf, never NaN, and no InputError is thrown.
TEST(Welch, OverflowingSumsOfFiniteSamplesAreNotReportedAsNonFiniteInput) {
  LongRecord r;
  const VectorXd big = r.u * 1e200;
  ASSERT_TRUE(big.allFinite());
  VectorXd psd;
  EXPECT_NO_THROW(psd = welch_psd(big, 1e4, r.options));
  ASSERT_EQ(psd.size(), r.options.nfft / 2 + 1);
  EXPECT_FALSE(psd.array().isNaN().any());
  EXPECT_TRUE((psd.array() == std::numeric_limits<double>::infinity()).any());
  // The same samples scaled down by 1e-200 give finite densities (1e-400 times these).
  const VectorXd small = welch_psd(r.u, 1e4, r.options);
  EXPECT_TRUE(small.allFinite());
  EXPECT_NO_THROW((void)cross_spectra(channel("u", big), {channel("y", r.y1)}, 1e4, r.options, "rec.mat"));
}

TEST(WelchErrors, ShortRecordDifferentLengthsZeroInputAndBadRate) {
  const VectorXd u = VectorXd::LinSpaced(100, 0.0, 1.0);
  WelchOptions o;
  o.nfft = 128;
  EXPECT_THROW((void)estimate_frf(channel("u", u), {channel("y", u)}, 1e3, o), InputError);
  o.nfft = 32;
  const VectorXd shorter = u.head(99);
  try {
    (void)estimate_frf(channel("u", u), {channel("d_e", shorter)}, 1e3, o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "d_e");
  }
  const VectorXd zero = VectorXd::Zero(100);
  try {
    (void)estimate_frf(channel("dac", zero), {channel("y", u)}, 1e3, o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "dac");
  }
  // A silent output is an error for H1 too (its coherence would be 0/0, printed "nan", exit 0).
  test::expect_input_error([&] { (void)estimate_frf(channel("u", u), {channel("y", zero)}, 1e3, o, "rec.mat"); },
                           {"rec.mat", "y", "zero power at every frequency", "constant channel"});
  o.estimator = FrfEstimator::kH2;
  EXPECT_THROW((void)estimate_frf(channel("u", u), {channel("y", zero)}, 1e3, o), InputError);
  EXPECT_THROW((void)estimate_frf(channel("u", u), {channel("y", u)}, 0.0, o), InputError);
  EXPECT_THROW((void)estimate_frf(channel("u", u), {}, 1e3, o), InputError);
}

TEST(WelchEnums, EstimatorNamesRoundTrip) {
  for (FrfEstimator e : {FrfEstimator::kH1, FrfEstimator::kH2}) EXPECT_EQ(frf_estimator_from_string(to_string(e)), e);
  EXPECT_THROW((void)frf_estimator_from_string("H3"), InputError);
}

}  // namespace
}  // namespace piezobench::dsp
