#include "piezobench/dsp/resolution_kernel.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

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
  const long most = std::min<long>(kResolutionKernelMaxHalfWidth, static_cast<long>(nfft / 2));
  for (long j = 0; j <= most; ++j) {
    std::complex<double> bin = 0.0;
    for (Eigen::Index k = 0; k < nfft; ++k) {
      bin += w(k) * std::polar(1.0, -2.0 * std::numbers::pi * static_cast<double>(j) * static_cast<double>(k) / n);
    }
    const double c = std::norm(bin) / total;
    if (j > 0 && c < kResolutionKernelFloor) break;
    side.push_back(c);
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
  return resolution_kernel(window, provenance.nfft, provenance.sample_rate);
}

}  // namespace piezobench::dsp
