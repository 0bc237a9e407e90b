#pragma once
// Small helpers shared by the rt sources (private).
#include <cmath>
#include <cstdio>
#include <string>

#include "piezobench/core/error.hpp"

namespace piezobench::rt::detail {

inline std::string str(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

inline void require_finite(double v, const char* field, const std::string& source) {
  if (!std::isfinite(v)) throw InputError(source, field, "a finite number", str(v));
}

inline void require_positive(double v, const char* field, const std::string& source) {
  if (!(std::isfinite(v) && v > 0.0)) throw InputError(source, field, "a finite number > 0", str(v));
}

inline void require_nonnegative(double v, const char* field, const std::string& source) {
  if (!(std::isfinite(v) && v >= 0.0)) throw InputError(source, field, "a finite number >= 0", str(v));
}

}  // namespace piezobench::rt::detail
