#include "piezobench/rt/safety.hpp"

#include <algorithm>
#include <cmath>

#include "piezobench/core/checked_number.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "util.hpp"

namespace piezobench::rt {

namespace {
const std::string kLimitsSource = "actuator limits";
}

std::string to_string(Fault fault) {
  switch (fault) {
    case Fault::kNone:
      return "none";
    case Fault::kNonFiniteSensor:
      return "non-finite sensor";
    case Fault::kSensorOutOfRange:
      return "sensor out of range";
    case Fault::kStaleSensor:
      return "stale sensor";
    case Fault::kWatchdog:
      return "watchdog";
    case Fault::kNonFiniteController:
      return "non-finite controller output";
    case Fault::kInterrupted:
      return "interrupted";
    case Fault::kSaturation:
      return "output saturated";
  }
  return "unknown";
}

void ActuatorLimits::validate() const {
  detail::require_positive(amplifier_gain, "amplifier_gain", kLimitsSource);
  detail::require_finite(va_min, "va_min", kLimitsSource);
  detail::require_finite(va_max, "va_max", kLimitsSource);
  if (!(va_min < va_max)) {
    throw InputError(kLimitsSource, "va_max", "a value above va_min = " + format_number(va_min) + " V", format_number(va_max));
  }
  if (!(std::isfinite(va_safe) && va_safe >= va_min && va_safe <= va_max)) {
    throw InputError(kLimitsSource, "va_safe", "a voltage in [" + format_number(va_min) + ", " + format_number(va_max) + "] V",
                     format_number(va_safe));
  }
  detail::require_positive(slew_rate, "slew_rate", kLimitsSource);
  // Times become cycle and nanosecond counts: range-checked before (core/checked_number.hpp).
  const auto field = [](const char* name) { return NumberOrigin::file(kLimitsSource, name); };
  checked_duration_s(ramp_in, 0.0, kMaxTime, field("ramp_in"));
  checked_duration_s(ramp_out, 0.0, kMaxTime, field("ramp_out"));
  checked_integer(std::int64_t{stale_cycles}, 0, kMaxStaleCycles, field("stale_cycles"));
  if (!(stale_budget >= 0.0 && stale_budget <= 0.01)) {
    throw InputError(kLimitsSource, "stale_budget", "a fraction of the samples in [0, 0.01]", format_number(stale_budget));
  }
  checked_duration_s(watchdog_timeout, 1e-6, kMaxTime, field("watchdog_timeout"));
  checked_duration_s(saturation_time, 1e-6, kMaxTime, field("saturation_time"));
  detail::require_positive(de_range, "de_range", kLimitsSource);
  detail::require_positive(vs_range, "vs_range", kLimitsSource);
}

std::optional<ActuatorDatasheet> actuator_datasheet(const std::string& name) {
  // Cedrat APA300ML: -20 .. 150 V, stroke 300 um; its two actuator stacks 9.9 uF. 10 A, ten times
  // what the default slew rate draws, bounds the slew limit at 1.01e6 V/s.
  if (name == "APA300ML") return ActuatorDatasheet{"APA300ML", -20.0, 150.0, 9.9e-6, 10.0, 300e-6};
  return std::nullopt;
}

void check_plausible(const ActuatorLimits& l, const std::string& source) {
  const auto beyond = [&](const char* field, const std::string& expected, double found) {
    throw InputError(source, field, expected, format_number(found));
  };
  double v_lo = -1000.0, v_hi = 1000.0, slew = 1e7, de = 0.1;
  std::string what = "the physical bounds of a piezo stack";
  if (const auto d = actuator_datasheet(l.actuator)) {
    v_lo = d->va_min;
    v_hi = d->va_max;
    slew = d->max_slew_rate();
    de = 10.0 * d->stroke;
    what = d->name + "'s datasheet";
  } else if (l.actuator != "custom") {
    throw InputError(source, "limits.actuator", "a known actuator (APA300ML) or \"custom\" (physical bounds only)",
                     "'" + l.actuator + "'");
  }
  if (!(l.va_min >= v_lo)) beyond("limits.va_min_V", "at least " + format_number(v_lo) + " V (" + what + ")", l.va_min);
  if (!(l.va_max <= v_hi)) beyond("limits.va_max_V", "at most " + format_number(v_hi) + " V (" + what + ")", l.va_max);
  if (!(l.slew_rate <= slew)) {
    beyond("limits.slew_rate_V_per_s", "at most " + format_number(slew) + " V/s (" + what + ")", l.slew_rate);
  }
  if (!(l.de_range <= de)) beyond("limits.de_range_m", "at most " + format_number(de) + " m (" + what + ")", l.de_range);
}

SafetyGuard::SafetyGuard(const ActuatorLimits& limits, double sample_rate) : limits_(limits) {
  limits.validate();
  detail::require_positive(sample_rate, "sample_rate", kLimitsSource);
  u_min_ = limits.u_min();
  u_max_ = limits.u_max();
  u_safe_ = limits.u_safe();
  max_step_ = limits.max_step(sample_rate);
  last_u_ = u_safe_;
  // At least one sample; a time longer than 2^62 samples is as good as never.
  const double cycles = std::ceil(limits.saturation_time * sample_rate);
  saturation_cycles_ = cycles < 0x1p62 ? std::max<std::uint64_t>(1, static_cast<std::uint64_t>(cycles)) : (1ULL << 62);
}

Fault SafetyGuard::check(const SensorSample& sample) noexcept {
  if (!std::isfinite(sample.de) || !std::isfinite(sample.vs)) {
    ++nonfinite_;
    return Fault::kNonFiniteSensor;
  }
  if (std::abs(sample.de) > limits_.de_range || std::abs(sample.vs) > limits_.vs_range) return Fault::kSensorOutOfRange;
  if (have_sequence_ && sample.sequence == last_sequence_) {
    ++stale_;
    if (++stale_run_ > limits_.stale_cycles) return Fault::kStaleSensor;
  } else {
    stale_run_ = 0;
  }
  have_sequence_ = true;
  last_sequence_ = sample.sequence;
  return Fault::kNone;
}

void SafetyGuard::trip(Fault fault, std::uint64_t cycle) noexcept {
  if (fault == Fault::kNone || safe_state()) return;
  fault_ = fault;
  fault_cycle_ = cycle;
  ++events_;
}

SafetyGuard::Output SafetyGuard::limit(double u) noexcept {
  Output out;
  if (safe_state()) u = u_safe_;
  if (std::isnan(u)) {
    u = last_u_;
    out.clamped = true;
  } else if (u < u_min_ || u > u_max_) {
    u = std::clamp(u, u_min_, u_max_);
    out.clamped = true;
  }
  const double step = u - last_u_;
  if (step > max_step_) {
    u = last_u_ + max_step_;
    out.slew_limited = true;
  } else if (step < -max_step_) {
    u = last_u_ - max_step_;
    out.slew_limited = true;
  }
  if (out.clamped) ++clamped_;
  if (!safe_state()) {
    if (out.clamped) {
      ++saturation_level_;
    } else if (saturation_level_ > 0) {
      --saturation_level_;
    }
  }
  if (out.slew_limited) ++slew_limited_;
  last_u_ = u;
  out.u = u;
  return out;
}

}  // namespace piezobench::rt
