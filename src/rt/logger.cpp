#include "piezobench/rt/logger.hpp"

#include <chrono>
#include <cmath>

#include "piezobench/core/error.hpp"
#include "util.hpp"

namespace piezobench::rt {
namespace {

const std::vector<std::string> kNames = {"u_prime", "u",  "Va", "Va_cmd",     "de",     "Vs",
                                         "y",       "latency_us", "step_us", "flags"};
const std::vector<std::string> kUnits = {"V", "V", "V", "V", "m", "V", "V", "us", "us", ""};

}  // namespace

void LoggerOptions::validate() const {
  const std::string source = "logger options";
  if (ring_capacity < 2) throw InputError(source, "ring_capacity", "at least 2 records", std::to_string(ring_capacity));
  if (ring_capacity > (std::size_t{1} << 26)) {
    throw InputError(source, "ring_capacity", "at most 2^26 records", std::to_string(ring_capacity));
  }
  detail::require_positive(sample_rate, "sample_rate", source);
  if (tap.deliver && tap.every < 1) throw InputError(source, "tap.every", "at least 1", std::to_string(tap.every));
}

namespace {
constexpr std::size_t kTapBatch = 256;  // records per delivery at most
}  // namespace

SignalLogger::SignalLogger(const LoggerOptions& options) : options_(options), ring_((options.validate(), options.ring_capacity)) {
  log_.names = kNames;
  log_.units = kUnits;
  log_.sample_rate = options.sample_rate;
  log_.settings = options.settings;
  log_.data.resize(static_cast<Eigen::Index>(options.max_samples), static_cast<Eigen::Index>(kNames.size()));
  log_.t.resize(static_cast<Eigen::Index>(options.max_samples));
  if (options_.tap.deliver) tap_batch_.reserve(kTapBatch);
}

SignalLogger::~SignalLogger() {
  if (!finished_) abandon_.store(true, std::memory_order_release);
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
}

void SignalLogger::start() {
  if (thread_.joinable()) return;
  thread_ = std::thread([this] { run(); });
}

bool SignalLogger::push(const LogRecord& record) noexcept {
  if (ring_.push(record)) return true;
  dropped_ring_.fetch_add(1, std::memory_order_relaxed);
  return false;
}

void SignalLogger::push_wait(const LogRecord& record) noexcept {
  while (!ring_.push(record)) std::this_thread::yield();
}

std::uint64_t SignalLogger::dropped() const noexcept {
  return dropped_ring_.load(std::memory_order_relaxed) + dropped_storage_.load(std::memory_order_relaxed);
}

void SignalLogger::tap(const LogRecord& r) noexcept {
  if (tap_count_++ % options_.tap.every != 0) return;
  tap_batch_.push_back(r);  // within the reserved capacity: flushed when full
  if (tap_batch_.size() == kTapBatch) flush_tap(false);
}

void SignalLogger::flush_tap(bool run_over) noexcept {
  const auto deliver = [this](std::span<const LogRecord> batch) noexcept {
    try {
      options_.tap.deliver(batch);
    } catch (...) {
      // A live view that fails must not end the record: its samples are lost, the log is not.
    }
  };
  if (!tap_batch_.empty()) deliver(std::span<const LogRecord>(tap_batch_.data(), tap_batch_.size()));
  tap_batch_.clear();
  if (run_over) deliver({});  // an empty batch: the run is over
}

void SignalLogger::store(const LogRecord& r) noexcept {
  if (!options_.keep) return;
  const std::uint64_t i = stored_.load(std::memory_order_relaxed);
  if (i >= options_.max_samples) {
    dropped_storage_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  const auto row = static_cast<Eigen::Index>(i);
  log_.t(row) = r.t;
  const double values[] = {r.u_prime, r.u, r.va, r.va_cmd, r.de, r.vs, r.y, r.latency_us, r.step_us,
                           static_cast<double>(r.flags)};
  for (Eigen::Index j = 0; j < static_cast<Eigen::Index>(std::size(values)); ++j) log_.data(row, j) = values[j];
  stored_.store(i + 1, std::memory_order_release);
}

void SignalLogger::run() noexcept {
  LogRecord r;
  for (;;) {
    // Read the flag before draining: every record pushed before stop was requested is then seen.
    const bool stopping = stop_.load(std::memory_order_acquire);
    while (ring_.pop(r)) {
      store(r);
      if (options_.tap.deliver) tap(r);
    }
    if (stopping) break;
    if (options_.tap.deliver) flush_tap(false);  // what the ring held: delivered within a millisecond
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  if (abandon_.load(std::memory_order_acquire)) return;
  if (options_.tap.deliver) flush_tap(true);
  // The run is over: shrink to what was stored and write the file (allocation and I/O are fine
  // here, the real-time thread has stopped).
  try {
    const auto n = static_cast<Eigen::Index>(stored_.load(std::memory_order_acquire));
    log_.data.conservativeResize(n, Eigen::NoChange);
    log_.t.conservativeResize(n);
    if (options_.file && n > 0) io::write_timeseries(log_, *options_.file);
  } catch (...) {
    error_ = std::current_exception();
  }
}

io::TimeSeries& SignalLogger::finish() {
  if (!finished_) {
    finished_ = true;
    stop_.store(true, std::memory_order_release);
    if (thread_.joinable()) {
      thread_.join();
    } else {
      run();  // never started: drain and write on this thread
    }
    if (error_) std::rethrow_exception(error_);
    if (options_.file && log_.samples() == 0) {
      throw InputError(options_.file->string(), "log", "at least one cycle to write", "no sample");
    }
  }
  return log_;
}

}  // namespace piezobench::rt
