#include "piezobench/dsp/frf.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "piezobench/core/error.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::dsp {
namespace {

Frf two_outputs() {
  Frf f;
  f.freq_Hz = Eigen::VectorXd::LinSpaced(5, 1.0, 5.0);
  f.input = std::string("u");  // (assigning the literal trips GCC 12 -Wrestrict, PR 105651)
  f.outputs.emplace_back("d_e");
  f.outputs.emplace_back("V_s");
  f.H = {Eigen::VectorXcd::Constant(5, {1.0, -1.0}), Eigen::VectorXcd::Constant(5, 2.0)};
  f.coherence = {Eigen::VectorXd::Ones(5), Eigen::VectorXd::Ones(5)};
  f.provenance.source = "run.mat";
  return f;
}

TEST(Frf, OutputIndexByName) {
  const Frf f = two_outputs();
  EXPECT_EQ(f.output_index("V_s"), 1);
  try {
    (void)f.output_index("force");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "output");
    const std::string what = e.what();
    EXPECT_NE(what.find("d_e, V_s"), std::string::npos) << what;
    EXPECT_NE(what.find("run.mat"), std::string::npos) << what;
  }
}

TEST(Frf, ValidateAcceptsAConsistentFrfAndNoCoherence) {
  Frf f = two_outputs();
  EXPECT_NO_THROW(f.validate());
  f.coherence.clear();
  EXPECT_NO_THROW(f.validate());
}

TEST(Frf, ValidateShowsTinyFrequenciesAsTheyAre) {
  // std::to_string printed both frequencies as "0.000000", as if they were zero.
  Frf f = two_outputs();
  f.freq_Hz << 0.0, 1e-12, 1e-12, 3.0, 4.0;
  try {
    f.validate();
    FAIL() << "no error for a repeated frequency";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "run.mat: freq_Hz: expected strictly increasing frequencies, found 1e-12 then 1e-12 at index 2");
  }
}

TEST(Frf, ValidateRejectsEachKindOfInconsistency) {
  auto expect_field = [](const Frf& f, const std::string& field) {
    try {
      f.validate("file.uff");
      ADD_FAILURE() << "no error for " << field;
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), field);
      EXPECT_NE(std::string(e.what()).find("file.uff"), std::string::npos);
    }
  };
  Frf f = two_outputs();
  f.freq_Hz(3) = f.freq_Hz(2);
  expect_field(f, "freq_Hz");
  f = two_outputs();
  f.H[1](2) = std::numeric_limits<double>::quiet_NaN();
  expect_field(f, "V_s");
  f = two_outputs();
  f.H[0].resize(4);
  expect_field(f, "d_e");
  f = two_outputs();
  f.H.pop_back();
  expect_field(f, "H");
  f = two_outputs();
  f.coherence[0](0) = std::numeric_limits<double>::infinity();
  expect_field(f, "d_e coherence");
  f = two_outputs();
  f.outputs[1] = "d_e";
  expect_field(f, "outputs");
  f = two_outputs();
  f.coherence.pop_back();
  expect_field(f, "coherence");
  // Issue 21: a coherence outside [0, 1] and negative frequencies were accepted from FRF files.
  f = two_outputs();
  f.coherence[1](3) = 1.5;
  expect_field(f, "V_s coherence");
  f = two_outputs();
  f.coherence[0](1) = -0.01;
  expect_field(f, "d_e coherence");
  f = two_outputs();
  f.coherence[0](1) = 1.0 + 1e-12;  // round-off of |Suy|^2 / (Suu Syy) on a noiseless record
  EXPECT_NO_THROW(f.validate());
  f = two_outputs();
  f.freq_Hz(0) = -1.0;
  expect_field(f, "freq_Hz");
}

TEST(ExcitedBand, FromTheCoherenceOfTheBestOutputIgnoringDipsAndIsolatedBins) {
  // 0 .. 100 Hz in 0.5 Hz bins; the input excites 2 .. 60 Hz. Output 0 has an anti-resonance dip
  // at 30 Hz (3 bins of low coherence), output 1 a single noisy bin of high coherence at 80 Hz.
  Frf f;
  const Eigen::Index n = 201;
  f.freq_Hz = Eigen::VectorXd::LinSpaced(n, 0.0, 100.0);
  f.input = std::string("u");
  f.outputs = {"a", "b"};
  f.H = {Eigen::VectorXcd::Ones(n), Eigen::VectorXcd::Ones(n)};
  Eigen::VectorXd a = Eigen::VectorXd::Constant(n, 0.05), b = Eigen::VectorXd::Constant(n, 0.05);
  for (Eigen::Index k = 0; k < n; ++k) {
    if (f.freq_Hz(k) >= 2.0 && f.freq_Hz(k) <= 60.0) a(k) = 0.95;
  }
  a(60) = a(61) = a(59) = 0.1;  // 29.5 .. 30.5 Hz
  b(160) = 0.99;                 // 80 Hz
  f.coherence = {a, b};
  const FrequencyBand band = excited_band(f, 0.5);
  EXPECT_TRUE(band.from_coherence);
  EXPECT_DOUBLE_EQ(band.fmin_Hz, 2.0);
  EXPECT_DOUBLE_EQ(band.fmax_Hz, 60.0);
  // Without coherence: the whole positive grid.
  f.coherence.clear();
  const FrequencyBand all = excited_band(f);
  EXPECT_FALSE(all.from_coherence);
  EXPECT_DOUBLE_EQ(all.fmin_Hz, 0.5);
  EXPECT_DOUBLE_EQ(all.fmax_Hz, 100.0);
  // Nothing excited: an error that says what to check.
  f.coherence = {Eigen::VectorXd::Constant(n, 0.1), Eigen::VectorXd::Constant(n, 0.2)};
  try {
    (void)excited_band(f);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "coherence");
    EXPECT_NE(std::string(e.what()).find("check the input and output channels"), std::string::npos) << e.what();
  }
}

TEST(SelectBand, KeepsTheLinesOutputsAndCoherenceAskedFor) {
  // 0 .. 5 Hz in 1 Hz lines; output 1's coherence is low at 3 Hz, output 0's at 5 Hz.
  Frf f;
  f.freq_Hz = Eigen::VectorXd::LinSpaced(6, 0.0, 5.0);
  f.input = std::string("u");
  f.outputs = {"a", "b"};
  f.H = {Eigen::VectorXcd::LinSpaced(6, 10.0, 15.0), Eigen::VectorXcd::LinSpaced(6, 20.0, 25.0)};
  Eigen::VectorXd cb = Eigen::VectorXd::Constant(6, 0.9);
  cb(3) = 0.2;
  Eigen::VectorXd ca = Eigen::VectorXd::Ones(6);
  ca(5) = 0.1;
  f.coherence = {ca, cb};
  f.provenance.source = "run.mat";

  // Inclusive bounds, the 0 Hz line kept when fmin is 0 and not excluded, every output.
  BandSelection s;
  s.fmax_Hz = 2.0;
  Frf all = select_band(f, s);
  ASSERT_EQ(all.freq_Hz.size(), 3);
  EXPECT_EQ(all.freq_Hz(0), 0.0);
  EXPECT_EQ(all.outputs, f.outputs);
  EXPECT_EQ(all.H[1](2), std::complex<double>(22.0, 0.0));
  ASSERT_EQ(all.coherence.size(), 2U);
  EXPECT_EQ(all.coherence[1](2), 0.9);
  EXPECT_EQ(all.provenance.source, "run.mat");
  EXPECT_NO_THROW(all.validate());

  // One output, no DC, no upper bound, and its low-coherence line dropped.
  s = BandSelection{};
  s.exclude_dc = true;
  s.min_coherence = 0.5;
  s.outputs = {1};
  const Frf b = select_band(f, s);
  ASSERT_EQ(b.freq_Hz.size(), 4);
  EXPECT_EQ(b.freq_Hz(0), 1.0);
  EXPECT_EQ(b.freq_Hz(2), 4.0);
  EXPECT_EQ(b.outputs, std::vector<std::string>{"b"});
  EXPECT_EQ(b.H[0](2), std::complex<double>(24.0, 0.0));
  // Both outputs: a line goes when either output's coherence is low.
  s.outputs = {};
  EXPECT_EQ(select_band(f, s).freq_Hz.size(), 3);
  // Without coherence nothing is filtered by it, and the band has none either.
  Frf no_coherence = f;
  no_coherence.coherence.clear();
  const Frf nc = select_band(no_coherence, s);
  EXPECT_EQ(nc.freq_Hz.size(), 5);
  EXPECT_TRUE(nc.coherence.empty());
  EXPECT_NO_THROW(nc.validate());

  // Nothing inside: no line (the caller decides); an output that does not exist: InputError.
  s = BandSelection{};
  s.fmin_Hz = 7.0;
  EXPECT_EQ(select_band(f, s).freq_Hz.size(), 0);
  s.fmin_Hz = 0.0;
  s.outputs = {2};
  EXPECT_THROW((void)select_band(f, s), InputError);
}

// A mass-spring-damper m x'' + c x' + k x = F with outputs [x, x'] and a second input that only
// moves the velocity output: H_x = 1 / (k - m w^2 + j c w), H_v = j w H_x.
lti::StateSpace two_output_plant() {
  const double m = 2.0, k = 8.0e4, c = 40.0;
  lti::StateSpace s;
  s.A = (lti::Matrix(2, 2) << 0.0, 1.0, -k / m, -c / m).finished();
  s.B = (lti::Matrix(2, 2) << 0.0, 0.0, 1.0 / m, 0.0).finished();
  s.C = lti::Matrix::Identity(2, 2);
  s.D = (lti::Matrix(2, 2) << 0.0, 0.0, 0.0, 3.0).finished();
  return s;
}

TEST(FrfConversion, ModelResponseToFrfIsHzNamedAndPerOutput) {
  const double m = 2.0, k = 8.0e4, c = 40.0;
  const Eigen::VectorXd f_Hz = Eigen::VectorXd::LinSpaced(50, 1.0, 100.0);
  const lti::FrequencyResponse r = lti::freqresp(two_output_plant(), kTwoPi * f_Hz);
  const Frf frf = to_frf(r, "F", {"x", "v"});
  EXPECT_EQ(frf.input, "F");
  ASSERT_EQ(frf.outputs.size(), 2U);
  EXPECT_EQ(frf.outputs[1], "v");
  EXPECT_TRUE(frf.coherence.empty());
  ASSERT_EQ(frf.freq_Hz.size(), 50);
  for (Eigen::Index i = 0; i < 50; ++i) {
    EXPECT_NEAR(frf.freq_Hz(i), f_Hz(i), 1e-13 * f_Hz(i));
    const double w = kTwoPi * f_Hz(i);
    const std::complex<double> hx = 1.0 / std::complex<double>(k - m * w * w, c * w);
    EXPECT_LT(std::abs(frf.H[0](i) - hx), 1e-12 * std::abs(hx));
    EXPECT_LT(std::abs(frf.H[1](i) - std::complex<double>(0.0, w) * hx), 1e-12 * std::abs(w * hx));
  }
  // The second input: only the feedthrough to v.
  const Frf second = to_frf(r, "G", {"x", "v"}, 1);
  EXPECT_EQ(second.H[0](7), std::complex<double>(0.0, 0.0));
  EXPECT_EQ(second.H[1](7), std::complex<double>(3.0, 0.0));
}

TEST(FrfConversion, FrfToResponseAndBackIsTheSame) {
  const Frf f = two_outputs();
  const lti::FrequencyResponse r = to_frequency_response(f);
  ASSERT_EQ(r.omega.size(), 5);
  ASSERT_EQ(r.H.size(), 5U);
  for (Eigen::Index k = 0; k < 5; ++k) {
    EXPECT_DOUBLE_EQ(r.omega(k), kTwoPi * f.freq_Hz(k));
    ASSERT_EQ(r.H[static_cast<std::size_t>(k)].rows(), 2);
    ASSERT_EQ(r.H[static_cast<std::size_t>(k)].cols(), 1);
  }
  EXPECT_EQ(r.channel(0, 0), f.H[0]);
  EXPECT_EQ(r.channel(1, 0), f.H[1]);
  const Frf back = to_frf(r, f.input, f.outputs);
  for (Eigen::Index k = 0; k < 5; ++k) EXPECT_DOUBLE_EQ(back.freq_Hz(k), f.freq_Hz(k));
  EXPECT_EQ(back.H[0], f.H[0]);
  EXPECT_EQ(back.H[1], f.H[1]);
}

TEST(FrfConversion, RefusesNamesSizesAndGridsThatDoNotFit) {
  const lti::FrequencyResponse r = lti::freqresp(two_output_plant(), Eigen::VectorXd::LinSpaced(4, 1.0, 4.0));
  const auto field_of = [](auto&& call) {
    try {
      call();
    } catch (const InputError& e) {
      return e.field();
    }
    return std::string("no error");
  };
  EXPECT_EQ(field_of([&] { (void)to_frf(r, "F", {"x"}); }), "outputs");
  EXPECT_EQ(field_of([&] { (void)to_frf(r, "F", {"x", "v"}, 2); }), "input");
  EXPECT_EQ(field_of([&] { (void)to_frf(r, "F", {"x", "x"}); }), "outputs");
  lti::FrequencyResponse bad = r;
  bad.omega(2) = bad.omega(1);  // not increasing
  EXPECT_EQ(field_of([&] { (void)to_frf(bad, "F", {"x", "v"}); }), "freq_Hz");
  bad.H.pop_back();
  EXPECT_EQ(field_of([&] { (void)to_frf(bad, "F", {"x", "v"}); }), "H");
  Frf f = two_outputs();
  f.H[1].resize(3);
  EXPECT_THROW((void)to_frequency_response(f), InputError);
}

}  // namespace
}  // namespace piezobench::dsp
