#include "piezobench/core/timestamp.hpp"

#include <ctime>

namespace piezobench {

std::string utc_timestamp(long long seconds_since_epoch) {
  const auto t = static_cast<std::time_t>(seconds_since_epoch);
  std::tm tm{};
  char text[32] = {};
  if (gmtime_r(&t, &tm) == nullptr || std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &tm) == 0) return "unknown";
  return text;
}

std::string utc_timestamp_now() { return utc_timestamp(static_cast<long long>(std::time(nullptr))); }

}  // namespace piezobench
