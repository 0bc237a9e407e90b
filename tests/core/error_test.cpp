#include "piezobench/core/error.hpp"

#include <gtest/gtest.h>

namespace piezobench {
namespace {

TEST(InputError, MessageNamesSourceFieldExpectedAndFound) {
  const InputError e("plant.toml", "den", "a non-zero leading coefficient", "0");
  EXPECT_STREQ(e.what(), "plant.toml: den: expected a non-zero leading coefficient, found 0");
  EXPECT_EQ(e.exit_code(), ExitCode::kBadInput);
  EXPECT_EQ(e.field(), "den");
}

TEST(InputError, WithSourcePrefixesTheFileName) {
  const InputError e("", "A", "a square matrix", "2x3");
  EXPECT_STREQ(e.with_source("sys.toml").what(), "sys.toml: A: expected a square matrix, found 2x3");
  EXPECT_STREQ(InputError("no data").with_source("f.csv").what(), "f.csv: no data");
}

TEST(NumericalError, SaysWhetherRetryingMayHelp) {
  const NumericalError hopeful("vector fitting", "poles did not settle in 10 iterations", true);
  EXPECT_STREQ(hopeful.what(), "vector fitting failed: poles did not settle in 10 iterations (other settings may succeed)");
  EXPECT_EQ(hopeful.exit_code(), ExitCode::kNumerical);
  const NumericalError hopeless("feedback", "1 - D1 D2 is singular", false);
  EXPECT_STREQ(hopeless.what(), "feedback failed: 1 - D1 D2 is singular");
  EXPECT_FALSE(hopeless.retry_may_help());
}

}  // namespace
}  // namespace piezobench
