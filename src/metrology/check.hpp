#pragma once
// Input checks shared by the metrology sources (private to the module).
#include <fmt/format.h>

#include <Eigen/Dense>
#include <cmath>
#include <string>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"

namespace piezobench::metrology::detail {

inline void require_finite_positive(double v, const std::string& source, const std::string& field,
                                    const std::string& unit) {
  if (!(std::isfinite(v) && v > 0.0)) throw InputError(source, field, "a finite value > 0 " + unit, format_number(v));
}

inline void require_finite_nonnegative(double v, const std::string& source, const std::string& field,
                                       const std::string& unit) {
  if (!(std::isfinite(v) && v >= 0.0)) throw InputError(source, field, "a finite value >= 0 " + unit, format_number(v));
}

// Every sample finite, at least `min_samples` of them.
inline void require_signal(const Eigen::Ref<const Eigen::VectorXd>& x, const std::string& source,
                           const std::string& field, Eigen::Index min_samples) {
  if (x.size() < min_samples) {
    throw InputError(source, field, fmt::format("at least {} samples", min_samples), fmt::format("{}", x.size()));
  }
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x(i))) throw InputError(source, field, "finite samples", fmt::format("{} at sample {}", x(i), i));
  }
}

inline void require_same_length(Eigen::Index a, Eigen::Index b, const std::string& source, const std::string& field) {
  if (a != b) throw InputError(source, field, fmt::format("{} samples (as the other channel)", a), fmt::format("{}", b));
}

}  // namespace piezobench::metrology::detail
