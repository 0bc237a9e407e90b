#pragma once
// The bench experiments (bench/experiments.hpp) on any rt backend: `piezobench measure`. Each of
// the experiment's primitives is one run of the real-time loop (loop.hpp) with the bench file's
// limits, so every command goes through the safety layer (clamp, slew limit, stale input,
// watchdog, Ctrl-C) and every cycle is logged; the loop's log becomes the experiment's record,
// with the same channels, units and settings as on the virtual bench (plus where it was made).
//
// Operator steps (the stiffness test's mass on and off) are prompted on `operator_out` at their
// time while the loop keeps running, and take effect when the operator confirms with a line on
// `operator_fd` (the terminal): the record's added_mass channel and t_on_s / t_off_s are the
// confirmation times.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "piezobench/bench/experiments.hpp"
#include "piezobench/rt/backend.hpp"
#include "piezobench/rt/bench_file.hpp"
#include "piezobench/rt/loop.hpp"

namespace piezobench::rt {

struct MeasureOptions {
  BenchDescription bench;                  // rate, limits, provenance
  bool realtime_priority = false;          // --realtime: SCHED_FIFO and mlockall (warned when refused)
  bool lockstep = false;                   // cycles back to back (simulated backends only; no operator steps)
  const std::atomic<bool>* stop = nullptr; // Ctrl-C (LoopOptions::stop)
  int operator_fd = 0;                     // where the operator's confirmations come from (stdin)
  std::ostream* operator_out = nullptr;    // where the prompts go (stderr when null)
  // The raw log of each loop run (every cycle, loop.hpp's channels) is written here when set:
  // FILE for one run, FILE with "-2", "-3" before the extension for the next ones.
  std::optional<std::filesystem::path> raw_log;
  std::function<void(const std::string&)> on_warning;
  // A live copy of each loop run's log while it runs (LoopOptions::log_tap; the station's page).
  LogTap log_tap;
};

struct OperatorConfirmation {
  std::string prompt;
  double asked_s = 0.0;      // s into the record (0: before it, with nothing moving)
  double confirmed_s = 0.0;  // s into the record; NaN if never confirmed
};

struct MeasureReport {
  std::vector<LoopReport> runs;               // one per primitive run
  std::vector<OperatorConfirmation> operator_steps;
  [[nodiscard]] IoStats io() const;           // summed over the runs (round trip: the last run's)
  [[nodiscard]] std::uint64_t cycles() const;
};

class BackendRunner final : public bench::BenchRunner {
 public:
  // The backend is not owned and must outlive the runner. Validates the bench description.
  BackendRunner(Backend& backend, MeasureOptions options);

  // bench::BenchRunner. Each throws InputError after the run (its raw log written) when the loop
  // entered its safe state (interrupted, stale input, watchdog, non-finite sensor): a record
  // that is not the experiment's is never returned.
  // u: V at the DAC.
  void open_loop(const Eigen::VectorXd& u, std::uint64_t seed, Eigen::MatrixXd& out, const bench::Progress& progress) override;
  // The loop's own feedforward stage (LoopOptions::feedforward), before its clamp and slew limit.
  // u_prime: V at the DAC; w: dimensionless.
  std::uint64_t open_loop_feedforward(const Eigen::VectorXd& u_prime, const Eigen::VectorXd& w, const ident::HysteresisModel& model,
                                      std::uint64_t seed, Eigen::MatrixXd& out, const bench::Progress& progress) override;
  // u_prime: V at the DAC; gain g: V/V.
  std::uint64_t iff(const Eigen::VectorXd& u_prime, double gain, std::uint64_t seed, Eigen::MatrixXd& out,
                    const bench::Progress& progress) override;
  std::vector<double> hold(Eigen::Index n, const std::vector<bench::OperatorStep>& steps, std::uint64_t seed,
                           Eigen::MatrixXd& out, const bench::Progress& progress) override;
  void describe(io::TimeSeries& record) const override;
  // Prompts each step and waits for its confirmation before anything moves (InputError without one).
  void prepare(const std::vector<std::string>& steps) override;

  [[nodiscard]] const MeasureReport& report() const { return report_; }

 private:
  io::TimeSeries run(LoopOptions lo, const std::vector<bench::OperatorStep>* steps);
  // u_prime: V at the DAC.
  void open_run(LoopOptions lo, const Eigen::VectorXd& u_prime, Eigen::MatrixXd& out, const bench::Progress& progress);
  Backend& backend_;
  MeasureOptions options_;
  MeasureReport report_;
};

// The bench options of the experiments for a bench description (rate, amplifier gain, stack range).
bench::BenchOptions bench_options(const BenchDescription& bench);

}  // namespace piezobench::rt
