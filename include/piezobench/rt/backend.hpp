#pragma once
// The I/O backend of the real-time loop: what a data-acquisition (DAQ) driver implements so that
// `rt::Loop` can run the controller against it. Two backends ship with piezobench: the virtual
// bench stepped in lockstep (virtual_backend.hpp: hardware-in-the-loop simulation) and the replay
// of a recorded file (replay_backend.hpp). docs/realtime.md describes the contract in full.
//
// One cycle of the loop is
//     s = backend.read();   u = controller and safety(s);   backend.write(u);
// read() returns the sensors acquired at the start of the cycle (the ADC sample), write() sets the
// DAC for the rest of the cycle (zero-order hold). The cycle functions run on the real-time thread:
// they must not allocate, lock, block on I/O other than the device's own, or throw.
#include <cstdint>
#include <limits>
#include <string>

#include "piezobench/core/fields.hpp"
#include "piezobench/rt/timing.hpp"

namespace piezobench::rt {

// One acquisition.
struct SensorSample {
  double de = 0.0;  // m, displacement (encoder)
  double vs = 0.0;  // V, force-sensor stack voltage (after the high-pass and the ADC)
  // V, amplifier output at the actuator stacks when the backend measures it; NaN = not measured
  // (the log then holds the commanded stack voltage instead).
  double va = std::numeric_limits<double>::quiet_NaN();
  // Increases by one for every fresh acquisition. A read that returns the same sequence number
  // as the previous one is stale (the ADC did not deliver a new sample); after
  // ActuatorLimits::stale_cycles of them the loop enters its safe state.
  std::uint64_t sequence = 0;
};

// What paces the loop.
enum class ClockSource {
  // The loop sleeps until absolute deadlines on CLOCK_MONOTONIC (clock_nanosleep, TIMER_ABSTIME):
  // the virtual bench in real time, a DAQ without its own sample clock.
  kHostMonotonic,
  // read() itself blocks until the hardware's next sample clock tick (a DAQ that owns the sample
  // clock); the loop does not sleep and measures its period from the wake-up times.
  kBackendSampleClock,
};
std::string to_string(ClockSource source);  // "host-monotonic", "backend-sample-clock"

// The I/O health of a backend that talks to a device over a link (udp, comedi): what the loop's
// report and `piezobench measure --json` show next to the safety counts.
struct IoStats {
  std::uint64_t exchanges = 0;   // I/O transactions started (datagrams sent, instruction lists run)
  std::uint64_t replies = 0;     // answered in time
  std::uint64_t late = 0;        // answered after the cycle had given up on them (stale input)
  std::uint64_t lost = 0;        // never answered (counted when the backend stops)
  std::uint64_t timeouts = 0;    // reads that returned no fresh sample in time (stale inputs)
  std::uint64_t errors = 0;      // device errors (each one also trips the safe state)
  std::uint64_t rejected = 0;    // datagrams refused (udp: another session's, a tag that does not verify)
  TimingSummary round_trip_us;   // request -> reply (udp) or instruction list (comedi) time
};

constexpr auto describe(core::Type<IoStats>) {
  using S = IoStats;
  using core::shown::kNone;
  return core::fields<S>("IoStats", "a backend's I/O health over a run",
      core::field("exchanges", &S::exchanges, kNone, "I/O transactions started (datagrams sent, instruction lists run)"),
      core::field("replies", &S::replies, kNone, "answered in time"),
      core::field("lost", &S::lost, kNone, "never answered (counted when the backend stops)"),
      core::field("late", &S::late, kNone, "answered after the cycle had given up on them (stale input)"),
      core::field("timeouts", &S::timeouts, kNone, "reads that returned no fresh sample in time").key("stale_inputs"),
      core::field("errors", &S::errors, kNone, "device errors (each one also trips the safe state)"),
      core::field("rejected", &S::rejected, kNone, "datagrams refused (udp: another session's, a tag that does not verify)"),
      core::field("round_trip_us", &S::round_trip_us, kNone, "request -> reply (udp) or instruction list (comedi) time, us"));
}

class Backend {
 public:
  virtual ~Backend() = default;
  Backend() = default;
  Backend(const Backend&) = delete;
  Backend& operator=(const Backend&) = delete;

  // "virtual", "replay", ... (reports and logs).
  [[nodiscard]] virtual std::string name() const = 0;
  // Hz, the rate the backend samples at; the loop runs at this rate.
  [[nodiscard]] virtual double sample_rate() const = 0;
  [[nodiscard]] virtual ClockSource clock_source() const { return ClockSource::kHostMonotonic; }

  // Before the first cycle, on the calling thread: open the device, arm the clock, write the safe
  // output. May allocate and throw (InputError for a device or file that cannot be used).
  virtual void start() = 0;
  // The sensors of this cycle. Real-time: noexcept, no allocation, no lock.
  virtual SensorSample read() noexcept = 0;
  // The DAC command u (V at the DAC) for the rest of this cycle. Real-time, as read().
  virtual void write(double u) noexcept = 0;
  // True when the backend has no more samples (end of a replayed file); the loop then stops.
  [[nodiscard]] virtual bool finished() const noexcept { return false; }
  // After the last cycle (the loop has written the safe output): close the device.
  virtual void stop() noexcept = 0;
  // Called from the loop's watchdog thread, concurrently with the cycle functions, when the loop
  // has not completed a cycle within ActuatorLimits::watchdog_timeout: force the output to its safe
  // value by a path that does not need the stalled loop (a hardware watchdog, a direct DAC write).
  // Must be thread-safe and async-signal-safe in spirit (no allocation, no lock). Default: nothing
  // (the simulated backends have no output that can go on moving while the loop is stalled).
  virtual void on_watchdog() noexcept {}
  // I/O health since start() (valid after stop()); zeros for the backends without a link.
  [[nodiscard]] virtual IoStats io_stats() const { return {}; }
};

}  // namespace piezobench::rt
