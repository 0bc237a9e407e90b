#include "piezobench/core/statistics.hpp"

#include <algorithm>
#include <cstddef>
#include <limits>

namespace piezobench::core {

double median(std::vector<double> values) {
  const std::size_t n = values.size();
  if (n == 0) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace piezobench::core
