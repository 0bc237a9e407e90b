#include "piezobench/dsp/resolution_kernel.hpp"

#include "piezobench/dsp/frf_variance.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>

#include "piezobench/core/error.hpp"

namespace piezobench::dsp {

ResolutionKernel resolution_kernel(WindowType window, Eigen::Index nfft, double sample_rate_Hz) {
  const std::string src = "resolution kernel";
  if (nfft < 2) throw InputError(src, "nfft", "at least 2 samples", std::to_string(nfft));
  if (!(std::isfinite(sample_rate_Hz) && sample_rate_Hz > 0.0)) {
    throw InputError(src, "sample_rate", "a finite rate > 0 Hz", fmt::format("{}", sample_rate_Hz));
  }
  const Eigen::VectorXd w = make_window(window, nfft);
  const double n = static_cast<double>(nfft);
  const double total = n * w.squaredNorm();  // sum over all bins of |W_j|^2 (Parseval)
  // |W_j|^2 / total for j = 0 .. K; a real window has |W_-j| = |W_j|.
  std::vector<double> side;
  std::vector<std::complex<double>> bins;
  const long most = std::min<long>(kResolutionKernelMaxHalfWidth, static_cast<long>(nfft / 2));
  for (long j = 0; j <= most; ++j) {
    std::complex<double> bin = 0.0;
    for (Eigen::Index k = 0; k < nfft; ++k) {
      bin += w(k) * std::polar(1.0, -2.0 * std::numbers::pi * static_cast<double>(j) * static_cast<double>(k) / n);
    }
    const double c = std::norm(bin) / total;
    if (j > 0 && c < kResolutionKernelFloor) break;
    side.push_back(c);
    bins.push_back(bin);
  }
  ResolutionKernel kernel;
  kernel.line_spacing_Hz = sample_rate_Hz / n;
  const auto half = static_cast<long>(side.size()) - 1;
  kernel.weights.resize(static_cast<std::size_t>(2 * half + 1));
  double sum = 0.0;
  for (long j = -half; j <= half; ++j) {
    const double c = side[static_cast<std::size_t>(std::abs(j))];
    kernel.weights[static_cast<std::size_t>(j + half)] = c;
    sum += c;
  }
  for (double& c : kernel.weights) c /= sum;
  kernel.nfft = nfft;
  kernel.window_bins.resize(kernel.weights.size());
  for (long j = -half; j <= half; ++j) {
    const std::complex<double> b = bins[static_cast<std::size_t>(std::abs(j))];
    kernel.window_bins[static_cast<std::size_t>(j + half)] = j < 0 ? std::conj(b) : b;  // a real window
  }
  return kernel;
}

ResolutionKernel resolution_kernel(const FrfProvenance& provenance) {
  if (provenance.window.empty() || provenance.nfft < 2 || !(std::isfinite(provenance.sample_rate) && provenance.sample_rate > 0.0)) {
    return {};
  }
  WindowType window{};
  try {
    window = window_type_from_string(provenance.window);
  } catch (const InputError&) {
    return {};  // a window this library does not know (a foreign file's): its kernel is unknown
  }
  ResolutionKernel kernel = resolution_kernel(window, provenance.nfft, provenance.sample_rate);
  kernel.adjacent_line_correlation = adjacent_line_correlation(provenance);
  if (const std::optional<WelchLayout> l = welch_layout(provenance)) {
    kernel.segments = provenance.averages;
    kernel.segment_shift = provenance.nfft - l->noverlap;
  }
  return kernel;
}

Eigen::VectorXd adjacent_line_pairs(const ResolutionKernel& kernel, const Eigen::VectorXd& omega) {
  const double rho = kernel.adjacent_line_correlation;
  if (!(rho > 0.0 && kernel.line_spacing_Hz > 0.0) || omega.size() < 2) return {};
  const double step = 2.0 * std::numbers::pi * kernel.line_spacing_Hz;
  Eigen::VectorXd c = Eigen::VectorXd::Zero(omega.size() - 1);
  for (Eigen::Index k = 0; k + 1 < omega.size(); ++k) {
    if (std::abs(omega(k + 1) - omega(k) - step) <= 1e-6 * step) c(k) = rho;
  }
  return c;
}

KernelGrid::KernelGrid(const ResolutionKernel& kernel, const Eigen::VectorXd& omega) : points_(omega.size()), nodes_(omega) {
  if (!kernel.active()) return;
  weights_ = kernel.weights;
  const long half = kernel.half_width();
  const auto width = static_cast<Eigen::Index>(2 * half + 1);
  const double step = 2.0 * std::numbers::pi * kernel.line_spacing_Hz;  // rad/s per line, as smoothed_response
  const double tol = 1e-6 * step;
  const bool ascending = std::is_sorted(omega.data(), omega.data() + omega.size());
  std::vector<double> extra;                  // shifted frequencies not in omega
  std::map<long long, Eigen::Index> by_line;  // their line offset from omega(0) -> node
  const auto node_of = [&](double t) -> Eigen::Index {
    if (ascending && omega.size() > 0) {
      const double* first = omega.data();
      const double* last = first + omega.size();
      const double* it = std::lower_bound(first, last, t);
      for (const double* c : {it, it == first ? it : it - 1}) {
        if (c != last && std::abs(*c - t) <= tol) return static_cast<Eigen::Index>(c - first);
      }
    }
    const double lines = omega.size() > 0 ? (t - omega(0)) / step : 0.0;
    const bool keyed = std::abs(lines) < 1e15;
    const long long key = keyed ? std::llround(lines) : 0;
    if (keyed) {
      if (const auto found = by_line.find(key); found != by_line.end()) {
        const double there = extra[static_cast<std::size_t>(found->second - omega.size())];
        if (std::abs(there - t) <= tol) return found->second;
      }
    }
    const auto node = omega.size() + static_cast<Eigen::Index>(extra.size());
    extra.push_back(t);
    if (keyed) by_line.emplace(key, node);
    return node;
  };
  index_.resize(static_cast<std::size_t>(omega.size() * width));
  for (Eigen::Index k = 0; k < omega.size(); ++k) {
    Eigen::Index* at = index_.data() + k * width + half;
    at[0] = k;
    for (long j = 1; j <= half; ++j) {
      const double delta = static_cast<double>(j) * step;
      at[j] = node_of(detail::shifted(omega(k), delta));
      at[-j] = node_of(detail::shifted(omega(k), -delta));
    }
  }
  nodes_.conservativeResize(omega.size() + static_cast<Eigen::Index>(extra.size()));
  for (std::size_t i = 0; i < extra.size(); ++i) nodes_(omega.size() + static_cast<Eigen::Index>(i)) = extra[i];
}

}  // namespace piezobench::dsp
