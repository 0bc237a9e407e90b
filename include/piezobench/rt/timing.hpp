#pragma once
// Per-cycle timing statistics of the real-time loop, kept like a task-execution-time monitor:
// every sample goes into a fixed log-spaced histogram (no allocation after construction, any run
// length), from which the percentiles are read; the exact maximum and count are kept aside.
//
// Resolution: 100 bins per decade from 1 ns to 10 s, so a percentile is the geometric centre of
// its bin, within 1.2 % of the exact sample percentile (values below 1 ns fall into the first bin,
// above 10 s into the last).
#include <array>
#include <cstdint>

#include "piezobench/core/fields.hpp"

namespace piezobench::rt {

struct TimingSummary {
  std::uint64_t count = 0;
  double p50 = 0.0, p99 = 0.0, p999 = 0.0, p9999 = 0.0, max = 0.0;  // same unit as the samples
  double mean = 0.0;                                                // same unit as the samples
};

// The loop's durations are microseconds (TimingHistogram::summary_us), not SI seconds: the unit they
// are kept and shown in.
inline constexpr core::Shown kMicrosecond{"us", "us", 1.0};
inline constexpr core::Shown kMillisecond{"ms", "ms", 1.0};

// A summary's keys are the bare percentile names: the unit is in its parent's key ("step_time_us").
constexpr auto describe(core::Type<TimingSummary>) {
  using S = TimingSummary;
  using core::shown::kNone;
  return core::fields<S>("TimingSummary", "percentiles of a loop duration (TimingHistogram, microseconds)",
      core::field("p50", &S::p50, kMicrosecond, "median").key("p50"),
      core::field("p99", &S::p99, kMicrosecond, "99th percentile").key("p99"),
      core::field("p999", &S::p999, kMicrosecond, "99.9th percentile").key("p999"),
      core::field("p9999", &S::p9999, kMicrosecond, "99.99th percentile").part_only(),
      core::field("max", &S::max, kMicrosecond, "largest sample (exact)").key("max"),
      core::field("mean", &S::mean, kMicrosecond, "mean of the samples").key("mean"),
      core::field("count", &S::count, kNone, "samples"));
}

class TimingHistogram {
 public:
  // Adds one non-negative duration in ns (negative or NaN values count as 0). noexcept, O(1).
  void add(double ns) noexcept;
  // Percentile q in [0, 1] (nearest rank: the smallest sample with at least q * count samples at
  // or below it), ns; 0 when empty.
  [[nodiscard]] double percentile(double q) const noexcept;
  [[nodiscard]] std::uint64_t count() const noexcept { return count_; }
  [[nodiscard]] double max() const noexcept { return max_; }
  // p50, p99, p999, p9999, max and mean converted to microseconds.
  [[nodiscard]] TimingSummary summary_us() const noexcept;

 private:
  static constexpr int kBinsPerDecade = 100;
  static constexpr int kDecades = 10;  // 1 ns .. 10 s
  static constexpr int kBins = kBinsPerDecade * kDecades;
  std::array<std::uint64_t, kBins> bins_{};
  std::uint64_t count_ = 0;
  double max_ = 0.0;  // same unit as the samples
  double sum_ = 0.0;  // same unit as the samples
};

// CLOCK_MONOTONIC now, ns.
std::int64_t monotonic_ns() noexcept;
// Sleeps until the absolute CLOCK_MONOTONIC time `deadline_ns` (clock_nanosleep, TIMER_ABSTIME,
// retried on EINTR). Returns at once when the deadline has passed.
void sleep_until_ns(std::int64_t deadline_ns) noexcept;

}  // namespace piezobench::rt
