#pragma once
// The loop's signal logger: the real-time thread pushes one record per cycle into a lock-free SPSC
// ring (spsc_ring.hpp); a logger thread drains it into storage allocated up front and, when the
// run ends, writes the signals as a time series (io::write_timeseries: .mat or .csv) and/or hands
// them to the caller. A record that finds the ring full is dropped and counted (real-time mode);
// in lockstep mode push_wait() waits for room instead, so nothing is lost.
//
// Channels of the log, one per record field (SI units): t [s], u_prime [V] (the damped plant's
// input, V at the DAC), u [V] (the DAC command written), Va [V] (the stack voltage: measured when
// the backend measures it, else the command times the amplifier gain), Va_cmd [V] (command times
// the amplifier gain), de [m], Vs [V], y [V] (controller output), latency_us (wake-up after the
// deadline), step_us (the cycle's execution time) and flags (bit 0 clamped, bit 1 slew-limited,
// bit 2 safe state, bit 3 ramping, bit 4 sensor fault: d_e or Vs was not finite and is logged
// as 0, since a log file holds finite numbers only).
#include <atomic>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "piezobench/io/timeseries.hpp"
#include "piezobench/rt/spsc_ring.hpp"

namespace piezobench::rt {

struct LogRecord {
  double t = 0.0;        // s
  double u_prime = 0.0;  // V at the DAC
  double u = 0.0;        // V at the DAC
  double va = 0.0;       // V
  double va_cmd = 0.0;   // V
  double de = 0.0;       // m
  double vs = 0.0;       // V
  double y = 0.0;        // V at the DAC (the controller's output)
  double latency_us = 0.0;
  double step_us = 0.0;
  std::uint32_t flags = 0;
  std::int64_t measured_ns = 0;  // CLOCK_MONOTONIC (steady_clock) at the cycle's start (not logged)
};
inline constexpr std::uint32_t kFlagClamped = 1u << 0;
inline constexpr std::uint32_t kFlagSlewLimited = 1u << 1;
inline constexpr std::uint32_t kFlagSafeState = 1u << 2;
inline constexpr std::uint32_t kFlagRamping = 1u << 3;
inline constexpr std::uint32_t kFlagSensorFault = 1u << 4;

// A live copy of the log while the run goes (the station's web page, web/live_hub.hpp): every
// `every`-th record, handed to `deliver` in order, in batches, on the logger thread, never on the
// loop's (the loop only pushes into the ring, as for the log); each record says when it was
// measured (measured_ns). An empty batch says the run is over. `deliver` should return within
// milliseconds: while it runs the ring fills, and the loop drops log records (counted) only when
// the ring is full (ring_capacity records). An exception from it is swallowed (the log goes on).
struct LogTap {
  std::size_t every = 1;
  std::function<void(std::span<const LogRecord> records)> deliver;  // empty: no tap
};

struct LoggerOptions {
  std::optional<std::filesystem::path> file;  // written at the end (.mat or .csv); none = memory only
  std::size_t ring_capacity = 1u << 16;       // records (6.5 s at 10 kHz)
  std::size_t max_samples = 0;                // storage; records beyond it are dropped and counted
  double sample_rate = 10e3;                  // Hz, of the log (the loop's rate)
  std::map<std::string, io::Setting> settings;  // written into the file's `settings`
  bool keep = true;                           // false: records only go to the tap (no storage)
  LogTap tap;
  void validate() const;                      // InputError naming the field
};

class SignalLogger {
 public:
  // Allocates the ring and the storage (max_samples rows). InputError for bad options.
  explicit SignalLogger(const LoggerOptions& options);
  ~SignalLogger();  // stops the thread if still running (the file is then not written)
  SignalLogger(const SignalLogger&) = delete;
  SignalLogger& operator=(const SignalLogger&) = delete;

  // Starts the logger thread.
  void start();
  // Real-time side: false (record dropped and counted) when the ring is full. No allocation.
  bool push(const LogRecord& record) noexcept;
  // Lockstep side: waits (yielding) until the ring has room; never drops.
  void push_wait(const LogRecord& record) noexcept;
  // Stops the thread after it has drained the ring, writes the file (in the logger thread) and
  // returns the log (the caller may move from it). Rethrows the write's InputError; InputError
  // when a file was asked for and no record arrived.
  io::TimeSeries& finish();

  [[nodiscard]] std::uint64_t dropped() const noexcept;  // ring full + beyond max_samples
  [[nodiscard]] std::uint64_t stored() const noexcept { return stored_.load(std::memory_order_acquire); }

 private:
  void run() noexcept;
  void store(const LogRecord& r) noexcept;
  void tap(const LogRecord& r) noexcept;
  void flush_tap(bool run_over) noexcept;

  LoggerOptions options_;
  SpscRing<LogRecord> ring_;
  io::TimeSeries log_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> abandon_{false};  // destroyed without finish(): do not write the file
  std::atomic<std::uint64_t> dropped_ring_{0};
  std::atomic<std::uint64_t> dropped_storage_{0};
  std::atomic<std::uint64_t> stored_{0};
  std::vector<LogRecord> tap_batch_;  // allocated once; the tap's records not yet delivered
  std::size_t tap_count_ = 0;
  std::exception_ptr error_;
  bool finished_ = false;
};

}  // namespace piezobench::rt
