#pragma once
// The one place where a number given from outside (a file's field, a command-line option) becomes
// an integer or a duration in nanoseconds. The value is range-checked BEFORE the conversion:
// converting a double beyond the target type's range is undefined behaviour (UBSan's
// float-cast-overflow: a campaign `id = 92233720368547758e07`, `--idle-timeout 1e10` as ns), and
// clamping it silently changes what the user asked for (`stale_cycles = 2^63-1` capped). A refused
// value is an InputError (exit 3) for a file's field, a UsageError (exit 2) for an option; either
// names the field, the range and the value found.
#include <cstdint>
#include <string>
#include <utility>

namespace piezobench {

// Where a number came from, for the error message and the exit code.
struct NumberOrigin {
  std::string source;   // the file ("" for a command-line option)
  std::string field;    // the key ("units[0].id", "limits.stale_cycles") or the option ("--idle-timeout")
  bool option = false;  // true: UsageError (exit 2); false: InputError (exit 3)

  static NumberOrigin file(std::string source, std::string field) { return {std::move(source), std::move(field), false}; }
  static NumberOrigin command_line(std::string option) { return {"", std::move(option), true}; }
  // Throws the error of this origin: "expected EXPECTED, found FOUND".
  [[noreturn]] void refuse(const std::string& expected, const std::string& found) const;
};

// `value` as an integer in [lo, hi]: refused when it is not finite, not a whole number or outside.
// value: dimensionless, a count or an index.
std::int64_t checked_integer(double value, std::int64_t lo, std::int64_t hi, const NumberOrigin& origin);
// An integer (a TOML integer, a parsed option) in [lo, hi].
std::int64_t checked_integer(std::int64_t value, std::int64_t lo, std::int64_t hi, const NumberOrigin& origin);

// A duration in seconds, refused unless finite and in [min_s, max_s]; returns the seconds.
// max_s is at most 9e9 s (2^63 ns, the range of a nanosecond count).
double checked_duration_s(double seconds, double min_s, double max_s, const NumberOrigin& origin);
// The same duration as a nanosecond count (rounded to the nearest ns).
std::int64_t checked_duration_ns(double seconds, double min_s, double max_s, const NumberOrigin& origin);

}  // namespace piezobench
