#include "piezobench/core/checked_number.hpp"

#include <cassert>
#include <cmath>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/usage_error.hpp"

namespace piezobench {

namespace {
// 2^63: every double in [-2^63, 2^63) converts to std::int64_t without overflow.
constexpr double kTwo63 = 9223372036854775808.0;
constexpr double kMaxDurationS = 9e9;

std::string integer_range(std::int64_t lo, std::int64_t hi) {
  return "an integer in " + std::to_string(lo) + " .. " + std::to_string(hi);
}
std::string duration_range(double min_s, double max_s) {
  return "a duration in [" + format_number(min_s) + ", " + format_number(max_s) + "] s";
}
}  // namespace

void NumberOrigin::refuse(const std::string& expected, const std::string& found) const {
  if (option) throw UsageError(field, expected, found);
  throw InputError(source, field, expected, found);
}

std::int64_t checked_integer(double value, std::int64_t lo, std::int64_t hi, const NumberOrigin& origin) {
  assert(lo <= hi);
  if (!(std::isfinite(value) && value == std::trunc(value) && value >= -kTwo63 && value < kTwo63)) {
    origin.refuse(integer_range(lo, hi), format_number(value, 17));
  }
  return checked_integer(static_cast<std::int64_t>(value), lo, hi, origin);
}

std::int64_t checked_integer(std::int64_t value, std::int64_t lo, std::int64_t hi, const NumberOrigin& origin) {
  assert(lo <= hi);
  if (value < lo || value > hi) origin.refuse(integer_range(lo, hi), std::to_string(value));
  return value;
}

double checked_duration_s(double seconds, double min_s, double max_s, const NumberOrigin& origin) {
  assert(min_s <= max_s && max_s <= kMaxDurationS);
  if (!(std::isfinite(seconds) && seconds >= min_s && seconds <= max_s)) {
    origin.refuse(duration_range(min_s, max_s), format_number(seconds));
  }
  return seconds;
}

std::int64_t checked_duration_ns(double seconds, double min_s, double max_s, const NumberOrigin& origin) {
  return std::llround(checked_duration_s(seconds, min_s, max_s, origin) * 1e9);
}

}  // namespace piezobench
