#include "piezobench/core/checked_number.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "piezobench/core/error.hpp"
#include "piezobench/core/usage_error.hpp"

namespace piezobench {
namespace {

const NumberOrigin kFile = NumberOrigin::file("c.toml", "units[0].id");
const NumberOrigin kOption = NumberOrigin::command_line("--idle-timeout");

TEST(CheckedInteger, WholeNumbersInsideTheRangeConvert) {
  EXPECT_EQ(checked_integer(3.0, 0, 1000000, kFile), 3);
  EXPECT_EQ(checked_integer(-20.0, -20, 150, kFile), -20);
  EXPECT_EQ(checked_integer(std::int64_t{150}, -20, 150, kFile), 150);
  // The largest double below 2^63 converts exactly: 2^63 - 1024.
  const std::int64_t big = std::numeric_limits<std::int64_t>::max();
  EXPECT_EQ(checked_integer(9223372036854774784.0, 0, big, kFile), 9223372036854774784);
}

TEST(CheckedInteger, ValuesBeyondInt64AreRefusedBeforeTheConversion) {
  // The campaign reproducer of issue 35: 9.2e23, far beyond 2^63 (UB if converted first).
  try {
    checked_integer(92233720368547758e07, 0, 1000000, kFile);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "c.toml: units[0].id: expected an integer in 0 .. 1000000, found 9.2233720368547758e+23");
    EXPECT_EQ(e.exit_code(), ExitCode::kBadInput);
  }
  const std::int64_t big = std::numeric_limits<std::int64_t>::max();
  EXPECT_THROW(checked_integer(9223372036854775808.0, 0, big, kFile), InputError);  // exactly 2^63
  EXPECT_THROW(checked_integer(-1e300, std::numeric_limits<std::int64_t>::min(), 0, kFile), InputError);
  EXPECT_THROW(checked_integer(std::nan(""), 0, 10, kFile), InputError);
  EXPECT_THROW(checked_integer(std::numeric_limits<double>::infinity(), 0, 10, kFile), InputError);
  EXPECT_THROW(checked_integer(2.5, 0, 10, kFile), InputError);
}

TEST(CheckedInteger, IntegersOutsideTheRangeAreRefusedNotClamped) {
  try {
    checked_integer(std::numeric_limits<std::int64_t>::max(), 0, 1000, NumberOrigin::file("b.toml", "limits.stale_cycles"));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "b.toml: limits.stale_cycles: expected an integer in 0 .. 1000, found 9223372036854775807");
  }
  EXPECT_THROW(checked_integer(std::int64_t{-1}, 0, 1000, kFile), InputError);
}

TEST(CheckedDuration, SecondsBecomeNanosecondsInsideTheRange) {
  EXPECT_EQ(checked_duration_ns(60.0, 1e-3, 1e6, kOption), 60'000'000'000);
  EXPECT_EQ(checked_duration_ns(2e-3, 1e-9, 1.0, kFile), 2'000'000);
  EXPECT_DOUBLE_EQ(checked_duration_s(0.02, 1e-6, 10.0, kFile), 0.02);
}

TEST(CheckedDuration, AnOptionOutOfRangeIsAUsageErrorNamingTheOption) {
  // --idle-timeout 1e10: 1e19 ns does not fit an int64 (issue 35).
  try {
    checked_duration_ns(1e10, 1e-3, 1e6, kOption);
    FAIL() << "no error";
  } catch (const UsageError& e) {
    EXPECT_STREQ(e.what(), "--idle-timeout: expected a duration in [0.001, 1e+06] s, found 1e+10");
    EXPECT_EQ(e.exit_code(), ExitCode::kUsage);
  }
  EXPECT_THROW(checked_duration_ns(-1.0, 1e-3, 1e6, kOption), UsageError);
  EXPECT_THROW(checked_duration_s(1e300, 1e-6, 10.0, NumberOrigin::file("b.toml", "limits.watchdog_s")), InputError);
  EXPECT_THROW(checked_duration_s(std::nan(""), 0.0, 10.0, kFile), InputError);
}

}  // namespace
}  // namespace piezobench
