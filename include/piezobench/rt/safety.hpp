#pragma once
// Safety of the real-time loop's output, configurable per actuator (DESIGN.md "Safety in the
// real-time loop"). Every cycle the requested DAC command goes through, in this order:
//   1. sensor check: a non-finite d_e or Vs, one outside the sensor's range (|d_e| > de_range,
//      |Vs| > vs_range: a reading no actuator of the bench can produce), or more than
//      `stale_cycles` consecutive reads without a fresh sample, trips the safe state;
//   2. safe state (latched until the end of the run): the request is replaced by the safe output;
//   3. clamp to the actuator's range [va_min, va_max] / amplifier_gain (counted: clamped samples);
//   4. slew-rate limit: |u[k] - u[k-1]| <= slew_rate / amplifier_gain / sample_rate (counted);
//   5. saturation policy: a saturation level goes up by one sample period for every clamped
//      sample and down by one for every sample inside the range (never below 0); when it reaches
//      saturation_time the loop trips the safe state (Fault::kSaturation). So an output pinned to
//      the limits for saturation_time, or clamped on more than half of the samples for a while
//      (an unstable loop banging between the limits), goes safe; occasional clamping does not.
// Clamping before the slew limit keeps both: a slew-limited step from a value inside the range
// towards a value inside the range stays inside it. So the stack voltage commanded never leaves
// [va_min, va_max] and never moves faster than slew_rate, in the safe state too (the output goes
// to the safe value at the slew limit, not in one jump). Nothing is limited silently: every
// limited sample is counted and the loop reports the counts.
//
// The ramp in and out (ramp_in, ramp_out) and the watchdog (watchdog_timeout) are applied by the
// loop (loop.hpp) with these settings.
#include <cstdint>
#include <optional>
#include <string>

#include "piezobench/core/fields.hpp"
#include "piezobench/rt/backend.hpp"

namespace piezobench::rt {

// Defaults: the APA300ML behind the PD200 amplifier of the report's bench.
struct ActuatorLimits {
  std::string actuator = "APA300ML";
  double amplifier_gain = 20.0;   // V/V, DAC voltage -> stack voltage
  double va_min = -20.0;          // V at the stacks (-1 V at the DAC)
  double va_max = 150.0;          // V at the stacks (7.5 V at the DAC)
  double va_safe = 0.0;           // V at the stacks: the output of the safe state and of the ramps' ends
  // V/s at the stacks. 1e5 V/s drives about 1 A into the APA300ML's two stacks (9.9 uF), a typical
  // amplifier current limit; the IFF loop at the optimal gain needs about a third of it.
  double slew_rate = 1e5;
  double ramp_in = 0.1;           // s, controller gain and output envelope from 0 to 1 at the start
  double ramp_out = 0.1;          // s, and back to 0 at the end of the run
  int stale_cycles = 3;           // consecutive stale reads tolerated (0 .. kMaxStaleCycles)
  // Held (stale) samples a run may contain, as a fraction of its cycles (0 .. 0.01). `measure`
  // refuses a record with more (exit 3): a held sample repeats the previous one, so a record with
  // many of them is not the actuator's response.
  double stale_budget = 1e-3;
  // s without a completed cycle before the watchdog trips the safe state. The default allows for a
  // host without real-time scheduling (a container); a real target would use a few periods.
  double watchdog_timeout = 20e-3;
  // s of (net) saturated output before the safe state (policy 5 above).
  double saturation_time = 0.1;
  // The sensors' ranges: a reading beyond is a sensor fault (safe state). d_e, m: 1 mm, three times
  // the APA300ML's stroke; Vs, V: 100 V, well above what the sensor stack gives at 150 V on the
  // actuator stacks (a few V with the 80.6 kOhm resistor, tens without).
  double de_range = 1e-3;
  double vs_range = 100.0;  // V

  static constexpr int kMaxStaleCycles = 1000;
  static constexpr double kMaxTime = 60.0;  // s: ramps, watchdog, saturation time

  // InputError (source "actuator limits") naming the field: finite values, amplifier_gain > 0,
  // va_min < va_max, va_safe inside [va_min, va_max], slew_rate > 0, ramps in [0, kMaxTime] s,
  // stale_cycles in 0 .. kMaxStaleCycles, stale_budget in [0, 0.01], watchdog_timeout and
  // saturation_time in (0, kMaxTime] s, de_range and vs_range > 0.
  void validate() const;

  [[nodiscard]] double u_min() const { return va_min / amplifier_gain; }    // V at the DAC
  [[nodiscard]] double u_max() const { return va_max / amplifier_gain; }
  [[nodiscard]] double u_safe() const { return va_safe / amplifier_gain; }
  // Largest change of the DAC command per sample at `sample_rate` Hz.
  [[nodiscard]] double max_step(double sample_rate) const { return slew_rate / amplifier_gain / sample_rate; }
};

inline constexpr core::Shown kVoltPerSecond{"V/s", "V/s", 1.0};

constexpr auto describe(core::Type<ActuatorLimits>) {
  using S = ActuatorLimits;
  using namespace core::shown;
  return core::fields<S>("ActuatorLimits", "the limits the real-time loop keeps the actuator's output in",
      core::field("actuator", &S::actuator, kNone, "actuator the limits are for"),
      core::field("va_min", &S::va_min, kVolt, "lowest stack voltage"),
      core::field("va_max", &S::va_max, kVolt, "highest stack voltage"),
      core::field("amplifier_gain", &S::amplifier_gain, kVoltPerVolt, "DAC voltage -> stack voltage").key("amplifier_gain"),
      core::field("va_safe", &S::va_safe, kVolt, "stack voltage of the safe state and of the ramps' ends").part_only(),
      core::field("slew_rate", &S::slew_rate, kVoltPerSecond, "largest rate of change of the stack voltage"),
      core::field("ramp_in", &S::ramp_in, kSecond, "controller gain and output envelope from 0 to 1 at the start").key("ramp_s"),
      core::field("ramp_out", &S::ramp_out, kSecond, "and back to 0 at the end of the run").part_only(),
      core::field("watchdog_timeout", &S::watchdog_timeout, kSecond, "without a completed cycle before the safe state").key("watchdog_s"),
      core::field("saturation_time", &S::saturation_time, kSecond, "of (net) saturated output before the safe state"),
      core::field("stale_cycles", &S::stale_cycles, kNone, "consecutive stale reads tolerated"),
      core::field("stale_budget", &S::stale_budget, kRatio, "held samples a run may contain, fraction of its cycles").part_only(),
      core::field("de_range", &S::de_range, kMetre, "|d_e| beyond is a sensor fault").part_only(),
      core::field("vs_range", &S::vs_range, kVolt, "|Vs| beyond is a sensor fault").part_only());
}

// What a datasheet says an actuator takes; the limits of a bench file must stay inside it.
struct ActuatorDatasheet {
  std::string name;
  double va_min = 0.0, va_max = 0.0;  // V at the stacks
  double capacitance = 0.0;           // F of the driven stacks: slew_rate x capacitance is the current
  double max_current = 0.0;           // A, the current the bench's amplifier may drive into them
  double stroke = 0.0;                // m, the free stroke
  [[nodiscard]] double max_slew_rate() const { return max_current / capacitance; }  // V/s
};
// The datasheet of a known actuator ("APA300ML": -20 .. 150 V, 9.9 uF, 300 um), or nothing.
std::optional<ActuatorDatasheet> actuator_datasheet(const std::string& name);
// InputError (source `source`, fields as a bench file names them: limits.va_min_V, ...) unless
// the limits are plausible: a known actuator's within its datasheet (voltages inside its range,
// slew rate within max_current / capacitance, de_range within 10 strokes); "custom" within the
// physical bounds of any piezo stack (|V| <= 1000 V, slew rate <= 1e7 V/s, de_range <= 0.1 m);
// any other name is refused (a typo must not skip the datasheet).
void check_plausible(const ActuatorLimits& limits, const std::string& source);

// Why the loop entered its safe state.
enum class Fault : std::uint8_t {
  kNone,
  kNonFiniteSensor,      // d_e or Vs was NaN or infinite
  kSensorOutOfRange,     // d_e or Vs beyond the sensor's range (de_range, vs_range)
  kStaleSensor,          // no fresh sample for more than stale_cycles reads
  kWatchdog,             // the loop did not complete a cycle within watchdog_timeout
  kNonFiniteController,  // the controller's output overflowed
  kInterrupted,          // a stop was requested (Ctrl-C)
  kSaturation,           // the output was saturated for saturation_time (policy 5)
};
std::string to_string(Fault fault);  // "none", "non-finite sensor", "sensor out of range", "stale sensor", ...

// The output stage: sensor checks, safe state, clamp and slew limit, with their counters.
// Allocates nothing after construction; all member functions but the constructor are noexcept.
class SafetyGuard {
 public:
  // Validates the limits (InputError) and the rate (> 0). The previous output starts at u_safe.
  // sample_rate: Hz.
  SafetyGuard(const ActuatorLimits& limits, double sample_rate);

  // Checks one acquisition: kNonFiniteSensor, kSensorOutOfRange, kStaleSensor (after stale_cycles
  // stale reads in a row) or kNone. Counts non-finite and stale samples. Does not trip by itself.
  Fault check(const SensorSample& sample) noexcept;
  // Enters the (latched) safe state for `fault` at cycle `cycle`; only the first trip is recorded
  // as the reason, every trip while not already safe counts as an event.
  void trip(Fault fault, std::uint64_t cycle) noexcept;
  [[nodiscard]] bool safe_state() const noexcept { return fault_ != Fault::kNone; }

  struct Output {
    double u = 0.0;             // V at the DAC, what to write
    bool clamped = false;       // the request was outside the range
    bool slew_limited = false;  // the step was limited
  };
  // The command to write for the request `u` (V at the DAC): in the safe state u_safe; then
  // clamped and slew-limited from the previous output. A NaN request counts as clamped and is
  // replaced by the previous output. Updates the saturation level (not in the safe state).
  Output limit(double u) noexcept;
  // True once the saturation level has reached saturation_time: the caller trips kSaturation.
  [[nodiscard]] bool saturated_too_long() const noexcept { return saturation_level_ >= saturation_cycles_; }

  [[nodiscard]] const ActuatorLimits& limits() const noexcept { return limits_; }
  [[nodiscard]] double last_output() const noexcept { return last_u_; }
  [[nodiscard]] Fault fault() const noexcept { return fault_; }
  [[nodiscard]] std::uint64_t fault_cycle() const noexcept { return fault_cycle_; }
  [[nodiscard]] std::uint64_t clamped_samples() const noexcept { return clamped_; }
  [[nodiscard]] std::uint64_t slew_limited_samples() const noexcept { return slew_limited_; }
  [[nodiscard]] std::uint64_t safe_state_events() const noexcept { return events_; }
  [[nodiscard]] std::uint64_t nonfinite_samples() const noexcept { return nonfinite_; }
  [[nodiscard]] std::uint64_t stale_samples() const noexcept { return stale_; }

 private:
  ActuatorLimits limits_;
  double u_min_, u_max_, u_safe_, max_step_;  // V at the DAC (max_step_: V per sample)
  double last_u_;                             // V at the DAC
  bool have_sequence_ = false;
  std::uint64_t last_sequence_ = 0;
  int stale_run_ = 0;
  std::uint64_t saturation_level_ = 0, saturation_cycles_ = 1;
  Fault fault_ = Fault::kNone;
  std::uint64_t fault_cycle_ = 0;
  std::uint64_t clamped_ = 0, slew_limited_ = 0, events_ = 0, nonfinite_ = 0, stale_ = 0;
};

}  // namespace piezobench::rt
