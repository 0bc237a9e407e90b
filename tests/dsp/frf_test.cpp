#include "piezobench/dsp/frf.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "piezobench/core/error.hpp"

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

}  // namespace
}  // namespace piezobench::dsp
