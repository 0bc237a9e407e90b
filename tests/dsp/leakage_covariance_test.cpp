#include "piezobench/dsp/leakage_covariance.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "piezobench/core/error.hpp"
#include "piezobench/dsp/welch.hpp"

namespace piezobench::dsp {
namespace {

using Complex = std::complex<double>;

// y(n) = u(n) - a1 y(n-1) - a2 y(n-2): a resonance at fn Hz (fs 64 Hz), white Gaussian input, no noise.
struct Resonator {
  double fs = 64.0, a1 = 0.0, a2 = 0.0;
  Resonator(double fn, double zeta) {
    const double wn = 2.0 * std::numbers::pi * fn / fs, r = std::exp(-zeta * wn), wd = wn * std::sqrt(1.0 - zeta * zeta);
    a1 = -2.0 * r * std::cos(wd);
    a2 = r * r;
  }
  [[nodiscard]] Complex h(double omega) const {
    const Complex z = std::polar(1.0, -omega / fs);
    return 1.0 / (1.0 + a1 * z + a2 * z * z);
  }
};

// The kernel of a Welch estimate with the segments' layout: hann, 256 samples at 64 Hz, 50 %, 9 segments.
ResolutionKernel hann_kernel_of_nine_segments() {
  FrfProvenance p;
  p.window = "hann-periodic";
  p.nfft = 256;
  p.overlap = 0.5;
  p.averages = 9;
  p.sample_rate = 64.0;
  return resolution_kernel(p);
}

// The leakage error of noise-free H1 estimates of a sharp resonance (10 Hz, zeta 0.05: four 0.25 Hz lines
// wide, as the virtual bench's resonance is 4.6 of its lines), hann at 50 %, 9 segments of 256 samples per
// record, 800 records: the empirical covariance E[e e^*], the one of the next line and the pseudo-covariance
// E[e e] at the 9 lines around the peak agree with leakage_covariance within 20 % of the line's variance
// (the Monte Carlo's own spread is 5-7 %; the prediction runs 1-12 % below it, the ratio's terms of order
// 1 / segments). The pseudo-covariance is a fifth of the variance at the peak: an error that is not
// circular, which the neighbouring-lines model of the noise cannot carry.
TEST(LeakageCovariance, PredictsTheNoiseFreeWelchEstimatesScatter) {
  const Resonator res(10.0, 0.05);
  const Eigen::Index nfft = 256, length = 5 * nfft, warmup = 4000, records = 800;
  WelchOptions o;
  o.nfft = nfft;
  o.overlap = 0.5;
  o.threads = 1;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  const Eigen::Index first = 30, count = 21;  // lines 7.5 .. 12.5 Hz
  std::vector<Eigen::VectorXcd> h;
  Frf last;
  for (Eigen::Index r = 0; r < records; ++r) {
    Eigen::VectorXd u(length), y(length);
    double y1 = 0.0, y2 = 0.0;
    for (Eigen::Index i = -warmup; i < length; ++i) {
      const double ui = g(rng), yi = ui - res.a1 * y1 - res.a2 * y2;
      y2 = y1;
      y1 = yi;
      if (i >= 0) {
        u(i) = ui;
        y(i) = yi;
      }
    }
    last = estimate_frf(channel("u", u), {channel("y", y)}, res.fs, o).frf;
    h.push_back(last.H[0].segment(first, count));
  }
  Eigen::VectorXcd mean = Eigen::VectorXcd::Zero(count);
  for (const auto& v : h) mean += v / static_cast<double>(records);
  Eigen::MatrixXcd cov = Eigen::MatrixXcd::Zero(count, count), pseudo = Eigen::MatrixXcd::Zero(count, count);
  for (const auto& v : h) {
    const Eigen::VectorXcd e = v - mean;
    cov += e * e.adjoint() / static_cast<double>(records - 1);
    pseudo += e * e.transpose() / static_cast<double>(records - 1);
  }
  const ResolutionKernel kernel = resolution_kernel(last.provenance);
  ASSERT_TRUE(knows_leakage(kernel));
  EXPECT_EQ(kernel.segments, 9);
  EXPECT_EQ(kernel.segment_shift, 128);
  const Eigen::VectorXd lines = 2.0 * std::numbers::pi * last.freq_Hz.segment(first, count);
  const auto response = [&](const Eigen::VectorXd& omega) {
    Eigen::VectorXcd out(omega.size());
    for (Eigen::Index i = 0; i < omega.size(); ++i) out(i) = res.h(omega(i));
    return out;
  };
  const LeakageCovariance predicted = leakage_covariance(kernel, lines, response);
  for (Eigen::Index k = 6; k <= 14; ++k) {
    const double var = cov(k, k).real();
    std::printf("%.2f Hz: var %.4g predicted %.4g; next %.3g%+.3gi predicted %.3g%+.3gi; pseudo %.3g%+.3gi predicted %.3g%+.3gi\n",
                last.freq_Hz(first + k), var, predicted.covariance(k, k).real(), cov(k, k + 1).real(), cov(k, k + 1).imag(),
                predicted.covariance(k, k + 1).real(), predicted.covariance(k, k + 1).imag(), pseudo(k, k).real(), pseudo(k, k).imag(),
                predicted.pseudo(k, k).real(), predicted.pseudo(k, k).imag());
    EXPECT_NEAR(predicted.covariance(k, k).real(), var, 0.2 * var) << k;
    EXPECT_LT(std::abs(predicted.covariance(k, k + 1) - cov(k, k + 1)), 0.2 * var) << k;
    EXPECT_LT(std::abs(predicted.pseudo(k, k) - pseudo(k, k)), 0.2 * var) << k;
  }
  EXPECT_GT(std::abs(pseudo(10, 10)), 0.1 * cov(10, 10).real());  // not circular at the peak
  // Hermitian and symmetric by construction; lines more than kLeakageMaxLineDistance apart: 0 (the
  // Monte Carlo's there is below its own spread).
  EXPECT_EQ(predicted.covariance(12, 9), std::conj(predicted.covariance(9, 12)));
  EXPECT_EQ(predicted.pseudo(12, 9), predicted.pseudo(9, 12));
  EXPECT_EQ(predicted.covariance(0, kLeakageMaxLineDistance + 1), Complex(0.0));
  EXPECT_LT(std::abs(cov(6, 6 + kLeakageMaxLineDistance + 1)), 0.05 * cov(6, 6).real());
}

TEST(LeakageCovariance, NeedsTheSegmentsLayoutAndConsecutiveLines) {
  const ResolutionKernel bare = resolution_kernel(WindowType::kHannPeriodic, 256, 64.0);  // no segments
  EXPECT_FALSE(knows_leakage(bare));
  const auto flat = [](const Eigen::VectorXd& omega) { return Eigen::VectorXcd::Ones(omega.size()); };
  const Eigen::VectorXd lines = Eigen::VectorXd::LinSpaced(5, 10.0, 10.0 + 4.0 * 2.0 * std::numbers::pi * 0.25);
  EXPECT_THROW((void)leakage_covariance(bare, lines, flat), InputError);
  const ResolutionKernel k = hann_kernel_of_nine_segments();
  ASSERT_TRUE(knows_leakage(k));
  Eigen::VectorXd gap = lines;
  gap(4) += 2.0 * std::numbers::pi * 0.25;
  EXPECT_THROW((void)leakage_covariance(k, gap, flat), InputError);
  // A flat response has no leakage error.
  const LeakageCovariance none = leakage_covariance(k, lines, flat);
  EXPECT_LT(none.upper.cwiseAbs().maxCoeff(), 1e-20);
  EXPECT_LT(none.upper_pseudo.cwiseAbs().maxCoeff(), 1e-20);
}

// The blocks a fit's covariance gets (leakage_residual_blocks): a resonance of 40 lines (10 Hz, zeta 0.05
// at 64 Hz, 256-sample hann at 50 %), the residuals u_k = g_k e_k. Each block's 2 x 2 entries are the
// real and imaginary parts' covariances of g_i e_i and g_l e_l from leakage_covariance; the rows start at
// first_row + 2 (first line); a line left out of the band ends a run; a line whose leakage variance is
// below a twentieth of its noise variance is left to the noise.
TEST(LeakageCovariance, ResidualBlocksCarryTheSensitivityAndSplitAtGaps) {
  const Resonator res(10.0, 0.05);
  const ResolutionKernel k = hann_kernel_of_nine_segments();
  const double step = 2.0 * std::numbers::pi * 0.25;
  std::vector<double> w;
  for (int i = 20; i <= 60; ++i) {
    if (i != 45) w.push_back(i * step);  // line 45 (11.25 Hz) left out
  }
  const Eigen::VectorXd lines = Eigen::Map<const Eigen::VectorXd>(w.data(), static_cast<Eigen::Index>(w.size()));
  const KernelGrid grid(k, lines);
  const auto response = [&res](const Eigen::VectorXd& omega) {
    Eigen::VectorXcd h(omega.size());
    for (Eigen::Index i = 0; i < omega.size(); ++i) h(i) = res.h(omega(i));
    return h;
  };
  const Eigen::VectorXcd at_nodes = response(grid.nodes());
  const Eigen::Index n = lines.size();
  Eigen::VectorXcd g(n);
  for (Eigen::Index i = 0; i < n; ++i) g(i) = std::polar(0.5 + 0.01 * i, 0.1 * i);
  const Eigen::VectorXd quiet = Eigen::VectorXd::Zero(n);
  const auto blocks = leakage_residual_blocks(k, grid, lines, g, quiet, at_nodes, response, 100);
  ASSERT_EQ(blocks.size(), 2U);  // split at the gap
  EXPECT_EQ(blocks[0].first, 100);
  EXPECT_EQ(blocks[0].covariance.rows(), 2 * 25);  // lines 20 .. 44
  EXPECT_EQ(blocks[1].first, 100 + 2 * 25);
  EXPECT_EQ(blocks[1].covariance.rows(), 2 * 15);  // lines 46 .. 60
  // One entry against leakage_covariance directly: lines 30 and 32 (i = 10, 12) of the first run.
  const LeakageCovariance lc = leakage_covariance(k, lines.head(25), response);
  const Complex cu = g(10) * lc.covariance(10, 12) * std::conj(g(12)), qu = g(10) * lc.pseudo(10, 12) * g(12);
  const Eigen::MatrixXd dense = Eigen::MatrixXd(blocks[0].covariance);
  EXPECT_NEAR(dense(20, 24), 0.5 * (cu + qu).real(), 1e-12 * std::abs(cu));
  EXPECT_NEAR(dense(21, 25), 0.5 * (cu - qu).real(), 1e-12 * std::abs(cu));
  EXPECT_NEAR(dense(20, 25), 0.5 * (qu - cu).imag(), 1e-12 * std::abs(cu));
  EXPECT_NEAR(dense(21, 24), 0.5 * (qu + cu).imag(), 1e-12 * std::abs(cu));
  EXPECT_NEAR((dense - dense.transpose()).cwiseAbs().maxCoeff(), 0.0, 1e-12 * dense.cwiseAbs().maxCoeff());
  // Loud noise everywhere: no block.
  EXPECT_TRUE(leakage_residual_blocks(k, grid, lines, g, Eigen::VectorXd::Constant(n, 10.0), at_nodes, response).empty());
  // A kernel without the segments' layout: none.
  const ResolutionKernel bare = resolution_kernel(WindowType::kHannPeriodic, 256, 64.0);
  EXPECT_TRUE(leakage_residual_blocks(bare, KernelGrid(bare, lines), lines, g, quiet, at_nodes, response).empty());
}

}  // namespace
}  // namespace piezobench::dsp
