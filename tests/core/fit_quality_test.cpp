#include "piezobench/core/fit_quality.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "piezobench/core/error.hpp"

namespace piezobench::core {
namespace {

TEST(FitQuality, ErrorsAboveTheLimitAndImpossibleParametersMakeItPoor) {
  FitQuality q;
  q.check_error("d_e", 0.05);
  EXPECT_FALSE(q.poor());
  EXPECT_EQ(q.summary(), "good");
  q.advise("never shown");
  EXPECT_TRUE(q.advice.empty());
  q.check_error("Vs", 0.96);
  EXPECT_TRUE(q.poor());
  EXPECT_FALSE(q.impossible);
  q.check_error("x", std::nan(""));
  EXPECT_EQ(q.problems.size(), 2u);
  q.add_problem("ke = -1e8 N/m is negative", /*physical=*/false);
  EXPECT_TRUE(q.impossible);
  q.advise("narrow the band");
  EXPECT_EQ(q.summary().rfind("poor: Vs: relative rms error 0.96 above 0.2;", 0), 0u) << q.summary();
  EXPECT_NE(q.summary().find("Try: narrow the band"), std::string::npos);
  EXPECT_EQ(to_string(FitVerdict::kPoor), "poor");
  EXPECT_EQ(fit_verdict_from_string("good"), FitVerdict::kGood);
  EXPECT_THROW(fit_verdict_from_string("fine"), InputError);
}

}  // namespace
}  // namespace piezobench::core
