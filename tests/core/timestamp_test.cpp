#include "piezobench/core/timestamp.hpp"

#include <gtest/gtest.h>

namespace piezobench {
namespace {

TEST(UtcTimestamp, Iso8601InUtcToTheSecond) {
  EXPECT_EQ(utc_timestamp(0), "1970-01-01T00:00:00Z");
  EXPECT_EQ(utc_timestamp(1795263303), "2026-11-21T12:15:03Z");  // date -u -d @1795263303
  EXPECT_EQ(utc_timestamp_now().size(), 20u);
}

}  // namespace
}  // namespace piezobench
