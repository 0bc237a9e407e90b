// Tests for src/lti/transfer_function.cpp: construction and validation of tf and zpk forms.
#include "piezobench/lti/transfer_function.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "piezobench/core/error.hpp"
#include "lti_test_util.hpp"
#include "test_util.hpp"

namespace piezobench::lti {
namespace {

using test::input_error;

using test::cvec;

TEST(TransferFunction, ConstructionAndOrder) {
  const TransferFunction tf(Vector{{1.0, 2.0}}, Vector{{1.0, 3.0, 2.0}}, 0.0, 2e-4);
  EXPECT_EQ(tf.order(), 2);
  EXPECT_FALSE(tf.is_discrete());
  EXPECT_EQ(tf.delay, 2e-4);
  // Leading zeros of num are ignored for properness: 0 s^3 + 0 s^2 + s + 1 over s + 2 is proper.
  const TransferFunction padded(Vector{{0.0, 0.0, 1.0, 1.0}}, Vector{{1.0, 2.0}}, 1e-3);
  EXPECT_TRUE(padded.is_discrete());
  EXPECT_EQ(padded.order(), 1);
  // An all-zero numerator is the zero system.
  EXPECT_NO_THROW(TransferFunction(Vector::Zero(3), Vector{{1.0}}));
}

TEST(TransferFunction, ValidateNamesTheBadField) {
  input_error([] { TransferFunction(Vector(), Vector{{1.0}}); }, "num");
  input_error([] { TransferFunction(Vector{{1.0}}, Vector()); }, "den");
  input_error([] { TransferFunction(Vector{{1.0, std::nan("")}}, Vector{{1.0, 1.0}}); }, "num(1)");
  input_error([] { TransferFunction(Vector{{1.0}}, Vector{{1.0, std::numeric_limits<double>::infinity()}}); },
              "den(1)");
  const std::string lead = input_error([] { TransferFunction(Vector{{1.0}}, Vector{{0.0, 1.0}}); }, "den(0)");
  EXPECT_NE(lead.find("nonzero leading coefficient"), std::string::npos);
  const std::string improper =
      input_error([] { TransferFunction(Vector{{1.0, 0.0, 0.0}}, Vector{{1.0, 1.0}}); }, "num");
  EXPECT_NE(improper.find("proper"), std::string::npos);
  EXPECT_NE(improper.find("found numerator degree 2"), std::string::npos);
  input_error([] { TransferFunction(Vector{{1.0}}, Vector{{1.0, 1.0}}, 0.0, -1e-3); }, "delay");
  input_error([] { TransferFunction(Vector{{1.0}}, Vector{{1.0, 1.0}}, -1.0); }, "sample_time");
  TransferFunction tf(Vector{{1.0}}, Vector{{1.0, 1.0}});
  tf.delay = std::nan("");
  const std::string named = input_error([&] { tf.validate("--plant"); }, "delay");
  EXPECT_EQ(named.rfind("--plant: delay: expected", 0), 0u) << named;
}

TEST(Zpk, ConstructionAcceptsConjugatePairs) {
  const Zpk z(cvec({{-1.0, 2.0}, {-1.0, -2.0}}), cvec({-3.0, {-0.5, 40.0}, {-0.5, -40.0}}), 2.0, 0.0, 1e-3);
  EXPECT_EQ(z.gain, 2.0);
  EXPECT_FALSE(z.is_discrete());
  // A pair typed with rounded digits (relative mismatch 1e-10) is accepted.
  EXPECT_NO_THROW(Zpk(CVector(), cvec({{-0.5, 40.0}, {-0.5, -40.000000004}}), 1.0));
}

TEST(Zpk, ValidateNamesTheBadField) {
  const std::string unpaired = input_error([] { Zpk(cvec({{-1.0, 2.0}}), cvec({-1.0, -2.0}), 1.0); }, "zeros(0)");
  EXPECT_NE(unpaired.find("conjugate"), std::string::npos);
  input_error([] { Zpk(CVector(), cvec({-1.0, {-2.0, -1.0}}), 1.0); }, "poles(1)");
  // Pair members too far apart are not a pair.
  input_error([] { Zpk(CVector(), cvec({{-1.0, 1.0}, {-1.0, -1.1}}), 1.0); }, "poles(0)");
  const std::string improper = input_error([] { Zpk(cvec({-1.0, -2.0}), cvec({-3.0}), 1.0); }, "zeros");
  EXPECT_NE(improper.find("found 2 zeros"), std::string::npos);
  input_error([] { Zpk(cvec({{std::nan(""), 0.0}}), cvec({-3.0}), 1.0); }, "zeros(0)");
  input_error([] { Zpk(CVector(), cvec({-3.0}), std::numeric_limits<double>::infinity()); }, "gain");
  input_error([] { Zpk(CVector(), cvec({-3.0}), 1.0, -1e-3); }, "sample_time");
  input_error([] { Zpk(CVector(), cvec({-3.0}), 1.0, 0.0, -1.0); }, "delay");
}

}  // namespace
}  // namespace piezobench::lti
