#pragma once
// The random error of a Welch H1 estimate that needs no noise: the excitation's own randomness seen
// through the window's leakage at a sharp resonance or anti-resonance (docs/uncertainty.md section 2).
//
// A segment's windowed spectra are U(k) = int W(k - nu) X(nu) dnu and Y(k) = int W(k - nu) H(nu) X(nu)
// dnu (nu in lines, W the window's DTFT, X the input's spectrum, white across the kernel), so
// U* Y - Hbar(k) |U|^2 = int int W*(k - nu) W(k - nu') X*(nu) X(nu') D_k(nu'), D_k = H - Hbar(k), with
// Hbar(k) = int |W(k - nu)|^2 H(nu) / int |W|^2 what the estimate converges to. It has mean 0; for a
// Gaussian input (Isserlis' theorem) its covariance between lines k and l, over segments s and s + j
// (start D j samples apart, the phase e^(-2 pi i nu j D / nfft)), is a product of two kernel integrals:
//
//   E[e_k e_l^*] = sum_j (S - |j|) / S^2 A_j(k, l) B_j(k, l) / P0^2
//     A_j = int W*(k - nu) W(l - nu) e^(-2 pi i nu j D / nfft),  B_j = int W(k - nu) W*(l - nu) D_k D_l^* e^(2 pi i nu j D / nfft)
//   E[e_k e_l]   = sum_j (S - |j|) / S^2 [int W*(k - nu) W(l - nu) D_l e^(2 pi i ..)] [int W(k - nu) W*(l - nu) D_k e^(-2 pi i ..)] / P0^2
//
// (S segments, P0 = int |W|^2; the lags whose segments share no sample are left out: their A_j
// vanishes). The integrals run over kLeakageSubBins points per line, kLeakageHalfWidth lines on each
// side; W(nu) = (1 / nfft) sum_j W_j D_nfft(nu - j) from the window's DFT bins (exact for the periodic
// cosine windows). Checked against scipy Welch estimates of a noise-free resonance (per line and
// propagated through a fit: tests/dsp/leakage_covariance_test.cpp, docs/uncertainty.md).
//
// Where it does not hold: an excitation that is periodic in the segment (a multisine synchronized with
// nfft) has no leakage error at all; this covariance then overstates the error (conservative).
#include <Eigen/Dense>
#include <complex>
#include <functional>
#include <vector>

#include "piezobench/core/fit_covariance.hpp"

#include "piezobench/dsp/resolution_kernel.hpp"

namespace piezobench::dsp {

inline constexpr int kLeakageSubBins = 8;      // integration points per line
inline constexpr long kLeakageHalfWidth = 6;   // lines of the window's DTFT on each side
inline constexpr long kLeakageMaxLineDistance = 8;  // lines apart at most for a nonzero covariance

// The leakage error e_k = H1_k - E[H1_k] at n consecutive lines of the estimate, in H's units squared,
// banded: lines more than kLeakageMaxLineDistance apart are uncorrelated.
struct LeakageCovariance {
  Eigen::MatrixXcd upper;         // n x (kLeakageMaxLineDistance + 1): upper(k, d) = E[e_k e_(k+d)^*]
  Eigen::MatrixXcd upper_pseudo;  // the same for E[e_k e_(k+d)]
  [[nodiscard]] Eigen::Index lines() const { return upper.rows(); }
  [[nodiscard]] std::complex<double> covariance(Eigen::Index k, Eigen::Index l) const;  // E[e_k e_l^*] (Hermitian)
  [[nodiscard]] std::complex<double> pseudo(Eigen::Index k, Eigen::Index l) const;      // E[e_k e_l] (symmetric)
};

// Does `kernel` (from the FRF's provenance) say enough for leakage_covariance: window bins, nfft,
// segments and their shift?
[[nodiscard]] bool knows_leakage(const ResolutionKernel& kernel);

// lines: n consecutive lines of the estimate (rad/s, kernel.line_spacing_Hz apart); response(omega)
// the system's response at any omega (rad/s; a model at the solution). InputError when the kernel
// does not know the leakage (knows_leakage) or the lines are not consecutive.
[[nodiscard]] LeakageCovariance leakage_covariance(const ResolutionKernel& kernel, const Eigen::VectorXd& lines,
                                                   const std::function<Eigen::VectorXcd(const Eigen::VectorXd&)>& response);

// Lines whose leakage error a fit's covariance counts: its relative variance (1/gamma_leak^2 - 1) /
// (2 segments) above kLeakageOfNoise of the line's relative noise variance, and 1/gamma_leak^2 - 1 above
// kLeakageLinesFraction of its largest value (gamma_leak: KernelGrid::leakage_coherence of the model).
inline constexpr double kLeakageOfNoise = 0.05;
inline constexpr double kLeakageLinesFraction = 1e-4;
inline constexpr Eigen::Index kLeakageMaxLines = 512;  // lines of one block at most (around its largest leakage)

// The leakage error in a fit's residuals u_k = g_k e_k (e_k the estimate's leakage error at line k,
// g_k the residual's complex sensitivity to it: -a_k G_k / H_k^2 for a_k (G_k / H_k - 1), -a_k for
// a_k (G_k - H_k)), as covariance blocks of the interleaved residuals [Re u_k, Im u_k] starting at row
// first_row (the residual vector's units squared), one per run of consecutive lines whose leakage
// counts (above). lines: the fit's lines (rad/s; a run ends where a line is left out); grid: their
// KernelGrid; noise_relative_std: each line's relative noise std (dimensionless); model_at_nodes: the
// model at grid.nodes(); response: the model at any omega. A run whose covariance or g is not finite is
// left out (its intervals then miss the leakage there) rather than failing the fit's standard errors.
// Empty when the kernel does not know the leakage (knows_leakage) or there are fewer than 2 lines.
[[nodiscard]] std::vector<core::ResidualCovarianceBlock> leakage_residual_blocks(
    const ResolutionKernel& kernel, const KernelGrid& grid, const Eigen::VectorXd& lines, const Eigen::VectorXcd& g,
    const Eigen::VectorXd& noise_relative_std, const Eigen::VectorXcd& model_at_nodes,
    const std::function<Eigen::VectorXcd(const Eigen::VectorXd&)>& response, Eigen::Index first_row = 0);

}  // namespace piezobench::dsp
