#include "piezobench/rt/measure.hpp"

#include <fmt/format.h>
#include <poll.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <thread>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/timestamp.hpp"

namespace piezobench::rt {

namespace {

// Forwards to a backend and counts the commands written, so that another thread can tell how far
// the loop has got (the operator prompts) without touching the loop.
class CountingBackend final : public Backend {
 public:
  explicit CountingBackend(Backend& inner) : inner_(inner) {}
  [[nodiscard]] std::string name() const override { return inner_.name(); }
  [[nodiscard]] double sample_rate() const override { return inner_.sample_rate(); }
  [[nodiscard]] ClockSource clock_source() const override { return inner_.clock_source(); }
  void start() override {
    writes_.store(0);
    inner_.start();
  }
  SensorSample read() noexcept override { return inner_.read(); }
  void write(double u) noexcept override {
    inner_.write(u);
    writes_.fetch_add(1, std::memory_order_release);
  }
  [[nodiscard]] bool finished() const noexcept override { return inner_.finished(); }
  void stop() noexcept override { inner_.stop(); }
  void on_watchdog() noexcept override { inner_.on_watchdog(); }
  [[nodiscard]] IoStats io_stats() const override { return inner_.io_stats(); }
  // Cycles completed: the loop writes the safe output once before the first cycle.
  [[nodiscard]] std::uint64_t cycles() const noexcept {
    const std::uint64_t w = writes_.load(std::memory_order_acquire);
    return w > 0 ? w - 1 : 0;
  }

 private:
  Backend& inner_;
  std::atomic<std::uint64_t> writes_{0};
};

// Waits for one line on fd until `done` becomes true; true when a line (or its end) came.
bool wait_line(int fd, const std::atomic<bool>& done) {
  for (;;) {
    if (done.load()) return false;
    pollfd p{fd, POLLIN, 0};
    const int r = ::poll(&p, 1, 20);
    if (r < 0) return false;
    if (r == 0) continue;
    if ((p.revents & (POLLIN | POLLHUP)) == 0) return false;
    char c = 0;
    const ssize_t n = ::read(fd, &c, 1);
    if (n <= 0) return false;  // end of input: no confirmation
    if (c == '\n') return true;
  }
}

std::filesystem::path numbered(const std::filesystem::path& file, std::size_t run) {
  if (run <= 1) return file;
  std::filesystem::path p = file;
  p.replace_filename(file.stem().string() + "-" + std::to_string(run) + file.extension().string());
  return p;
}

}  // namespace

IoStats MeasureReport::io() const {
  IoStats s;
  for (const LoopReport& r : runs) {
    s.exchanges += r.io.exchanges;
    s.replies += r.io.replies;
    s.late += r.io.late;
    s.lost += r.io.lost;
    s.timeouts += r.io.timeouts;
    s.errors += r.io.errors;
    s.rejected += r.io.rejected;
    s.round_trip_us = r.io.round_trip_us;
  }
  return s;
}

std::uint64_t MeasureReport::cycles() const {
  std::uint64_t n = 0;
  for (const LoopReport& r : runs) n += r.cycles;
  return n;
}

bench::BenchOptions bench_options(const BenchDescription& bench) {
  bench::BenchOptions b;
  b.sample_rate = bench.sample_rate;
  b.amplifier_gain = bench.limits.amplifier_gain;
  b.va_min = bench.limits.va_min;
  b.va_max = bench.limits.va_max;
  b.encoder_resolution = bench.encoder_resolution;
  return b;
}

BackendRunner::BackendRunner(Backend& backend, MeasureOptions options) : backend_(backend), options_(std::move(options)) {
  options_.bench.validate();
  const double rate = backend.sample_rate();
  if (std::abs(rate - options_.bench.sample_rate) > 1e-9 * options_.bench.sample_rate) {
    throw InputError(options_.bench.source, "bench.sample_rate_Hz",
                     fmt::format("the backend's rate {} Hz", format_number_exact(rate)),
                     fmt::format("{} Hz", format_number_exact(options_.bench.sample_rate)));
  }
}

io::TimeSeries BackendRunner::run(LoopOptions lo, const std::vector<bench::OperatorStep>* steps) {
  const double rate = backend_.sample_rate();
  lo.limits = options_.bench.limits;
  lo.realtime = !options_.lockstep;
  lo.sched_fifo = lo.lock_memory = options_.realtime_priority;
  lo.stop = options_.stop;
  lo.keep_log = true;
  lo.max_log_samples = static_cast<std::size_t>(std::llround(lo.duration * rate)) + 16;
  lo.on_warning = options_.on_warning;
  lo.log_tap = options_.log_tap;
  if (options_.raw_log) lo.log_file = numbered(*options_.raw_log, report_.runs.size() + 1);
  lo.log_settings["command"] = std::string("measure");
  lo.log_settings["bench_file"] = options_.bench.source;

  CountingBackend counting(backend_);
  io::TimeSeries log;
  LoopReport rep;
  if (steps == nullptr || steps->empty()) {
    rep = run_loop(counting, lo, &log);
  } else {
    if (options_.lockstep) {
      throw InputError("measure", "operator", "a bench paced in real time (the operator acts while it runs)", "lockstep");
    }
    std::ostream& out = options_.operator_out ? *options_.operator_out : std::cerr;
    std::atomic<bool> done{false};
    std::exception_ptr error;
    std::thread loop_thread([&] {
      try {
        rep = run_loop(counting, lo, &log);
      } catch (...) {
        error = std::current_exception();
      }
      done.store(true);
    });
    for (const bench::OperatorStep& s : *steps) {
      OperatorConfirmation c{s.prompt, s.t, std::numeric_limits<double>::quiet_NaN()};
      const auto at = static_cast<std::uint64_t>(std::llround(s.t * rate));
      while (!done.load() && counting.cycles() < at) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      if (done.load()) {
        report_.operator_steps.push_back(c);
        continue;
      }
      out << fmt::format("operator, at t = {:.1f} s: {}; press Enter when done\n", s.t, s.prompt) << std::flush;
      if (wait_line(options_.operator_fd, done)) {
        c.confirmed_s = static_cast<double>(counting.cycles()) / rate;
        out << fmt::format("operator: confirmed at t = {:.3f} s\n", c.confirmed_s) << std::flush;
      }
      report_.operator_steps.push_back(c);
    }
    loop_thread.join();
    if (error) std::rethrow_exception(error);
  }
  report_.runs.push_back(rep);
  if (rep.safe_state_cycle >= 0) {
    throw InputError(
        "measure on " + backend_.name(), "run", "a run without a safety trip",
        fmt::format("the safe state ({}) at t = {} s; the output was brought to {} V{}", rep.safe_state_reason,
                    format_number_fixed(static_cast<double>(rep.safe_state_cycle) / rate, 4),
                    format_number(lo.limits.va_safe),
                    lo.log_file ? "; the log up to then is in " + lo.log_file->string() : std::string()));
  }
  // A held sample repeats the previous one: beyond the budget the record is not the response.
  const double budget = std::floor(lo.limits.stale_budget * static_cast<double>(rep.cycles));
  if (static_cast<double>(rep.stale_sensor_samples) > budget) {
    throw InputError(
        "measure on " + backend_.name(), "stale samples",
        fmt::format("at most {} held samples ({} % of the run's {} cycles, limits.stale_budget)",
                    format_number_exact(budget), format_number(100.0 * lo.limits.stale_budget), rep.cycles),
        fmt::format("{}{}", rep.stale_sensor_samples,
                    lo.log_file ? "; the log is in " + lo.log_file->string() : std::string()));
  }
  const auto n = static_cast<Eigen::Index>(std::llround(lo.duration * rate));
  if (log.samples() < n) {
    throw InputError("measure on " + backend_.name(), "log", fmt::format("{} samples", n),
                     fmt::format("{} ({} dropped)", log.samples(), rep.dropped_log_samples));
  }
  return log;
}

namespace {
void copy_columns(const io::TimeSeries& log, Eigen::Index n, Eigen::MatrixXd& out) {
  out.resize(n, 4);
  out.col(0) = log.channel("u").head(n);
  out.col(1) = log.channel("Va").head(n);
  out.col(2) = log.channel("de").head(n);
  out.col(3) = log.channel("Vs").head(n);
}
}  // namespace

void BackendRunner::open_loop(const Eigen::VectorXd& u, std::uint64_t, Eigen::MatrixXd& out, const bench::Progress& progress) {
  open_run({}, u, out, progress);
}

std::uint64_t BackendRunner::open_loop_feedforward(const Eigen::VectorXd& u_prime, const Eigen::VectorXd& w, const ident::HysteresisModel& model,
                                                   std::uint64_t, Eigen::MatrixXd& out, const bench::Progress& progress) {
  LoopOptions lo;
  lo.feedforward = model;
  lo.feedforward_weight = w;
  open_run(std::move(lo), u_prime, out, progress);
  return report_.runs.back().clamped_samples;
}

void BackendRunner::open_run(LoopOptions lo, const Eigen::VectorXd& u_prime, Eigen::MatrixXd& out, const bench::Progress& progress) {
  lo.controller = false;
  lo.excitation = u_prime;
  lo.duration = static_cast<double>(u_prime.size()) / backend_.sample_rate();
  copy_columns(run(std::move(lo), nullptr), u_prime.size(), out);
  if (progress) progress(1.0);
}

std::uint64_t BackendRunner::iff(const Eigen::VectorXd& u_prime, double gain, std::uint64_t, Eigen::MatrixXd& out,
                                 const bench::Progress& progress) {
  LoopOptions lo;
  lo.controller = true;
  lo.gain = gain;
  lo.excitation = u_prime;
  lo.duration = static_cast<double>(u_prime.size()) / backend_.sample_rate();
  copy_columns(run(lo, nullptr), u_prime.size(), out);
  if (progress) progress(1.0);
  return report_.runs.back().clamped_samples;
}

std::vector<double> BackendRunner::hold(Eigen::Index n, const std::vector<bench::OperatorStep>& steps, std::uint64_t,
                                        Eigen::MatrixXd& out, const bench::Progress& progress) {
  LoopOptions lo;
  lo.controller = false;
  lo.duration = static_cast<double>(n) / backend_.sample_rate();
  const std::size_t first = report_.operator_steps.size();
  const io::TimeSeries log = run(lo, &steps);
  std::vector<double> done;
  for (std::size_t i = first; i < report_.operator_steps.size(); ++i) {
    const OperatorConfirmation& c = report_.operator_steps[i];
    if (!std::isfinite(c.confirmed_s)) {
      throw InputError("measure", "operator", "a confirmation (Enter) of: " + c.prompt,
                       "none before the end of the record (or the end of the input)");
    }
    done.push_back(c.confirmed_s);
  }
  out.resize(n, 2);
  out.col(0) = log.channel("de").head(n);
  const double fs = backend_.sample_rate();
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / fs;
    double mass = 0.0;
    for (std::size_t i = 0; i < steps.size(); ++i) {
      if (t >= done[i]) mass = steps[i].added_mass;
    }
    out(k, 1) = mass;
  }
  if (progress) progress(1.0);
  return done;
}

void BackendRunner::prepare(const std::vector<std::string>& steps) {
  std::ostream& out = options_.operator_out ? *options_.operator_out : std::cerr;
  const std::atomic<bool> never{false};
  for (const std::string& prompt : steps) {
    out << fmt::format("operator, before the record (nothing moves): {}; press Enter when done\n", prompt) << std::flush;
    if (!wait_line(options_.operator_fd, never)) {
      throw InputError("measure", "operator", "a confirmation (Enter) of: " + prompt, "the end of the input");
    }
    report_.operator_steps.push_back({prompt, 0.0, 0.0});
  }
}

void BackendRunner::describe(io::TimeSeries& ts) const {
  // What the virtual bench knows and a real bench does not.
  for (const char* key : {"defective", "noise", "suspended_mass_kg", "hpf_resistance_ohm", "sensor_shunt_ohm"}) {
    ts.settings.erase(key);
  }
  const BenchDescription& b = options_.bench;
  ts.settings["backend"] = backend_.name();
  ts.settings["bench_file"] = b.source;
  if (!b.name.empty()) ts.settings["bench_name"] = b.name;
  ts.settings["bench"] = b.name.empty() ? b.source : b.name;
  if (b.backend == "udp") ts.settings["udp_address"] = b.udp_address;
  if (b.backend == "comedi") {
    ts.settings["device"] = b.comedi_device;
    ts.settings["calibration"] = b.calibration;
  }
  ts.settings["slew_rate_V_per_s"] = b.limits.slew_rate;
  ts.settings["encoder_resolution_m"] = b.encoder_resolution;
  if (!report_.runs.empty()) {
    const LoopReport& r = report_.runs.back();
    ts.settings["slew_limited_samples"] = static_cast<double>(r.slew_limited_samples);
    ts.settings["io_lost"] = static_cast<double>(r.io.lost);
    ts.settings["io_late"] = static_cast<double>(r.io.late);
    ts.settings["io_rejected"] = static_cast<double>(r.io.rejected);
    ts.settings["stale_samples"] = static_cast<double>(r.stale_sensor_samples);
  }
}

}  // namespace piezobench::rt
