#pragma once
// What `simulate`, `measure`, `rt` and `bench serve` share: one experiment run and reported
// (simulate is measure on the virtual bench), the backend a bench file names, Ctrl-C.
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>
#include <string>

#include "piezobench/bench/experiments.hpp"
#include "piezobench/bench/twin.hpp"
#include "piezobench/bench/virtual_bench.hpp"
#include "piezobench/rt/backend.hpp"
#include "piezobench/rt/bench_file.hpp"
#include "piezobench/rt/loop.hpp"

namespace piezobench::app {

struct MeasureRequest {
  std::string experiment;
  bench::ExperimentOptions options;  // options.bench: the virtual bench's (virtual) or from the bench file
  int unit = 1;
  std::uint64_t seed = 1;
  std::string out;                   // default EXPERIMENT-unitN.mat
  bool json = false;
  // Hardware (or remote) bench: the experiment runs through rt::BackendRunner; none: the virtual
  // bench (bench::simulate).
  std::optional<rt::BenchDescription> bench;
  bool realtime = false;             // SCHED_FIFO and mlockall
  std::string log;                   // raw loop log
  bool reset_target = false;
  std::string serial;                // the unit's serial number when known: recorded (settings.serial)         // --reset-target: clear a UDP target's latched safe state after the operator's Enter
  // The virtual bench of a digital twin (bench/twin.hpp) instead of the batch unit: its unit; its
  // chain is already in options.bench (bench::apply_chain).
  std::optional<bench::Twin> twin;
};
// --feedforward MODEL.toml of simulate and measure: the tracking experiment's model (InputError
// naming the file; a model for another experiment is refused by ExperimentOptions::validate).
void set_feedforward(bench::ExperimentOptions& options, const std::string& file);
// --hysteresis-law NAME of simulate, rt, measure and bench serve (the virtual bench's law;
// docs/virtual-bench.md): UsageError naming the option and the laws.
bench::HysteresisLaw hysteresis_law_option(const std::string& name);
inline constexpr const char* kHysteresisLawHelp =
    "virtual bench: law of the stacks' hysteresis, prandtl-ishlinskii (play operators), bouc-wen or bouc-wen-asymmetric "
    "(docs/virtual-bench.md)";
// Runs the experiment, writes the record, prints the summary (or the JSON document).
int run_measurement(const MeasureRequest& request);

// One loop run as JSON, the same in `rt --json` and in each run of `measure --json` (which shows
// a part of it): rt::LoopReport's declared fields (io::results_object), plus the timing figures
// grouped again by where they come from: what the shared host took ("host": late wake-ups,
// skipped deadlines, wait for a core, preemptions) apart from what the code took ("code": long
// steps, step time). The pacing percentiles are null in lockstep (no clock to be late on).
nlohmann::json loop_report_json(const rt::LoopReport& report);

// The backend a bench file names (virtual: the batch unit of its [virtual] table, or its twin). InputError when
// the device cannot be used. reset_target: a UDP target found in its latched safe state is reset
// once the operator confirms on stdin (otherwise refused).
std::unique_ptr<rt::Backend> make_backend(const rt::BenchDescription& bench, bool reset_target = false);

// Ctrl-C (SIGINT) sets the returned flag instead of killing the process, until the process ends:
// the loop brings the output to the safe value and the log is written.
const std::atomic<bool>* stop_on_sigint();

}  // namespace piezobench::app
