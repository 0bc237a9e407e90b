#include "piezobench/dsp/leakage_covariance.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Sparse>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"

namespace piezobench::dsp {

using Complex = std::complex<double>;
using Eigen::Index;

namespace {

// sum_{n=0}^{N-1} e^(-2 pi i x n / N) (x in lines, not an integer multiple of N).
Complex dirichlet(double x, double n) {
  const double pi = std::numbers::pi;
  const double den = std::sin(pi * x / n);
  if (std::abs(den) < 1e-300) return Complex(n, 0.0);
  return std::polar(std::sin(pi * x) / den, -pi * x * (n - 1.0) / n);
}

// W(nu) at the integration points nu_i = -(i + 0.5) / P + K (i = 0 .. 2 K P - 1): the window seen from
// line k at nu = k + s_i, s_i = (i + 0.5) / P - K, is W(k - nu) = W(-s_i).
std::vector<Complex> window_at_points(const ResolutionKernel& kernel) {
  const long half = kernel.half_width();
  const double n = static_cast<double>(kernel.nfft);
  const long points = 2 * kLeakageHalfWidth * kLeakageSubBins;
  std::vector<Complex> w(static_cast<std::size_t>(points));
  for (long i = 0; i < points; ++i) {
    const double s = (static_cast<double>(i) + 0.5) / kLeakageSubBins - static_cast<double>(kLeakageHalfWidth);
    Complex sum = 0.0;
    for (long j = -half; j <= half; ++j) sum += kernel.window_bins[static_cast<std::size_t>(j + half)] * dirichlet(-s - static_cast<double>(j), n);
    w[static_cast<std::size_t>(i)] = sum / n;
  }
  return w;
}

}  // namespace

Complex LeakageCovariance::covariance(Index k, Index l) const {
  if (k > l) return std::conj(covariance(l, k));
  return l - k <= kLeakageMaxLineDistance ? upper(k, l - k) : Complex(0.0);
}

Complex LeakageCovariance::pseudo(Index k, Index l) const {
  if (k > l) return pseudo(l, k);
  return l - k <= kLeakageMaxLineDistance ? upper_pseudo(k, l - k) : Complex(0.0);
}

bool knows_leakage(const ResolutionKernel& kernel) {
  return kernel.line_spacing_Hz > 0.0 && kernel.nfft >= 2 && kernel.segments >= 1 && kernel.segment_shift >= 1 &&
         kernel.window_bins.size() == kernel.weights.size() && !kernel.window_bins.empty();
}

LeakageCovariance leakage_covariance(const ResolutionKernel& kernel, const Eigen::VectorXd& lines,
                                     const std::function<Eigen::VectorXcd(const Eigen::VectorXd&)>& response) {
  const std::string src = "leakage covariance";
  if (!knows_leakage(kernel)) throw InputError(src, "kernel", "the window's bins, nfft, segments and their shift", "an incomplete provenance");
  const double step = 2.0 * std::numbers::pi * kernel.line_spacing_Hz;
  const Index n = lines.size();
  for (Index k = 1; k < n; ++k) {
    if (std::abs(lines(k) - lines(k - 1) - step) > 1e-6 * step) {
      throw InputError(src, "lines", "consecutive lines of the estimate", "a gap after " + format_number_exact(lines(k - 1)) + " rad/s");
    }
  }
  constexpr long P = kLeakageSubBins, K = kLeakageHalfWidth;
  const long width = 2 * K * P;  // integration points around one line
  const std::vector<Complex> w = window_at_points(kernel);
  double power = 0.0;
  for (const Complex& v : w) power += std::norm(v);
  // The response on the union of the lines' integration points: line k's point i is fine(k P + i).
  Eigen::VectorXd at((n + 2 * K) * P);
  for (Index f = 0; f < at.size(); ++f) {
    const double s = (static_cast<double>(f) + 0.5) / P - static_cast<double>(K);  // lines from lines(0)
    at(f) = (n > 0 ? lines(0) : 0.0) + s * step;
  }
  const Eigen::VectorXcd h = at.size() > 0 ? response(at) : Eigen::VectorXcd();
  Eigen::VectorXcd mean(n);  // Hbar(k)
  for (Index k = 0; k < n; ++k) {
    Complex m = 0.0;
    for (long i = 0; i < width; ++i) m += std::norm(w[static_cast<std::size_t>(i)]) * h(k * P + i);
    mean(k) = m / power;
  }
  // The lags whose segments share samples, with their weights (S - |j|) / S^2 and phases per point.
  const Index segments = kernel.segments, shift = kernel.segment_shift;
  struct Lag {
    double weight;
    std::vector<Complex> phase;  // e^(-2 pi i s_i j D / nfft)
  };
  std::vector<Lag> lags;
  for (Index j = 1 - segments; j < segments; ++j) {
    if (std::abs(j) * shift >= kernel.nfft) continue;
    Lag l{static_cast<double>(segments - std::abs(j)) / static_cast<double>(segments * segments), std::vector<Complex>(static_cast<std::size_t>(width))};
    for (long i = 0; i < width; ++i) {
      const double s = (static_cast<double>(i) + 0.5) / P - static_cast<double>(K);
      l.phase[static_cast<std::size_t>(i)] =
          std::polar(1.0, -2.0 * std::numbers::pi * s * static_cast<double>(j * shift) / static_cast<double>(kernel.nfft));
    }
    lags.push_back(std::move(l));
  }
  // With pair_i = W*(k - nu_i) W(l - nu_i) and D_k = h - Hbar(k), D_l = h - Hbar(l) at the same point,
  // A_j = sum pair ph, B_j = sum conj(pair ph) D_k D_l^*, and the pseudo-covariance's two factors
  // sum pair ph^* D_l and sum conj(pair ph^*) D_k: each a combination of sums of v = pair ph and
  // u = pair ph^* against 1, h, h^* and |h|^2 (A_j and those against 1 do not depend on k).
  const long reach = std::min<long>(2 * K, kLeakageMaxLineDistance + 1);
  LeakageCovariance out{Eigen::MatrixXcd::Zero(n, kLeakageMaxLineDistance + 1), Eigen::MatrixXcd::Zero(n, kLeakageMaxLineDistance + 1)};
  const double scale = 1.0 / (power * power);
  std::vector<Complex> v(static_cast<std::size_t>(width)), u(static_cast<std::size_t>(width));
  for (long d = 0; d < reach && d < n; ++d) {
    for (const Lag& lag : lags) {
      Complex a = 0.0, sum_u = 0.0;  // A_j = sum v (also the v's sum in B), and the u's sum
      for (long i = d * P; i < width; ++i) {
        const Complex pair = std::conj(w[static_cast<std::size_t>(i)]) * w[static_cast<std::size_t>(i - d * P)];
        const Complex ph = lag.phase[static_cast<std::size_t>(i)];
        v[static_cast<std::size_t>(i)] = pair * ph;
        u[static_cast<std::size_t>(i)] = pair * std::conj(ph);
        a += v[static_cast<std::size_t>(i)];
        sum_u += u[static_cast<std::size_t>(i)];
      }
      for (Index k = 0; k + d < n; ++k) {
        const Index l = k + d;
        Complex vhh = 0.0, vh = 0.0, vhc = 0.0, uh = 0.0, uch = 0.0;  // sums of conj(v) |h|^2, conj(v) h, conj(v) h^*, u h, conj(u) h
        const Complex* hk = h.data() + k * P;
        for (long i = d * P; i < width; ++i) {
          const Complex hi = hk[i], cv = std::conj(v[static_cast<std::size_t>(i)]), ui = u[static_cast<std::size_t>(i)];
          vhh += cv * std::norm(hi);
          vh += cv * hi;
          vhc += cv * std::conj(hi);
          uh += ui * hi;
          uch += std::conj(ui) * hi;
        }
        const Complex mk = mean(k), ml = mean(l);
        // B = sum conj(v) (h - mk)(h - ml)^* = vhh - ml^* vh - mk vhc + mk ml^* sum conj(v)
        const Complex b = vhh - std::conj(ml) * vh - mk * vhc + mk * std::conj(ml) * std::conj(a);
        const Complex q1 = uh - ml * sum_u;                 // sum u (h - ml)
        const Complex q2 = uch - mk * std::conj(sum_u);     // sum conj(u) (h - mk)
        out.upper(k, d) += lag.weight * a * b * scale;
        out.upper_pseudo(k, d) += lag.weight * q1 * q2 * scale;
      }
    }
  }
  return out;
}

std::vector<core::ResidualCovarianceBlock> leakage_residual_blocks(const ResolutionKernel& kernel, const KernelGrid& grid,
                                                                   const Eigen::VectorXd& lines, const Eigen::VectorXcd& g,
                                                                   const Eigen::VectorXd& noise_relative_std,
                                                                   const Eigen::VectorXcd& model_at_nodes,
                                                                   const std::function<Eigen::VectorXcd(const Eigen::VectorXd&)>& response,
                                                                   Index first_row) {
  const Index n = lines.size();
  if (!knows_leakage(kernel) || n < 2 || g.size() != n || noise_relative_std.size() != n) return {};
  const Eigen::VectorXd leak = grid.leakage_coherence(model_at_nodes);
  Eigen::VectorXd excess(n);
  for (Index k = 0; k < n; ++k) excess(k) = leak(k) > 0.0 ? 1.0 / leak(k) - 1.0 : 0.0;
  const double most = excess.maxCoeff();
  if (!(most > 1e-12)) return {};
  std::vector<bool> counts(static_cast<std::size_t>(n));
  for (Index k = 0; k < n; ++k) {
    const double noise = noise_relative_std(k);
    counts[static_cast<std::size_t>(k)] = excess(k) > kLeakageLinesFraction * most &&
                                          excess(k) / (2.0 * static_cast<double>(kernel.segments)) > kLeakageOfNoise * noise * noise;
  }
  const double step = 2.0 * std::numbers::pi * kernel.line_spacing_Hz;
  std::vector<core::ResidualCovarianceBlock> blocks;
  for (Index k = 0; k < n;) {
    if (!counts[static_cast<std::size_t>(k)]) {
      ++k;
      continue;
    }
    Index end = k + 1;
    while (end < n && counts[static_cast<std::size_t>(end)] && std::abs(lines(end) - lines(end - 1) - step) <= 1e-6 * step) ++end;
    Index first = k, count = end - k;
    if (count > kLeakageMaxLines) {  // keep the lines around the largest leakage
      Index peak = k;
      for (Index i = k; i < end; ++i) {
        if (excess(i) > excess(peak)) peak = i;
      }
      first = std::clamp<Index>(peak - kLeakageMaxLines / 2, k, end - kLeakageMaxLines);
      count = kLeakageMaxLines;
    }
    k = end;
    if (count < 2) continue;
    const LeakageCovariance lc = leakage_covariance(kernel, lines.segment(first, count), response);
    const Eigen::VectorXcd gi = g.segment(first, count);
    if (!gi.allFinite() || !lc.upper.allFinite() || !lc.upper_pseudo.allFinite()) continue;
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(static_cast<std::size_t>(4 * count * (2 * kLeakageMaxLineDistance + 1)));
    for (Index i = 0; i < count; ++i) {
      for (Index l = std::max<Index>(0, i - kLeakageMaxLineDistance); l < std::min(count, i + kLeakageMaxLineDistance + 1); ++l) {
        const std::complex<double> cu = gi(i) * lc.covariance(i, l) * std::conj(gi(l)), qu = gi(i) * lc.pseudo(i, l) * gi(l);
        t.emplace_back(2 * i, 2 * l, 0.5 * (cu + qu).real());
        t.emplace_back(2 * i + 1, 2 * l + 1, 0.5 * (cu - qu).real());
        t.emplace_back(2 * i, 2 * l + 1, 0.5 * (qu - cu).imag());
        t.emplace_back(2 * i + 1, 2 * l, 0.5 * (qu + cu).imag());
      }
    }
    core::ResidualCovarianceBlock block{first_row + 2 * first, Eigen::SparseMatrix<double>(2 * count, 2 * count)};
    block.covariance.setFromTriplets(t.begin(), t.end());
    blocks.push_back(std::move(block));
  }
  return blocks;
}

}  // namespace piezobench::dsp
