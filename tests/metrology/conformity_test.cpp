#include "piezobench/metrology/conformity.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "piezobench/core/error.hpp"

namespace piezobench::metrology {
namespace {

// Phi(z) values: Phi(2) = 0.9772498680518208, Phi(1) = 0.8413447460685429, Phi(0) = 0.5.
constexpr double kPhi2 = 0.9772498680518208, kPhi1 = 0.8413447460685429;

TEST(Conformity, ZonesOfAOneSidedLowerLimit) {
  // stroke >= 100 um, U = 4 um: pass from 104, fail below 96, marginal between.
  EXPECT_EQ(decide(110.0, 4.0, 100.0, std::nullopt).verdict, Conformity::kPass);
  EXPECT_EQ(decide(104.0, 4.0, 100.0, std::nullopt).verdict, Conformity::kPass);  // the zone's edge
  EXPECT_EQ(decide(103.9, 4.0, 100.0, std::nullopt).verdict, Conformity::kMarginal);
  EXPECT_EQ(decide(100.0, 4.0, 100.0, std::nullopt).verdict, Conformity::kMarginal);
  EXPECT_EQ(decide(96.0, 4.0, 100.0, std::nullopt).verdict, Conformity::kMarginal);
  EXPECT_EQ(decide(95.9, 4.0, 100.0, std::nullopt).verdict, Conformity::kFail);
}

TEST(Conformity, ProbabilityOfConformityIsJcgm106sGaussian) {
  // At the acceptance zone's edge y = min + U with k = 2: p_c = Phi(2), false accept 1 - Phi(2) = 2.3 %.
  const ConformityDecision edge = decide(104.0, 4.0, 100.0, std::nullopt);
  EXPECT_NEAR(edge.probability_of_conformity, kPhi2, 1e-15);
  EXPECT_NEAR(edge.false_accept_probability, 1.0 - kPhi2, 1e-15);
  EXPECT_EQ(edge.guard_band, 4.0);
  // On the limit: an even chance; marginal, so no false accept.
  const ConformityDecision on = decide(100.0, 4.0, 100.0, std::nullopt);
  EXPECT_NEAR(on.probability_of_conformity, 0.5, 1e-15);
  EXPECT_EQ(on.false_accept_probability, 0.0);
  // Two-sided [1.8, 2.2] N/um, y = 2.0, U = 0.2 (u = 0.1): p_c = Phi(2) - Phi(-2).
  const ConformityDecision two = decide(2.0, 0.2, 1.8, 2.2);
  EXPECT_EQ(two.verdict, Conformity::kPass);
  EXPECT_NEAR(two.probability_of_conformity, 2.0 * kPhi2 - 1.0, 1e-14);
  // k = 1 (U = u): y one u inside the upper limit.
  EXPECT_NEAR(decide(9.0, 1.0, std::nullopt, 10.0, 1.0).probability_of_conformity, kPhi1, 1e-15);
}

TEST(Conformity, TwoSidedZonesAndAToleranceNarrowerThanTwoU) {
  EXPECT_EQ(decide(2.25, 0.02, 1.8, 2.2).verdict, Conformity::kFail);
  EXPECT_EQ(decide(2.21, 0.02, 1.8, 2.2).verdict, Conformity::kMarginal);
  EXPECT_EQ(decide(1.79, 0.02, 1.8, 2.2).verdict, Conformity::kMarginal);
  EXPECT_EQ(decide(1.75, 0.02, 1.8, 2.2).verdict, Conformity::kFail);
  // U larger than half the tolerance: nothing can pass (no acceptance zone left).
  EXPECT_EQ(decide(2.0, 0.3, 1.8, 2.2).verdict, Conformity::kMarginal);
}

TEST(Conformity, ZeroUncertaintyIsThePlainComparison) {
  EXPECT_EQ(decide(100.0, 0.0, 100.0, std::nullopt).verdict, Conformity::kPass);
  EXPECT_EQ(decide(99.999, 0.0, 100.0, std::nullopt).verdict, Conformity::kFail);
  EXPECT_EQ(decide(99.999, 0.0, 100.0, std::nullopt).probability_of_conformity, 0.0);
}

TEST(Conformity, RefusesWhatIsNotADecision) {
  EXPECT_THROW((void)decide(1.0, -0.1, 0.0, std::nullopt), InputError);
  EXPECT_THROW((void)decide(std::nan(""), 0.1, 0.0, std::nullopt), InputError);
  EXPECT_THROW((void)decide(1.0, 0.1, std::nullopt, std::nullopt), InputError);
  EXPECT_THROW((void)decide(1.0, 0.1, 2.0, 1.0), InputError);
  EXPECT_THROW((void)decide(1.0, 0.1, 0.0, std::nullopt, 0.0), InputError);
  EXPECT_EQ(to_string(Conformity::kMarginal), "marginal");
  EXPECT_EQ(conformity_from_string("fail"), Conformity::kFail);
  EXPECT_THROW((void)conformity_from_string("ok"), InputError);
}

}  // namespace
}  // namespace piezobench::metrology
