#include "piezobench/core/timestamp.hpp"

#include <gtest/gtest.h>

namespace piezobench {
namespace {

TEST(UtcTimestamp, Iso8601InUtcToTheSecond) {
  EXPECT_EQ(utc_timestamp(0), "1970-01-01T00:00:00Z");
  EXPECT_EQ(utc_timestamp(1795263303), "2026-11-21T12:15:03Z");  // date -u -d @1795263303
  EXPECT_EQ(utc_timestamp_now().size(), 20u);
}

// The inverse, against GNU date (date -u -d TEXT +%s): leap days, century years, before 1970.
TEST(UtcTimestamp, ParsedBackToSecondsOnlyInItsOwnFormat) {
  EXPECT_EQ(parse_utc_timestamp("1970-01-01T00:00:00Z"), 0);
  EXPECT_EQ(parse_utc_timestamp("2026-11-21T12:15:03Z"), 1795263303);
  EXPECT_EQ(parse_utc_timestamp("2000-02-29T23:59:59Z"), 951868799);
  EXPECT_EQ(parse_utc_timestamp("2100-03-01T00:00:00Z"), 4107542400);
  EXPECT_EQ(parse_utc_timestamp("1900-01-01T00:00:00Z"), -2208988800);
  EXPECT_EQ(parse_utc_timestamp(utc_timestamp(4107542399)), 4107542399);
  for (const char* bad : {"2026-11-21 12:15:03Z", "2026-11-21T12:15:03", "2026-13-01T00:00:00Z", "2100-02-29T00:00:00Z",
                          "2026-11-21T24:00:00Z", "2026-11- 1T00:00:00Z", "+026-11-21T12:15:03Z", "unknown", ""}) {
    EXPECT_FALSE(parse_utc_timestamp(bad).has_value()) << bad;
  }
  EXPECT_FALSE(utc_seconds(0, 1, 1, 0, 0, 0).has_value());
}

}  // namespace
}  // namespace piezobench
