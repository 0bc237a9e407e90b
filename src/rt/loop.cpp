#include "piezobench/rt/loop.hpp"

#include <fmt/format.h>

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <thread>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "util.hpp"

namespace piezobench::rt {

struct Loop::Shared {
  std::atomic<std::uint64_t> heartbeat{0};  // cycles completed
  std::atomic<bool> watchdog{false};        // set by the watchdog thread
  std::atomic<std::uint64_t> watchdog_trips{0};
};

void LoopOptions::validate() const {
  const std::string source = "rt loop";
  detail::require_positive(duration, "duration", source);
  if (duration > 1e6) throw InputError(source, "duration", "at most 1e6 s", format_number(duration));
  if (priority < 1 || priority > 99) throw InputError(source, "priority", "an integer in 1..99", std::to_string(priority));
  detail::require_finite(gain, "gain", source);
  for (Eigen::Index i = 0; i < excitation.size(); ++i) {
    if (!std::isfinite(excitation(i))) {
      throw InputError(source, "excitation", "finite samples", "NaN or Inf at sample " + std::to_string(i));
    }
  }
  if (feedforward_weight.size() > 0) {
    if (!feedforward) throw InputError(source, "feedforward_weight", "none without a feedforward", std::to_string(feedforward_weight.size()) + " samples");
    if (feedforward_weight.size() != excitation.size()) {
      throw InputError(source, "feedforward_weight", fmt::format("{} samples (the excitation's)", excitation.size()),
                       std::to_string(feedforward_weight.size()));
    }
    for (Eigen::Index i = 0; i < feedforward_weight.size(); ++i) {
      if (!(feedforward_weight(i) >= 0.0 && feedforward_weight(i) <= 1.0)) {
        throw InputError(source, "feedforward_weight", "weights in [0, 1]", fmt::format("{} at sample {}", feedforward_weight(i), i));
      }
    }
  }
  if (log_ring_capacity < 2) throw InputError(source, "log_ring_capacity", "at least 2", std::to_string(log_ring_capacity));
  limits.validate();
  if (feedforward) feedforward->validate("rt loop: feedforward");
}

Loop::Loop(Backend& backend, const LoopOptions& options)
    : backend_(backend),
      options_((options.validate(), options)),
      rate_(backend.sample_rate()),
      total_cycles_(0),
      ramp_in_cycles_(0),
      ramp_out_cycles_(0),
      iff_(options.controller_params,
           [&] {
             control::DiscreteIffOptions d = options.discrete;
             d.sample_rate = backend.sample_rate();
             return d;
           }(),
           0.0),
      guard_(options.limits, backend.sample_rate()),
      shared_(std::make_unique<Shared>()) {
  detail::require_positive(rate_, "sample_rate", "backend " + backend.name());
  if (rate_ > kMaxSampleRate) {
    throw InputError("backend " + backend.name(), "sample_rate", "at most " + format_number(kMaxSampleRate) + " Hz", format_number(rate_) + " Hz");
  }
  if (options.feedforward) feedforward_.emplace(*options.feedforward, rate_);
  const double cycles = std::round(options.duration * rate_);
  total_cycles_ = static_cast<std::uint64_t>(std::max(1.0, cycles));
  ramp_in_cycles_ = static_cast<std::uint64_t>(std::llround(options.limits.ramp_in * rate_));
  ramp_out_cycles_ = static_cast<std::uint64_t>(std::llround(options.limits.ramp_out * rate_));
  period_ns_ = static_cast<std::int64_t>(std::llround(1e9 / rate_));
  watchdog_ns_ = static_cast<std::int64_t>(std::llround(options.limits.watchdog_timeout * 1e9));
  if (options.keep_log || options.log_file || options.log_tap.deliver) {
    LoggerOptions lo;
    lo.keep = options.keep_log || options.log_file;
    lo.tap = options.log_tap;
    lo.file = options.log_file;
    lo.ring_capacity = options.log_ring_capacity;
    lo.max_samples = lo.keep ? static_cast<std::size_t>(std::min<std::uint64_t>(total_cycles_, options.max_log_samples)) : 0;
    lo.sample_rate = rate_;
    lo.settings = options.log_settings;
    lo.settings["backend"] = backend.name();
    lo.settings["gain"] = options.gain;
    lo.settings["controller"] = std::string(options.controller ? "iff" : "off");
    lo.settings["actuator"] = options.limits.actuator;
    lo.settings["amplifier_gain"] = options.limits.amplifier_gain;
    lo.settings["va_min"] = options.limits.va_min;
    lo.settings["va_max"] = options.limits.va_max;
    lo.settings["slew_rate"] = options.limits.slew_rate;
    lo.settings["realtime"] = options.realtime ? 1.0 : 0.0;
    lo.settings["feedforward"] = options.feedforward ? 1.0 : 0.0;
    logger_ = std::make_unique<SignalLogger>(lo);
  }
  last_va_cmd_ = guard_.last_output() * options.limits.amplifier_gain;
  va_cmd_min_ = va_cmd_max_ = last_va_cmd_;
}

Loop::~Loop() {
  if (started_ && !finished_) {
    backend_.stop();
  }
}

void Loop::start() {
  if (started_) return;
  backend_.start();
  backend_.write(guard_.last_output());  // the safe output before the first cycle
  if (logger_) logger_->start();
  started_ = true;
}

void Loop::watchdog_trip() noexcept {
  if (!shared_->watchdog.exchange(true, std::memory_order_acq_rel)) {
    shared_->watchdog_trips.fetch_add(1, std::memory_order_relaxed);
  }
  backend_.on_watchdog();
}

std::uint64_t Loop::heartbeat() const noexcept { return shared_->heartbeat.load(std::memory_order_acquire); }

// The steps of Loop::cycle(), inlined there: noexcept and allocation-free as it is.
struct Loop::Cycle {
  struct Clock {
    bool timed = false;         // real-time mode with a wake-up time
    bool late = false;          // woken after the watchdog timeout since the last cycle's end
    std::int64_t start_ns = 0;  // CLOCK_MONOTONIC
    double latency_us = 0.0;    // wake-up after the deadline
  };

  // Wind-down: bring the output to the safe value at the slew limit (the ramp out normally ends
  // there already; not after an early end of the backend or a trip mid-slew).
  static bool wind_down(Loop& l, double u_safe) noexcept {
    if (l.guard_.last_output() == u_safe) return false;
    const SafetyGuard::Output out = l.guard_.limit(u_safe);
    l.backend_.write(out.u);
    ++l.wind_down_;
    l.shared_->heartbeat.fetch_add(1, std::memory_order_release);
    return true;
  }

  // The cycle's start, and in real-time mode the jitter, the wake-up latency and whether the cycle
  // woke too late for the watchdog.
  static Clock wake_up(Loop& l, std::int64_t deadline_ns, std::int64_t wake_ns) noexcept {
    Clock c;
    c.timed = l.options_.realtime && wake_ns != 0;
    c.start_ns = c.timed ? wake_ns : monotonic_ns();
    if (c.timed) {
      if (l.cycle_ > 0) {
        l.jitter_.add(std::abs(static_cast<double>(wake_ns - l.last_wake_ns_ - l.period_ns_)));
        c.late = wake_ns - l.last_end_ns_ > l.watchdog_ns_;
      }
      c.latency_us = static_cast<double>(wake_ns - deadline_ns) * 1e-3;
      l.latency_.add(static_cast<double>(wake_ns - deadline_ns));
      l.last_wake_ns_ = wake_ns;
    }
    return c;
  }

  // The sample's checks, the watchdog and a stop request; a fault latches the safe state and
  // resets the controller.
  static void check_faults(Loop& l, const SensorSample& s, bool late) noexcept {
    Fault fault = l.guard_.check(s);
    if (fault == Fault::kNone && (late || l.shared_->watchdog.load(std::memory_order_acquire))) {
      fault = Fault::kWatchdog;
      if (late && !l.shared_->watchdog.exchange(true, std::memory_order_acq_rel)) {
        l.shared_->watchdog_trips.fetch_add(1, std::memory_order_relaxed);
      }
    }
    if (l.options_.stop != nullptr && l.options_.stop->load(std::memory_order_relaxed)) {
      l.stopping_ = true;
      if (fault == Fault::kNone) fault = Fault::kInterrupted;
    }
    if (fault != Fault::kNone && !l.guard_.safe_state()) {
      l.guard_.trip(fault, l.cycle_);
      l.iff_.reset();
    }
  }

  // Ramp factor: 0 -> 1 over the first ramp_in cycles, 1 -> 0 over the last ramp_out cycles.
  static double ramp_factor(const Loop& l) noexcept {
    double r = 1.0;
    if (l.ramp_in_cycles_ > 0) r = std::min(r, static_cast<double>(l.cycle_) / static_cast<double>(l.ramp_in_cycles_));
    if (l.ramp_out_cycles_ > 0) {
      r = std::min(r, static_cast<double>(l.total_cycles_ - 1 - l.cycle_) / static_cast<double>(l.ramp_out_cycles_));
    }
    return r;
  }

  // The controller's output y, the request u_safe + r (u_ff + y - u_safe) through the safety guard
  // (a trip on a non-finite controller output or a saturation too long), anti-windup, and the
  // command written to the backend.
  static SafetyGuard::Output command(Loop& l, const SensorSample& s, double r, double u_ff, double u_safe, double& y) noexcept {
    double request = u_safe;
    if (!l.guard_.safe_state()) {
      if (l.options_.controller) {
        l.iff_.set_gain(r * l.options_.gain);
        y = l.iff_.step(s.vs);
        if (l.iff_.nonfinite_inputs() != l.controller_nonfinite_seen_) {
          l.controller_nonfinite_seen_ = l.iff_.nonfinite_inputs();
          l.guard_.trip(Fault::kNonFiniteController, l.cycle_);
          l.iff_.reset();
          y = 0.0;
        }
      }
      if (!l.guard_.safe_state()) request = u_safe + r * (u_ff + y - u_safe);
    }
    const SafetyGuard::Output out = l.guard_.limit(request);
    if (!l.guard_.safe_state() && l.guard_.saturated_too_long()) {
      l.guard_.trip(Fault::kSaturation, l.cycle_);  // from the next cycle on
      l.iff_.reset();
    }
    if (!l.guard_.safe_state() && l.options_.controller && r > 0.0 && (out.clamped || out.slew_limited)) {
      // Anti-windup: the controller's share of what was really applied.
      l.iff_.applied((out.u - u_safe) / r + u_safe - u_ff);
    }
    l.backend_.write(out.u);
    return out;
  }

  static void record_command(Loop& l, double va_cmd) noexcept {
    l.va_cmd_min_ = std::min(l.va_cmd_min_, va_cmd);
    l.va_cmd_max_ = std::max(l.va_cmd_max_, va_cmd);
    l.max_step_ = std::max(l.max_step_, std::abs(va_cmd - l.last_va_cmd_));
    l.last_va_cmd_ = va_cmd;
  }

  // The step time, and an overrun (a cycle ending after the next deadline) by its cause.
  static void record_timing(Loop& l, const Clock& clock, std::int64_t deadline_ns, std::int64_t wake_ns, std::int64_t end_ns) noexcept {
    l.step_time_.add(static_cast<double>(end_ns - clock.start_ns));
    if (clock.timed && end_ns > deadline_ns + l.period_ns_) {
      ++l.overruns_;
      if (wake_ns - deadline_ns >= end_ns - wake_ns) {
        ++l.overruns_late_wakeup_;
      } else {
        ++l.overruns_long_step_;
      }
    }
    l.last_end_ns_ = end_ns;
  }

  static void log_cycle(Loop& l, const SensorSample& s, const SafetyGuard::Output& out, double u_prime, double y, double r,
                          const Clock& clock, std::int64_t end_ns) noexcept {
    LogRecord rec;
    rec.t = static_cast<double>(l.cycle_) / l.rate_;
    rec.u_prime = u_prime;
    rec.u = out.u;
    rec.va_cmd = l.last_va_cmd_;
    rec.va = std::isfinite(s.va) ? s.va : rec.va_cmd;
    const bool sensor_ok = std::isfinite(s.de) && std::isfinite(s.vs);
    rec.de = sensor_ok ? s.de : 0.0;
    rec.vs = sensor_ok ? s.vs : 0.0;
    rec.y = y;
    rec.latency_us = clock.latency_us;
    rec.step_us = static_cast<double>(end_ns - clock.start_ns) * 1e-3;
    rec.measured_ns = clock.start_ns;
    rec.flags = (out.clamped ? kFlagClamped : 0u) | (out.slew_limited ? kFlagSlewLimited : 0u) |
                (l.guard_.safe_state() ? kFlagSafeState : 0u) | (r < 1.0 ? kFlagRamping : 0u) |
                (sensor_ok ? 0u : kFlagSensorFault);
    if (l.options_.realtime) {
      l.logger_->push(rec);
    } else {
      l.logger_->push_wait(rec);
    }
  }
};

bool Loop::cycle(std::int64_t deadline_ns, std::int64_t wake_ns) noexcept {
  if (!started_ || finished_) return false;
  const double u_safe = guard_.limits().u_safe();
  const double amp = guard_.limits().amplifier_gain;
  // A stop request ends the run once the safe state has brought the output to the safe value.
  if (stopping_ && guard_.last_output() == u_safe) total_cycles_ = std::min(total_cycles_, cycle_);
  if (cycle_ >= total_cycles_ || backend_.finished()) return Cycle::wind_down(*this, u_safe);
  const Cycle::Clock clock = Cycle::wake_up(*this, deadline_ns, wake_ns);
  const SensorSample s = backend_.read();
  Cycle::check_faults(*this, s, clock.late);
  const double r = Cycle::ramp_factor(*this);
  const auto played = static_cast<Eigen::Index>(options_.excitation.size() > 0 ? cycle_ % static_cast<std::uint64_t>(options_.excitation.size()) : 0);
  const double u_prime = options_.excitation.size() > 0 ? options_.excitation(played) : 0.0;
  // The feedforward's share of the request (V at the DAC): u' through the inverse hysteresis,
  // weighted.
  double u_ff = u_prime;
  if (feedforward_) {
    const double w = options_.feedforward_weight.size() > 0 ? options_.feedforward_weight(played) : 1.0;
    u_ff = feedforward_->step(u_prime * amp, w) / amp;
  }
  double y = 0.0;
  const SafetyGuard::Output out = Cycle::command(*this, s, r, u_ff, u_safe, y);
  Cycle::record_command(*this, out.u * amp);
  const std::int64_t end_ns = monotonic_ns();
  Cycle::record_timing(*this, clock, deadline_ns, wake_ns, end_ns);
  if (logger_) Cycle::log_cycle(*this, s, out, u_prime, y, r, clock, end_ns);
  ++cycle_;
  shared_->heartbeat.fetch_add(1, std::memory_order_release);
  return true;
}

LoopReport Loop::finish() {
  LoopReport rep;
  if (finished_) throw std::logic_error("rt::Loop::finish called twice");
  if (started_) {
    // Normally already at the safe output (ramp out, wind-down); make sure.
    backend_.write(guard_.last_output());
    backend_.stop();
  }
  finished_ = true;
  rep.backend = backend_.name();
  rep.sample_rate = rate_;
  rep.realtime = options_.realtime;
  rep.cycles = cycle_;
  rep.overruns = overruns_;
  rep.overruns_late_wakeup = overruns_late_wakeup_;
  rep.overruns_long_step = overruns_long_step_;
  rep.skipped_deadlines = skipped_;
  rep.wind_down_cycles = wind_down_;
  rep.period_jitter_us = jitter_.summary_us();
  rep.wake_latency_us = latency_.summary_us();
  rep.step_time_us = step_time_.summary_us();
  rep.feedforward = feedforward_.has_value();
  rep.clamped_samples = guard_.clamped_samples();
  rep.slew_limited_samples = guard_.slew_limited_samples();
  rep.safe_state_events = guard_.safe_state_events();
  rep.safe_state_reason = to_string(guard_.fault());
  rep.safe_state_cycle = guard_.safe_state() ? static_cast<std::int64_t>(guard_.fault_cycle()) : -1;
  rep.nonfinite_sensor_samples = guard_.nonfinite_samples();
  rep.stale_sensor_samples = guard_.stale_samples();
  rep.watchdog_trips = shared_->watchdog_trips.load();
  rep.interrupted = stopping_;
  rep.io = backend_.io_stats();
  rep.va_cmd_min = va_cmd_min_;
  rep.va_cmd_max = va_cmd_max_;
  rep.max_va_cmd_step = max_step_;
  rep.warnings = warnings_;
  if (logger_) {
    io::TimeSeries& log = logger_->finish();  // joins the logger thread, writes the file
    rep.logged_samples = logger_->stored();
    rep.dropped_log_samples = logger_->dropped();
    if (options_.keep_log) log_ = std::move(log);
  }
  if (rep.dropped_log_samples > 0) {
    rep.warnings.push_back(std::to_string(rep.dropped_log_samples) + " log samples dropped (ring full or storage exhausted)");
  }
  return rep;
}

const io::TimeSeries& Loop::log() const {
  if (!finished_ || !options_.keep_log) {
    throw std::logic_error("rt::Loop::log: only after finish() and with LoopOptions::keep_log");
  }
  return log_;
}

namespace {

// Touches a stack area so that its pages are mapped before the cycles (no page fault later).
void prefault_stack() {
  constexpr std::size_t kBytes = 256 * 1024;
  unsigned char buffer[kBytes];
  for (std::size_t i = 0; i < kBytes; i += 4096) buffer[i] = 0;
  // Keep the writes: the compiler must assume the asm reads the buffer.
  asm volatile("" : : "r"(buffer) : "memory");
}

// What the host has taken from the calling thread so far: run-queue wait (ns, from
// /proc/thread-self/schedstat) and involuntary context switches; -1 each when not available.
struct HostShare {
  std::int64_t wait_ns = -1;
  std::int64_t preemptions = -1;
};
HostShare host_share() {
  HostShare h;
  std::ifstream in("/proc/thread-self/schedstat");
  std::int64_t cpu_ns = 0, wait_ns = 0;
  if (in >> cpu_ns >> wait_ns) h.wait_ns = wait_ns;
  rusage ru{};
  if (getrusage(RUSAGE_THREAD, &ru) == 0) h.preemptions = ru.ru_nivcsw;
  return h;
}

std::string errno_text(int err) {
  return std::string(err == EPERM ? "EPERM" : err == ENOMEM ? "ENOMEM" : err == EAGAIN ? "EAGAIN" : "errno " + std::to_string(err)) +
         ", " + std::strerror(err);
}

}  // namespace

LoopReport run_loop(Backend& backend, const LoopOptions& options, io::TimeSeries* log) {
  Loop loop(backend, options);
  std::vector<std::string> warnings;
  auto warn = [&](const std::string& w) {
    warnings.push_back(w);
    if (options.on_warning) options.on_warning(w);
  };
  bool memory_locked = false, fifo = false;
  std::int64_t host_wait_ns = -1, host_preemptions = -1;  // set by the loop thread (real time)
  loop.start();
  if (!options.realtime) {
    while (loop.cycle()) {
    }
  } else {
    if (options.lock_memory) {
      if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
        memory_locked = true;
      } else {
        const int err = errno;
        warn("mlockall refused (" + errno_text(err) +
             "; needs CAP_IPC_LOCK or a large enough RLIMIT_MEMLOCK): memory is not locked, page faults can add latency");
      }
    }
    std::atomic<bool> done{false};
    const std::int64_t period_ns = static_cast<std::int64_t>(std::llround(1e9 / backend.sample_rate()));
    const bool host_clock = backend.clock_source() == ClockSource::kHostMonotonic;
    std::thread rt_thread([&] {
      if (options.sched_fifo) {
        sched_param param{};
        param.sched_priority = options.priority;
        const int err = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
        if (err == 0) {
          fifo = true;
        } else {
          // Reported at once, before the first cycle (the main thread is waiting in join()).
          warn("SCHED_FIFO priority " + std::to_string(options.priority) + " refused (" + errno_text(err) +
               "; needs CAP_SYS_NICE or RLIMIT_RTPRIO): the loop runs at normal priority, expect jitter and overruns");
        }
      }
      // 1 ns timer slack: without it a normal-priority thread's sleeps end up to 50 us late (the
      // kernel ignores the slack for SCHED_FIFO threads anyway).
      prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
      prefault_stack();
      const HostShare host_before = host_share();
      std::int64_t deadline = monotonic_ns() + 1'000'000;  // first cycle 1 ms from now
      for (;;) {
        if (host_clock) sleep_until_ns(deadline);
        const std::int64_t wake = monotonic_ns();
        if (!host_clock) deadline = wake;  // the backend's read() paces the loop
        if (!loop.cycle(deadline, wake)) break;
        deadline += period_ns;
        const std::int64_t now = monotonic_ns();
        if (host_clock && now > deadline + period_ns) {
          // More than a whole period late: skip to the next future deadline.
          const std::int64_t missed = (now - deadline) / period_ns;
          deadline += missed * period_ns;
          loop.add_skipped(static_cast<std::uint64_t>(missed));
        }
      }
      const HostShare host_after = host_share();
      if (host_before.wait_ns >= 0 && host_after.wait_ns >= 0) host_wait_ns = host_after.wait_ns - host_before.wait_ns;
      if (host_before.preemptions >= 0 && host_after.preemptions >= 0) host_preemptions = host_after.preemptions - host_before.preemptions;
      done.store(true, std::memory_order_release);
    });
    // Watchdog: the loop must complete a cycle within watchdog_timeout.
    const auto timeout_ns = static_cast<std::int64_t>(options.limits.watchdog_timeout * 1e9);
    const auto poll = std::chrono::nanoseconds(std::max<std::int64_t>(timeout_ns / 4, 100'000));
    std::thread watchdog([&] {
      std::uint64_t last = loop.heartbeat();
      std::int64_t last_change = monotonic_ns();
      while (!done.load(std::memory_order_acquire)) {
        std::this_thread::sleep_for(poll);
        const std::uint64_t hb = loop.heartbeat();
        const std::int64_t now = monotonic_ns();
        if (hb != last) {
          last = hb;
          last_change = now;
        } else if (now - last_change > timeout_ns && !done.load(std::memory_order_acquire)) {
          loop.watchdog_trip();
          last_change = now;
        }
      }
    });
    rt_thread.join();
    watchdog.join();
    if (memory_locked) munlockall();
  }
  LoopReport report = loop.finish();
  report.sched_fifo = fifo;
  report.host_wait_ms = host_wait_ns >= 0 ? static_cast<double>(host_wait_ns) * 1e-6 : -1.0;
  report.host_preemptions = host_preemptions;
  report.memory_locked = memory_locked;
  warnings.insert(warnings.end(), report.warnings.begin(), report.warnings.end());
  report.warnings = warnings;
  if (log != nullptr && options.keep_log) *log = loop.log();
  return report;
}

}  // namespace piezobench::rt
