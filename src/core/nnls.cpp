#include "piezobench/core/nnls.hpp"

#include <Eigen/QR>
#include <cmath>
#include <limits>
#include <string>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"

namespace piezobench {

void NnlsOptions::validate() const {
  if (max_iterations < 0) throw InputError("nnls options", "max_iterations", "an integer >= 0", std::to_string(max_iterations));
  if (!(std::isfinite(tolerance) && tolerance >= 0.0)) {
    throw InputError("nnls options", "tolerance", "a finite tolerance >= 0", format_number_exact(tolerance));
  }
}

namespace {

// Least squares on the passive columns; the other entries of the result are 0.
Eigen::VectorXd solve_passive(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, const std::vector<bool>& passive) {
  const Eigen::Index n = a.cols();
  std::vector<Eigen::Index> cols;
  for (Eigen::Index j = 0; j < n; ++j) {
    if (passive[static_cast<std::size_t>(j)]) cols.push_back(j);
  }
  Eigen::VectorXd z = Eigen::VectorXd::Zero(n);
  if (cols.empty()) return z;
  Eigen::MatrixXd sub(a.rows(), static_cast<Eigen::Index>(cols.size()));
  for (std::size_t k = 0; k < cols.size(); ++k) sub.col(static_cast<Eigen::Index>(k)) = a.col(cols[k]);
  const Eigen::VectorXd zs = sub.colPivHouseholderQr().solve(b);
  for (std::size_t k = 0; k < cols.size(); ++k) z(cols[k]) = zs(static_cast<Eigen::Index>(k));
  return z;
}

// The problem reduced to n rows (see nnls()); `used` false when A is not taller than twice its
// width, where the reduction would not pay.
struct Reduced {
  bool used = false;
  Eigen::MatrixXd r;  // n x n, upper triangular
  Eigen::VectorXd c;  // the first n entries of Q^T b
};

Reduced reduce(const Eigen::MatrixXd& a, const Eigen::VectorXd& b) {
  Reduced out;
  const Eigen::Index m = a.rows(), n = a.cols();
  if (n == 0 || m <= 2 * n) return out;
  Eigen::MatrixXd ab(m, n + 1);
  ab.leftCols(n) = a;
  ab.col(n) = b;
  Eigen::HouseholderQR<Eigen::Ref<Eigen::MatrixXd>> qr(ab);  // in place
  out.r = ab.topLeftCorner(n, n).triangularView<Eigen::Upper>();
  out.c = ab.col(n).head(n);
  out.used = true;
  return out;
}

}  // namespace

NnlsResult nnls(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, const std::vector<bool>& free_variables,
                const NnlsOptions& options) {
  options.validate();
  const std::string source = "nnls";
  if (a.rows() != b.size()) {
    throw InputError(source, "b", std::to_string(a.rows()) + " rows (those of A)", std::to_string(b.size()));
  }
  const Eigen::Index n = a.cols();
  if (!free_variables.empty() && static_cast<Eigen::Index>(free_variables.size()) != n) {
    throw InputError(source, "free_variables", std::to_string(n) + " flags (the columns of A)",
                     std::to_string(free_variables.size()));
  }
  if (!a.allFinite() || !b.allFinite()) throw InputError(source, "A, b", "finite entries", "NaN or Inf");
  auto is_free = [&](Eigen::Index j) { return !free_variables.empty() && free_variables[static_cast<std::size_t>(j)]; };

  NnlsResult r;
  r.x = Eigen::VectorXd::Zero(n);
  std::vector<bool> passive(static_cast<std::size_t>(n), false);
  for (Eigen::Index j = 0; j < n; ++j) passive[static_cast<std::size_t>(j)] = is_free(j);
  const double eps = std::numeric_limits<double>::epsilon();
  const double norm1 = n > 0 ? a.cwiseAbs().colwise().sum().maxCoeff() : 0.0;
  const double tol = options.tolerance > 0.0
                         ? options.tolerance
                         : 10.0 * eps * norm1 * static_cast<double>(std::max(a.rows(), n)) * std::max(1.0, b.cwiseAbs().maxCoeff());
  const int max_iter = options.max_iterations > 0 ? options.max_iterations : 3 * static_cast<int>(std::max<Eigen::Index>(n, 1));
  // A tall problem is first reduced to its triangular factor: with [A b] = Q [R c; 0 rho],
  // ||A x - b||^2 = ||R x - c||^2 + rho^2 and A^T (b - A x) = R^T (c - R x), so the active-set steps
  // below see the same problem with n rows instead of m (each passive solve is a QR of the passive
  // columns: m n^2 per step on A, n^3 on R; the hysteresis fits have thousands of rows).
  const Reduced reduced = reduce(a, b);
  const Eigen::MatrixXd& ar = reduced.used ? reduced.r : a;
  const Eigen::VectorXd& br = reduced.used ? reduced.c : b;
  r.x = solve_passive(ar, br, passive);  // the free variables alone

  r.converged = false;
  for (r.iterations = 0; r.iterations < max_iter; ++r.iterations) {
    const Eigen::VectorXd w = ar.transpose() * (br - ar * r.x);
    Eigen::Index best = -1;
    double wmax = tol;
    for (Eigen::Index j = 0; j < n; ++j) {
      if (!passive[static_cast<std::size_t>(j)] && w(j) > wmax) {
        wmax = w(j);
        best = j;
      }
    }
    if (best < 0) {
      r.converged = true;
      break;
    }
    passive[static_cast<std::size_t>(best)] = true;
    // Inner loop: step towards the unconstrained solution on the passive set until it is feasible.
    for (int inner = 0; inner <= n; ++inner) {
      const Eigen::VectorXd z = solve_passive(ar, br, passive);
      double alpha = 1.0;
      Eigen::Index blocking = -1;
      for (Eigen::Index j = 0; j < n; ++j) {
        if (!passive[static_cast<std::size_t>(j)] || is_free(j) || z(j) > 0.0) continue;
        const double denom = r.x(j) - z(j);
        const double t = denom > 0.0 ? r.x(j) / denom : 0.0;
        if (t < alpha) {
          alpha = t;
          blocking = j;
        }
      }
      if (blocking < 0) {
        r.x = z;
        break;
      }
      r.x += alpha * (z - r.x);
      passive[static_cast<std::size_t>(blocking)] = false;
      r.x(blocking) = 0.0;
      for (Eigen::Index j = 0; j < n; ++j) {
        if (passive[static_cast<std::size_t>(j)] && !is_free(j) && r.x(j) <= 0.0) {
          passive[static_cast<std::size_t>(j)] = false;
          r.x(j) = 0.0;
        }
      }
    }
  }
  for (Eigen::Index j = 0; j < n; ++j) {
    if (!is_free(j) && r.x(j) < 0.0) r.x(j) = 0.0;
  }
  r.residual_norm = (a * r.x - b).norm();
  r.active.assign(static_cast<std::size_t>(n), false);
  for (Eigen::Index j = 0; j < n; ++j) r.active[static_cast<std::size_t>(j)] = !is_free(j) && !passive[static_cast<std::size_t>(j)];
  return r;
}

}  // namespace piezobench
