#include "spectral.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "balance.hpp"
#include "check.hpp"
#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"

namespace piezobench::lti::detail {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

// Nearest power of two, so that scaling by it is exact.
double power_of_two(double x) {
  if (!(x > 0.0) || !std::isfinite(x)) return 1.0;
  return std::ldexp(1.0, static_cast<int>(std::lround(std::log2(x))));
}

struct Quad {
  Matrix a, b, c, d;
};

Quad dual(const Quad& s) { return Quad{s.a.transpose(), s.c.transpose(), s.b.transpose(), s.d.transpose()}; }

Index rank_of(const Vector& singular_values, double tol) {
  Index r = 0;
  for (Index i = 0; i < singular_values.size(); ++i) {
    if (singular_values(i) > tol) ++r;
  }
  return r;
}

// One reduction of Emami-Naeini & Van Dooren (1982), repeated until D has full row rank. Each pass
// removes the states that a rank-deficient D lets the zero-feedthrough outputs see directly: with
// U^T [C D] = [C1 0; C2 D2] (D2 full row rank) and C1 V = [0 Ctil] (Ctil invertible), the rows
// through Ctil pin x2 = 0 and can be eliminated, which leaves the finite zeros unchanged (a
// unimodular transformation of the pencil). Orthogonal transformations only, so backward stable.
Quad reduce(Quad s, double tol) {
  for (;;) {
    const Index n = s.a.rows();
    const Index m = s.d.cols();
    const Index p = s.d.rows();
    if (p == 0) return s;
    Matrix u = Matrix::Identity(p, p);
    Index sigma = 0;
    if (m > 0) {
      Eigen::JacobiSVD<Matrix> svd(s.d, Eigen::ComputeFullU);
      sigma = rank_of(svd.singularValues(), tol);
      u = svd.matrixU();
    }
    if (sigma == p) return s;
    const Matrix c1 = u.rightCols(p - sigma).transpose() * s.c;  // outputs with no feedthrough
    const Matrix c2 = u.leftCols(sigma).transpose() * s.c;
    const Matrix d2 = u.leftCols(sigma).transpose() * s.d;
    Index rho = 0;
    Matrix v;
    if (n > 0) {
      Eigen::JacobiSVD<Matrix> svd(c1, Eigen::ComputeFullV);
      rho = rank_of(svd.singularValues(), tol);
      v = svd.matrixV();
    }
    if (rho == 0) {
      // Rows [0 0] of the pencil only lower its normal rank; they hold no zero.
      s.c = c2;
      s.d = d2;
      continue;
    }
    const Index k = n - rho;
    Matrix vp(n, n);
    vp << v.rightCols(k), v.leftCols(rho);  // x = vp [x1; x2], x2 along the row space of C1
    const Matrix at = vp.transpose() * s.a * vp;
    const Matrix bt = vp.transpose() * s.b;
    const Matrix ct = c2 * vp;
    Quad r;
    r.a = at.topLeftCorner(k, k);
    r.b = bt.topRows(k);
    // Eigen's comma initializer takes a block of the destination for each piece: into an empty matrix
    // (no states left, or no inputs) that is an offset from a null pointer, so an empty one is only sized.
    r.c.resize(rho + sigma, k);
    if (r.c.size() > 0) r.c << at.bottomLeftCorner(rho, k), ct.leftCols(k);
    r.d.resize(rho + sigma, m);
    if (r.d.size() > 0) r.d << bt.bottomRows(rho), d2;
    s = std::move(r);
  }
}

}  // namespace

void sort_roots(CVector& v) {
  std::stable_sort(v.data(), v.data() + v.size(), [](const Complex& x, const Complex& y) {
    const double ax = std::abs(x);
    const double ay = std::abs(y);
    if (ax != ay) return ax < ay;
    if (x.real() != y.real()) return x.real() < y.real();
    return x.imag() < y.imag();
  });
}

CVector balanced_eigenvalues(const Matrix& a) {
  assert(a.rows() == a.cols());
  if (a.rows() == 0) return CVector();
  const Vector d = balancing_scales(a);
  // D^-1 A D, exact since d holds powers of two.
  const Matrix ab = d.cwiseInverse().asDiagonal() * a * d.asDiagonal();
  Eigen::EigenSolver<Matrix> es(ab, /*computeEigenvectors=*/false);
  if (es.info() != Eigen::Success) {
    throw NumericalError("eigenvalues (real Schur form)", "the QR iteration did not converge", false);
  }
  CVector ev = es.eigenvalues();
  sort_roots(ev);
  return ev;
}

ConjugateSplit split_conjugates(const CVector& values, const std::string& source, const std::string& field) {
  ConjugateSplit out;
  std::vector<Index> upper;
  std::vector<Index> lower;
  for (Index i = 0; i < values.size(); ++i) {
    const Complex v = values(i);
    if (std::abs(v.imag()) <= 8.0 * kEps * std::abs(v)) {
      out.real.push_back(v.real());
    } else if (v.imag() > 0.0) {
      upper.push_back(i);
    } else {
      lower.push_back(i);
    }
  }
  std::vector<bool> used(lower.size(), false);
  for (const Index i : upper) {
    const Complex v = values(i);
    double best = std::numeric_limits<double>::infinity();
    std::size_t best_j = lower.size();
    for (std::size_t j = 0; j < lower.size(); ++j) {
      if (used[j]) continue;
      const double dist = std::abs(std::conj(values(lower[j])) - v);
      if (dist < best) {
        best = dist;
        best_j = j;
      }
    }
    if (best_j == lower.size() || best > 1e-8 * std::abs(v)) {
      std::ostringstream os;
      os.precision(10);
      os << v << " without its conjugate";
      throw InputError(source, entry(field, i), "complex values in conjugate pairs", os.str());
    }
    used[best_j] = true;
    out.pairs.push_back(0.5 * (v + std::conj(values(lower[best_j]))));
  }
  for (std::size_t j = 0; j < lower.size(); ++j) {
    if (!used[j]) {
      std::ostringstream os;
      os.precision(10);
      os << values(lower[j]) << " without its conjugate";
      throw InputError(source, entry(field, lower[j]), "complex values in conjugate pairs", os.str());
    }
  }
  return out;
}

PencilZeros system_zeros(const Matrix& a_in, const Matrix& b_in, const Matrix& c_in, const Matrix& d_in) {
  Quad s{a_in, b_in, c_in, d_in};
  const Index n = s.a.rows();
  const Index m = s.d.cols();
  const Index p = s.d.rows();

  // Scaling, none of which moves a zero: (1) diagonal state balancing (a similarity);
  // (2) frequency scaling A/alpha, B/alpha, whose zeros are those of the system divided by alpha,
  // so that ||A|| ~ 1 and the rank tolerance below means the same for slow and fast systems;
  // (3) unit-norm input columns [B; D] and output rows [C D] (nonsingular input/output scalings).
  // Every factor is a power of two, so the scaling itself adds no round-off.
  balance_realization(s.a, s.b, s.c);
  double alpha = 1.0;
  if (n > 0) {
    alpha = power_of_two(s.a.norm());
    if (s.a.norm() == 0.0) {
      // A = 0: scale by the coupling terms instead (any alpha is valid).
      const double bc = std::sqrt(s.b.norm() * s.c.norm());
      alpha = power_of_two(bc > 0.0 ? bc : 1.0);
    }
    s.a /= alpha;
    s.b /= alpha;
  }
  for (Index j = 0; j < m; ++j) {
    const double nj = std::hypot(s.b.col(j).norm(), s.d.col(j).norm());
    if (nj > 0.0) {
      const double f = power_of_two(nj);
      s.b.col(j) /= f;
      s.d.col(j) /= f;
    }
  }
  for (Index i = 0; i < p; ++i) {
    const double ni = std::hypot(s.c.row(i).norm(), s.d.row(i).norm());
    if (ni > 0.0) {
      const double f = power_of_two(ni);
      s.c.row(i) /= f;
      s.d.row(i) /= f;
    }
  }

  // Rank decisions: a singular value counts when it exceeds max(n+p, n+m) * 10 eps ||S||_F, S the
  // scaled system matrix [A B; C D] (the tolerance of SLICOT AB08ND with a safety factor of 10).
  // Every later matrix is an orthogonal transformation of a block of S, so one tolerance serves all.
  const double s_norm =
      std::sqrt(s.a.squaredNorm() + s.b.squaredNorm() + s.c.squaredNorm() + s.d.squaredNorm());
  const double tol = 10.0 * kEps * static_cast<double>(std::max(n + p, n + m)) * std::max(s_norm, 1e-300);

  Quad r = reduce(s, tol);         // D full row rank
  r = dual(reduce(dual(r), tol));  // D full column rank too: square and invertible
  const Index nf = r.a.rows();
  const Index rf = r.d.rows();
  if (r.d.cols() != rf) {
    throw NumericalError("zeros (Emami-Naeini & Van Dooren reduction)",
                         "the reduced feedthrough is " + shape(rf, r.d.cols()) + ", not square",
                         /*retry_may_help=*/false);
  }
  PencilZeros out;
  out.normal_rank = rf;
  if (nf == 0) return out;

  Matrix af;
  Matrix ef;
  if (rf == 0) {
    af = r.a;
    ef = Matrix::Identity(nf, nf);
  } else {
    // Column-compress [C D] with an orthogonal Z: [C D] Z = [0 Dt]. Then [A - sI, B] Z restricted to
    // its first nf columns is the regular pencil Af - s Ef that holds the zeros.
    Matrix cd(rf, nf + rf);
    cd << r.c, r.d;
    Eigen::HouseholderQR<Matrix> qr(cd.transpose());
    const Matrix q = qr.householderQ() * Matrix::Identity(nf + rf, nf + rf);
    const Matrix z1 = q.rightCols(nf);  // orthogonal to the rows of [C D]
    Matrix ab(nf, nf + rf);
    ab << r.a, r.b;
    af = ab * z1;
    ef = z1.topRows(nf);
  }
  Eigen::GeneralizedEigenSolver<Matrix> ges(af, ef, /*computeEigenvectors=*/false);
  if (ges.info() != Eigen::Success) {
    throw NumericalError("zeros (QZ)", "the QZ iteration did not converge", false);
  }
  const CVector alphas = ges.alphas();
  const Vector betas = ges.betas();
  std::vector<Complex> finite;
  for (Index i = 0; i < nf; ++i) {
    // An infinite eigenvalue cannot remain after the reduction; a beta at round-off level relative
    // to alpha (a zero beyond ~1e13 in scaled units) is treated as one anyway.
    if (std::abs(betas(i)) > 1e2 * kEps * std::abs(alphas(i))) finite.push_back(alphas(i) / betas(i) * alpha);
  }
  out.zeros = Eigen::Map<const CVector>(finite.data(), static_cast<Index>(finite.size()));
  return out;
}

CMatrix evaluate_dense(const Matrix& a_in, const Matrix& b_in, const Matrix& c_in, const Matrix& d, Complex s) {
  const Index n = a_in.rows();
  if (n == 0) return d.cast<Complex>();
  Matrix a = a_in;
  Matrix b = b_in;
  Matrix c = c_in;
  balance_realization(a, b, c);
  CMatrix m = -a.cast<Complex>();
  m.diagonal().array() += s;
  Eigen::PartialPivLU<CMatrix> lu(m);
  if (!(lu.rcond() > 10.0 * kEps)) {
    std::ostringstream os;
    os.precision(10);
    os << "sI - A is singular at s = " << s;
    throw NumericalError("transfer function evaluation", os.str(), false);
  }
  const CMatrix x = lu.solve(b.cast<Complex>());
  return d.cast<Complex>() + c.cast<Complex>() * x;
}

}  // namespace piezobench::lti::detail
