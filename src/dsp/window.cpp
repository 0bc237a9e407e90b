#include "piezobench/dsp/window.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <numbers>
#include <utility>

#include "piezobench/core/error.hpp"

namespace piezobench::dsp {
namespace {

constexpr std::array<std::pair<WindowType, const char*>, 8> kNames{{
    {WindowType::kRectangular, "rectangular"},
    {WindowType::kHanning, "hanning"},
    {WindowType::kHannPeriodic, "hann-periodic"},
    {WindowType::kHannSymmetric, "hann-symmetric"},
    {WindowType::kHammingPeriodic, "hamming-periodic"},
    {WindowType::kHammingSymmetric, "hamming-symmetric"},
    {WindowType::kFlatTopPeriodic, "flattop-periodic"},
    {WindowType::kFlatTopSymmetric, "flattop-symmetric"},
}};

// Other programs' names (scipy.signal.get_window, MATLAB/Octave functions), matched without case.
constexpr std::array<std::pair<WindowType, const char*>, 7> kAliases{{
    {WindowType::kHannPeriodic, "hann"},          // scipy "hann" (periodic, its Welch default)
    {WindowType::kHammingPeriodic, "hamming"},    // scipy "hamming"
    {WindowType::kFlatTopPeriodic, "flattop"},    // scipy "flattop"
    {WindowType::kFlatTopSymmetric, "flattopwin"},  // MATLAB flattopwin(M)
    {WindowType::kRectangular, "boxcar"},         // scipy
    {WindowType::kRectangular, "rectwin"},        // MATLAB
    {WindowType::kRectangular, "rect"},
}};

// scipy.signal.windows.flattop (and MATLAB flattopwin).
constexpr std::array<double, 5> kFlatTop{0.21557895, 0.41663158, 0.277263158, 0.083578947, 0.006947368};

// sum_k a_k cos(k x_n), x_n = -pi + 2 pi n / (m - 1): scipy's general_cosine on a symmetric grid of m
// points. Evaluated the same way as scipy (cos of k times the linspace value) so that the windows
// agree to the last bits, not only to round-off.
Eigen::VectorXd general_cosine_symmetric(Eigen::Index m, const double* a, std::size_t terms) {
  Eigen::VectorXd w = Eigen::VectorXd::Zero(m);
  const double pi = std::numbers::pi;
  const double step = 2.0 * pi / static_cast<double>(m - 1);
  for (Eigen::Index n = 0; n < m; ++n) {
    // numpy.linspace(-pi, pi, m): start + n * step, last point set to stop exactly.
    const double x = (n == m - 1) ? pi : -pi + static_cast<double>(n) * step;
    double sum = 0.0;
    for (std::size_t k = 0; k < terms; ++k) sum += a[k] * std::cos(static_cast<double>(k) * x);
    w(n) = sum;
  }
  return w;
}

bool is_periodic(WindowType type) {
  return type == WindowType::kHannPeriodic || type == WindowType::kHammingPeriodic ||
         type == WindowType::kFlatTopPeriodic;
}

}  // namespace

std::string to_string(WindowType type) {
  for (const auto& [t, name] : kNames) {
    if (t == type) return name;
  }
  return "unknown";
}

WindowType window_type_from_string(const std::string& name) {
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  std::string known;
  for (const auto& [t, n] : kNames) {
    if (lower == n) return t;
    known += known.empty() ? n : std::string(", ") + n;
  }
  for (const auto& [t, n] : kAliases) {
    if (lower == n) return t;
    known += std::string(", ") + n + " (= " + to_string(t) + ")";
  }
  throw InputError("", "window", "one of " + known, "\"" + name + "\"");
}

Eigen::VectorXd make_window(WindowType type, Eigen::Index length) {
  if (length < 1) throw InputError("", "window length", "at least 1", std::to_string(length));
  if (length == 1 || type == WindowType::kRectangular) return Eigen::VectorXd::Ones(length);
  if (type == WindowType::kHanning) {
    // MATLAB hanning(M) = hann(M + 2) without its two zero end points.
    const double a[2] = {0.5, 0.5};
    return general_cosine_symmetric(length + 2, a, 2).segment(1, length);
  }
  // Periodic windows are the first `length` points of the symmetric window of length + 1
  // (scipy's _extend/_truncate), i.e. one full period sampled without its repeated end point.
  const Eigen::Index m = is_periodic(type) ? length + 1 : length;
  Eigen::VectorXd w;
  switch (type) {
    case WindowType::kHannPeriodic:
    case WindowType::kHannSymmetric: {
      const double a[2] = {0.5, 0.5};
      w = general_cosine_symmetric(m, a, 2);
      break;
    }
    case WindowType::kHammingPeriodic:
    case WindowType::kHammingSymmetric: {
      const double a[2] = {0.54, 0.46};
      w = general_cosine_symmetric(m, a, 2);
      break;
    }
    case WindowType::kFlatTopPeriodic:
    case WindowType::kFlatTopSymmetric:
      w = general_cosine_symmetric(m, kFlatTop.data(), kFlatTop.size());
      break;
    case WindowType::kRectangular:
    case WindowType::kHanning:
      break;
  }
  return w.head(length);
}

}  // namespace piezobench::dsp
