#include "piezobench/core/format.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace piezobench {

std::string format_number(double value, int significant_digits) {
  if (std::isnan(value)) return "nan";
  const int digits = std::clamp(significant_digits, 1, 17);
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", digits, value);
  return buf;
}

std::string format_number_fixed(double value, int decimals) {
  if (!std::isfinite(value)) return format_number(value);
  char buf[360];  // 1e308 with 17 decimals fits
  std::snprintf(buf, sizeof buf, "%.*f", std::clamp(decimals, 0, 17), value);
  return buf;
}

std::string format_number_exact(double value) {
  if (!std::isfinite(value)) return format_number(value);
  // From 6 digits up: %g drops the trailing zeros, and fewer digits would only switch round
  // numbers to the exponent form (150 as "1.5e+02").
  for (int digits = 6; digits < 17; ++digits) {
    std::string text = format_number(value, digits);
    if (std::strtod(text.c_str(), nullptr) == value) return text;
  }
  return format_number(value, 17);
}

}  // namespace piezobench
