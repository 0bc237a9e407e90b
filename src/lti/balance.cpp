#include "balance.hpp"

#include <algorithm>
#include <cmath>

namespace piezobench::lti::detail {
namespace {

// Iterates the Parlett-Reinsch sweep on the leading n x n block of `m` (with `extra_rows` rows of
// C below and `extra_cols` columns of B to its right contributing to the norms).
Vector balance_block(Matrix& m, Index n) {
  constexpr double kRadix = 2.0;
  constexpr double kFactor = 0.95;
  constexpr int kMaxSteps = 1100;
  Vector d = Vector::Ones(n);
  bool converged = false;
  for (int sweep = 0; sweep < 100 && !converged; ++sweep) {
    converged = true;
    for (Index i = 0; i < n; ++i) {
      double c = 0.0;
      double r = 0.0;
      for (Index j = 0; j < m.rows(); ++j) {
        if (j != i) c += std::abs(m(j, i));
      }
      for (Index j = 0; j < m.cols(); ++j) {
        if (j != i) r += std::abs(m(i, j));
      }
      // A non-finite norm (an overflowed entry) would keep the loops below scaling forever: such a
      // row is left as it is (the caller's finiteness checks report it).
      if (c == 0.0 || r == 0.0 || !std::isfinite(c) || !std::isfinite(r)) continue;
      double g = r / kRadix;
      double f = 1.0;
      const double s = c + r;
      // Each loop moves the exponent of f by one; 2 * 1100 steps cover the whole double range.
      for (int k = 0; k < kMaxSteps && c < g; ++k) {
        f *= kRadix;
        c *= kRadix * kRadix;
      }
      g = r * kRadix;
      for (int k = 0; k < kMaxSteps && c >= g; ++k) {
        f /= kRadix;
        c /= kRadix * kRadix;
      }
      // Apply only a scaling that keeps every entry finite and every scale representable.
      const double grown = std::max(m.col(i).cwiseAbs().maxCoeff() * f, m.row(i).cwiseAbs().maxCoeff() / f);
      if (!std::isfinite(grown) || !std::isfinite(d(i) * f) || d(i) * f == 0.0) continue;
      if ((c + r) / f < kFactor * s) {
        converged = false;
        d(i) *= f;
        m.row(i) /= f;
        m.col(i) *= f;
      }
    }
  }
  return d;
}

}  // namespace

Vector balancing_scales(const Matrix& a) {
  Matrix m = a;
  return balance_block(m, a.rows());
}

void balance_realization(Matrix& a, Matrix& b, Matrix& c) {
  const Index n = a.rows();
  if (n == 0) return;
  Matrix m = Matrix::Zero(n + c.rows(), n + b.cols());
  m.topLeftCorner(n, n) = a;
  m.topRightCorner(n, b.cols()) = b;
  m.bottomLeftCorner(c.rows(), n) = c;
  const Vector d = balance_block(m, n);
  a = m.topLeftCorner(n, n);
  b = m.topRightCorner(n, b.cols());
  c = m.bottomLeftCorner(c.rows(), n);
  (void)d;
}

}  // namespace piezobench::lti::detail
