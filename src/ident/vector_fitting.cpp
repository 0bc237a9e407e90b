#include "piezobench/ident/vector_fitting.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "piezobench/core/error.hpp"
#include "piezobench/dsp/frf.hpp"

namespace piezobench::ident {
namespace {

constexpr const char* kSource = "vector fitting";
constexpr const char* kOptionsSource = "vector fitting options";
constexpr Complex kJ{0.0, 1.0};

std::string num(double v) {
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

// Real poles first (by magnitude), then pairs (p, conj p), Im p > 0 first, by imaginary part.
// Eigenvalues of a real matrix (Eigen's real Schur form) come as exact conjugates or with an
// imaginary part of exactly zero, so the split below is exact for them; user input is checked by
// validate() with a tolerance and snapped to exact conjugates before it gets here.
CVector canonical_poles(const CVector& raw) {
  std::vector<double> reals;
  std::vector<Complex> uppers;
  for (Index i = 0; i < raw.size(); ++i) {
    if (raw(i).imag() == 0.0) {
      reals.push_back(raw(i).real());
    } else if (raw(i).imag() > 0.0) {
      uppers.push_back(raw(i));
    }
  }
  std::sort(reals.begin(), reals.end(), [](double a, double b) { return std::abs(a) < std::abs(b); });
  std::sort(uppers.begin(), uppers.end(), [](Complex a, Complex b) { return a.imag() < b.imag(); });
  CVector out(static_cast<Index>(reals.size() + 2 * uppers.size()));
  Index k = 0;
  for (double r : reals) out(k++) = Complex(r, 0.0);
  for (Complex u : uppers) {
    out(k++) = u;
    out(k++) = std::conj(u);
  }
  return out;
}

// Basis of the partial fractions for canonical poles: 1/(s - p) for a real pole; for a pair,
// 1/(s - p) + 1/(s - p*) and j/(s - p) - j/(s - p*), so that real coefficients (c', c'') give
// the residue c' + j c'' on p (Gustavsen & Semlyen 1999, eq. A.3).
void fill_basis(const CVector& s, const CVector& poles, CMatrix& basis) {
  // 1/z as conj(z)/|z|^2: the data are well scaled (s is normalized), and this avoids the slow
  // overflow-safe library division, which dominated the cost of this loop.
  const auto inv = [](Complex z) {
    const double n2 = z.real() * z.real() + z.imag() * z.imag();
    return Complex(z.real() / n2, -z.imag() / n2);
  };
  const Index n = poles.size();
  for (Index i = 0; i < n; ++i) {
    const Complex p = poles(i);
    if (p.imag() == 0.0) {
      for (Index k = 0; k < s.size(); ++k) basis(k, i) = inv(s(k) - p);
    } else {
      for (Index k = 0; k < s.size(); ++k) {
        const Complex a = inv(s(k) - p);
        const Complex b = inv(s(k) - std::conj(p));
        basis(k, i) = a + b;
        basis(k, i + 1) = kJ * (a - b);
      }
      ++i;
    }
  }
}

// Real realization (A, b) of the canonical poles: 1x1 blocks for real poles, [[a, w], [-w, a]]
// with b = [2, 0] for a pair a + j w, so that c (sI - A)^-1 b = sum of the partial fractions with
// the coefficients of fill_basis.
void real_realization(const CVector& poles, Matrix& a, Vector& b) {
  const Index n = poles.size();
  a.setZero(n, n);
  b.setZero(n);
  for (Index i = 0; i < n; ++i) {
    const Complex p = poles(i);
    if (p.imag() == 0.0) {
      a(i, i) = p.real();
      b(i) = 1.0;
    } else {
      a(i, i) = p.real();
      a(i + 1, i + 1) = p.real();
      a(i, i + 1) = p.imag();
      a(i + 1, i) = -p.imag();
      b(i) = 2.0;
      ++i;
    }
  }
}

// Symmetric relative distance between two pole sets, over the significant poles of `before`: the
// distance from each of them to the nearest new pole, and from each new pole whose nearest old pole
// is significant to that pole, relative to the old pole's magnitude.
// `significance` (of `now`; empty = all significant) restricts the measure to the new poles that
// matter and the old poles nearest to them.
double pole_change(const CVector& now, const CVector& before, const Vector& significance, double floor_sig) {
  const auto rel = [&](Index i, Index j) {
    return std::abs(now(i) - before(j)) / std::max(std::abs(before(j)), std::numeric_limits<double>::min());
  };
  const auto counts = [&](Index i) { return significance.size() == 0 || significance(i) >= floor_sig; };
  double worst = 0.0;
  for (Index i = 0; i < now.size(); ++i) {
    if (!counts(i)) continue;
    double best = std::numeric_limits<double>::infinity();
    for (Index j = 0; j < before.size(); ++j) best = std::min(best, rel(i, j));
    worst = std::max(worst, best);
  }
  for (Index j = 0; j < before.size(); ++j) {
    Index nearest = -1;
    double best = std::numeric_limits<double>::infinity();
    for (Index i = 0; i < now.size(); ++i) {
      if (rel(i, j) < best) {
        best = rel(i, j);
        nearest = i;
      }
    }
    if (nearest >= 0 && counts(nearest)) worst = std::max(worst, best);
  }
  return worst;
}

Index asymptote_terms(Asymptote a) {
  switch (a) {
    case Asymptote::kNone: return 0;
    case Asymptote::kConstant: return 1;
    case Asymptote::kConstantAndLinear: return 2;
  }
  return 0;
}

// Scales the columns of m to unit 2-norm (zero columns are left alone) and returns the factors.
Vector scale_columns(Matrix& m) {
  Vector factors(m.cols());
  for (Index j = 0; j < m.cols(); ++j) {
    const double norm = m.col(j).norm();
    factors(j) = norm > 0.0 ? 1.0 / norm : 1.0;
    m.col(j) *= factors(j);
  }
  return factors;
}

CVector automatic_starting_poles(const Vector& omega, const VectorFittingOptions& o) {
  double w_lo = 0.0;
  for (Index k = 0; k < omega.size(); ++k) {
    if (omega(k) > 0.0) {
      w_lo = omega(k);
      break;
    }
  }
  const double w_hi = omega(omega.size() - 1);
  const bool log_spaced = o.starting_spacing == PoleSpacing::kLogarithmic;
  const double mid = log_spaced ? std::sqrt(w_lo * w_hi) : 0.5 * (w_lo + w_hi);
  const Index pairs = o.order / 2;
  CVector p(o.order);
  Index k = 0;
  if (o.order % 2 == 1) p(k++) = Complex(-mid, 0.0);
  for (Index i = 0; i < pairs; ++i) {
    double beta = mid;
    if (pairs > 1) {
      const double t = static_cast<double>(i) / static_cast<double>(pairs - 1);
      beta = log_spaced ? w_lo * std::pow(w_hi / w_lo, t) : w_lo + (w_hi - w_lo) * t;
    }
    const Complex pole(-o.starting_damping * beta, beta);
    p(k++) = pole;
    p(k++) = std::conj(pole);
  }
  return p;
}

Matrix make_weights(const CMatrix& data, const Matrix& user, Weighting weighting) {
  if (user.size() > 0) return user;
  if (weighting == Weighting::kUnit) return Matrix::Ones(data.rows(), 1);
  Matrix w(data.rows(), data.cols());
  for (Index i = 0; i < data.cols(); ++i) {
    // A zero sample would get an infinite weight; floor the magnitude at a tiny fraction of the
    // output's largest one.
    const double floor_mag = 1e-12 * data.col(i).cwiseAbs().maxCoeff();
    for (Index k = 0; k < data.rows(); ++k) {
      const double mag = std::max(std::abs(data(k, i)), floor_mag);
      w(k, i) = weighting == Weighting::kInverseMagnitude ? 1.0 / mag : 1.0 / std::sqrt(mag);
    }
  }
  return w;
}

void check_input(const Vector& omega, const CMatrix& data, const Matrix& weights,
                 const VectorFittingOptions& o) {
  const Index ns = omega.size();
  if (ns == 0) throw InputError(kSource, "omega", "at least one frequency", "none");
  for (Index k = 0; k < ns; ++k) {
    if (!std::isfinite(omega(k)) || omega(k) < 0.0) {
      throw InputError(kSource, "omega[" + std::to_string(k) + "]", "finite frequency >= 0 rad/s",
                       num(omega(k)));
    }
    if (k > 0 && omega(k) <= omega(k - 1)) {
      throw InputError(kSource, "omega[" + std::to_string(k) + "]", "strictly increasing frequencies",
                       num(omega(k)) + " after " + num(omega(k - 1)));
    }
  }
  if (omega(ns - 1) <= 0.0) throw InputError(kSource, "omega", "at least one frequency > 0", "only 0");
  if (data.rows() != ns || data.cols() < 1) {
    throw InputError(kSource, "data",
                     std::to_string(ns) + " rows (one per frequency) and at least one column",
                     std::to_string(data.rows()) + "x" + std::to_string(data.cols()));
  }
  for (Index i = 0; i < data.cols(); ++i) {
    for (Index k = 0; k < ns; ++k) {
      if (!std::isfinite(data(k, i).real()) || !std::isfinite(data(k, i).imag())) {
        throw InputError(kSource, "data(" + std::to_string(k) + ", " + std::to_string(i) + ")",
                         "finite value", "non-finite");
      }
    }
  }
  if (data.cwiseAbs().maxCoeff() == 0.0) throw InputError(kSource, "data", "a nonzero response", "all zeros");
  if (weights.size() > 0) {
    if (weights.rows() != ns || (weights.cols() != 1 && weights.cols() != data.cols())) {
      throw InputError(kSource, "weights",
                       std::to_string(ns) + "x1 or " + std::to_string(ns) + "x" + std::to_string(data.cols()),
                       std::to_string(weights.rows()) + "x" + std::to_string(weights.cols()));
    }
    for (Index i = 0; i < weights.size(); ++i) {
      const double w = weights.data()[i];
      if (!std::isfinite(w) || w <= 0.0) throw InputError(kSource, "weights", "finite values > 0", num(w));
    }
  }
  // Each output's pole-relocation problem has 2N + terms + 1 unknowns (one removed by the
  // normalization, one constraint row added); require at least as many real equations so that it
  // is not underdetermined. Beyond this bound the method would only interpolate noise.
  Index equations = 0;
  for (Index k = 0; k < ns; ++k) equations += omega(k) > 0.0 ? 2 : 1;
  const Index needed = 2 * o.order + asymptote_terms(o.asymptote) + 1;
  if (equations < needed) {
    const Index max_order = (equations - asymptote_terms(o.asymptote) - 1) / 2;
    throw InputError(kSource, "order",
                     "at most " + std::to_string(std::max<Index>(max_order, 0)) + " poles for " +
                         std::to_string(ns) + " frequencies (" + std::to_string(equations) +
                         " real equations; " + std::to_string(needed) + " needed for " +
                         std::to_string(o.order) + " poles)",
                     std::to_string(o.order));
  }
}

// The fitting problem in scaled units: s = j omega / scale.
class Fitter {
 public:
  Fitter(const Vector& omega, const CMatrix& data, const Matrix& weights, const VectorFittingOptions& o,
         double scale)
      : data_(data), weights_(weights), opts_(o), ns_(omega.size()), nc_(data.cols()), n_(o.order),
        offs_(asymptote_terms(o.asymptote)) {
    s_ = (kJ * omega / scale).eval();
    basis_.resize(ns_, n_ + 2);
    data_max_ = data.cwiseAbs().maxCoeff();
    double wd = 0.0;
    for (Index i = 0; i < nc_; ++i) {
      const auto w = weights.col(weights.cols() == 1 ? 0 : i);
      for (Index k = 0; k < ns_; ++k) wd += w(k) * w(k) * std::norm(data(k, i));
    }
    weighted_data_norm_ = std::sqrt(wd);
  }

  // Quality of a model with these poles and the coefficients x from identify(): the relative
  // weighted rms error, and the significance of each pole, i.e. its largest peak contribution
  // |r| / |Re p| (|r| / |p| for a real pole) over the outputs, relative to the largest data
  // magnitude. Uses the basis left by identify().
  double assess(const CVector& poles, const Matrix& x, Vector& significance) const {
    double err = 0.0;
    const Index cols = n_ + offs_;
    for (Index i = 0; i < nc_; ++i) {
      const auto w = weights_.col(weights_.cols() == 1 ? 0 : i);
      const CVector fit = basis_.leftCols(cols) * x.col(i).cast<Complex>();
      err += (w.cast<Complex>().cwiseProduct(fit - data_.col(i))).squaredNorm();
    }
    significance.setZero(n_);
    for (Index k = 0; k < n_; ++k) {
      const Complex p = poles(k);
      for (Index i = 0; i < nc_; ++i) {
        const double v = p.imag() == 0.0 ? std::abs(x(k, i)) / std::abs(p)
                                         : std::hypot(x(k, i), x(k + 1, i)) / std::abs(p.real());
        significance(k) = std::max(significance(k), std::isfinite(v) ? v / data_max_ : 0.0);
      }
      if (p.imag() != 0.0) {
        significance(k + 1) = significance(k);
        ++k;
      }
    }
    return std::sqrt(err) / weighted_data_norm_;
  }

  // One pole relocation: returns the zeros of sigma (canonical, possibly unstable).
  CVector relocate(const CVector& poles) {
    fill_basis(s_, poles, basis_);
    basis_.col(n_).setOnes();
    basis_.col(n_ + 1) = s_;
    CVector relocated;
    if (opts_.relaxed) {
      if (solve_sigma(poles, /*relaxed=*/true, relocated)) return relocated;
    }
    if (!solve_sigma(poles, /*relaxed=*/false, relocated)) {
      throw NumericalError(kSource, "the pole-relocation least-squares problem is singular",
                           /*retry_may_help=*/true);
    }
    return relocated;
  }

  // Residues, d and e for fixed poles (the linear problem), one column per output:
  // rows 0..N-1 partial-fraction coefficients (real form), N.. the asymptotic terms.
  Matrix identify(const CVector& poles) {
    fill_basis(s_, poles, basis_);
    basis_.col(n_).setOnes();
    basis_.col(n_ + 1) = s_;
    const Index cols = n_ + offs_;
    Matrix x(cols, nc_);
    Matrix a(2 * ns_, cols);
    Matrix rhs(2 * ns_, nc_);
    const bool common = weights_.cols() == 1;
    const Index passes = common ? 1 : nc_;
    for (Index pass = 0; pass < passes; ++pass) {
      const Vector w = weights_.col(pass);
      for (Index j = 0; j < cols; ++j) {
        a.col(j).head(ns_) = w.cwiseProduct(basis_.col(j).real());
        a.col(j).tail(ns_) = w.cwiseProduct(basis_.col(j).imag());
      }
      const Vector colscale = scale_columns(a);
      // Column pivoting: with more poles than the data can resolve, the problem is rank
      // deficient and the basic solution keeps the coefficients finite.
      Eigen::ColPivHouseholderQR<Matrix> qr(a);
      const Index first = common ? 0 : pass;
      const Index count = common ? nc_ : 1;
      for (Index i = first; i < first + count; ++i) {
        rhs.col(i).head(ns_) = w.cwiseProduct(data_.col(i).real());
        rhs.col(i).tail(ns_) = w.cwiseProduct(data_.col(i).imag());
        x.col(i) = colscale.cwiseProduct(qr.solve(rhs.col(i)));
      }
    }
    return x;
  }

 private:
  // Builds each output's least-squares problem [A b], QR-reduces it, stacks the sigma blocks of the
  // triangular factors (with the matching part of Q^T b) and solves the stacked problem.
  //
  // The QR is done in place on the augmented matrix [A b], which yields Q^T b in the last column
  // for free. Long records are fed in chunks of kChunkPoints frequencies (a sequential TSQR): the
  // triangular factor so far sits on top of the next chunk and the stack is re-factorized, as
  // backward stable as one QR of the whole matrix with a bounded working set. (Smaller chunks were
  // measured slower: Eigen's QR of a 4000 x 43 matrix already runs at about 10 GFlop/s.)
  bool solve_sigma(const CVector& poles, bool relaxed, CVector& relocated) {
    constexpr Index kChunkPoints = 4096;
    const Index left = n_ + offs_;
    const Index nsig = relaxed ? n_ + 1 : n_;
    const Index cols = left + nsig;  // plus one column for the right-hand side
    const Index rcols = cols + 1;
    work_.resize(rcols + 2 * std::min(kChunkPoints, ns_) + 1, rcols);
    stacked_.resize(nc_ * nsig, nsig);
    stacked_rhs_.resize(nc_ * nsig);

    // Relaxed normalization (Gustavsen 2006, eq. 8): Re sum_k sigma(s_k) = Ns, scaled by the size of
    // the data so that the constraint row weighs like the others.
    double scale = 0.0;
    if (relaxed) {
      for (Index i = 0; i < nc_; ++i) {
        const auto w = weights_.col(weights_.cols() == 1 ? 0 : i);
        for (Index k = 0; k < ns_; ++k) scale += w(k) * w(k) * std::norm(data_(k, i));
      }
      scale = std::sqrt(scale) / static_cast<double>(ns_);
    }

    for (Index i = 0; i < nc_; ++i) {
      const auto w = weights_.col(weights_.cols() == 1 ? 0 : i);
      const bool constrained = relaxed && i == nc_ - 1;
      Index top = 0;  // rows of the triangular factor on top of work_
      for (Index k0 = 0; k0 < ns_; k0 += kChunkPoints) {
        const Index cnt = std::min(kChunkPoints, ns_ - k0);
        const bool final_chunk = k0 + cnt == ns_;
        const Index extra = constrained && final_chunk ? 1 : 0;
        const Index rows = top + 2 * cnt + extra;
        for (Index j = 0; j < left; ++j) {
          for (Index k = 0; k < cnt; ++k) {
            const Complex v = w(k0 + k) * basis_(k0 + k, j);
            work_(top + k, j) = v.real();
            work_(top + cnt + k, j) = v.imag();
          }
        }
        for (Index j = 0; j < nsig; ++j) {
          for (Index k = 0; k < cnt; ++k) {
            const Complex v = -w(k0 + k) * basis_(k0 + k, j) * data_(k0 + k, i);
            work_(top + k, left + j) = v.real();
            work_(top + cnt + k, left + j) = v.imag();
          }
        }
        for (Index k = 0; k < cnt; ++k) {
          // Fixed normalization: sigma's constant is 1, so its term moves to the right-hand side.
          const Complex v = relaxed ? Complex(0.0, 0.0) : w(k0 + k) * data_(k0 + k, i);
          work_(top + k, cols) = v.real();
          work_(top + cnt + k, cols) = v.imag();
        }
        if (extra == 1) {
          const Index r = top + 2 * cnt;
          work_.row(r).head(left).setZero();
          for (Index j = 0; j < nsig; ++j) work_(r, left + j) = scale * basis_.col(j).sum().real();
          work_(r, cols) = static_cast<double>(ns_) * scale;
        }
        Eigen::Ref<Matrix> block = work_.topRows(rows);
        Eigen::HouseholderQR<Eigen::Ref<Matrix>> qr(block);  // in place
        top = std::min(rows, rcols);
        work_.topRows(top).triangularView<Eigen::StrictlyLower>().setZero();
      }
      if (top < rcols) work_.middleRows(top, rcols - top).setZero();
      stacked_.block(i * nsig, 0, nsig, nsig) = work_.block(left, left, nsig, nsig);
      stacked_rhs_.segment(i * nsig, nsig) = work_.col(cols).segment(left, nsig);
    }

    const Vector colscale = scale_columns(stacked_);
    // Column pivoting: when the data can be matched with fewer poles, the stacked problem is
    // (nearly) rank deficient; the basic solution then leaves the undetermined sigma coefficients at
    // zero, i.e. those poles are not moved, instead of failing.
    Eigen::ColPivHouseholderQR<Matrix> solver(stacked_);
    const Vector xs = solver.solve(stacked_rhs_);
    const Vector x = colscale.cwiseProduct(xs);
    if (!x.allFinite()) return false;

    double d_sigma = 1.0;
    if (relaxed) {
      // A vanishing constant term means the relaxed problem found the trivial solution direction;
      // fall back to the fixed normalization (as vectfit3 does).
      d_sigma = x(n_);
      if (!(std::abs(d_sigma) > 1e-8 && std::abs(d_sigma) < 1e8)) return false;
    }
    // Zeros of sigma(s) = d + c (sI - A)^-1 b are the eigenvalues of A - b c / d.
    Matrix lam;
    Vector bb;
    real_realization(poles, lam, bb);
    lam.noalias() -= bb * x.head(n_).transpose() / d_sigma;
    Eigen::EigenSolver<Matrix> eig(lam, /*computeEigenvectors=*/false);
    if (eig.info() != Eigen::Success) return false;
    CVector z = eig.eigenvalues();
    if (!z.allFinite()) return false;
    if (opts_.enforce_stable_poles) {
      for (Index k = 0; k < z.size(); ++k) {
        if (z(k).real() > 0.0) z(k) = Complex(-z(k).real(), z(k).imag());
      }
    }
    relocated = canonical_poles(z);
    return relocated.size() == n_;
  }

  const CMatrix& data_;
  const Matrix& weights_;
  const VectorFittingOptions& opts_;
  Index ns_, nc_, n_, offs_;
  CVector s_;
  CMatrix basis_;
  Matrix work_;
  Matrix stacked_;
  Vector stacked_rhs_;
  double data_max_ = 1.0;
  double weighted_data_norm_ = 1.0;
};

}  // namespace

std::string to_string(Asymptote a) {
  switch (a) {
    case Asymptote::kNone: return "none";
    case Asymptote::kConstant: return "d";
    case Asymptote::kConstantAndLinear: return "de";
  }
  return "none";
}

Asymptote asymptote_from_string(const std::string& s) {
  if (s == "none") return Asymptote::kNone;
  if (s == "d") return Asymptote::kConstant;
  if (s == "de") return Asymptote::kConstantAndLinear;
  throw InputError("", "asymptote", "one of none, d, de", "'" + s + "'");
}

std::string to_string(Convergence c) {
  switch (c) {
    case Convergence::kNotConverged: return "not-converged";
    case Convergence::kPolesSettled: return "poles-settled";
    case Convergence::kResidualSettled: return "residual-settled";
  }
  return "not-converged";
}

Convergence convergence_from_string(const std::string& s) {
  if (s == "not-converged") return Convergence::kNotConverged;
  if (s == "poles-settled") return Convergence::kPolesSettled;
  if (s == "residual-settled") return Convergence::kResidualSettled;
  throw InputError("", "convergence", "one of not-converged, poles-settled, residual-settled", "'" + s + "'");
}

std::string to_string(PoleSpacing p) { return p == PoleSpacing::kLogarithmic ? "log" : "lin"; }

PoleSpacing pole_spacing_from_string(const std::string& s) {
  if (s == "log") return PoleSpacing::kLogarithmic;
  if (s == "lin") return PoleSpacing::kLinear;
  throw InputError("", "starting_spacing", "one of log, lin", "'" + s + "'");
}

std::string to_string(Weighting w) {
  switch (w) {
    case Weighting::kUnit: return "unit";
    case Weighting::kInverseMagnitude: return "inverse-magnitude";
    case Weighting::kInverseSqrtMagnitude: return "inverse-sqrt-magnitude";
  }
  return "unit";
}

Weighting weighting_from_string(const std::string& s) {
  if (s == "unit") return Weighting::kUnit;
  if (s == "inverse-magnitude") return Weighting::kInverseMagnitude;
  if (s == "inverse-sqrt-magnitude") return Weighting::kInverseSqrtMagnitude;
  throw InputError("", "weighting", "one of unit, inverse-magnitude, inverse-sqrt-magnitude", "'" + s + "'");
}

void VectorFittingOptions::validate() const {
  if (order < 1) throw InputError(kOptionsSource, "order", "at least 1 pole", std::to_string(order));
  if (max_iterations < 0) {
    throw InputError(kOptionsSource, "max_iterations", ">= 0", std::to_string(max_iterations));
  }
  if (!std::isfinite(pole_tolerance) || pole_tolerance < 0.0) {
    throw InputError(kOptionsSource, "pole_tolerance", "finite value >= 0", num(pole_tolerance));
  }
  if (!std::isfinite(residual_tolerance) || residual_tolerance < 0.0) {
    throw InputError(kOptionsSource, "residual_tolerance", "finite value >= 0 (0 = off)", num(residual_tolerance));
  }
  if (!std::isfinite(significance_floor) || significance_floor < 0.0 || significance_floor >= 1.0) {
    throw InputError(kOptionsSource, "significance_floor", "value in [0, 1)", num(significance_floor));
  }
  if (!std::isfinite(starting_damping) || starting_damping <= 0.0 || starting_damping >= 1.0) {
    throw InputError(kOptionsSource, "starting_damping", "value in (0, 1)", num(starting_damping));
  }
  if (!std::isfinite(frequency_scale) || frequency_scale < 0.0) {
    throw InputError(kOptionsSource, "frequency_scale", "finite value >= 0 rad/s (0 = automatic)",
                     num(frequency_scale));
  }
  if (starting_poles.size() > 0) {
    if (starting_poles.size() != order) {
      throw InputError(kOptionsSource, "starting_poles", std::to_string(order) + " poles (= order)",
                       std::to_string(starting_poles.size()));
    }
    if (!starting_poles.allFinite()) throw InputError(kOptionsSource, "starting_poles", "finite values", "non-finite");
    // Every complex pole needs its conjugate (same tolerance as the zpk checks: relative 1e-9).
    std::vector<bool> used(static_cast<size_t>(order), false);
    for (Index i = 0; i < order; ++i) {
      const Complex p = starting_poles(i);
      if (p.imag() == 0.0 || used[static_cast<size_t>(i)]) continue;
      bool found = false;
      for (Index j = 0; j < order && !found; ++j) {
        if (j == i || used[static_cast<size_t>(j)]) continue;
        if (std::abs(starting_poles(j) - std::conj(p)) <= 1e-9 * std::abs(p)) {
          used[static_cast<size_t>(i)] = used[static_cast<size_t>(j)] = true;
          found = true;
        }
      }
      if (!found) {
        std::ostringstream os;
        os << p;
        throw InputError(kOptionsSource, "starting_poles", "complex poles in conjugate pairs",
                         "unpaired pole " + os.str());
      }
    }
  }
}

CVector VectorFittingResult::evaluate_at(Complex s) const {
  CVector out(outputs());
  for (Index i = 0; i < outputs(); ++i) out(i) = d(i) + s * e(i);
  for (Index n = 0; n < poles.size(); ++n) {
    // r / z as r conj(z) / |z|^2 (no overflow concern at frequencies where the model is used).
    const Complex z = s - poles(n);
    const Complex inv = std::conj(z) / std::norm(z);
    for (Index i = 0; i < outputs(); ++i) out(i) += residues(i, n) * inv;
  }
  return out;
}

CMatrix VectorFittingResult::evaluate(const Vector& omega) const {
  CMatrix out(omega.size(), outputs());
  for (Index k = 0; k < omega.size(); ++k) out.row(k) = evaluate_at(Complex(0.0, omega(k))).transpose();
  return out;
}

std::string VectorFittingResult::brief_report() const {
  std::ostringstream os;
  os.precision(3);
  os << "vector fitting: " << poles.size() << " poles, " << outputs() << " output(s), " << iterations
     << " iteration(s), " << to_string(convergence) << " (last relative pole change "
     << last_pole_change << "), rms error " << rms_error << " (relative " << relative_rms_error << ")";
  return os.str();
}

VectorFittingResult vector_fit(const Vector& omega, const CMatrix& data, const VectorFittingOptions& options) {
  return vector_fit(omega, data, Matrix(), options);
}

VectorFittingResult vector_fit(const Vector& omega, const CMatrix& data, const Matrix& user_weights,
                               const VectorFittingOptions& options) {
  options.validate();
  check_input(omega, data, user_weights, options);
  const Matrix weights = make_weights(data, user_weights, options.weighting);
  const double scale = options.frequency_scale > 0.0 ? options.frequency_scale : omega(omega.size() - 1);

  CVector start = options.starting_poles.size() > 0 ? options.starting_poles
                                                     : automatic_starting_poles(omega, options);
  // Snap user pairs to exact conjugates (validate() accepted them within 1e-9).
  for (Index i = 0; i < start.size(); ++i) {
    if (std::abs(start(i).imag()) <= 1e-15 * std::abs(start(i))) start(i) = Complex(start(i).real(), 0.0);
  }
  {
    CVector snapped(start.size());
    Index k = 0;
    std::vector<bool> used(static_cast<size_t>(start.size()), false);
    for (Index i = 0; i < start.size(); ++i) {
      if (used[static_cast<size_t>(i)]) continue;
      used[static_cast<size_t>(i)] = true;
      if (start(i).imag() == 0.0) {
        snapped(k++) = start(i);
        continue;
      }
      Index best = -1;
      for (Index j = 0; j < start.size(); ++j) {
        if (used[static_cast<size_t>(j)]) continue;
        if (best < 0 || std::abs(start(j) - std::conj(start(i))) < std::abs(start(best) - std::conj(start(i)))) {
          best = j;
        }
      }
      assert(best >= 0);
      used[static_cast<size_t>(best)] = true;
      const Complex upper(start(i).real(), std::abs(start(i).imag()));
      snapped(k++) = upper;
      snapped(k++) = std::conj(upper);
    }
    start = snapped;
  }
  CVector poles = canonical_poles(start / scale);

  Fitter fitter(omega, data, weights, options, scale);
  VectorFittingResult result;
  result.frequency_scale = scale;
  // Each relocation is first judged on all poles (cheap). When that has not settled, the residues
  // for the new poles are identified (one linear least-squares problem) so that poles the data do
  // not determine can be left out, and the fit error can be compared with the previous one.
  const bool assess_each = options.significance_floor > 0.0 || options.residual_tolerance > 0.0;
  double previous_error = -1.0;
  Matrix x;
  bool x_current = false;
  Vector significance;
  for (int it = 0; it < options.max_iterations; ++it) {
    const CVector relocated = fitter.relocate(poles);
    const double raw_change = pole_change(relocated, poles, Vector(), 0.0);
    const CVector before = poles;
    poles = relocated;
    result.iterations = it + 1;
    result.last_pole_change = raw_change;
    x_current = false;
    if (raw_change < options.pole_tolerance) {
      result.converged = true;
      result.convergence = Convergence::kPolesSettled;
      break;
    }
    if (!assess_each) continue;
    x = fitter.identify(poles);
    x_current = true;
    const double error = fitter.assess(poles, x, significance);
    result.last_pole_change = pole_change(poles, before, significance, options.significance_floor);
    if (result.last_pole_change < options.pole_tolerance) {
      result.converged = true;
      result.convergence = Convergence::kPolesSettled;
      break;
    }
    if (options.residual_tolerance > 0.0 && previous_error >= 0.0 &&
        std::abs(error - previous_error) <= options.residual_tolerance * previous_error) {
      result.converged = true;
      result.convergence = Convergence::kResidualSettled;
      break;
    }
    previous_error = error;
  }
  if (!result.converged && options.max_iterations > 0 && options.fail_if_not_converged) {
    throw NumericalError(kSource,
                         "poles did not settle after " + std::to_string(result.iterations) +
                             " relocations (last relative change " + num(result.last_pole_change) +
                             ", tolerance " + num(options.pole_tolerance) +
                             "); try another order, more iterations, weights or a looser tolerance",
                         /*retry_may_help=*/true);
  }

  if (!x_current) x = fitter.identify(poles);
  const Index n = options.order;
  const Index nc = data.cols();
  const Index offs = asymptote_terms(options.asymptote);
  result.poles = poles * scale;
  result.residues.resize(nc, n);
  result.d = Vector::Zero(nc);
  result.e = Vector::Zero(nc);
  for (Index i = 0; i < nc; ++i) {
    for (Index k = 0; k < n; ++k) {
      if (poles(k).imag() == 0.0) {
        result.residues(i, k) = x(k, i) * scale;
      } else {
        const Complex r = Complex(x(k, i), x(k + 1, i)) * scale;
        result.residues(i, k) = r;
        result.residues(i, k + 1) = std::conj(r);
        ++k;
      }
    }
    if (offs >= 1) result.d(i) = x(n, i);
    if (offs >= 2) result.e(i) = x(n + 1, i) / scale;
  }
  if (!result.residues.allFinite() || !result.d.allFinite() || !result.e.allFinite()) {
    throw NumericalError(kSource, "the residue least-squares problem gave non-finite values",
                         /*retry_may_help=*/true);
  }

  // Real state space of the proper part.
  lti::StateSpace& m = result.model;
  Vector b;
  real_realization(result.poles, m.A, b);
  m.B = b;
  m.C.resize(nc, n);
  for (Index i = 0; i < nc; ++i) {
    for (Index k = 0; k < n; ++k) {
      if (result.poles(k).imag() == 0.0) {
        m.C(i, k) = result.residues(i, k).real();
      } else {
        m.C(i, k) = result.residues(i, k).real();
        m.C(i, k + 1) = result.residues(i, k).imag();
        ++k;
      }
    }
  }
  m.D = result.d;
  m.sample_time = 0.0;

  const CMatrix fit = result.evaluate(omega);
  const double count = static_cast<double>(data.size());
  result.rms_error = std::sqrt((fit - data).squaredNorm() / count);
  result.relative_rms_error = result.rms_error / std::sqrt(data.squaredNorm() / count);
  return result;
}

VectorFittingResult vector_fit(const dsp::Frf& frf, const VectorFittingOptions& options) {
  frf.validate(frf.provenance.source);
  const Index ns = frf.freq_hz.size();
  CMatrix data(ns, static_cast<Index>(frf.H.size()));
  for (size_t i = 0; i < frf.H.size(); ++i) data.col(static_cast<Index>(i)) = frf.H[i];
  const Vector omega = 2.0 * std::numbers::pi * frf.freq_hz;
  try {
    return vector_fit(omega, data, options);
  } catch (const InputError& e) {
    if (frf.provenance.source.empty()) throw;
    throw e.with_source(frf.provenance.source);
  }
}

}  // namespace piezobench::ident
