#pragma once
// Small helpers shared by the rt sources (private).
#include <cmath>
#include <cstdio>
#include <string>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"

namespace piezobench::rt::detail {

inline void require_finite(double v, const char* field, const std::string& source) {
  if (!std::isfinite(v)) throw InputError(source, field, "a finite number", format_number(v));
}

inline void require_positive(double v, const char* field, const std::string& source) {
  if (!(std::isfinite(v) && v > 0.0)) throw InputError(source, field, "a finite number > 0", format_number(v));
}

inline void require_nonnegative(double v, const char* field, const std::string& source) {
  if (!(std::isfinite(v) && v >= 0.0)) throw InputError(source, field, "a finite number >= 0", format_number(v));
}

}  // namespace piezobench::rt::detail
