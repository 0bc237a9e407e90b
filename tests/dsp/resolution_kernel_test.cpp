#include "piezobench/dsp/resolution_kernel.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "piezobench/core/error.hpp"
#include "piezobench/dsp/frf_variance.hpp"
#include "piezobench/dsp/welch.hpp"

namespace piezobench::dsp {
namespace {

using Complex = std::complex<double>;

TEST(ResolutionKernel, CosineWindowsGiveTheirSquaredCoefficients) {
  // Periodic hann 0.5 - 0.5 cos(2 pi n / N): W_0 = N/2, W_+-1 = -N/4, so |W|^2 is 4 : 1 : 1 -> (1/6, 2/3, 1/6).
  const ResolutionKernel hann = resolution_kernel(WindowType::kHannPeriodic, 40000, 10000.0);
  ASSERT_EQ(hann.weights.size(), 3u);
  EXPECT_NEAR(hann.weights[0], 1.0 / 6.0, 1e-12);
  EXPECT_NEAR(hann.weights[1], 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(hann.weights[2], 1.0 / 6.0, 1e-12);
  EXPECT_DOUBLE_EQ(hann.line_spacing_Hz, 0.25);
  EXPECT_TRUE(hann.active());
  // Periodic hamming 0.54 - 0.46 cos: W_0 = 0.54 N, W_+-1 = -0.23 N.
  const ResolutionKernel hamming = resolution_kernel(WindowType::kHammingPeriodic, 1024, 1024.0);
  const double total = 0.54 * 0.54 + 2.0 * 0.23 * 0.23;
  ASSERT_EQ(hamming.weights.size(), 3u);
  EXPECT_NEAR(hamming.weights[1], 0.54 * 0.54 / total, 1e-12);
  EXPECT_NEAR(hamming.weights[0], 0.23 * 0.23 / total, 1e-12);
  EXPECT_DOUBLE_EQ(hamming.line_spacing_Hz, 1.0);
  // Periodic flat-top sum (-1)^k a_k cos: W_0 = a_0 N, W_+-k = +-a_k N / 2: four bins on each side.
  const double a[] = {0.21557895, 0.41663158, 0.277263158, 0.083578947, 0.006947368};
  double ft = a[0] * a[0];
  for (int k = 1; k < 5; ++k) ft += 2.0 * a[k] * a[k] / 4.0;
  const ResolutionKernel flattop = resolution_kernel(WindowType::kFlatTopPeriodic, 2048, 100.0);
  ASSERT_EQ(flattop.weights.size(), 9u);
  EXPECT_NEAR(flattop.weights[4], a[0] * a[0] / ft, 1e-12);
  for (int k = 1; k < 5; ++k) EXPECT_NEAR(flattop.weights[static_cast<std::size_t>(4 + k)], a[k] * a[k] / 4.0 / ft, 1e-12);
  // Rectangular: a single bin, no smoothing on its own grid.
  const ResolutionKernel rect = resolution_kernel(WindowType::kRectangular, 1000, 1000.0);
  EXPECT_EQ(rect.weights.size(), 1u);
  EXPECT_FALSE(rect.active());
}

// The kernel from a provenance carries the adjacent lines' error correlation; adjacent_line_pairs gives
// it for consecutive points one line apart and 0 across a gap; nothing without it.
TEST(ResolutionKernel, AdjacentLinePairsFollowTheGrid) {
  FrfProvenance p;
  p.window = "hann-periodic";
  p.nfft = 4000;
  p.overlap = 0.5;
  p.averages = 9;
  p.sample_rate = 1000.0;  // 0.25 Hz lines
  const ResolutionKernel k = resolution_kernel(p);
  EXPECT_DOUBLE_EQ(k.adjacent_line_correlation, adjacent_line_correlation(WindowType::kHannPeriodic, 4000, 2000, 9));
  const double w0 = 2.0 * std::numbers::pi * 0.25;
  Eigen::VectorXd omega(5);
  omega << 40 * w0, 41 * w0, 42 * w0, 45 * w0, 46 * w0;
  const Eigen::VectorXd pairs = adjacent_line_pairs(k, omega);
  ASSERT_EQ(pairs.size(), 4);
  EXPECT_DOUBLE_EQ(pairs(0), k.adjacent_line_correlation);
  EXPECT_DOUBLE_EQ(pairs(1), k.adjacent_line_correlation);
  EXPECT_EQ(pairs(2), 0.0);
  EXPECT_DOUBLE_EQ(pairs(3), k.adjacent_line_correlation);
  EXPECT_EQ(adjacent_line_pairs(resolution_kernel(WindowType::kHannPeriodic, 4000, 1000.0), omega).size(), 0);
}

TEST(ResolutionKernel, SecondMomentIsTheContinuousKernels) {
  // The continuous |W(nu)|^2's second moment in lines^2 is (N / 2 pi)^2 sum |w'|^2 / sum w^2 (Parseval on
  // the derivative): 1/3 for hann. The sampled kernel has the same, for the symmetric window too (to O(1/N)).
  for (const WindowType type : {WindowType::kHannPeriodic, WindowType::kHannSymmetric, WindowType::kHammingPeriodic}) {
    const Eigen::Index n = 4096;
    const ResolutionKernel k = resolution_kernel(type, n, 1.0);
    double moment = 0.0, sum = 0.0;
    for (long j = -k.half_width(); j <= k.half_width(); ++j) {
      moment += k.weights[static_cast<std::size_t>(j + k.half_width())] * static_cast<double>(j * j);
      sum += k.weights[static_cast<std::size_t>(j + k.half_width())];
    }
    EXPECT_NEAR(sum, 1.0, 1e-14);
    // Continuous window of the same cosine coefficients: hann (0.5, 0.5): (1/2 * 0.25) / 0.375 / 1 = 1/3.
    const double c1 = type == WindowType::kHammingPeriodic ? 0.46 : 0.5, c0 = type == WindowType::kHammingPeriodic ? 0.54 : 0.5;
    const double continuous = (c1 * c1 / 2.0) / (c0 * c0 + c1 * c1 / 2.0);
    EXPECT_NEAR(moment, continuous, type == WindowType::kHannSymmetric ? 2e-3 : 1e-12) << to_string(type);
  }
}

TEST(ResolutionKernel, SmoothsAQuadraticByItsSecondMoment) {
  // H(f) = c0 + c1 f + c2 f^2: hann's (1/6, 2/3, 1/6) gives H + c2 df^2 / 3 (a line is unchanged).
  const ResolutionKernel k = resolution_kernel(WindowType::kHannPeriodic, 400, 100.0);  // df = 0.25 Hz
  const Complex c0(1.0, -2.0), c1(0.3, 0.1), c2(-0.05, 0.02);
  const auto h = [&](double omega) {
    const double f = omega / (2.0 * std::numbers::pi);
    return c0 + c1 * f + c2 * f * f;
  };
  const double f = 37.0, w = 2.0 * std::numbers::pi * f;
  const Complex s = smoothed_response(k, w, h);
  const Complex expected = h(w) + c2 * 0.25 * 0.25 / 3.0;
  EXPECT_NEAR(std::abs(s - expected), 0.0, 1e-12);
  // Inactive kernel: the response itself.
  EXPECT_EQ(smoothed_response(ResolutionKernel{}, w, h), h(w));
  // A vector of outputs goes through as a whole.
  const auto two = [&](double omega) { return Eigen::Vector2cd(h(omega), 2.0 * h(omega)); };
  const Eigen::Vector2cd v = smoothed_response(k, w, two);
  EXPECT_NEAR(std::abs(v(1) - 2.0 * expected), 0.0, 1e-12);
}

TEST(KernelGrid, EvaluatesEachLineOnceAndGivesTheSmoothedResponse) {
  // A 5 Hz resonance on hann's grid of 0.25 Hz lines 2..200, lines 50..52 and 120 missing (low
  // coherence): the nodes are the 195 lines plus the 5 shifted lines not among them (1, 201, 50
  // and 52 next to the gap of three, 120), not 3 x 195.
  const ResolutionKernel k = resolution_kernel(WindowType::kHannPeriodic, 400, 100.0);
  const double dw = 2.0 * std::numbers::pi * 0.25;
  std::vector<double> lines;
  for (int i = 2; i <= 200; ++i) {
    if ((i < 50 || i > 52) && i != 120) lines.push_back(i * dw);
  }
  const Eigen::VectorXd omega = Eigen::Map<const Eigen::VectorXd>(lines.data(), static_cast<Eigen::Index>(lines.size()));
  const double wn = 2.0 * std::numbers::pi * 5.0;
  const auto h = [&](double w) { return wn * wn / Complex(wn * wn - w * w, 2.0 * 0.05 * wn * w); };
  const KernelGrid grid(k, omega);
  ASSERT_EQ(grid.nodes().size(), omega.size() + 5);
  EXPECT_EQ(grid.nodes().head(omega.size()), omega);
  Eigen::MatrixX2cd at_nodes(grid.nodes().size(), 2);
  for (Eigen::Index i = 0; i < grid.nodes().size(); ++i) at_nodes.row(i) << h(grid.nodes()(i)), -3.0 * h(grid.nodes()(i));
  const Eigen::MatrixX2cd smooth = grid.smooth(at_nodes);
  ASSERT_EQ(smooth.rows(), omega.size());
  for (Eigen::Index i = 0; i < omega.size(); ++i) {
    const Complex want = smoothed_response(k, omega(i), h);
    EXPECT_NEAR(std::abs(smooth(i, 0) / want - 1.0), 0.0, 1e-13) << i;  // the lines differ from omega + df by round-off
    EXPECT_NEAR(std::abs(smooth(i, 1) / want + 3.0), 0.0, 1e-13) << i;
  }
  // Frequencies off the grid (and out of order) share nothing: exactly smoothed_response.
  Eigen::VectorXd odd(3);
  odd << 30.1, 10.0, 20.7;
  const KernelGrid apart(k, odd);
  EXPECT_EQ(apart.nodes().size(), 9);
  Eigen::VectorXcd values(apart.nodes().size());
  for (Eigen::Index i = 0; i < values.size(); ++i) values(i) = h(apart.nodes()(i));
  const Eigen::VectorXcd s = apart.smooth(values);
  for (Eigen::Index i = 0; i < odd.size(); ++i) EXPECT_EQ(s(i), smoothed_response(k, odd(i), h));
  // An inactive kernel: the nodes are omega and smooth() the values.
  const KernelGrid none(ResolutionKernel{}, odd);
  EXPECT_EQ(none.nodes(), odd);
  EXPECT_EQ(none.smooth(Eigen::Vector3cd(1.0, 2.0, 3.0)), Eigen::Vector3cd(1.0, 2.0, 3.0));
}

// A resonance of fn Hz and damping zeta (the exact discrete impulse-invariant two-pole filter) driven
// by `segments` 256-sample segments of white noise at 64 Hz, its output noise-free, estimated with
// hann at 50 %; with the filter's exact response h(omega).
struct ResonanceRecord {
  double fs = 64.0, a1 = 0.0, a2 = 0.0;
  Frf frf;
  [[nodiscard]] Complex h(double omega) const {
    const Complex z = std::polar(1.0, -omega / fs);  // z^-1
    return 1.0 / (1.0 + a1 * z + a2 * z * z);
  }
};
ResonanceRecord resonance_record(double fn, double zeta, Eigen::Index segments, unsigned seed) {
  ResonanceRecord out;
  const Eigen::Index nfft = 256, n = nfft * segments;
  const double wn = 2.0 * std::numbers::pi * fn / out.fs, r = std::exp(-zeta * wn), wd = wn * std::sqrt(1.0 - zeta * zeta);
  out.a1 = -2.0 * r * std::cos(wd);
  out.a2 = r * r;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::VectorXd u(n), y(n);
  double y1 = 0.0, y2 = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    u(i) = g(rng);
    const double yi = u(i) - out.a1 * y1 - out.a2 * y2;
    y(i) = yi;
    y2 = y1;
    y1 = yi;
  }
  WelchOptions o;
  o.nfft = nfft;
  o.overlap = 0.5;
  o.threads = 1;
  out.frf = estimate_frf(channel("u", u), {channel("y", y)}, out.fs, o).frf;
  return out;
}

TEST(ResolutionKernel, WelchEstimateOfAResonanceConvergesToTheSmoothedResponse) {
  // A resonance of 10 Hz, zeta 0.05 (half-power width 1 Hz, four 0.25 Hz lines, as the virtual bench's
  // resonance is 16 of its lines) driven by white noise, noise-free output, estimated with hann at 50 %:
  // at the peak the estimate is ~7 % below H (H'' df^2 / 6 to second order) and within its random error
  // (0.4-1 % at the peak for 800 segments, seeds 4-6; 2.5 % for seed 3) of the smoothed response. The
  // continuous kernel's expectation differs from the three sampled bins by 0.2 % there (numpy, not here).
  const double fn = 10.0;
  const ResonanceRecord rec = resonance_record(fn, 0.05, 400, 4);
  const Frf& frf = rec.frf;
  const auto h = [&](double omega) { return rec.h(omega); };
  const ResolutionKernel k = resolution_kernel(frf.provenance);
  ASSERT_TRUE(k.active());
  double raw = 0.0, smooth = 0.0;
  for (Eigen::Index i = 0; i < frf.freq_Hz.size(); ++i) {
    if (std::abs(frf.freq_Hz(i) - fn) > 0.6) continue;
    const double w = 2.0 * std::numbers::pi * frf.freq_Hz(i);
    raw = std::max(raw, std::abs(frf.H[0](i) / h(w) - 1.0));
    smooth = std::max(smooth, std::abs(frf.H[0](i) / smoothed_response(k, w, h) - 1.0));
  }
  EXPECT_GT(raw, 0.05);
  EXPECT_LT(smooth, raw / 4.0);
  std::printf("peak error against H %.4f, against the smoothed H %.4f\n", raw, smooth);
}

// The coherence of a noise-free Welch estimate of a sharp resonance drops at the peak by the window's
// leakage alone; KernelGrid::leakage_coherence (|sum c R|^2 / sum c |R|^2 of the sampled kernel)
// predicts that drop. The same resonance as above (10 Hz, zeta 0.05, four lines wide), 400 segments,
// no noise: within 0.6 Hz of the peak the measured 1 - gamma^2 and the predicted one agree within a
// third (their largest values: printed); a flat response has coherence 1; an inactive kernel gives 1.
TEST(ResolutionKernel, LeakageCoherencePredictsTheNoiseFreeEstimatesCoherence) {
  const double fn = 10.0;
  const ResonanceRecord rec = resonance_record(fn, 0.05, 200, 5);
  const Frf& frf = rec.frf;
  const auto h = [&](double omega) { return rec.h(omega); };
  const ResolutionKernel k = resolution_kernel(frf.provenance);
  std::vector<Eigen::Index> near;
  for (Eigen::Index i = 0; i < frf.freq_Hz.size(); ++i) {
    if (std::abs(frf.freq_Hz(i) - fn) <= 0.6) near.push_back(i);
  }
  Eigen::VectorXd omega(static_cast<Eigen::Index>(near.size()));
  for (std::size_t j = 0; j < near.size(); ++j) omega(static_cast<Eigen::Index>(j)) = 2.0 * std::numbers::pi * frf.freq_Hz(near[j]);
  const KernelGrid grid(k, omega);
  Eigen::VectorXcd at_nodes(grid.nodes().size());
  for (Eigen::Index i = 0; i < at_nodes.size(); ++i) at_nodes(i) = h(grid.nodes()(i));
  const Eigen::VectorXd leak = grid.leakage_coherence(at_nodes);
  double measured_max = 0.0, predicted_max = 0.0;
  for (std::size_t j = 0; j < near.size(); ++j) {
    const double measured = 1.0 - frf.coherence[0](near[j]), predicted = 1.0 - leak(static_cast<Eigen::Index>(j));
    measured_max = std::max(measured_max, measured);
    predicted_max = std::max(predicted_max, predicted);
    EXPECT_NEAR(predicted, measured, measured / 3.0) << frf.freq_Hz(near[j]) << " Hz";
  }
  std::printf("1 - coherence near the peak: measured up to %.4f, predicted up to %.4f\n", measured_max, predicted_max);
  EXPECT_GT(measured_max, 0.005);
  const Eigen::VectorXd flat = grid.leakage_coherence(Eigen::VectorXcd::Constant(grid.nodes().size(), Complex(2.0, -1.0)));
  EXPECT_LT((flat.array() - 1.0).abs().maxCoeff(), 1e-15);
  const KernelGrid none(ResolutionKernel{}, omega);
  EXPECT_EQ(none.leakage_coherence(at_nodes.head(omega.size())), Eigen::VectorXd::Ones(omega.size()));
}

TEST(ResolutionKernel, ProvenanceGivesTheKernelOrNone) {
  FrfProvenance p;
  EXPECT_FALSE(resolution_kernel(p).active());
  p.window = "hann";
  p.nfft = 40000;
  p.sample_rate = 10000.0;
  const ResolutionKernel k = resolution_kernel(p);
  EXPECT_TRUE(k.active());
  EXPECT_DOUBLE_EQ(k.line_spacing_Hz, 0.25);
  p.window = "kaiser";  // not one of ours: its kernel is unknown
  EXPECT_FALSE(resolution_kernel(p).active());
  EXPECT_THROW((void)resolution_kernel(WindowType::kHannPeriodic, 1, 10.0), InputError);
  EXPECT_THROW((void)resolution_kernel(WindowType::kHannPeriodic, 64, 0.0), InputError);
}

}  // namespace
}  // namespace piezobench::dsp
