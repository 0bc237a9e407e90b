#include "piezobench/rt/timing.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <ctime>

namespace piezobench::rt {

void TimingHistogram::add(double ns) noexcept {
  if (!(ns > 0.0)) ns = 0.0;  // also NaN
  ns = std::min(ns, 1e300);   // +inf: the last bin (its log must convert to an int)
  int bin = 0;
  if (ns > 1.0) {
    bin = static_cast<int>(std::floor(std::log10(ns) * kBinsPerDecade));
    bin = std::clamp(bin, 0, kBins - 1);
  }
  ++bins_[static_cast<std::size_t>(bin)];
  ++count_;
  max_ = std::max(max_, ns);
  sum_ += ns;
}

double TimingHistogram::percentile(double q) const noexcept {
  if (count_ == 0) return 0.0;
  q = std::clamp(q, 0.0, 1.0);
  const auto rank = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(count_))));
  if (rank >= count_) return max_;  // the largest sample is known exactly
  std::uint64_t seen = 0;
  for (int i = 0; i < kBins; ++i) {
    seen += bins_[static_cast<std::size_t>(i)];
    if (seen >= rank) {
      // Geometric centre of the bin [10^(i/B), 10^((i+1)/B)), never above the exact maximum.
      const double centre = std::pow(10.0, (i + 0.5) / kBinsPerDecade);
      return std::min(centre, max_);
    }
  }
  return max_;
}

TimingSummary TimingHistogram::summary_us() const noexcept {
  TimingSummary s;
  s.count = count_;
  s.p50 = percentile(0.5) * 1e-3;
  s.p99 = percentile(0.99) * 1e-3;
  s.p999 = percentile(0.999) * 1e-3;
  s.p9999 = percentile(0.9999) * 1e-3;
  s.max = max_ * 1e-3;
  s.mean = count_ > 0 ? sum_ / static_cast<double>(count_) * 1e-3 : 0.0;
  return s;
}

std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void sleep_until_ns(std::int64_t deadline_ns) noexcept {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(deadline_ns / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(deadline_ns % 1'000'000'000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace piezobench::rt
