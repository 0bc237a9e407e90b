#pragma once
// The resolution of a Welch FRF estimate: what its lines converge to, as a kernel a model's response
// is passed through before it is compared with the estimate.
//
// A Welch estimate with the window w of nfft samples does not converge to H(f) but to H smoothed by
// the window's spectral kernel |W(nu)|^2 (for an input whose spectrum is flat across the kernel,
// H1 -> integral H(nu) |W(f - nu)|^2 dnu / integral |W|^2): a resonance or an anti-resonance a few
// lines wide comes out wider and shallower (the resonance damping of the virtual bench +3 %, its
// anti-resonance damping +1-2 %, docs/uncertainty.md section 6). On the estimate's own line grid,
// df = fs / nfft, the kernel is sampled at the window's DFT bins:
//
//   H_est(f) ~ sum_j c_j H(f + j df),   c_j = |W_j|^2 / sum_i |W_i|^2,   W_j = sum_n w(n) e^(-2 pi i j n / nfft)
//
// (sum_i |W_i|^2 = nfft sum_n w(n)^2, Parseval). For a cosine-sum window (hann, hamming, flat-top)
// the bins are exactly the cosine coefficients: periodic hann 0.5 - 0.5 cos gives W_0 = nfft/2,
// W_+-1 = -nfft/4, c = (1/6, 2/3, 1/6); periodic hamming (0.23^2, 0.54^2, 0.23^2) / 0.3974; the
// rectangular window c = (1): no smoothing on its own grid. The sampled kernel has the same second
// moment as the continuous one, sum_j c_j j^2 = (nfft / 2 pi)^2 sum |w'|^2 / sum w^2 in lines^2
// (1/3 for hann), so it reproduces the continuous smoothing to second order in df (a response whose
// curvature is H'' gets H'' df^2 / 6 from hann, which is how the resonance's damping moves).
// Bins with c_j below kResolutionKernelFloor are left out (a symmetric window's DFT has
// O(1/nfft^2) tails) and the rest renormalized to a sum of 1.
#include <Eigen/Dense>
#include <algorithm>
#include <complex>
#include <numbers>
#include <type_traits>
#include <vector>

#include "piezobench/dsp/frf.hpp"
#include "piezobench/dsp/window.hpp"

namespace piezobench::dsp {

// The kernel on an FRF's line grid: weights[j] for the offset (j - half_width()) lines, line_spacing_Hz
// apart. Inactive (no weights, or the single weight of a rectangular window): the identity.
struct ResolutionKernel {
  double line_spacing_Hz = 0.0;  // Hz, df = sample rate / nfft; 0: none
  std::vector<double> weights;   // dimensionless, odd count, symmetric, sum 1
  // The correlation of the estimate's random error at adjacent lines (dsp/frf_variance.hpp,
  // adjacent_line_correlation), which the fits' covariances use; 0 when the provenance does not say
  // how the segments overlapped (or for resolution_kernel(window, nfft, rate)).
  double adjacent_line_correlation = 0.0;
  // What dsp/leakage_covariance.hpp needs of the estimate (0 / empty when unknown): the window's DFT
  // bins W_j (j = -half_width() .. half_width(), dimensionless, the window's own scale), its nfft,
  // the segments averaged and the samples between consecutive segments' starts.
  std::vector<std::complex<double>> window_bins;
  Eigen::Index nfft = 0;
  Eigen::Index segments = 0;
  Eigen::Index segment_shift = 0;
  [[nodiscard]] bool active() const { return line_spacing_Hz > 0.0 && weights.size() > 1; }
  [[nodiscard]] long half_width() const { return static_cast<long>(weights.size() / 2); }
};

inline constexpr double kResolutionKernelFloor = 1e-9;  // relative weight below which a bin is dropped
inline constexpr long kResolutionKernelMaxHalfWidth = 8;  // lines on each side at most (flat-top: 4)

// The kernel of `window` of nfft samples at sample_rate_Hz (line spacing sample_rate_Hz / nfft).
// InputError (source "resolution kernel") for nfft < 2 or a sample rate that is not finite and > 0.
[[nodiscard]] ResolutionKernel resolution_kernel(WindowType window, Eigen::Index nfft, double sample_rate_Hz);

// The kernel of a Welch FRF from its provenance (window, nfft, sample_rate); inactive when the
// provenance does not give all three (an FRF computed from a model, or read from a file that does
// not say how it was estimated, or names a window window_type_from_string does not know).
[[nodiscard]] ResolutionKernel resolution_kernel(const FrfProvenance& provenance);

// For each pair of consecutive points of omega (rad/s): the kernel's adjacent_line_correlation when
// they are neighbouring lines of the estimate's grid (2 pi line_spacing_Hz apart), else 0 (a band
// with lines left out). Size omega.size() - 1; empty when the kernel carries no correlation.
[[nodiscard]] Eigen::VectorXd adjacent_line_pairs(const ResolutionKernel& kernel, const Eigen::VectorXd& omega);

namespace detail {
// omega + delta, omega and delta in rad/s.
inline double shifted(double omega, double delta) { return omega + delta; }
// omega + delta for every frequency, omega and delta in rad/s.
inline Eigen::VectorXd shifted(const Eigen::VectorXd& omega, double delta) { return (omega.array() + delta).matrix(); }
}  // namespace detail

// sum_j c_j response(omega + j 2 pi df) at omega (rad/s; one frequency or a vector of them): what a
// Welch estimate of `response` converges to; response(omega) itself when the kernel is inactive.
// `response` takes what omega is and returns a complex value or an Eigen matrix of them (outputs,
// frequencies).
template <class Omega, class Response>
auto smoothed_response(const ResolutionKernel& kernel, const Omega& omega, const Response& response) {
  using Value = std::decay_t<decltype(response(omega))>;
  if (!kernel.active()) return Value(response(omega));
  const double step = 2.0 * std::numbers::pi * kernel.line_spacing_Hz;  // rad/s per line
  const long half = kernel.half_width();
  Value sum = Value(response(omega)) * kernel.weights[static_cast<std::size_t>(half)];
  for (long j = 1; j <= half; ++j) {
    const double c = kernel.weights[static_cast<std::size_t>(half + j)];
    const double delta = static_cast<double>(j) * step;
    sum += (Value(response(detail::shifted(omega, delta))) + Value(response(detail::shifted(omega, -delta)))) * c;
  }
  return sum;
}

// smoothed_response at a fixed set of frequencies, each distinct frequency evaluated once. On a
// Welch estimate's uniform grid omega_k + j 2 pi df is (to round-off) the line omega_(k+j), so a
// fit that passes its model through the kernel at every iteration evaluates it at about n + 2 half
// frequencies instead of n (2 half + 1): the plant fits and the 2-DoF tuning evaluated their models
// three times over with hann's kernel (docs/performance.md, "The demo"). A shifted frequency within
// 1e-6 lines of one of omega (or of an earlier shifted one) is taken as that frequency; the response
// there differs from smoothed_response's by the model's change over that round-off.
class KernelGrid {
 public:
  KernelGrid() = default;  // inactive: nodes() empty, smooth() the identity
  // The grid of `kernel` at omega (rad/s, any order; only an ascending omega is searched for lines).
  KernelGrid(const ResolutionKernel& kernel, const Eigen::VectorXd& omega);

  // Where to evaluate the response (rad/s): omega itself first, then the shifted frequencies that
  // are not in omega.
  [[nodiscard]] const Eigen::VectorXd& nodes() const { return nodes_; }

  // sum_j c_j R(omega_k + j df) for every k, R's values at nodes() in `at_nodes` (one row per node,
  // any number of columns); the sum in smoothed_response's order.
  template <class Derived>
  [[nodiscard]] Eigen::Matrix<typename Derived::Scalar, Eigen::Dynamic, Derived::ColsAtCompileTime> smooth(
      const Eigen::MatrixBase<Derived>& at_nodes) const {
    using Out = Eigen::Matrix<typename Derived::Scalar, Eigen::Dynamic, Derived::ColsAtCompileTime>;
    if (weights_.size() <= 1) return Out(at_nodes.topRows(points_));
    Out sum(points_, at_nodes.cols());
    const auto width = static_cast<Eigen::Index>(weights_.size());
    const Eigen::Index half = width / 2;
    for (Eigen::Index k = 0; k < points_; ++k) {
      const Eigen::Index* at = index_.data() + k * width + half;  // at[j]: the node of omega_k + j df
      sum.row(k) = at_nodes.row(at[0]) * weights_[static_cast<std::size_t>(half)];
      for (Eigen::Index j = 1; j <= half; ++j) {
        sum.row(k) += (at_nodes.row(at[j]) + at_nodes.row(at[-j])) * weights_[static_cast<std::size_t>(half + j)];
      }
    }
    return sum;
  }

  // The coherence a noise-free Welch estimate of the response R shows at each point because of the
  // window's leakage alone: |sum_j c_j R_j|^2 / sum_j c_j |R_j|^2 (the cross-spectrum averages R over
  // the kernel, the output's auto-spectrum |R|^2), 1 where the kernel is inactive. Near a sharp
  // resonance it drops below 1 although nothing is random: dividing a measured coherence by it leaves
  // the part that the noise explains. R's values at nodes().
  [[nodiscard]] Eigen::VectorXd leakage_coherence(const Eigen::VectorXcd& at_nodes) const {
    if (weights_.size() <= 1) return Eigen::VectorXd::Ones(points_);
    const Eigen::VectorXcd mean = smooth(at_nodes);
    const Eigen::VectorXd power = smooth(Eigen::VectorXd(at_nodes.cwiseAbs2()));
    Eigen::VectorXd c(points_);
    for (Eigen::Index k = 0; k < points_; ++k) c(k) = power(k) > 0.0 ? std::min(1.0, std::norm(mean(k)) / power(k)) : 1.0;
    return c;
  }

 private:
  Eigen::Index points_ = 0;
  Eigen::VectorXd nodes_;              // rad/s
  std::vector<double> weights_;        // the kernel's, or empty when it is inactive
  std::vector<Eigen::Index> index_;    // (k, j + half) -> node, row-major
};

}  // namespace piezobench::dsp
