#include "piezobench/lti/freqresp.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <string>
#include <thread>

#include "balance.hpp"
#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/lti/conversions.hpp"

namespace piezobench::lti {
namespace {

// Working memory of one frequency point, allocated once per thread and reused. Complex numbers are
// kept as separate real and imaginary arrays: the inner loops then vectorize, and they avoid
// std::complex's NaN-checking multiply (__muldc3).
struct Workspace {
  Index n = 0;
  Index m = 0;
  Index p = 0;
  std::vector<double> cr, ci;  // the row carried down by the elimination (columns k..n-1)
  std::vector<double> rr, ri;  // right-hand side of the carried row (m)
  std::vector<double> tr, ti;  // T = Z U accumulated so far, p x n (row-major)
  std::vector<double> hr, hi;  // H accumulated, p x m (row-major)
  Workspace(Index states, Index inputs, Index outputs)
      : n(states),
        m(inputs),
        p(outputs),
        cr(static_cast<size_t>(states)),
        ci(static_cast<size_t>(states)),
        rr(static_cast<size_t>(inputs)),
        ri(static_cast<size_t>(inputs)),
        tr(static_cast<size_t>(outputs * states)),
        ti(static_cast<size_t>(outputs * states)),
        hr(static_cast<size_t>(outputs * inputs)),
        hi(static_cast<size_t>(outputs * inputs)) {}
};

[[noreturn]] void throw_pole(Complex s) {
  throw NumericalError("freqresp",
                       "the evaluation point (" + format_number(s.real(), 10) + ", " + format_number(s.imag(), 10) +
                           ") is numerically a pole of the system",
                       /*retry_may_help=*/true);
}

// On x86-64 the kernel is also compiled for AVX2/FMA (x86-64-v3) and the loader picks the version
// for the CPU at hand (GCC function multi-versioning): twice the vector width in the O(n^2) loops,
// where almost all the time goes.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__linux__)
#define PIEZOBENCH_KERNEL_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define PIEZOBENCH_KERNEL_CLONES
#endif

// The steps of the kernel below are inlined into each of its clones (so they get the clone's
// instruction set): they are always_inline, not just inline.
#if defined(__GNUC__)
#define PIEZOBENCH_KERNEL_STEP inline __attribute__((always_inline))
#else
#define PIEZOBENCH_KERNEL_STEP inline
#endif

// One frequency point's sweep of hessenberg_response: the system's arrays (H row-major n x n,
// G = Q^T B column-major n x m, CQ row-major p x n), s, and the workspace's arrays (the carried
// row cr/ci and its right-hand side rr/ri, T = tr/ti, the result hr/hi).
struct Sweep {
  const double* __restrict h;
  const double* __restrict g;
  const double* __restrict cq;
  Index n, m, p;
  double sr, si;
  double* __restrict cr;
  double* __restrict ci;
  double* __restrict rr;
  double* __restrict ri;
  double* __restrict tr;
  double* __restrict ti;
  double* __restrict hr;
  double* __restrict hi;
};

// Carried row: row 0 of s I - H, with right-hand side G(0, :); T = 0; the result starts at D
// (column-major, p x m).
PIEZOBENCH_KERNEL_STEP void start_sweep(const Sweep& e, const double* d) {
  const Index n = e.n, m = e.m, p = e.p;
  for (Index j = 0; j < n; ++j) {
    e.cr[j] = -e.h[j];
    e.ci[j] = 0.0;
  }
  e.cr[0] += e.sr;
  e.ci[0] += e.si;
  for (Index c = 0; c < m; ++c) {
    e.rr[c] = e.g[c * n];
    e.ri[c] = 0.0;
  }
  for (Index i = 0; i < p * n; ++i) {
    e.tr[i] = 0.0;
    e.ti[i] = 0.0;
  }
  for (Index r = 0; r < p; ++r) {
    for (Index c = 0; c < m; ++c) {
      e.hr[r * m + c] = d[c * p + r];
      e.hi[r * m + c] = 0.0;
    }
  }
}

// Step k with the carried row as pivot: U row k is the carried row, Y row k its right-hand side;
// then the new carried row is the fresh row (row k + 1 of s I - H, `hrow` the row of H) minus l
// times the carried one.
PIEZOBENCH_KERNEL_STEP void eliminate_with_carried_pivot(const Sweep& e, Index k, bool last, const double* hrow_in, double fresh_pivot,
                                                         double carried_mag2) {
  const Index n = e.n, m = e.m, p = e.p;
  const double sr = e.sr, si = e.si;
  const double* __restrict hrow = hrow_in;
  const double inv_r = e.cr[k] / carried_mag2;  // 1 / U(k, k)
  const double inv_i = -e.ci[k] / carried_mag2;
  // l = fresh_pivot / carried(k) (unused on the last row).
  const double lr = fresh_pivot * inv_r;
  const double li = fresh_pivot * inv_i;
  for (Index r = 0; r < p; ++r) {
    double* __restrict trow_r = e.tr + r * n;
    double* __restrict trow_i = e.ti + r * n;
    const double ar = e.cq[r * n + k] - trow_r[k];
    const double ai = -trow_i[k];
    const double zr = ar * inv_r - ai * inv_i;
    const double zi = ar * inv_i + ai * inv_r;
    for (Index c = 0; c < m; ++c) {
      e.hr[r * m + c] += zr * e.rr[c] - zi * e.ri[c];
      e.hi[r * m + c] += zr * e.ri[c] + zi * e.rr[c];
    }
    if (p == 1 && !last) {
      // Single output: T update and elimination in one pass over the row.
      for (Index j = k + 1; j < n; ++j) {
        const double xr = e.cr[j];
        const double xi = e.ci[j];
        trow_r[j] += zr * xr - zi * xi;
        trow_i[j] += zr * xi + zi * xr;
        e.cr[j] = -hrow[j] - (lr * xr - li * xi);
        e.ci[j] = -(lr * xi + li * xr);
      }
    } else {
      for (Index j = k + 1; j < n; ++j) {
        trow_r[j] += zr * e.cr[j] - zi * e.ci[j];
        trow_i[j] += zr * e.ci[j] + zi * e.cr[j];
      }
    }
  }
  if (last) return;
  if (p != 1) {
    for (Index j = k + 1; j < n; ++j) {
      const double ar = e.cr[j];
      const double ai = e.ci[j];
      e.cr[j] = -hrow[j] - (lr * ar - li * ai);
      e.ci[j] = -(lr * ai + li * ar);
    }
  }
  e.cr[k + 1] += sr;
  e.ci[k + 1] += si;
  for (Index c = 0; c < m; ++c) {
    const double ar = e.rr[c];
    const double ai = e.ri[c];
    e.rr[c] = e.g[c * n + k + 1] - (lr * ar - li * ai);
    e.ri[c] = -(lr * ai + li * ar);
  }
}

// Step k with the fresh row as pivot: U row k is the fresh row (-H(k+1, :) plus s in column k + 1),
// Y row k is G(k + 1, :); then the new carried row is the carried row minus l times the fresh one.
PIEZOBENCH_KERNEL_STEP void eliminate_with_fresh_pivot(const Sweep& e, Index k, const double* hrow_in, double fresh_pivot) {
  const Index n = e.n, m = e.m, p = e.p;
  const double sr = e.sr, si = e.si;
  const double* __restrict hrow = hrow_in;
  const double inv = 1.0 / fresh_pivot;
  // l = carried(k) / fresh_pivot
  const double lr = e.cr[k] * inv;
  const double li = e.ci[k] * inv;
  for (Index r = 0; r < p; ++r) {
    double* __restrict trow_r = e.tr + r * n;
    double* __restrict trow_i = e.ti + r * n;
    const double zr = (e.cq[r * n + k] - trow_r[k]) * inv;
    const double zi = -trow_i[k] * inv;
    for (Index c = 0; c < m; ++c) {
      const double gv = e.g[c * n + k + 1];
      e.hr[r * m + c] += zr * gv;
      e.hi[r * m + c] += zi * gv;
    }
    if (p == 1) {
      // Single output: T update and elimination in one pass (carried + l * h).
      for (Index j = k + 1; j < n; ++j) {
        const double f = hrow[j];
        trow_r[j] -= zr * f;
        trow_i[j] -= zi * f;
        e.cr[j] += lr * f;
        e.ci[j] += li * f;
      }
    } else {
      for (Index j = k + 1; j < n; ++j) {
        trow_r[j] -= zr * hrow[j];
        trow_i[j] -= zi * hrow[j];
      }
    }
    trow_r[k + 1] += zr * sr - zi * si;
    trow_i[k + 1] += zr * si + zi * sr;
  }
  if (p != 1) {
    for (Index j = k + 1; j < n; ++j) {
      const double f = hrow[j];  // carried - l * (-h) = carried + l * h
      e.cr[j] += lr * f;
      e.ci[j] += li * f;
    }
  }
  e.cr[k + 1] -= lr * sr - li * si;  // the fresh row also holds s in column k + 1
  e.ci[k + 1] -= lr * si + li * sr;
  for (Index c = 0; c < m; ++c) {
    const double gv = e.g[c * n + k + 1];
    e.rr[c] -= lr * gv;
    e.ri[c] -= li * gv;
  }
}

// Computes C Q (s I - H)^-1 G + D for upper Hessenberg H (row-major, n x n), real G = Q^T B
// (column-major, n x m), CQ (row-major, p x n) and D (column-major, p x m) into w.hr/w.hi.
//
// Gaussian elimination with partial pivoting between adjacent rows, P (s I - H) = L U (backward
// stable as GEPP; growth at most n for Hessenberg matrices). Only the row carried down by the
// elimination is complex: the fresh row k + 1 of s I - H is real but for s on its diagonal. With
// Y = L^-1 P G formed along the way, the result is Z Y + D where Z U = C Q. Z is solved by columns
// as the rows of U appear (z_k = (cq_k - T_k) / U(k, k), then T += z_k U(k, :)), so U is never
// stored and there is no separate back substitution: one pass over H per frequency.
// `scale` is a norm of H, used to decide that a pivot is zero to working precision. Returns false
// when s is numerically a pole (the caller throws: no exception leaves the multi-versioned kernel,
// whose clones need not all carry unwind tables under every toolchain configuration).
PIEZOBENCH_KERNEL_CLONES
bool hessenberg_response(const double* h, const double* g, const double* cq, const double* d, Complex s,
                         double scale, Workspace& w) {
  const Index n = w.n;
  const Sweep e{h,         g,         cq,        n,         w.m,       w.p,       s.real(),  s.imag(),
                w.cr.data(), w.ci.data(), w.rr.data(), w.ri.data(), w.tr.data(), w.ti.data(), w.hr.data(), w.hi.data()};
  const double tiny = std::numeric_limits<double>::epsilon() * (scale + std::abs(s));
  start_sweep(e, d);
  for (Index k = 0; k < n; ++k) {
    const bool last = k + 1 == n;
    const double* hrow = last ? nullptr : h + (k + 1) * n;  // row k + 1 of H
    const double fresh_pivot = last ? 0.0 : -hrow[k];       // (s I - H)(k + 1, k), real
    const double carried_mag2 = e.cr[k] * e.cr[k] + e.ci[k] * e.ci[k];
    const bool swap = !last && fresh_pivot * fresh_pivot > carried_mag2;
    if (!swap) {
      if (carried_mag2 <= tiny * tiny) return false;  // column k vanishes from row k down
      eliminate_with_carried_pivot(e, k, last, hrow, fresh_pivot, carried_mag2);
    } else {
      if (fresh_pivot * fresh_pivot <= tiny * tiny) return false;
      eliminate_with_fresh_pivot(e, k, hrow, fresh_pivot);
    }
  }
  return true;
}

// The fixed, per-system data of an evaluation, in the layout the kernel wants.
struct Kernel {
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> h;   // H
  Matrix g;                                                                    // Q^T B
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> cq;  // C Q
  Matrix d;                                                                    // D
  double scale = 0.0;
};

Kernel make_kernel(const Matrix& hessenberg, const Matrix& qtb, const Matrix& cq, const Matrix& d) {
  Kernel k;
  k.h = hessenberg;
  k.g = qtb;
  k.cq = cq;
  k.d = d;
  k.scale = hessenberg.size() > 0 ? hessenberg.cwiseAbs().colwise().sum().maxCoeff() : 0.0;
  return k;
}

// H(s) without delays into `out` (outputs x inputs).
void evaluate_point(const Kernel& kern, Complex s, Workspace& w, CMatrix& out) {
  const Index m = w.m;
  const Index p = w.p;
  out.resize(p, m);
  if (w.n == 0) {
    out = kern.d.cast<Complex>();
    return;
  }
  if (!hessenberg_response(kern.h.data(), kern.g.data(), kern.cq.data(), kern.d.data(), s, kern.scale, w)) {
    throw_pole(s);
  }
  for (Index r = 0; r < p; ++r) {
    for (Index c = 0; c < m; ++c) {
      out(r, c) = Complex(w.hr[static_cast<size_t>(r * m + c)], w.hi[static_cast<size_t>(r * m + c)]);
    }
  }
  if (!out.allFinite()) throw_pole(s);
}

// Sum of |a(i, j)| over the entries below the subdiagonal: what a Hessenberg reduction must remove.
double below_subdiagonal(const Matrix& a) {
  double sum = 0.0;
  for (Index j = 0; j < a.cols(); ++j) {
    for (Index i = j + 2; i < a.rows(); ++i) sum += std::abs(a(i, j));
  }
  return sum;
}

Complex point_of(const StateSpace& sys, double omega) {
  if (sys.is_discrete()) return std::polar(1.0, omega * sys.sample_time);
  return Complex(0.0, omega);
}

void apply_delays(const StateSpace& sys, double omega, CMatrix& h) {
  if (!sys.has_delay()) return;
  for (Index c = 0; c < h.cols(); ++c) {
    for (Index r = 0; r < h.rows(); ++r) {
      const double tau = sys.channel_delay(r, c);
      if (tau != 0.0) h(r, c) *= std::polar(1.0, -omega * tau);
    }
  }
}

void check_omega(const Vector& omega, const std::string& source) {
  for (Index k = 0; k < omega.size(); ++k) {
    if (!std::isfinite(omega(k))) {
      throw InputError(source, "omega(" + std::to_string(k) + ")", "a finite frequency in rad/s",
                       format_number_exact(omega(k)));
    }
  }
}

}  // namespace

CVector FrequencyResponse::channel(Index output, Index input) const {
  CVector out(static_cast<Index>(H.size()));
  for (size_t k = 0; k < H.size(); ++k) {
    const CMatrix& hk = H[k];
    if (output < 0 || output >= hk.rows()) {
      throw InputError("FrequencyResponse::channel", "output", "an index below " + std::to_string(hk.rows()),
                       std::to_string(output));
    }
    if (input < 0 || input >= hk.cols()) {
      throw InputError("FrequencyResponse::channel", "input", "an index below " + std::to_string(hk.cols()),
                       std::to_string(input));
    }
    out(static_cast<Index>(k)) = hk(output, input);
  }
  return out;
}

FrequencyResponseEvaluator::FrequencyResponseEvaluator(const StateSpace& sys) : sys_(sys) {
  sys_.validate("freqresp");
  Matrix a = sys_.A;
  Matrix b = sys_.B;
  Matrix c = sys_.C;
  const Index n = a.rows();
  // An orthogonal reduction has a backward error of eps |A| in every entry, which blurs structure
  // such as exact zeros at s = 0 or wide spreads of mode frequencies. Cascades (series connections,
  // tf -> ss sections) are block lower triangular: in reversed state order they are (nearly) upper
  // Hessenberg already and the reduction has (almost) nothing to do, so take that order when it
  // leaves less to eliminate. A permutation is exact.
  if (n > 2) {
    const Matrix reversed = a.colwise().reverse().rowwise().reverse();
    if (below_subdiagonal(reversed) < below_subdiagonal(a)) {
      a = reversed;
      b = b.colwise().reverse().eval();
      c = c.rowwise().reverse().eval();
    }
  }
  // Balancing: the reduction and the solves then work on a matrix whose rows and columns have
  // comparable norms, which keeps the backward error small for badly scaled (SI-unit) models.
  detail::balance_realization(a, b, c);
  if (n == 0) {
    hessenberg_ = a;
    qtb_ = b;
    cq_ = c;
    return;
  }
  const Eigen::HessenbergDecomposition<Matrix> hd(a);
  hessenberg_ = hd.matrixH();
  const Matrix q = hd.matrixQ();
  qtb_ = q.transpose() * b;
  cq_ = c * q;
}

CMatrix FrequencyResponseEvaluator::evaluate(Complex s_or_z) const {
  if (!std::isfinite(s_or_z.real()) || !std::isfinite(s_or_z.imag())) {
    throw InputError("FrequencyResponseEvaluator::evaluate", "s", "a finite complex number", "a non-finite value");
  }
  const Kernel kern = make_kernel(hessenberg_, qtb_, cq_, sys_.D);
  Workspace w(sys_.states(), sys_.inputs(), sys_.outputs());
  CMatrix out;
  evaluate_point(kern, s_or_z, w, out);
  return out;
}

FrequencyResponse FrequencyResponseEvaluator::response(const Vector& omega, int threads) const {
  check_omega(omega, "freqresp");
  if (threads < 0) {
    throw InputError("freqresp", "threads", "0 (all cores) or a positive count", std::to_string(threads));
  }
  FrequencyResponse result;
  result.omega = omega;
  const auto count = static_cast<size_t>(omega.size());
  result.H.resize(count);
  const Kernel kern = make_kernel(hessenberg_, qtb_, cq_, sys_.D);

  auto work = [&](size_t begin, size_t end) {
    Workspace w(sys_.states(), sys_.inputs(), sys_.outputs());
    for (size_t k = begin; k < end; ++k) {
      const double wk = omega(static_cast<Index>(k));
      evaluate_point(kern, point_of(sys_, wk), w, result.H[k]);
      apply_delays(sys_, wk, result.H[k]);
    }
  };

  size_t workers = threads == 0 ? std::max(1U, std::thread::hardware_concurrency()) : static_cast<size_t>(threads);
  // Below a few hundred points per thread the thread start-up costs more than it saves.
  constexpr size_t kMinPointsPerThread = 256;
  workers = std::min(workers, std::max<size_t>(1, count / kMinPointsPerThread));
  if (workers <= 1) {
    work(0, count);
    return result;
  }
  std::vector<std::thread> pool;
  std::vector<std::exception_ptr> errors(workers);
  const size_t chunk = (count + workers - 1) / workers;
  for (size_t t = 0; t < workers; ++t) {
    const size_t begin = std::min(count, t * chunk);
    const size_t end = std::min(count, begin + chunk);
    pool.emplace_back([&, t, begin, end] {
      try {
        work(begin, end);
      } catch (...) {
        errors[t] = std::current_exception();
      }
    });
  }
  for (auto& th : pool) th.join();
  for (const auto& e : errors) {
    if (e) std::rethrow_exception(e);
  }
  return result;
}

FrequencyResponse freqresp(const StateSpace& sys, const Vector& omega) {
  return FrequencyResponseEvaluator(sys).response(omega, /*threads=*/1);
}

CVector freqresp(const Zpk& zpk, const Vector& omega) {
  zpk.validate("freqresp");
  check_omega(omega, "freqresp");
  CVector out(omega.size());
  const Index nz = zpk.zeros.size();
  const Index np = zpk.poles.size();
  for (Index k = 0; k < omega.size(); ++k) {
    const double w = omega(k);
    const Complex s = zpk.is_discrete() ? std::polar(1.0, w * zpk.sample_time) : Complex(0.0, w);
    // Factors are taken as ratios (s - z_i)/(s - p_i) so that the running product stays near the
    // final magnitude: no overflow for high orders, and each factor is exact to round-off even
    // next to a lightly damped pole or zero (no polynomial is ever formed).
    Complex h(zpk.gain, 0.0);
    for (Index i = 0; i < std::max(nz, np); ++i) {
      if (i < nz) h *= (s - zpk.zeros(i));
      if (i < np) {
        const Complex den = s - zpk.poles(i);
        if (den == Complex(0.0, 0.0)) throw_pole(s);
        h /= den;
      }
    }
    if (zpk.delay != 0.0) h *= std::polar(1.0, -w * zpk.delay);
    if (!std::isfinite(h.real()) || !std::isfinite(h.imag())) throw_pole(s);
    out(k) = h;
  }
  return out;
}

CVector freqresp(const TransferFunction& tf, const Vector& omega) {
  tf.validate("freqresp");
  Zpk z = to_zpk(tf);
  z.delay = tf.delay;
  return freqresp(z, omega);
}

Vector logspace(double lo_exponent, double hi_exponent, Index n) {
  if (!std::isfinite(lo_exponent)) {
    throw InputError("logspace", "lo_exponent", "a finite number", format_number_exact(lo_exponent));
  }
  if (!std::isfinite(hi_exponent)) {
    throw InputError("logspace", "hi_exponent", "a finite number", format_number_exact(hi_exponent));
  }
  if (n < 0) throw InputError("logspace", "n", "a count >= 0", std::to_string(n));
  Vector out(n);
  if (n == 0) return out;
  if (n == 1) {
    out(0) = std::pow(10.0, hi_exponent);
    return out;
  }
  const double step = (hi_exponent - lo_exponent) / static_cast<double>(n - 1);
  for (Index k = 0; k < n; ++k) out(k) = std::pow(10.0, lo_exponent + static_cast<double>(k) * step);
  out(n - 1) = std::pow(10.0, hi_exponent);
  return out;
}

}  // namespace piezobench::lti
