#pragma once
// The real-time loop of the report's Figure 2.9: u = u' + g K0(z) Vs at the backend's rate, with
// the actuator's safety limits (safety.hpp), a signal log (logger.hpp) and timing statistics
// (timing.hpp). docs/realtime.md describes it; in short:
//
//  - Pacing (real-time mode): absolute deadlines t0 + k T on CLOCK_MONOTONIC, slept to with
//    clock_nanosleep(TIMER_ABSTIME), so errors do not accumulate. The loop runs on its own thread,
//    with SCHED_FIFO (`priority`) and mlockall(MCL_CURRENT | MCL_FUTURE) when the system permits;
//    when it does not (a container, no CAP_SYS_NICE / CAP_IPC_LOCK) the loop still runs and a
//    warning says so (stderr and LoopReport::warnings). A cycle that ends after the next deadline
//    is an overrun (counted); when a whole period has been missed the loop skips to the next
//    future deadline (counted as skipped deadlines) instead of running late cycles back to back.
//  - Lockstep mode (realtime = false): no sleeping; cycles run back to back as fast as possible,
//    for simulation (tests, the damped-plant study). The log never drops a record then.
//  - Inside a cycle: read the sensors, check them, step the controller, pass u' through the
//    inverse hysteresis feedforward when there is one, ramp, clamp, slew-limit, write the command,
//    push the log record.
//  - Feedforward (LoopOptions::feedforward, control/hysteresis_feedforward.hpp): u' is read as a
//    linear command c = amplifier_gain u' (V at the stacks) and replaced by the stack voltage the
//    inverse of the identified hysteresis and creep asks for, divided by the amplifier gain. It sits
//    before the ramps, the clamp and the slew limit, so the limits hold whatever it asks for; an
//    optional weight per cycle (feedforward_weight) blends it in and out. No allocation, no lock, no I/O other than the
//    backend's (tests/rt/loop_test.cpp counts allocations around cycle()).
//  - Ramps: over ramp_in seconds at the start and ramp_out seconds at the end of the run a factor
//    r goes 0 -> 1 (-> 0); the controller's gain is r g (bumpless: the gain acts at the sections'
//    input) and the command is u_safe + r (u' + y - u_safe), so the run starts and ends at the safe
//    output without a step.
//  - Safe state (latched): a non-finite or stale sensor sample, a non-finite controller output, an
//    output saturated for limits.saturation_time (safety.hpp, policy 5) or
//    the watchdog (no completed cycle within watchdog_timeout: checked every cycle from the wake-up
//    time, and by a watchdog thread that calls Backend::on_watchdog() when the loop is stuck) sets
//    the output to the safe value at the slew limit and resets the controller; the loop keeps
//    running (and timing) to the end of the run with the safe output.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "piezobench/control/discrete_iff.hpp"
#include "piezobench/control/hysteresis_feedforward.hpp"
#include "piezobench/core/fields.hpp"
#include "piezobench/ident/hysteresis.hpp"
#include "piezobench/io/timeseries.hpp"
#include "piezobench/rt/backend.hpp"
#include "piezobench/rt/logger.hpp"
#include "piezobench/rt/safety.hpp"
#include "piezobench/rt/timing.hpp"

namespace piezobench::rt {

// Highest loop rate accepted (Hz): far above what a host loop can pace (10 kHz is the report's),
// and it bounds the per-second work and log of a run (docs/cli.md, resource bounds).
inline constexpr double kMaxSampleRate = 1e6;

struct LoopOptions {
  double duration = 1.0;      // s; the run has round(duration * rate) cycles (fewer if the backend ends)
  bool realtime = true;       // false = lockstep, as fast as possible
  bool sched_fifo = true;     // try SCHED_FIFO for the loop thread (real-time mode)
  int priority = 80;          // SCHED_FIFO priority, 1..99
  bool lock_memory = true;    // try mlockall (real-time mode)
  bool controller = true;     // false: open loop (u = u' only)
  double gain = 0.0;          // V/V, IFF gain g
  control::IffControllerParams controller_params;      // K0 (eq. 2.4 by default)
  control::DiscreteIffOptions discrete;                // its sample_rate is replaced by the backend's
  ActuatorLimits limits;
  Eigen::VectorXd excitation;  // u' (V at the DAC), played cyclically from cycle 0; empty = 0
  // Inverse hysteresis feedforward on u' (see above); unset = none. Validated by the Loop.
  std::optional<ident::HysteresisModel> feedforward;
  // Its weight w per cycle in [0, 1], played with the excitation (same length): the stage's share
  // u' + w (u_ff - u') of the request, to blend it in and out without a step (a run that starts and
  // ends at rest); the stage itself steps on every u'. Empty = 1.
  Eigen::VectorXd feedforward_weight;
  // Signal log: kept in memory when `keep_log` (Loop::log()) and/or written to `log_file`.
  std::optional<std::filesystem::path> log_file;
  bool keep_log = false;
  std::size_t log_ring_capacity = 1u << 16;
  // Rows of log storage allocated before the run (11 doubles each: 3e6 rows = 264 MB, 5 min at
  // 10 kHz); records beyond are dropped and counted in dropped_log_samples.
  std::size_t max_log_samples = 3'000'000;
  std::map<std::string, io::Setting> log_settings;  // added to the log file's settings
  // A live copy of the log while the run goes (logger.hpp, LogTap): on the logger thread, so the
  // cycles never wait on it, lock or allocate for it. With neither keep_log nor log_file, a logger
  // runs for the tap alone.
  LogTap log_tap;
  // Stop request (Ctrl-C; set from a signal handler): the loop enters its safe state (reason
  // "interrupted"), brings the output to the safe value at the slew limit (at most
  // max(|va_max|, |va_min|) / slew_rate + one period: 1.5 ms for the APA300ML) and ends the run
  // there; the log holds every cycle up to that moment. Not owned; may be null.
  const std::atomic<bool>* stop = nullptr;
  // Called (on the setup path, never inside a cycle) with each warning as it arises, e.g. to print
  // it on stderr at once; the warnings are also returned in LoopReport::warnings.
  std::function<void(const std::string&)> on_warning;
  // InputError naming the field (duration > 0 and finite, priority 1..99, gain finite, finite
  // excitation, limits).
  void validate() const;
};

struct LoopReport {
  std::string backend;
  double sample_rate = 0.0;         // Hz
  bool realtime = false;
  bool sched_fifo = false;          // SCHED_FIFO obtained
  bool memory_locked = false;       // mlockall obtained
  std::uint64_t cycles = 0;
  std::uint64_t overruns = 0;       // cycles that ended after the next deadline
  // The overruns by cause (real time; they add up to `overruns`): each is charged to the larger of
  // its two parts, the wake-up's lateness (deadline -> wake-up: the host's timer and scheduler) or
  // the step (wake-up -> end: the code's execution time, plus any preemption inside it).
  std::uint64_t overruns_late_wakeup = 0;
  std::uint64_t overruns_long_step = 0;
  // What the shared host took from the loop thread during the cycles (Linux; -1 when unknown, and
  // in lockstep mode): time runnable but waiting for a core (schedstat run delay) and involuntary
  // context switches (preemptions by other threads).
  double host_wait_ms = -1.0;
  std::int64_t host_preemptions = -1;
  std::uint64_t skipped_deadlines = 0;
  std::uint64_t wind_down_cycles = 0;  // extra cycles that brought the output to the safe value
  TimingSummary period_jitter_us;   // |actual period - T| between consecutive wake-ups
  TimingSummary wake_latency_us;    // wake-up time - deadline
  TimingSummary step_time_us;       // execution time of a cycle: read .. log push
  bool feedforward = false;         // the inverse hysteresis feedforward was on
  std::uint64_t clamped_samples = 0;
  std::uint64_t slew_limited_samples = 0;
  std::uint64_t safe_state_events = 0;
  std::string safe_state_reason = "none";  // to_string(Fault)
  std::int64_t safe_state_cycle = -1;      // first cycle in the safe state, -1 = never
  std::uint64_t nonfinite_sensor_samples = 0;
  std::uint64_t stale_sensor_samples = 0;
  std::uint64_t watchdog_trips = 0;
  bool interrupted = false;                // the run was ended by LoopOptions::stop
  IoStats io;                              // the backend's I/O health (Backend::io_stats)
  std::uint64_t logged_samples = 0;
  std::uint64_t dropped_log_samples = 0;
  double va_cmd_min = 0.0, va_cmd_max = 0.0;  // V, extremes of the commanded stack voltage
  double max_va_cmd_step = 0.0;               // V, largest |change| of it between two cycles
  std::vector<std::string> warnings;
};

// The host's share, null when unknown (-1: not Linux, lockstep mode).
inline std::optional<double> known_host_wait_ms(const LoopReport& r) {
  return r.host_wait_ms >= 0 ? std::optional<double>(r.host_wait_ms) : std::nullopt;
}
inline std::optional<std::int64_t> known_host_preemptions(const LoopReport& r) {
  return r.host_preemptions >= 0 ? std::optional<std::int64_t>(r.host_preemptions) : std::nullopt;
}

// `rt --json`'s keys (the command adds the duplicates under "host" and "code" and its options).
constexpr auto describe(core::Type<LoopReport>) {
  using S = LoopReport;
  using namespace core::shown;
  return core::fields<S>("LoopReport", "what a run of the real-time loop did",
      core::field("backend", &S::backend, kNone, "\"virtual\", \"replay\", \"udp\", ...").part_only(),
      core::field("sample_rate", &S::sample_rate, kHertz, "the loop's rate").key("rate_Hz"),
      core::field("realtime", &S::realtime, kNone, "paced by the clock (false: lockstep)"),
      core::field("sched_fifo", &S::sched_fifo, kNone, "SCHED_FIFO obtained"),
      core::field("memory_locked", &S::memory_locked, kNone, "mlockall obtained"),
      core::field("cycles", &S::cycles, kNone, "cycles run"),
      core::field("overruns", &S::overruns, kNone, "cycles that ended after the next deadline"),
      core::field("overruns_late_wakeup", &S::overruns_late_wakeup, kNone, "overruns charged to the wake-up's lateness (the host)")
          .key("overrun_causes.late_wakeup"),
      core::field("overruns_long_step", &S::overruns_long_step, kNone, "overruns charged to the step's execution time (the code)")
          .key("overrun_causes.long_step"),
      core::field("host_wait_ms", &S::host_wait_ms, kMillisecond, "time runnable but waiting for a core, -1 unknown").part_only(),
      core::field("host_preemptions", &S::host_preemptions, kNone, "involuntary context switches, -1 unknown").part_only(),
      core::derived("host_wait", &known_host_wait_ms, kMillisecond, "time runnable but waiting for a core (null: unknown)")
          .key("host.wait_ms"),
      core::derived("host_preemptions_known", &known_host_preemptions, kNone, "involuntary context switches (null: unknown)")
          .key("host.preemptions"),
      core::field("skipped_deadlines", &S::skipped_deadlines, kNone, "deadlines skipped after an overrun"),
      core::field("wind_down_cycles", &S::wind_down_cycles, kNone, "extra cycles that brought the output to the safe value"),
      core::field("period_jitter_us", &S::period_jitter_us, kNone, "|actual period - T| between consecutive wake-ups, us"),
      core::field("wake_latency_us", &S::wake_latency_us, kNone, "wake-up time - deadline, us"),
      core::field("step_time_us", &S::step_time_us, kNone, "execution time of a cycle: read .. log push, us"),
      core::field("feedforward", &S::feedforward, kNone, "the inverse hysteresis feedforward was on"),
      core::field("clamped_samples", &S::clamped_samples, kNone, "outputs clamped to the actuator's range"),
      core::field("slew_limited_samples", &S::slew_limited_samples, kNone, "outputs held to the slew rate"),
      core::field("safe_state_events", &S::safe_state_events, kNone, "entries into the safe state"),
      core::field("safe_state_reason", &S::safe_state_reason, kNone, "to_string(Fault), \"none\""),
      core::field("safe_state_cycle", &S::safe_state_cycle, kNone, "first cycle in the safe state, -1 = never"),
      core::field("nonfinite_sensor_samples", &S::nonfinite_sensor_samples, kNone, "sensor readings that were not finite"),
      core::field("stale_sensor_samples", &S::stale_sensor_samples, kNone, "reads without a fresh sample"),
      core::field("watchdog_trips", &S::watchdog_trips, kNone, "safe states tripped by the watchdog"),
      core::field("interrupted", &S::interrupted, kNone, "the run was ended by LoopOptions::stop").part_only(),
      core::field("io", &S::io, kNone, "the backend's I/O health"),
      core::field("logged_samples", &S::logged_samples, kNone, "samples written to the log"),
      core::field("dropped_log_samples", &S::dropped_log_samples, kNone, "samples the logger could not keep"),
      core::field("va_cmd_min", &S::va_cmd_min, kVolt, "lowest commanded stack voltage"),
      core::field("va_cmd_max", &S::va_cmd_max, kVolt, "highest commanded stack voltage"),
      core::field("max_va_cmd_step", &S::max_va_cmd_step, kVolt, "largest |change| of it between two cycles"),
      core::field("warnings", &S::warnings, kNone, "what the run noticed"));
}

// The loop with the pacing left to the caller: start(), then cycle() until it returns false, then
// finish(). run_loop() does this with the pacing, the threads and the real-time setup; tests call
// cycle() directly.
class Loop {
 public:
  // Validates (InputError); allocates everything the cycles need.
  Loop(Backend& backend, const LoopOptions& options);
  ~Loop();
  Loop(const Loop&) = delete;
  Loop& operator=(const Loop&) = delete;

  // Starts the backend and the logger thread (allocates, may throw).
  void start();
  // One cycle. `deadline_ns` and `wake_ns` (CLOCK_MONOTONIC) feed the timing statistics in
  // real-time mode; in lockstep mode pass 0 for both. Returns false, doing nothing, once the run
  // is complete or the backend has finished. noexcept, allocation-free.
  bool cycle(std::int64_t deadline_ns = 0, std::int64_t wake_ns = 0) noexcept;
  // Writes the safe output, stops the backend and the logger (which writes the file) and returns
  // the report. Rethrows a log write error (InputError).
  LoopReport finish();

  // The log (when options.keep_log), valid after finish().
  [[nodiscard]] const io::TimeSeries& log() const;
  [[nodiscard]] std::uint64_t cycles() const noexcept { return cycle_; }
  [[nodiscard]] std::uint64_t total_cycles() const noexcept { return total_cycles_; }
  [[nodiscard]] const SafetyGuard& guard() const noexcept { return guard_; }
  [[nodiscard]] const control::DiscreteIff& controller() const noexcept { return iff_; }

  // Used by run_loop(): skipped deadlines and the watchdog.
  void add_skipped(std::uint64_t n) noexcept { skipped_ += n; }
  void watchdog_trip() noexcept;
  [[nodiscard]] std::uint64_t heartbeat() const noexcept;

 private:
  struct Shared;
  struct Cycle;  // the steps of cycle() (loop.cpp)
  Backend& backend_;
  LoopOptions options_;
  double rate_;  // Hz
  std::uint64_t total_cycles_;
  std::uint64_t ramp_in_cycles_, ramp_out_cycles_;
  control::DiscreteIff iff_;
  std::optional<control::HysteresisFeedforward> feedforward_;
  SafetyGuard guard_;
  std::unique_ptr<SignalLogger> logger_;
  std::unique_ptr<Shared> shared_;  // atomics shared with the watchdog thread
  TimingHistogram jitter_, latency_, step_time_;
  std::uint64_t cycle_ = 0;
  std::uint64_t overruns_ = 0, overruns_late_wakeup_ = 0, overruns_long_step_ = 0, skipped_ = 0, wind_down_ = 0;
  std::uint64_t controller_nonfinite_seen_ = 0;
  std::int64_t last_wake_ns_ = 0;
  std::int64_t last_end_ns_ = 0;
  double va_cmd_min_ = 0.0, va_cmd_max_ = 0.0, max_step_ = 0.0, last_va_cmd_ = 0.0;  // V
  std::int64_t period_ns_ = 0, watchdog_ns_ = 0;
  bool started_ = false, finished_ = false, stopping_ = false;
  io::TimeSeries log_;
  std::vector<std::string> warnings_;
};

// The whole run: real-time setup (SCHED_FIFO, mlockall, stack prefault; warnings when refused),
// the loop thread paced by absolute deadlines (or lockstep), the watchdog thread, the logger.
// When `log` is given and options.keep_log, the log is moved there. Errors: InputError (options,
// backend start, log file), NumericalError never.
LoopReport run_loop(Backend& backend, const LoopOptions& options, io::TimeSeries* log = nullptr);

}  // namespace piezobench::rt
