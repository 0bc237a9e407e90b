#include "piezobench/ident/vector_fitting.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/dsp/frf.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::ident {
namespace {

constexpr const char* kSource = "vector fitting";
constexpr const char* kOptionsSource = "vector fitting options";
constexpr Complex kJ{0.0, 1.0};

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

// The loops that build the least-squares rows, the basis and the model's evaluation are compiled
// for AVX-512 (x86-64-v4), AVX2 (v3) and the baseline; the loader picks one (GCC's target_clones;
// the build itself stays generic x86-64).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define PB_CLONES [[gnu::target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")]]
#else
#define PB_CLONES
#endif

// Basis of the partial fractions for canonical poles at s = j w (w: the scaled frequencies): 1/(s - p)
// for a real pole; for a pair, 1/(s - p) + 1/(s - p*) and j/(s - p) - j/(s - p*), so that real
// coefficients (c', c'') give the residue c' + j c'' on p (Gustavsen & Semlyen 1999, eq. A.3).
// Written in real arithmetic: s is imaginary, and GCC's complex product checks every result for
// NaN (a call to __muldc3), which kept these loops from being vectorized. The real and imaginary
// parts are kept apart (re, im): the loops that build the least-squares rows from them then read
// contiguous doubles.
//
// The columns of pole p (one for a real pole, two for a pair) at the cnt scaled frequencies w.
PB_CLONES Index basis_columns(const double* w, Index cnt, Complex p, double* re0, double* im0, double* re1,
                              double* im1) {
  const double a = p.real();
  const double b = p.imag();
  if (b == 0.0) {
    // 1/(j w - a) = (-a - j w) / (a^2 + w^2)
    for (Index k = 0; k < cnt; ++k) {
      const double inv = 1.0 / (a * a + w[k] * w[k]);
      re0[k] = -a * inv;
      im0[k] = -w[k] * inv;
    }
    return 1;
  }
  // 1/(s - p) + 1/(s - p*) = 2 (s - a) / q and j (1/(s - p) - 1/(s - p*)) = -2 b / q with
  // q = (s - p)(s - p*) = (a^2 + b^2 - w^2) - 2 j a w: one reciprocal per pair.
  const double m2 = a * a + b * b;
  for (Index k = 0; k < cnt; ++k) {
    const double qr = m2 - w[k] * w[k];
    const double qi = -2.0 * a * w[k];
    const double inv = 1.0 / (qr * qr + qi * qi);
    const double rr = qr * inv;  // 1/q = (qr - j qi) / |q|^2
    const double ri = -qi * inv;
    re0[k] = 2.0 * (-a * rr - w[k] * ri);
    im0[k] = 2.0 * (-a * ri + w[k] * rr);
    re1[k] = -2.0 * b * rr;
    im1[k] = -2.0 * b * ri;
  }
  return 2;
}

// Rows of a least-squares column: out[k] = w[k] re[k], out[cnt + k] = w[k] im[k].
PB_CLONES void scaled_rows(Index cnt, const double* w, const double* re, const double* im, double* out) {
  for (Index k = 0; k < cnt; ++k) {
    out[k] = w[k] * re[k];
    out[cnt + k] = w[k] * im[k];
  }
}

// Rows of the complex product (re + j im)(pr + j pi): real parts in out[0..cnt), imaginary parts
// in out[cnt..2 cnt); in real arithmetic (no NaN check per product, see above).
PB_CLONES void product_rows(Index cnt, const double* re, const double* im, const double* pr, const double* pi,
                            double* out) {
  for (Index k = 0; k < cnt; ++k) {
    out[k] = re[k] * pr[k] - im[k] * pi[k];
    out[cnt + k] = re[k] * pi[k] + im[k] * pr[k];
  }
}

// The whole basis (points x poles), column by column.
void fill_basis(const Vector& w, const CVector& poles, Eigen::Ref<Matrix> re, Eigen::Ref<Matrix> im) {
  for (Index i = 0; i < poles.size();) {
    const Index next = std::min(i + 1, poles.size() - 1);
    i += basis_columns(w.data(), w.size(), poles(i), re.col(i).data(), im.col(i).data(), re.col(next).data(),
                       im.col(next).data());
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
  Vector before_abs(before.size());
  for (Index j = 0; j < before.size(); ++j) {
    before_abs(j) = std::max(std::abs(before(j)), std::numeric_limits<double>::min());
  }
  const auto rel = [&](Index i, Index j) { return std::abs(now(i) - before(j)) / before_abs(j); };
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

Matrix base_weights(const CMatrix& data, const Matrix& user, Weighting weighting) {
  if (user.size() > 0) return user;
  if (weighting == Weighting::kUnit) return Matrix::Ones(data.rows(), 1);
  if (weighting == Weighting::kInverseStd) {
    throw InputError(kSource, "weighting", "inverse-std with the data's standard deviations (an FRF with std_H, or explicit weights)",
                     "none given");
  }
  Matrix w(data.rows(), data.cols());
  if (weighting == Weighting::kOutputScale) {
    // 1 / rms |f_i|: outputs in different units (m/V and V/V) count alike.
    for (Index i = 0; i < data.cols(); ++i) {
      const double rms = std::sqrt(data.col(i).squaredNorm() / static_cast<double>(data.rows()));
      w.col(i).setConstant(rms > 0.0 ? 1.0 / rms : 1.0);
    }
    return w;
  }
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
                       format_number(omega(k)));
    }
    if (k > 0 && omega(k) <= omega(k - 1)) {
      throw InputError(kSource, "omega[" + std::to_string(k) + "]", "strictly increasing frequencies",
                       format_number(omega(k)) + " after " + format_number(omega(k - 1)));
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
  if (data.cwiseAbs2().maxCoeff() == 0.0) throw InputError(kSource, "data", "a nonzero response", "all zeros");
  if (o.point_weights.size() > 0 && o.point_weights.size() != ns) {
    throw InputError(kSource, "point_weights", std::to_string(ns) + " values (one per frequency)",
                     std::to_string(o.point_weights.size()));
  }
  if (weights.size() > 0) {
    if (weights.rows() != ns || (weights.cols() != 1 && weights.cols() != data.cols())) {
      throw InputError(kSource, "weights",
                       std::to_string(ns) + "x1 or " + std::to_string(ns) + "x" + std::to_string(data.cols()),
                       std::to_string(weights.rows()) + "x" + std::to_string(weights.cols()));
    }
    for (Index i = 0; i < weights.size(); ++i) {
      const double w = weights.data()[i];
      if (!std::isfinite(w) || w <= 0.0) throw InputError(kSource, "weights", "finite values > 0", format_number(w));
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

// ---- Householder triangularization of tall blocks --------------------------------------------
//
// The pole relocation spends most of its time in the QR of tall matrices (2 rows per frequency,
// 2N + 2 columns). Eigen's HouseholderQR treats a matrix of fewer than 48 columns as one panel and
// applies each reflector separately (a matrix-vector product and a rank-1 update per reflector).
// The kernel below applies the reflectors in panels of P = 4 (compact WY form, Q = I - V T V^T):
// two passes over the trailing columns per panel instead of two per reflector, G trailing columns
// per pass (each load of V serves all G: G = 4 with AVX-512's 32 vector registers, 2 otherwise;
// panels of 8 measured slower: their reflector-by-reflector part grows), with the sums over rows
// in W-wide vectors (GCC/Clang vector extensions; the compiler does not vectorize floating-point
// sums by itself). It is compiled three times, for W = 2 (SSE2 on x86-64, NEON on ARM), W = 4
// (AVX2 with FMA) and W = 8 (AVX-512), and the widest the processor has is chosen once at run time
// (the build itself stays generic x86-64). It is the same Householder QR (beta = -sign(x) ||x||, as Eigen's), so R agrees
// with Eigen's to round-off; the variants differ from one another by round-off only (FMA).
// docs/performance.md ("ident") has the figures.

#define PB_KERNEL [[gnu::always_inline]] inline

template <int W>
struct Lanes {
  typedef double Vec __attribute__((vector_size(8 * W), aligned(8), may_alias));
};

// sum_i x[i] y[i]
template <int W>
PB_KERNEL double dot(const double* x, const double* y, Index n) {
  using V = typename Lanes<W>::Vec;
  // Four independent sums: one would wait on the latency of each addition.
  V acc0 = {}, acc1 = {}, acc2 = {}, acc3 = {};
  Index i = 0;
  for (; i + 4 * W <= n; i += 4 * W) {
    acc0 += *reinterpret_cast<const V*>(x + i) * *reinterpret_cast<const V*>(y + i);
    acc1 += *reinterpret_cast<const V*>(x + i + W) * *reinterpret_cast<const V*>(y + i + W);
    acc2 += *reinterpret_cast<const V*>(x + i + 2 * W) * *reinterpret_cast<const V*>(y + i + 2 * W);
    acc3 += *reinterpret_cast<const V*>(x + i + 3 * W) * *reinterpret_cast<const V*>(y + i + 3 * W);
  }
  for (; i + W <= n; i += W) acc0 += *reinterpret_cast<const V*>(x + i) * *reinterpret_cast<const V*>(y + i);
  acc0 += acc1;
  acc2 += acc3;
  acc0 += acc2;
  double sum = 0.0;
  for (int l = 0; l < W; ++l) sum += acc0[l];
  for (; i < n; ++i) sum += x[i] * y[i];
  return sum;
}

// Where a panel's reflectors live: reflector q (q < nb) is 1 at row k0 + q, vcol[q][i] in rows
// k0 + q + 1 .. bulk - 1 (V's lower triangle) and in the dense rows `dense` .. rows - 1; rows
// bulk .. dense - 1 are zero in every reflector (the zero part of the triangle carried on top of
// a TSQR block) and are skipped. Unused columns (q >= nb) repeat the last with a zero row of T.
template <int P>
struct Panel {
  const double* vcol[P];
  double t[P][P];  // T of Q = I - V T V^T (upper triangular)
  int nb;
  Index k0, bulk, dense, rows;
};

// The block reflector applied to G consecutive trailing columns c[0..G): c -= V (T^T (V^T c)).
template <int W, int P, int G>
PB_KERNEL void apply_panel(const Panel<P>& pn, double* const* c) {
  using V = typename Lanes<W>::Vec;
  // Local copies: the stores into c (may_alias vectors) could otherwise alias pn and force reloads.
  const double* vcol[P];
  for (int q = 0; q < P; ++q) vcol[q] = pn.vcol[q];
  const Index dense = pn.dense, dlen = pn.rows - dense;
  double w[G][P] = {};
  for (int g = 0; g < G; ++g) {
    for (int q = 0; q < pn.nb; ++q) {
      double d = c[g][pn.k0 + q];
      for (Index i = pn.k0 + q + 1; i < pn.bulk; ++i) d += vcol[q][i] * c[g][i];
      w[g][q] = d;
    }
  }
  {
    V acc[G][P];
    for (int g = 0; g < G; ++g) {
      for (int q = 0; q < P; ++q) acc[g][q] = V{};
    }
    Index i = 0;
    for (; i + W <= dlen; i += W) {
      V v[P];
      for (int q = 0; q < P; ++q) v[q] = *reinterpret_cast<const V*>(vcol[q] + dense + i);
      for (int g = 0; g < G; ++g) {
        const V x = *reinterpret_cast<const V*>(c[g] + dense + i);
        for (int q = 0; q < P; ++q) acc[g][q] += v[q] * x;
      }
    }
    for (int g = 0; g < G; ++g) {
      double sum[P];
      for (int q = 0; q < P; ++q) {
        sum[q] = 0.0;
        for (int l = 0; l < W; ++l) sum[q] += acc[g][q][l];
      }
      for (Index r = i; r < dlen; ++r) {
        for (int q = 0; q < P; ++q) sum[q] += vcol[q][dense + r] * c[g][dense + r];
      }
      for (int q = 0; q < pn.nb; ++q) w[g][q] += sum[q];
    }
  }
  double tw[G][P] = {};
  for (int g = 0; g < G; ++g) {
    for (int q = 0; q < pn.nb; ++q) {
      for (int p = 0; p <= q; ++p) tw[g][q] += pn.t[p][q] * w[g][p];
    }
    for (int q = 0; q < pn.nb; ++q) {
      c[g][pn.k0 + q] -= tw[g][q];
      for (Index i = pn.k0 + q + 1; i < pn.bulk; ++i) c[g][i] -= vcol[q][i] * tw[g][q];
    }
  }
  Index i = 0;
  for (; i + W <= dlen; i += W) {
    V v[P];
    for (int q = 0; q < P; ++q) v[q] = *reinterpret_cast<const V*>(vcol[q] + dense + i);
    for (int g = 0; g < G; ++g) {
      V u = v[0] * tw[g][0];
      for (int q = 1; q < P; ++q) u += v[q] * tw[g][q];
      *reinterpret_cast<V*>(c[g] + dense + i) -= u;
    }
  }
  for (; i < dlen; ++i) {
    for (int g = 0; g < G; ++g) {
      double u = 0.0;
      for (int q = 0; q < P; ++q) u += tw[g][q] * vcol[q][dense + i];
      c[g][dense + i] -= u;
    }
  }
}

// The panel's reflectors, one by one on the panel's own columns (reflector k is I - tau v v^T
// with v = 1 at row k and v[i] = a(i, k) below it, zero in the rows above `top`); returns the taus.
template <int W, int P>
PB_KERNEL void factor_panel(double* a, Index rows, Index ld, Index top, Index k0, int nb, double* tau) {
  for (int q = 0; q < nb; ++q) {
    const Index k = k0 + q;
    double* col = a + k * ld;
    const Index first = std::max(k + 1, top);  // rows k + 1 .. top - 1 are zero in column k
    double* v = col + first;
    const Index len = rows - first;
    tau[q] = 0.0;
    const double sigma = dot<W>(v, v, len);
    if (sigma == 0.0) continue;  // already triangular in this column: tau = 0
    const double x = col[k];
    const double norm = std::sqrt(x * x + sigma);
    const double beta = x >= 0.0 ? -norm : norm;
    const double inv = 1.0 / (x - beta);
    tau[q] = (beta - x) / beta;
    col[k] = beta;
    for (Index i = 0; i < len; ++i) v[i] *= inv;
    for (Index j = k + 1; j < k0 + nb; ++j) {
      double* c = a + j * ld;
      const double d = tau[q] * (c[k] + dot<W>(v, c + first, len));
      c[k] -= d;
      for (Index i = 0; i < len; ++i) c[first + i] -= d * v[i];
    }
  }
}

// A full panel (P reflectors) in one pass over its columns per reflector: the pass that scales
// reflector q and applies it to the panel's later columns also sums what reflector q + 1 needs (the
// squared norm of the next column below its diagonal and its products with the columns after it:
// v^T c = u^T c / (x - beta) for the unscaled u) and the products of reflector q with the earlier
// ones (for T). The same reflectors as factor_panel (to round-off), with about half the passes.
template <int P>
struct FusedPanel {
  double* col[P];
  Index rows, top, k0;
  double sig;      // squared norm of the current column below its diagonal
  double g[P];     // its products with the later columns (same rows)
  double tau[P];
  double vv[P][P];  // vv[p][q] = v_p^T v_q, p < q
};

template <int W>
PB_KERNEL double hsum(const typename Lanes<W>::Vec& v) {
  double s = 0.0;
  for (int l = 0; l < W; ++l) s += v[l];
  return s;
}

template <int W, int P, int Q>
PB_KERNEL void fused_step(FusedPanel<P>& s) {
  using V = typename Lanes<W>::Vec;
  double* col[P];
  for (int q = 0; q < P; ++q) col[q] = s.col[q];
  const Index rows = s.rows;
  const Index k = s.k0 + Q;
  const Index first = std::max(k + 1, s.top);
  double inv = 1.0;
  double d[P] = {};
  s.tau[Q] = 0.0;
  if (s.sig != 0.0) {  // else the column is already triangular (tau = 0, v = 0 below the diagonal)
    const double x = col[Q][k];
    const double norm = std::sqrt(x * x + s.sig);
    const double beta = x >= 0.0 ? -norm : norm;
    inv = 1.0 / (x - beta);
    s.tau[Q] = (beta - x) / beta;
    col[Q][k] = beta;
    for (int j = Q + 1; j < P; ++j) {
      d[j] = s.tau[Q] * (col[j][k] + inv * s.g[j]);
      col[j][k] -= d[j];
    }
  }
  double vs[P] = {};   // v_p^T v_Q, scalar part
  double ss = 0.0;     // next column's squared norm, scalar part
  double gs[P] = {};   // next column's products, scalar part
  Index i = first;
  // Row k + 1 is the next column's diagonal: updated, but not in its sums.
  if (s.top <= k + 1 && i < rows) {
    const double v = col[Q][i] * inv;
    col[Q][i] = v;
    for (int p = 0; p < Q; ++p) vs[p] += col[p][i] * v;
    for (int j = Q + 1; j < P; ++j) col[j][i] -= d[j] * v;
    ++i;
  }
  V vacc[P > 1 ? P - 1 : 1] = {};
  V sacc = {};
  V gacc[P] = {};
  for (; i + W <= rows; i += W) {
    const V v = *reinterpret_cast<const V*>(col[Q] + i) * inv;
    *reinterpret_cast<V*>(col[Q] + i) = v;
    for (int p = 0; p < Q; ++p) vacc[p] += *reinterpret_cast<const V*>(col[p] + i) * v;
    if constexpr (Q + 1 < P) {
      const V c1 = *reinterpret_cast<const V*>(col[Q + 1] + i) - d[Q + 1] * v;
      *reinterpret_cast<V*>(col[Q + 1] + i) = c1;
      sacc += c1 * c1;
      for (int j = Q + 2; j < P; ++j) {
        const V cj = *reinterpret_cast<const V*>(col[j] + i) - d[j] * v;
        *reinterpret_cast<V*>(col[j] + i) = cj;
        gacc[j] += c1 * cj;
      }
    }
  }
  for (; i < rows; ++i) {
    const double v = col[Q][i] * inv;
    col[Q][i] = v;
    for (int p = 0; p < Q; ++p) vs[p] += col[p][i] * v;
    if constexpr (Q + 1 < P) {
      const double c1 = col[Q + 1][i] - d[Q + 1] * v;
      col[Q + 1][i] = c1;
      ss += c1 * c1;
      for (int j = Q + 2; j < P; ++j) {
        const double cj = col[j][i] - d[j] * v;
        col[j][i] = cj;
        gs[j] += c1 * cj;
      }
    }
  }
  for (int p = 0; p < Q; ++p) s.vv[p][Q] = col[p][k] + (hsum<W>(vacc[p]) + vs[p]);
  if constexpr (Q + 1 < P) {
    s.sig = hsum<W>(sacc) + ss;
    for (int j = Q + 2; j < P; ++j) s.g[j] = hsum<W>(gacc[j]) + gs[j];
    fused_step<W, P, Q + 1>(s);
  }
}

// factor_panel and panel_t for a full panel (nb = P), fused.
template <int W, int P>
PB_KERNEL void factor_panel_fused(double* a, Index rows, Index ld, Index top, Panel<P>& pn, double* tau) {
  using V = typename Lanes<W>::Vec;
  FusedPanel<P> s;
  for (int q = 0; q < P; ++q) s.col[q] = a + (pn.k0 + q) * ld;
  s.rows = rows;
  s.top = top;
  s.k0 = pn.k0;
  {
    // The first column's sums.
    const Index first = std::max(pn.k0 + 1, top);
    V sacc = {};
    V gacc[P] = {};
    Index i = first;
    for (; i + W <= rows; i += W) {
      const V c0 = *reinterpret_cast<const V*>(s.col[0] + i);
      sacc += c0 * c0;
      for (int j = 1; j < P; ++j) gacc[j] += c0 * *reinterpret_cast<const V*>(s.col[j] + i);
    }
    double ss = 0.0, gs[P] = {};
    for (; i < rows; ++i) {
      ss += s.col[0][i] * s.col[0][i];
      for (int j = 1; j < P; ++j) gs[j] += s.col[0][i] * s.col[j][i];
    }
    s.sig = hsum<W>(sacc) + ss;
    for (int j = 1; j < P; ++j) s.g[j] = hsum<W>(gacc[j]) + gs[j];
  }
  fused_step<W, P, 0>(s);
  for (int p = 0; p < P; ++p) {
    tau[p] = s.tau[p];
    for (int q = 0; q < P; ++q) pn.t[p][q] = 0.0;
  }
  for (int q = 0; q < P; ++q) {
    pn.t[q][q] = tau[q];
    for (int p = 0; p < q; ++p) {
      double sum = 0.0;
      for (int r = p; r < q; ++r) sum += pn.t[p][r] * s.vv[r][q];
      pn.t[p][q] = -tau[q] * sum;
    }
  }
}

// T (upper triangular): T(q,q) = tau_q, T(0:q,q) = -tau_q T(0:q,0:q) V(:,0:q)^T V(:,q).
template <int W, int P>
PB_KERNEL void panel_t(Panel<P>& pn, const double* tau) {
  const Index dlen = pn.rows - pn.dense;
  for (int p = 0; p < P; ++p) {
    for (int q = 0; q < P; ++q) pn.t[p][q] = 0.0;
  }
  for (int q = 0; q < pn.nb; ++q) {
    pn.t[q][q] = tau[q];
    double vv[P] = {};
    for (int p = 0; p < q; ++p) {
      double d = pn.vcol[p][pn.k0 + q];
      for (Index i = pn.k0 + q + 1; i < pn.bulk; ++i) d += pn.vcol[p][i] * pn.vcol[q][i];
      vv[p] = d + dot<W>(pn.vcol[p] + pn.dense, pn.vcol[q] + pn.dense, dlen);
    }
    for (int p = 0; p < q; ++p) {
      double sum = 0.0;
      for (int r = p; r < q; ++r) sum += pn.t[p][r] * vv[r];
      pn.t[p][q] = -tau[q] * sum;
    }
  }
}

// In place on the column-major rows x cols matrix `a` (leading dimension ld): the first
// min(rows, steps) Householder reflectors, each applied to all the columns after its own. With
// steps >= cols, the upper triangle (trapezoid if rows < cols) holds R on return. Rows 0 .. top - 1
// must be upper triangular (zero below the diagonal: the triangle carried on top of a TSQR block);
// their zeros are skipped. Below the diagonal, rows top .. rows - 1 hold the reflectors on return;
// the zeros of rows < top stay.
template <int W, int P, int G>
PB_KERNEL void triangularize_lanes(double* a, Index rows, Index cols, Index ld, Index top, Index steps) {
  const Index kmax = std::min({rows, cols, steps});
  for (Index k0 = 0; k0 < kmax; k0 += P) {
    Panel<P> pn;
    pn.nb = static_cast<int>(std::min<Index>(P, kmax - k0));
    pn.k0 = k0;
    pn.bulk = k0 + pn.nb;
    pn.dense = std::max(pn.bulk, top);
    pn.rows = rows;
    double tau[P];
    for (int q = 0; q < P; ++q) pn.vcol[q] = a + (k0 + std::min(q, pn.nb - 1)) * ld;
    if (pn.nb == P) {
      factor_panel_fused<W, P>(a, rows, ld, top, pn, tau);
      if (pn.bulk >= cols) continue;
    } else {
      factor_panel<W, P>(a, rows, ld, top, k0, pn.nb, tau);
      if (pn.bulk >= cols) continue;
      panel_t<W, P>(pn, tau);
    }
    // Trailing columns, G at a time.
    Index j = pn.bulk;
    if constexpr (G == 4) {
      // 4 k + 2 columns (the usual case: 2 N + 2 columns): the last 6 in one pass rather than
      // 4 then 2 (a pass over 2 columns loads V for half the work).
      if ((cols - j) % 4 == 2 && cols - j >= 6) {
        for (; j + 6 + G <= cols; j += G) {
          double* c[G];
          for (int g = 0; g < G; ++g) c[g] = a + (j + g) * ld;
          apply_panel<W, P, G>(pn, c);
        }
        double* c[6];
        for (int g = 0; g < 6; ++g) c[g] = a + (j + g) * ld;
        apply_panel<W, P, 6>(pn, c);
        j += 6;
      }
    }
    for (; j + G <= cols; j += G) {
      double* c[G];
      for (int g = 0; g < G; ++g) c[g] = a + (j + g) * ld;
      apply_panel<W, P, G>(pn, c);
    }
    if constexpr (G > 2) {
      for (; j + 2 <= cols; j += 2) {
        double* const c[2] = {a + j * ld, a + (j + 1) * ld};
        apply_panel<W, P, 2>(pn, c);
      }
    }
    if (j < cols) {
      double* const c[1] = {a + j * ld};
      apply_panel<W, P, 1>(pn, c);
    }
  }
}

void triangularize_generic(double* a, Index rows, Index cols, Index ld, Index top, Index steps) {
  triangularize_lanes<2, 4, 2>(a, rows, cols, ld, top, steps);
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
[[gnu::target("avx2,fma")]] void triangularize_avx2(double* a, Index rows, Index cols, Index ld, Index top,
                                                    Index steps) {
  triangularize_lanes<4, 4, 2>(a, rows, cols, ld, top, steps);
}
[[gnu::target("avx512f,avx2,fma")]] void triangularize_avx512(double* a, Index rows, Index cols, Index ld,
                                                             Index top, Index steps) {
  triangularize_lanes<8, 4, 4>(a, rows, cols, ld, top, steps);
}
#endif

using TriangularizeFn = void (*)(double*, Index, Index, Index, Index, Index);

// The widest variant this processor runs, chosen once.
TriangularizeFn pick_triangularize() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f")) return triangularize_avx512;
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return triangularize_avx2;
#endif
  return triangularize_generic;
}

void triangularize(double* a, Index rows, Index cols, Index ld, Index top, Index steps) {
  static const TriangularizeFn fn = pick_triangularize();
  fn(a, rows, cols, ld, top, steps);
}

// The triangular factor R of a tall matrix whose rows are supplied in blocks (a sequential TSQR):
// each block is QR-reduced together with the triangle so far, in place. As backward stable as one
// Householder QR of the whole matrix, with a working set that stays in the cache (a 4000 x 43
// matrix does not fit in a 1 MB L2 cache; blocks of 1024 rows do) and without the large buffer.
// Columns holding right-hand sides b end up holding Q^T b.
//
// With steps < cols only the first `steps` columns are reduced (Q^T of their QR is applied to the
// others); the rows each block leaves below the triangle, zero in the reduced columns, are then
// the caller's (residual()) to reduce further, as those of a QR of the whole matrix would be.
class TriangularFactor {
 public:
  // Starts a factorization of `cols` columns (the first `steps` reduced; all by default), rows
  // added in blocks of at most max_block_rows.
  void reset(Index cols, Index max_block_rows, Index steps = -1) {
    cols_ = cols;
    steps_ = steps < 0 ? cols : steps;
    top_ = 0;
    residual_rows_ = 0;
    work_.resize(steps_ + max_block_rows, cols);
  }
  // The next `rows` rows, to fill before add_block().
  Eigen::Block<Matrix> block(Index rows) {
    rows_ = rows;
    return work_.block(top_, 0, rows, cols_);
  }
  void add_block() {
    const Index rows = top_ + rows_;
    triangularize(work_.data(), rows, cols_, work_.outerStride(), top_, steps_);
    top_ = std::min(rows, steps_);
    residual_rows_ = rows - top_;
    // triangularize() skips the zeros below the carried triangle: they must be zeros.
    work_.topRows(top_).triangularView<Eigen::StrictlyLower>().setZero();
  }
  // After add_block(), with steps < cols: the rows below the triangle in the columns after the
  // reduced ones (valid until the next block()).
  Eigen::Block<Matrix> residual() { return work_.block(top_, steps_, residual_rows_, cols_ - steps_); }
  // R, cols x cols (upper triangular; rows beyond the number of rows supplied are zero).
  Eigen::Block<Matrix> r() {
    if (top_ < cols_) work_.middleRows(top_, cols_ - top_).setZero();
    top_ = cols_;
    return work_.topRows(cols_);
  }

 private:
  Matrix work_;
  Index cols_ = 0;
  Index steps_ = 0;
  Index top_ = 0;
  Index rows_ = 0;
  Index residual_rows_ = 0;
};

// Frequencies per row block of the least-squares problems (two real rows each).
constexpr Index kBlockPoints = 512;

// The fitting problem in scaled units: s = j omega / scale.
class Fitter {
 public:
  Fitter(const Vector& omega, const CMatrix& data, const Matrix& weights, const VectorFittingOptions& o,
         double scale)
      : data_(data), weights_(weights), opts_(o), ns_(omega.size()), nc_(data.cols()), n_(o.order),
        offs_(asymptote_terms(o.asymptote)) {
    w_ = omega / scale;
    col_re_.resize(std::min(kBlockPoints, ns_), 2);
    col_im_.resize(std::min(kBlockPoints, ns_), 2);
    ones_.setOnes(std::min(kBlockPoints, ns_));
    zeros_.setZero(std::min(kBlockPoints, ns_));
    // max |H| (|.| of the element of largest |.|^2: one hypot instead of one per point)
    Index kmax = 0, imax = 0;
    data.cwiseAbs2().maxCoeff(&kmax, &imax);
    data_max_ = std::abs(data(kmax, imax));
    double wd = 0.0;
    for (Index i = 0; i < nc_; ++i) {
      const auto w = weights.col(weights.cols() == 1 ? 0 : i);
      for (Index k = 0; k < ns_; ++k) wd += w(k) * w(k) * std::norm(data(k, i));
    }
    weighted_data_norm_ = std::sqrt(wd);
    // Weights common to the outputs: one column, or one constant per output (e.g. "output-scale").
    // A constant factor c on an output's rows scales its sigma block R22 by c and leaves its
    // residues alone, so the latter are treated as common (unit) row weights with the factor on
    // the output's sigma columns (out_scale_): the left block is then shared by the outputs.
    out_scale_.setOnes(nc_);
    common_ = weights.cols() == 1;
    if (common_) {
      common_w_ = weights.col(0);
    } else {
      common_ = true;
      for (Index i = 0; i < nc_ && common_; ++i) {
        common_ = (weights.col(i).array() == weights(0, i)).all();
        out_scale_(i) = weights(0, i);
      }
      if (common_) common_w_.setOnes(ns_);
    }
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
      const Vector fit_re = basis_re().leftCols(cols) * x.col(i);
      const Vector fit_im = basis_im().leftCols(cols) * x.col(i);
      err += (w.cwiseProduct(fit_re - data_.col(i).real())).squaredNorm() +
             (w.cwiseProduct(fit_im - data_.col(i).imag())).squaredNorm();
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
  //
  // The tall problem [A B] (2 rows per frequency) is first reduced to its triangular factor
  // [R_A Q^T B] (TriangularFactor); the column-pivoted QR that solves it then works on the small
  // R_A: the same least-squares solution (||A x - b|| and ||R_A x - (Q^T b)_top|| differ by a
  // constant), for a fraction of the cost of pivoting on the tall matrix.
  //
  // keep_basis: leave the whole basis in basis_ for assess(). Without it (and with weights common
  // to the outputs) the basis is computed per row block and pole, as in reduce_sigma_blocks.
  Matrix identify(const CVector& poles, bool keep_basis) {
    const Index cols = n_ + offs_;
    Matrix x(cols, nc_);
    const bool common = common_;
    const bool whole_basis = keep_basis || !common;
    if (whole_basis) fill_basis(poles);
    const Index passes = common ? 1 : nc_;
    const Index nrhs = common ? nc_ : 1;
    const Index block_points = std::min(kBlockPoints, ns_);
    for (Index pass = 0; pass < passes; ++pass) {
      const Eigen::Ref<const Vector> w = common ? Eigen::Ref<const Vector>(common_w_)
                                                : Eigen::Ref<const Vector>(weights_.col(pass));
      const Index first = common ? 0 : pass;
      tall_.reset(cols + nrhs, 2 * block_points);
      for (Index k0 = 0; k0 < ns_; k0 += block_points) {
        const Index cnt = std::min(block_points, ns_ - k0);
        auto rows = tall_.block(2 * cnt);
        const double* wk = w.data() + k0;
        if (whole_basis) {
          for (Index j = 0; j < cols; ++j) {
            scaled_rows(cnt, wk, basis_re().col(j).data() + k0, basis_im().col(j).data() + k0, rows.col(j).data());
          }
        } else {
          const double* wsc = w_.data() + k0;
          for (Index j = 0; j < n_;) {
            const Index c = basis_columns(wsc, cnt, poles(j), col_re_.col(0).data(), col_im_.col(0).data(),
                                          col_re_.col(1).data(), col_im_.col(1).data());
            for (Index q = 0; q < c; ++q) {
              scaled_rows(cnt, wk, col_re_.col(q).data(), col_im_.col(q).data(), rows.col(j + q).data());
            }
            j += c;
          }
          if (offs_ >= 1) scaled_rows(cnt, wk, ones_.data(), zeros_.data(), rows.col(n_).data());
          if (offs_ >= 2) scaled_rows(cnt, wk, zeros_.data(), wsc, rows.col(n_ + 1).data());
        }
        for (Index i = 0; i < nrhs; ++i) {
          for (Index k = 0; k < cnt; ++k) {
            rows(k, cols + i) = w(k0 + k) * data_(k0 + k, first + i).real();
            rows(cnt + k, cols + i) = w(k0 + k) * data_(k0 + k, first + i).imag();
          }
        }
        tall_.add_block();
      }
      const auto r = tall_.r();
      Matrix a = r.topLeftCorner(cols, cols);
      const Vector colscale = scale_columns(a);
      // Column pivoting: with more poles than the data can resolve, the problem is rank
      // deficient and the basic solution keeps the coefficients finite.
      Eigen::ColPivHouseholderQR<Matrix> qr(a);
      for (Index i = 0; i < nrhs; ++i) {
        x.col(first + i) = colscale.cwiseProduct(qr.solve(r.col(cols + i).head(cols)));
      }
    }
    return x;
  }

 private:
  // Builds each output's least-squares problem [A B b] (A: the partial fractions and asymptotic
  // terms of the output, B: those of sigma times the data; b: the right-hand side of the fixed
  // normalization), reduces it to its triangular factor (reduce_sigma_blocks) and keeps only the
  // sigma block R22 and the matching part of Q^T b (Gustavsen's fast VF); the sigma blocks of all
  // outputs are then stacked and solved. With the relaxed normalization b is zero on every data
  // row: the column is left out, and the normalization row (zero on A) joins the stacked problem
  // directly, which is the same least-squares problem.
  bool solve_sigma(const CVector& poles, bool relaxed, CVector& relocated) {
    const Index nsig = relaxed ? n_ + 1 : n_;
    const Index stacked_rows = nc_ * nsig + (relaxed ? 1 : 0);
    stacked_.resize(stacked_rows, nsig);
    stacked_rhs_.setZero(stacked_rows);

    if (common_) {
      reduce_sigma_blocks(poles, common_w_, 0, nc_, relaxed);
    } else {
      for (Index i = 0; i < nc_; ++i) reduce_sigma_blocks(poles, weights_.col(i), i, 1, relaxed);
    }
    if (relaxed) {
      // Relaxed normalization (Gustavsen 2006, eq. 8): Re sum_k sigma(s_k) = Ns, scaled by the
      // size of the data so that the constraint row weighs like the others.
      const double scale = weighted_data_norm_ / static_cast<double>(ns_);
      for (Index j = 0; j < nsig; ++j) stacked_(nc_ * nsig, j) = scale * basis_sum_(j);
      stacked_rhs_(nc_ * nsig) = static_cast<double>(ns_) * scale;
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

  // The sigma blocks of the outputs first .. first + count - 1, which share the row weights w, into
  // stacked_ (and stacked_rhs_). The left block [A] (partial fractions and asymptotic terms) is the
  // same for all of them: its QR is done once (TriangularFactor with steps = its columns) and its
  // Q^T applied to every output's [B b]; each output's remaining rows are then reduced on their own
  // (own_[i]). R22 is that of the QR of the output's [A B b] up to the signs of its rows, which do
  // not change the stacked least-squares solution; per output this saves the QR of A.
  //
  // The basis is computed per row block and column (basis_columns) and used at once, for the left
  // block and every output's sigma block, instead of being stored whole (it would take L2 cache
  // from the QR); its real parts are summed on the way for the relaxed normalization (basis_sum_).
  void reduce_sigma_blocks(const CVector& poles, const Eigen::Ref<const Vector>& w, Index first, Index count,
                           bool relaxed) {
    const Index left = n_ + offs_;
    const Index nsig = relaxed ? n_ + 1 : n_;
    const Index own_cols = nsig + (relaxed ? 0 : 1);  // B, and b with the fixed normalization
    const Index block_points = std::min(kBlockPoints, ns_);
    // One output: the QR of its whole [A B b] (the same reflectors, without the copies).
    const bool shared = count > 1;
    tall_.reset(left + count * own_cols, 2 * block_points, shared ? left : -1);
    if (static_cast<Index>(own_.size()) < count) own_.resize(static_cast<size_t>(count));
    for (Index i = 0; i < count; ++i) own_[static_cast<size_t>(i)].reset(own_cols, 2 * block_points);
    basis_sum_.setZero(n_ + 2);
    wd_re_.resize(block_points, count);
    wd_im_.resize(block_points, count);
    for (Index k0 = 0; k0 < ns_; k0 += block_points) {
      const Index cnt = std::min(block_points, ns_ - k0);
      auto rows = tall_.block(2 * cnt);
      const double* wk = w.data() + k0;
      for (Index i = 0; i < count; ++i) {
        double* wdr = wd_re_.col(i).data();
        double* wdi = wd_im_.col(i).data();
        const double scale = common_ ? out_scale_(first + i) : 1.0;  // the output's constant weight
        for (Index k = 0; k < cnt; ++k) {
          const Complex h = data_(k0 + k, first + i);
          wdr[k] = -wk[k] * scale * h.real();
          wdi[k] = -wk[k] * scale * h.imag();
        }
        if (!relaxed) {
          // Fixed normalization: sigma's constant is 1, so its term moves to the right-hand side.
          const Index c = left + i * own_cols + nsig;
          for (Index k = 0; k < cnt; ++k) {
            rows(k, c) = -wdr[k];
            rows(cnt + k, c) = -wdi[k];
          }
        }
      }
      // Column j of the basis: the left block's column j and, for j < nsig, each output's sigma column j.
      const auto put = [&](Index j, const double* bre, const double* bim) {
        if (j < left) scaled_rows(cnt, wk, bre, bim, rows.col(j).data());
        if (j >= nsig) return;
        basis_sum_(j) += Eigen::Map<const Vector>(bre, cnt).sum();  // vectorized (a plain loop sums in order)
        for (Index i = 0; i < count; ++i) {
          const double* wdr = wd_re_.col(i).data();
          const double* wdi = wd_im_.col(i).data();
          product_rows(cnt, bre, bim, wdr, wdi, rows.col(left + i * own_cols + j).data());
        }
      };
      const double* wsc = w_.data() + k0;
      for (Index j = 0; j < n_;) {
        const Index c = basis_columns(wsc, cnt, poles(j), col_re_.col(0).data(), col_im_.col(0).data(),
                                      col_re_.col(1).data(), col_im_.col(1).data());
        for (Index q = 0; q < c; ++q) put(j + q, col_re_.col(q).data(), col_im_.col(q).data());
        j += c;
      }
      // sigma's constant and d (1), then e (s).
      put(n_, ones_.data(), zeros_.data());
      if (n_ + 1 < std::max(left, nsig)) put(n_ + 1, zeros_.data(), wsc);
      tall_.add_block();
      const auto residual = tall_.residual();
      if (!shared || residual.rows() == 0) continue;
      for (Index i = 0; i < count; ++i) {
        TriangularFactor& own = own_[static_cast<size_t>(i)];
        own.block(residual.rows()) = residual.middleCols(i * own_cols, own_cols);
        own.add_block();
      }
    }
    if (!shared) {
      const auto r = tall_.r();
      stacked_.middleRows(first * nsig, nsig) = r.block(left, left, nsig, nsig);
      if (!relaxed) stacked_rhs_.segment(first * nsig, nsig) = r.col(left + nsig).segment(left, nsig);
      return;
    }
    for (Index i = 0; i < count; ++i) {
      const auto r = own_[static_cast<size_t>(i)].r();
      stacked_.middleRows((first + i) * nsig, nsig) = r.topLeftCorner(nsig, nsig);
      if (!relaxed) stacked_rhs_.segment((first + i) * nsig, nsig) = r.col(nsig).head(nsig);
    }
  }

  const CMatrix& data_;
  const Matrix& weights_;
  bool common_ = true;  // the same row weights (common_w_) for all outputs, up to out_scale_
  Vector common_w_;
  Vector out_scale_;
  const VectorFittingOptions& opts_;
  Index ns_, nc_, n_, offs_;
  Vector w_;  // omega / scale
  // The basis at the scaled frequencies for the current poles (fill_basis), then sigma's constant
  // (1) and s: real and imaginary parts.
  // (1) and s: real parts in the left half of basis_, imaginary parts in the right half (one
  // allocation: two of this size per call cost page faults).
  void fill_basis(const CVector& poles) {
    basis_.resize(ns_, 2 * (n_ + 2));  // allocated at the first use only
    ident::fill_basis(w_, poles, basis_re(), basis_im());
    basis_re().col(n_).setOnes();
    basis_im().col(n_).setZero();
    basis_re().col(n_ + 1).setZero();
    basis_im().col(n_ + 1) = w_;
  }
  Eigen::Block<Matrix, Eigen::Dynamic, Eigen::Dynamic, true> basis_re() { return basis_.leftCols(n_ + 2); }
  Eigen::Block<Matrix, Eigen::Dynamic, Eigen::Dynamic, true> basis_im() { return basis_.rightCols(n_ + 2); }
  Eigen::Block<const Matrix, Eigen::Dynamic, Eigen::Dynamic, true> basis_re() const { return basis_.leftCols(n_ + 2); }
  Eigen::Block<const Matrix, Eigen::Dynamic, Eigen::Dynamic, true> basis_im() const { return basis_.rightCols(n_ + 2); }

  Matrix basis_;
  Matrix wd_re_, wd_im_;  // -w H of each output over one row block
  Matrix col_re_, col_im_;  // one pole's basis columns over one row block
  Vector ones_, zeros_;
  Vector basis_sum_;  // sum of each basis column's real part over the points
  TriangularFactor tall_;
  std::vector<TriangularFactor> own_;  // per output: the rows of [B b] left by the QR of A
  Matrix stacked_;
  Vector stacked_rhs_;
  double data_max_ = 1.0;
  double weighted_data_norm_ = 1.0;
};

}  // namespace

Matrix vector_fitting_weights(const CMatrix& data, const Matrix& user, const VectorFittingOptions& o) {
  Matrix w = base_weights(data, user, o.weighting);
  if (o.point_weights.size() > 0) w.array().colwise() *= o.point_weights.array();
  return w;
}

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
    case Weighting::kOutputScale: return "output-scale";
    case Weighting::kInverseStd: return "inverse-std";
  }
  return "unit";
}

Weighting weighting_from_string(const std::string& s) {
  if (s == "unit") return Weighting::kUnit;
  if (s == "inverse-magnitude") return Weighting::kInverseMagnitude;
  if (s == "inverse-sqrt-magnitude") return Weighting::kInverseSqrtMagnitude;
  if (s == "output-scale") return Weighting::kOutputScale;
  if (s == "inverse-std") return Weighting::kInverseStd;
  throw InputError("", "weighting", "one of unit, output-scale, inverse-magnitude, inverse-sqrt-magnitude, inverse-std", "'" + s + "'");
}

void VectorFittingOptions::validate() const {
  if (order < 1) throw InputError(kOptionsSource, "order", "at least 1 pole", std::to_string(order));
  if (max_iterations < 0) {
    throw InputError(kOptionsSource, "max_iterations", ">= 0", std::to_string(max_iterations));
  }
  if (!std::isfinite(pole_tolerance) || pole_tolerance < 0.0) {
    throw InputError(kOptionsSource, "pole_tolerance", "finite value >= 0", format_number(pole_tolerance));
  }
  if (!std::isfinite(residual_tolerance) || residual_tolerance < 0.0) {
    throw InputError(kOptionsSource, "residual_tolerance", "finite value >= 0 (0 = off)", format_number(residual_tolerance));
  }
  if (!std::isfinite(significance_floor) || significance_floor < 0.0 || significance_floor >= 1.0) {
    throw InputError(kOptionsSource, "significance_floor", "value in [0, 1)", format_number(significance_floor));
  }
  if (!std::isfinite(starting_damping) || starting_damping <= 0.0 || starting_damping >= 1.0) {
    throw InputError(kOptionsSource, "starting_damping", "value in (0, 1)", format_number(starting_damping));
  }
  if (!std::isfinite(frequency_scale) || frequency_scale < 0.0) {
    throw InputError(kOptionsSource, "frequency_scale", "finite value >= 0 rad/s (0 = automatic)",
                     format_number(frequency_scale));
  }
  for (Index k = 0; k < point_weights.size(); ++k) {
    if (!std::isfinite(point_weights(k)) || point_weights(k) <= 0.0) {
      throw InputError(kOptionsSource, "point_weights[" + std::to_string(k) + "]", "finite value > 0",
                       format_number(point_weights(k)));
    }
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

namespace {

// The model d + s e + sum_n r_n / (s - p_n) of every output at the points s (one row per point),
// frequencies innermost (their loops vectorize; compiled for AVX-512 and AVX2 too, PB_CLONES).
// r / z as r conj(z) / |z|^2 (no overflow concern at frequencies where the model is used; one
// reciprocal per term), the product in real arithmetic (GCC's complex product checks each result
// for NaN).
PB_CLONES CMatrix model_at(const VectorFittingResult& m, const CVector& s) {
  const Index ns = s.size();
  CMatrix out(ns, m.outputs());
  for (Index i = 0; i < m.outputs(); ++i) {
    Complex* o = out.col(i).data();
    for (Index k = 0; k < ns; ++k) o[k] = m.d(i) + s(k) * m.e(i);
  }
  for (Index n = 0; n < m.poles.size(); ++n) {
    const double pr = m.poles(n).real(), pi = m.poles(n).imag();
    for (Index i = 0; i < m.outputs(); ++i) {
      const double rr = m.residues(i, n).real(), ri = m.residues(i, n).imag();
      Complex* o = out.col(i).data();
      for (Index k = 0; k < ns; ++k) {
        const double zr0 = s(k).real() - pr, zi0 = s(k).imag() - pi;
        const double inv = 1.0 / (zr0 * zr0 + zi0 * zi0);
        const double zr = zr0 * inv, zi = -zi0 * inv;
        o[k] += Complex(rr * zr - ri * zi, rr * zi + ri * zr);
      }
    }
  }
  return out;
}

}  // namespace

CVector VectorFittingResult::evaluate_at(Complex s) const {
  return model_at(*this, CVector::Constant(1, s)).row(0).transpose();
}

CMatrix VectorFittingResult::evaluate(const Vector& omega) const {
  return model_at(*this, omega.cast<Complex>() * kJ);
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

namespace {

// The starting poles (the options' or automatic ones), user pairs snapped to exact conjugates
// (validate() accepted them within 1e-9), each pair upper then lower.
CVector snapped_starting_poles(const Vector& omega, const VectorFittingOptions& options) {
  CVector start = options.starting_poles.size() > 0 ? options.starting_poles
                                                     : automatic_starting_poles(omega, options);
  for (Index i = 0; i < start.size(); ++i) {
    if (std::abs(start(i).imag()) <= 1e-15 * std::abs(start(i))) start(i) = Complex(start(i).real(), 0.0);
  }
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
  return snapped;
}

// The pole relocations until they settle (or the iterations run out). Each relocation is first
// judged on all poles (cheap). When that has not settled, the residues for the new poles are
// identified (one linear least-squares problem) so that poles the data do not determine can be
// left out, and the fit error can be compared with the previous one. Returns the residues'
// solution for the final poles when the last step identified it (empty otherwise).
std::optional<Matrix> relocate_until_settled(Fitter& fitter, const VectorFittingOptions& options, CVector& poles,
                                             VectorFittingResult& result) {
  const bool assess_each = options.significance_floor > 0.0 || options.residual_tolerance > 0.0;
  double previous_error = -1.0;
  std::optional<Matrix> x;
  Vector significance;
  for (int it = 0; it < options.max_iterations; ++it) {
    const CVector relocated = fitter.relocate(poles);
    const double raw_change = pole_change(relocated, poles, Vector(), 0.0);
    const CVector before = poles;
    poles = relocated;
    result.iterations = it + 1;
    result.last_pole_change = raw_change;
    x.reset();
    if (raw_change < options.pole_tolerance) {
      result.converged = true;
      result.convergence = Convergence::kPolesSettled;
      break;
    }
    if (!assess_each) continue;
    x = fitter.identify(poles, /*keep_basis=*/true);
    const double error = fitter.assess(poles, *x, significance);
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
  return x;
}

// Poles (scaled back), residues and the asymptote terms d, e from the solution x of the scaled
// problem (a complex pair's residue as its real and imaginary part in two rows).
void unpack_solution(const Matrix& x, const CVector& poles, double scale, const VectorFittingOptions& options, Index nc,
                     VectorFittingResult& result) {
  const Index n = options.order;
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
}

// Real state space of the proper part.
void realize(VectorFittingResult& result) {
  const Index nc = result.residues.rows();
  const Index n = result.residues.cols();
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
}

// The errors, then every output's own relative error (a small output is not hidden by a large
// one); returns whether an output's error is too large (too few poles for its modes).
bool fit_errors(const Vector& omega, const CMatrix& data, VectorFittingResult& result) {
  const CMatrix fit = result.evaluate(omega);
  const double count = static_cast<double>(data.size());
  result.rms_error = std::sqrt((fit - data).squaredNorm() / count);
  result.relative_rms_error = result.rms_error / std::sqrt(data.squaredNorm() / count);
  result.relative_rms_error_per_output.resize(data.cols());
  bool misses = false;
  for (Index i = 0; i < data.cols(); ++i) {
    const double e = std::sqrt((fit.col(i) - data.col(i)).squaredNorm() / data.col(i).squaredNorm());
    result.relative_rms_error_per_output(i) = e;
    result.quality.check_error("output " + std::to_string(i + 1), e);
    misses = misses || !(e <= core::kPoorRelativeError);
  }
  return misses;
}

// Poles that fit noise: a resonance far outside the band of the data, or unstable. Returns
// whether there is one.
bool spurious_poles(const Vector& omega, VectorFittingResult& result) {
  bool spurious = false;
  const double w_lo = omega.minCoeff() > 0.0 ? omega.minCoeff() : (omega.size() > 1 ? omega(1) : omega(0));
  const double w_hi = omega.maxCoeff();
  for (Index k = 0; k < result.poles.size(); ++k) {
    const Complex p = result.poles(k);
    if (p.imag() <= 0.0) continue;  // real poles shape the slope; a resonance needs data around it
    const double w = std::abs(p);
    if (w > 2.0 * w_hi || w < 0.5 * w_lo) {
      std::ostringstream text;
      text << "pole at " << w / kTwoPi << " Hz outside the fitted band " << w_lo / kTwoPi
           << " to " << w_hi / kTwoPi << " Hz";
      result.quality.add_problem(text.str());
      spurious = true;
    }
    if (p.real() > 0.0) {
      result.quality.add_problem("unstable pole (Re > 0) at " + format_number(w / kTwoPi) + " Hz");
      spurious = true;
    }
  }
  return spurious;
}

// The quality verdict. The advice points the way the problems do: a large error with every pole
// in the band means modes the order cannot hold; poles outside the band or unstable fit noise.
void assess_quality(const Vector& omega, const CMatrix& data, Index n, VectorFittingResult& result) {
  const bool misses = fit_errors(omega, data, result);
  const bool spurious = spurious_poles(omega, result);
  if (!result.converged) result.quality.add_problem("the poles did not settle (not converged)");
  const std::string order = std::to_string(n);
  if (misses && !spurious) {
    result.quality.advise("a higher order than " + order + " (--order " + std::to_string(n + 4) +
                          ": the fit misses modes), or a band where the coherence is high (--fmin/--fmax)");
  } else if (spurious && !misses) {
    result.quality.advise("a lower order than " + order + " (the extra poles fit noise), a band where the coherence is high "
                          "(--fmin/--fmax), or --weighting output-scale");
  } else {
    result.quality.advise("a band where the coherence is high (--fmin/--fmax), another order than " + order +
                          ", or --weighting output-scale");
  }
}

}  // namespace

VectorFittingResult vector_fit(const Vector& omega, const CMatrix& data, const Matrix& user_weights,
                               const VectorFittingOptions& options) {
  options.validate();
  check_input(omega, data, user_weights, options);
  const Matrix weights = vector_fitting_weights(data, user_weights, options);
  const double scale = options.frequency_scale > 0.0 ? options.frequency_scale : omega(omega.size() - 1);
  CVector poles = canonical_poles(snapped_starting_poles(omega, options) / scale);

  Fitter fitter(omega, data, weights, options, scale);
  VectorFittingResult result;
  result.frequency_scale = scale;
  std::optional<Matrix> x = relocate_until_settled(fitter, options, poles, result);
  if (!result.converged && options.max_iterations > 0 && options.fail_if_not_converged) {
    throw NumericalError(kSource,
                         "poles did not settle after " + std::to_string(result.iterations) +
                             " relocations (last relative change " + format_number(result.last_pole_change) +
                             ", tolerance " + format_number(options.pole_tolerance) +
                             "); try another order, more iterations, weights or a looser tolerance",
                         /*retry_may_help=*/true);
  }
  if (!x) x = fitter.identify(poles, /*keep_basis=*/false);
  unpack_solution(*x, poles, scale, options, data.cols(), result);
  realize(result);
  assess_quality(omega, data, options.order, result);
  return result;
}

Matrix frf_row_weights(const dsp::Frf& frf, const VectorFittingOptions& options) {
  if (options.weighting != Weighting::kInverseStd) return {};
  const Index ns = frf.freq_Hz.size();
  const std::string source = frf.provenance.source.empty() ? std::string(kSource) : frf.provenance.source;
  Matrix w(ns, static_cast<Index>(frf.H.size()));
  for (std::size_t i = 0; i < frf.H.size(); ++i) {
    const std::string field = "std_H of " + (i < frf.outputs.size() ? frf.outputs[i] : "output " + std::to_string(i + 1));
    if (i >= frf.std_H.size() || frf.std_H[i].size() != ns) {
      throw InputError(source, field, std::to_string(ns) + " standard deviations (weighting inverse-std)", "none");
    }
    for (Index k = 0; k < ns; ++k) {
      const double sd = frf.std_H[i](k);
      if (!(std::isfinite(sd) && sd > 0.0)) {
        throw InputError(source, field + "[" + std::to_string(k) + "]", "finite and > 0 (weighting inverse-std)", format_number(sd));
      }
      w(k, static_cast<Index>(i)) = 1.0 / sd;
    }
  }
  return w;
}

VectorFittingResult vector_fit(const dsp::Frf& frf, const VectorFittingOptions& options) {
  frf.validate(frf.provenance.source);
  const Index ns = frf.freq_Hz.size();
  CMatrix data(ns, static_cast<Index>(frf.H.size()));
  for (size_t i = 0; i < frf.H.size(); ++i) data.col(static_cast<Index>(i)) = frf.H[i];
  const Vector omega = kTwoPi * frf.freq_Hz;
  const Matrix weights = frf_row_weights(frf, options);
  VectorFittingResult r;
  try {
    r = vector_fit(omega, data, weights, options);
  } catch (const InputError& e) {
    if (frf.provenance.source.empty()) throw;
    throw e.with_source(frf.provenance.source);
  }
  // The outputs' names in the verdict, and the data's own evidence: a band where most points have
  // a low coherence was not excited, whatever the error of the model fitted to its noise.
  for (auto& problem : r.quality.problems) {
    for (size_t i = 0; i < frf.outputs.size(); ++i) {
      const std::string generic = "output " + std::to_string(i + 1) + ":";
      if (problem.rfind(generic, 0) == 0) problem = frf.outputs[i] + ":" + problem.substr(generic.size());
    }
  }
  for (size_t i = 0; i < frf.coherence.size() && i < frf.outputs.size(); ++i) {
    const Vector& c = frf.coherence[i];
    if (c.size() != ns) continue;
    const auto low = (c.array() < 0.5).count();
    if (2 * low > ns) {
      std::ostringstream text;
      text << frf.outputs[i] << ": coherence below 0.5 at " << low << " of " << ns << " points (the band was not excited)";
      r.quality.add_problem(text.str());
    }
  }
  r.quality.advise("a band where the coherence is high (--fmin/--fmax)");
  return r;
}

}  // namespace piezobench::ident
