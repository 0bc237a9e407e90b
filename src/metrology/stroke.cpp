#include "piezobench/metrology/stroke.hpp"

#include "piezobench/metrology/uncertainty_budget.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "check.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"

namespace piezobench::metrology {

using Eigen::Index;
using Eigen::VectorXd;

void StrokeOptions::validate() const {
  detail::require_finite_nonnegative(smoothing_s, "stroke options", "smoothing_s", "s");
}

void HysteresisOptions::validate() const {
  if (skip_periods < 0) throw InputError("hysteresis options", "skip_periods", "an integer >= 0", std::to_string(skip_periods));
}

namespace {

// Centred moving average over `w` samples (shorter at the ends).
VectorXd moving_average(const Eigen::Ref<const VectorXd>& x, Index w) {
  if (w <= 1) return x;
  const Index n = x.size();
  VectorXd cum(n + 1);
  cum(0) = 0.0;
  for (Index i = 0; i < n; ++i) cum(i + 1) = cum(i) + x(i);
  VectorXd y(n);
  const Index half = w / 2;
  for (Index i = 0; i < n; ++i) {
    const Index a = std::max<Index>(0, i - half);
    const Index b = std::min<Index>(n, i - half + w);
    y(i) = (cum(b) - cum(a)) / static_cast<double>(b - a);
  }
  return y;
}

struct Crossings {
  std::vector<double> rising, falling;  // d_e interpolated where Va crosses the level
  Index first_used = -1;                // sample of the first crossing kept
};

// Crossings of `level` by va, armed by a Schmitt trigger at level -+ hysteresis (0: plain sign
// changes). The first `skip` crossings of each direction are dropped.
Crossings crossings(const Eigen::Ref<const VectorXd>& va, const Eigen::Ref<const VectorXd>& de, double level,
                    double hysteresis, int skip) {
  // kBelow: was below level - hysteresis, a rising crossing counts; kAbove: the opposite.
  enum class State { kUnknown, kBelow, kAbove, kDone };
  Crossings c;
  State state = State::kUnknown;
  int seen_up = 0;
  int seen_down = 0;
  for (Index k = 0; k < va.size(); ++k) {
    if (k > 0) {
      const double a = va(k - 1) - level;
      const double b = va(k) - level;
      if (state == State::kBelow && a < 0.0 && b >= 0.0) {
        if (seen_up++ >= skip) {
          c.rising.push_back(de(k - 1) + a / (a - b) * (de(k) - de(k - 1)));
          if (c.first_used < 0) c.first_used = k - 1;
        }
        state = State::kDone;
      } else if (state == State::kAbove && a > 0.0 && b <= 0.0) {
        if (seen_down++ >= skip) {
          c.falling.push_back(de(k - 1) + a / (a - b) * (de(k) - de(k - 1)));
          if (c.first_used < 0) c.first_used = k - 1;
        }
        state = State::kDone;
      }
    }
    if (va(k) < level - hysteresis) state = State::kBelow;
    if (va(k) > level + hysteresis) state = State::kAbove;
  }
  return c;
}

double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (const double x : v) s += x;
  return s / static_cast<double>(v.size());
}

}  // namespace

StrokeResult analyze_stroke(const Eigen::Ref<const VectorXd>& va, const Eigen::Ref<const VectorXd>& de, double fs,
                            const StrokeOptions& options, const std::string& source) {
  options.validate();
  detail::require_finite_positive(fs, source, "sample rate", "Hz");
  detail::require_signal(va, source, "Va", 10);
  detail::require_signal(de, source, "de", 10);
  detail::require_same_length(va.size(), de.size(), source, "de");
  const Index w = std::max<Index>(1, static_cast<Index>(std::lround(options.smoothing_s * fs)));
  const VectorXd vs = moving_average(va, w);
  const VectorXd ds = moving_average(de, w);
  StrokeResult r;
  r.va_min = va.minCoeff();
  r.va_max = va.maxCoeff();
  if (r.va_max - r.va_min < 1.0) {
    throw InputError(source, "Va", "a voltage ramp spanning at least 1 V", fmt::format("{} V", format_number(r.va_max - r.va_min)));
  }
  r.stroke = ds.maxCoeff() - ds.minCoeff();
  r.noise = noise_from_second_differences({de.data(), static_cast<std::size_t>(de.size())});
  r.smoothing_samples = static_cast<long>(w);
  // Straight line d_e = a + b Va (least squares).
  const double vm = va.mean();
  const double dm = de.mean();
  r.sensitivity = ((va.array() - vm) * (de.array() - dm)).sum() / (va.array() - vm).square().sum();
  // Loop width: rising vs falling branch on a grid inside the smoothed voltage range.
  const double lo = vs.minCoeff();
  const double hi = vs.maxCoeff();
  for (int i = 1; i < 50; ++i) {
    const double level = lo + (hi - lo) * i / 50.0;
    const Crossings c = crossings(vs, ds, level, 0.0, 0);
    if (c.rising.empty() || c.falling.empty()) continue;
    r.loop_width = std::max(r.loop_width, std::abs(mean(c.rising) - mean(c.falling)));
  }
  return r;
}

HysteresisResult analyze_hysteresis(const Eigen::Ref<const VectorXd>& va, const Eigen::Ref<const VectorXd>& de,
                                    const HysteresisOptions& options, const std::string& source) {
  options.validate();
  detail::require_signal(va, source, "Va", 10);
  detail::require_signal(de, source, "de", 10);
  detail::require_same_length(va.size(), de.size(), source, "de");
  // The sine lies between the first and the last maximum of Va: ramps in and out (from and to 0 V)
  // are outside. A record without a trough between two maxima is used whole.
  const double top = va.maxCoeff();
  const double range = top - va.minCoeff();
  Index first = 0;
  while (first < va.size() && va(first) < top - 0.02 * range) ++first;
  Index last = va.size() - 1;
  while (last > 0 && va(last) < top - 0.02 * range) --last;
  Index from = 0;
  Index count = va.size();
  if (last > first && va.segment(first, last - first + 1).minCoeff() < top - 0.1 * range) {
    from = first;
    count = last - first + 1;
  }
  const auto v = va.segment(from, count);
  const auto d = de.segment(from, count);
  HysteresisResult r;
  const double hi = v.maxCoeff();
  const double lo = v.minCoeff();
  r.offset = 0.5 * (hi + lo);
  r.amplitude = 0.5 * (hi - lo);
  if (r.amplitude < 0.1) {
    throw InputError(source, "Va", "a sine of amplitude >= 0.1 V", fmt::format("{} V", format_number(r.amplitude)));
  }
  const Crossings c = crossings(v, d, r.offset, 0.5 * r.amplitude, options.skip_periods);
  if (c.rising.empty() || c.falling.empty()) {
    throw InputError(source, "Va",
                     fmt::format("at least {} periods of the sine (rising and falling through the offset {} V)",
                                 options.skip_periods + 1, format_number(r.offset)),
                     fmt::format("{} rising and {} falling crossings after the first {} periods",
                                 c.rising.size(), c.falling.size(), options.skip_periods));
  }
  r.width = std::abs(mean(c.rising) - mean(c.falling));
  r.periods = static_cast<int>(std::min(c.rising.size(), c.falling.size()));
  // Peak-to-peak displacement over the periods used.
  const Index start = options.skip_periods > 0 ? c.first_used : 0;
  const auto used = d.segment(start, d.size() - start);
  r.loop_stroke = used.maxCoeff() - used.minCoeff();
  r.relative_width = r.loop_stroke > 0.0 ? r.width / r.loop_stroke : 0.0;
  r.first_sample = from;
  r.samples = count;
  return r;
}

}  // namespace piezobench::metrology
