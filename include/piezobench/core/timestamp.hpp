#pragma once
// The time a measurement file records (`recorded_at`): ISO 8601 in UTC, to the second.
#include <string>

namespace piezobench {

// A time in seconds since the epoch: "2026-11-27T12:15:03Z".
std::string utc_timestamp(long long seconds_since_epoch);
// The time now, as utc_timestamp.
std::string utc_timestamp_now();

}  // namespace piezobench
