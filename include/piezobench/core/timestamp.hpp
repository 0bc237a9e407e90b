#pragma once
// The time a measurement file records (`recorded_at`): ISO 8601 in UTC, to the second.
#include <optional>
#include <string>

namespace piezobench {

// A time in seconds since the epoch: "2026-11-27T12:15:03Z".
std::string utc_timestamp(long long seconds_since_epoch);
// The time now, as utc_timestamp.
std::string utc_timestamp_now();
// Seconds since the epoch of a date and time in UTC (proleptic Gregorian; year 1..9999, no leap
// seconds); nullopt for a field out of range.
std::optional<long long> utc_seconds(int year, int month, int day, int hour, int minute, int second);
// utc_timestamp's inverse: "2026-11-27T12:15:03Z" as seconds since the epoch; nullopt for any
// other text.
std::optional<long long> parse_utc_timestamp(const std::string& text);

}  // namespace piezobench
