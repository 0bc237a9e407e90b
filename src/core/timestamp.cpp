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

std::optional<long long> utc_seconds(int year, int month, int day, int hour, int minute, int second) {
  static constexpr int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  const bool leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
  if (year < 1 || year > 9999 || month < 1 || month > 12 || day < 1 || hour < 0 || hour > 23 || minute < 0 || minute > 59 ||
      second < 0 || second > 59 || day > kDays[month - 1] + (month == 2 && leap ? 1 : 0)) {
    return std::nullopt;
  }
  // Days from 1970-01-01 (H. Hinnant's days_from_civil: eras of 400 years from March 1).
  const long long y = year - (month <= 2 ? 1 : 0);
  const long long era = y / 400;  // y >= 0 here
  const long long yoe = y - era * 400;
  const long long doy = (153 * (month + (month > 2 ? -3 : 9)) + 2) / 5 + day - 1;
  const long long doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  const long long days = era * 146097 + doe - 719468;
  return days * 86400 + hour * 3600 + minute * 60 + second;
}

std::optional<long long> parse_utc_timestamp(const std::string& text) {
  // Exactly YYYY-MM-DDTHH:MM:SSZ, digits where digits belong.
  static constexpr char kPattern[] = "dddd-dd-ddTdd:dd:ddZ";
  if (text.size() != sizeof kPattern - 1) return std::nullopt;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const bool digit = text[i] >= '0' && text[i] <= '9';
    if (kPattern[i] == 'd' ? !digit : text[i] != kPattern[i]) return std::nullopt;
  }
  const auto field = [&](std::size_t at, std::size_t n) { return std::stoi(text.substr(at, n)); };
  return utc_seconds(field(0, 4), field(5, 2), field(8, 2), field(11, 2), field(14, 2), field(17, 2));
}

}  // namespace piezobench
