#include "piezobench/core/format.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace piezobench {

std::string format_number(double value, int significant_digits) {
  if (std::isnan(value)) return "nan";
  const int digits = std::clamp(significant_digits, 1, 17);
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", digits, value);
  return buf;
}

}  // namespace piezobench
