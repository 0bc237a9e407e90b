#include "piezobench/rt/safety.hpp"

#include <algorithm>
#include <cmath>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "rt/util.hpp"

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
  detail::require_nonnegative(ramp_in, "ramp_in", kLimitsSource);
  detail::require_nonnegative(ramp_out, "ramp_out", kLimitsSource);
  if (stale_cycles < 0) throw InputError(kLimitsSource, "stale_cycles", "an integer >= 0", std::to_string(stale_cycles));
  detail::require_positive(watchdog_timeout, "watchdog_timeout", kLimitsSource);
  detail::require_positive(saturation_time, "saturation_time", kLimitsSource);
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
