#include "piezobench/io/lti_toml.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "piezobench/core/error.hpp"
#include "piezobench/lti/freqresp.hpp"
#include "test_util.hpp"

namespace piezobench::io {
namespace {

using test::near;

// |H(j w)| of the parsed system at one frequency.
lti::Complex response_at(const LtiFile& f, double w) {
  lti::Vector omega(1);
  omega << w;
  return lti::freqresp(f.system, omega).H.front()(0, 0);
}

std::string error_of(const std::string& text) {
  try {
    parse_lti_toml(text, "sys.toml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(LtiToml, WrittenTransferFunctionReadsBack) {
  // The IFF plant form: num/den in descending powers, a delay, a description with quotes.
  const lti::TransferFunction tf((lti::Vector(4) << 8.7e-6, -7.1e-5, 0.583, 0.0).finished(),
                                 (lti::Vector(4) << 2.78e-6, 2.79e-5, 1.00005, 2.5155).finished(), 0.0, 300e-6);
  test::TempDir dir;
  const auto path = dir.path() / "plant.toml";
  write_lti_toml(tf, path, "fitted to \"u -> Vs\"");
  const LtiFile f = read_lti_toml(path);
  EXPECT_EQ(f.form, LtiForm::kTransferFunction);
  EXPECT_EQ(f.description, "fitted to \"u -> Vs\"");
  ASSERT_EQ(f.system.input_delay.size(), 1);
  EXPECT_DOUBLE_EQ(f.system.input_delay(0), 300e-6);
  const lti::Vector w = lti::Vector::LinSpaced(20, 1.0, 5000.0);
  EXPECT_TRUE(test::all_near(lti::freqresp(f.system, w).channel(0, 0), lti::freqresp(tf, w), {1e-12, 0.0}));
}

TEST(LtiToml, TransferFunctionMatchesItsPolynomials) {
  const LtiFile f = parse_lti_toml("num = [2.0, 6.0]\nden = [1, 3.0, 2.0]\ndescription = 'test'\n", "sys.toml");
  EXPECT_EQ(f.form, LtiForm::kTransferFunction);
  EXPECT_EQ(f.description, "test");
  const lti::Complex s(0.0, 1.7);
  const lti::Complex expected = (2.0 * s + 6.0) / (s * s + 3.0 * s + 2.0);
  EXPECT_TRUE(test::near(response_at(f, 1.7), expected, {test::kRoundoff, 0.0}));
}

TEST(LtiToml, LargeIntegersAreTakenAsTheNearestDouble) {
  // toml++ converts only exactly representable integers; 2^63 - 1 was refused as "expected a
  // number, found a number".
  const LtiFile f = parse_lti_toml("num = [9223372036854775807]\nden = [1, 9223372036854775807]\n", "big.toml");
  EXPECT_TRUE(test::near(response_at(f, 0.0), lti::Complex(1.0, 0.0), {test::kRoundoff, 0.0}));
}

TEST(LtiToml, ZpkAcceptsRealAndComplexEntries) {
  const LtiFile f = parse_lti_toml("zeros = [-1.0]\npoles = [[-1.0, 2.0], [-1.0, -2.0], -5]\ngain = 3.0\n", "z.toml");
  EXPECT_EQ(f.form, LtiForm::kZpk);
  const lti::Complex s(0.0, 0.9);
  const lti::Complex expected = 3.0 * (s + 1.0) / ((s - lti::Complex(-1, 2)) * (s - lti::Complex(-1, -2)) * (s + 5.0));
  EXPECT_TRUE(test::near(response_at(f, 0.9), expected, {test::kRoundoff, 0.0}));
}

TEST(LtiToml, StateSpaceWithDelayAndDefaultD) {
  const LtiFile f = parse_lti_toml("A = [[0.0, 1.0], [-4.0, -0.4]]\nB = [[0.0], [1.0]]\nC = [[1.0, 0.0]]\ndelay = 0.01\n", "s.toml");
  EXPECT_EQ(f.form, LtiForm::kStateSpace);
  ASSERT_EQ(f.system.D.rows(), 1);
  EXPECT_EQ(f.system.D(0, 0), 0.0);
  const double w = 3.0;
  const lti::Complex s(0.0, w);
  const lti::Complex expected = std::exp(-s * 0.01) / (s * s + 0.4 * s + 4.0);
  EXPECT_TRUE(test::near(response_at(f, w), expected, {test::kRoundoff, 0.0}));
}

TEST(LtiToml, MalformedTomlNamesTheLine) {
  const std::string e = error_of("num = [1.0\nden = [1.0]\n");
  EXPECT_NE(e.find("sys.toml: line"), std::string::npos) << e;
  EXPECT_NE(e.find("expected valid TOML"), std::string::npos) << e;
}

TEST(LtiToml, ZeroLeadingDenominatorCoefficientIsRejected) {
  const std::string e = error_of("num = [1.0]\nden = [0.0, 1.0, 2.0]\n");
  EXPECT_NE(e.find("sys.toml: den"), std::string::npos) << e;
}

TEST(LtiToml, ImproperTransferFunctionIsRejected) {
  const std::string e = error_of("num = [1.0, 2.0, 3.0]\nden = [1.0, 2.0]\n");
  EXPECT_NE(e.find("sys.toml: num"), std::string::npos) << e;
  EXPECT_NE(e.find("proper"), std::string::npos) << e;
}

TEST(LtiToml, WrongMatrixSizesNameTheMatrix) {
  EXPECT_NE(error_of("A = [[0.0, 1.0], [-4.0, -0.4]]\nB = [[0.0], [1.0], [2.0]]\nC = [[1.0, 0.0]]\n").find("sys.toml: B"),
            std::string::npos);
  EXPECT_NE(error_of("A = [[0.0, 1.0], [-4.0]]\nB = [[0.0], [1.0]]\nC = [[1.0, 0.0]]\n").find("sys.toml: line 1: A[1]: expected a row of 2 numbers, found 1 numbers"),
            std::string::npos);
  EXPECT_NE(error_of("A = [[0.0, 1.0], [-4.0, -0.4]]\nB = [[0.0], [1.0]]\nC = [[1.0, 0.0, 2.0]]\n").find("sys.toml: C"),
            std::string::npos);
}

TEST(LtiToml, UnknownMissingAndMixedKeysAreNamed) {
  EXPECT_NE(error_of("num = [1.0]\nden = [1.0, 1.0]\ngian = 2\n").find("sys.toml: line 3: gian: expected one of num, den,"), std::string::npos);
  EXPECT_NE(error_of("num = [1.0]\n").find("sys.toml: den"), std::string::npos);
  EXPECT_NE(error_of("num = [1.0]\nden = [1.0, 1.0]\nzeros = []\n").find("sys.toml: form"), std::string::npos);
  EXPECT_NE(error_of("").find("found none"), std::string::npos);
}

TEST(LtiToml, NonFiniteAndWrongTypesAreRejected) {
  EXPECT_NE(error_of("num = [nan]\nden = [1.0, 1.0]\n").find("sys.toml: line 1: num[0]: expected a finite number, found nan"), std::string::npos);
  EXPECT_NE(error_of("num = ['one']\nden = [1.0, 1.0]\n").find("sys.toml: line 1: num[0]: expected a number, found a string"),
            std::string::npos);
  EXPECT_NE(error_of("num = 1.0\nden = [1.0, 1.0]\n").find("sys.toml: line 1: num: expected an array"), std::string::npos);
  EXPECT_NE(error_of("zeros = []\npoles = [[1.0, 2.0, 3.0]]\ngain = 1\n").find("sys.toml: line 2: poles[0]: expected a number or a pair [re, im], found an array of 3"), std::string::npos);
  EXPECT_NE(error_of("num = [1.0]\nden = [1.0, 1.0]\ndelay = -1.0\n").find("sys.toml: line 3: delay: expected a delay >= 0 s, found -1"), std::string::npos);
}

// Issue 21: hostile files end with an InputError at once: the two-line file whose C overflows
// (it looped forever in the balancing), an integer beyond double precision (it said "expected a
// number, found a number"), a denominator of 100,000 coefficients (it ran out of memory).
TEST(LtiToml, HostileFilesAreInputErrorsOrFinite) {
  // (StateSpace validates its matrices: the realization is finite or this is an InputError.)
  const std::string overflow = error_of("num = [1e308, 0.0]\nden = [1.0, 2.5]\n");
  EXPECT_TRUE(overflow == "no error" || test::contains(overflow, "sys.toml")) << overflow;
  const LtiFile big = parse_lti_toml("num = [9223372036854775807]\nden = [1.0, 2.5]\n", "sys.toml");
  EXPECT_EQ(big.system.D(0, 0), 0.0);
  EXPECT_NEAR(response_at(big, 0.0).real() / (9223372036854775807.0 / 2.5), 1.0, 1e-12);
  std::string den = "num = [1.0]\nden = [1.0";
  for (int i = 0; i < 100000; ++i) den += ", 1.0";
  const std::string order = error_of(den + "]\n");
  EXPECT_TRUE(test::contains(order, "sys.toml: line 2: den: expected at most 201 entries")) << order;
}

TEST(LtiToml, MissingFileIsAnInputError) {
  try {
    read_lti_toml("/nonexistent/plant.toml");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/plant.toml"), std::string::npos);
  }
}

}  // namespace
}  // namespace piezobench::io
