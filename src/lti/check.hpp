#pragma once
// Private to the lti module: small helpers that build InputError messages (field, expected, found).
#include <Eigen/Dense>
#include <cmath>
#include <sstream>
#include <string>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"

namespace piezobench::lti::detail {

inline std::string shape(Eigen::Index rows, Eigen::Index cols) {
  return std::to_string(rows) + "x" + std::to_string(cols);
}

// "field(i)" or "field(i, j)", 0-based as everywhere in the C++ API.
inline std::string entry(const std::string& field, Eigen::Index i) { return field + "(" + std::to_string(i) + ")"; }
inline std::string entry(const std::string& field, Eigen::Index i, Eigen::Index j) {
  return field + "(" + std::to_string(i) + ", " + std::to_string(j) + ")";
}

// Throws InputError at the first non-finite entry of a real or complex matrix/vector.
template <typename Derived>
void require_finite(const Eigen::DenseBase<Derived>& m, const std::string& source, const std::string& field) {
  for (Eigen::Index j = 0; j < m.cols(); ++j) {
    for (Eigen::Index i = 0; i < m.rows(); ++i) {
      using std::isfinite;
      const auto v = m(i, j);
      bool finite = true;
      if constexpr (Eigen::NumTraits<typename Derived::Scalar>::IsComplex) {
        finite = isfinite(v.real()) && isfinite(v.imag());
      } else {
        finite = isfinite(v);
      }
      if (!finite) {
        // Built only on failure: validating a finite matrix allocates nothing.
        std::ostringstream found;
        found.precision(10);
        found << v;
        const std::string name = m.cols() == 1 ? entry(field, i) : entry(field, i, j);
        throw InputError(source, name, "a finite value", found.str());
      }
    }
  }
}

inline void require_sample_time(double ts, const std::string& source, const std::string& field = "sample_time") {
  if (!std::isfinite(ts) || ts < 0.0) {
    throw InputError(source, field, "a finite value >= 0 s (0 = continuous)", format_number(ts, 10));
  }
}

inline void require_delay(double delay, const std::string& source, const std::string& field) {
  if (!std::isfinite(delay) || delay < 0.0) throw InputError(source, field, "a finite delay >= 0 s", format_number(delay, 10));
}

}  // namespace piezobench::lti::detail
