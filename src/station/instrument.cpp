// The station's bench (phase_runner.hpp, BenchInstrument): each phase's record made as `measure`
// makes it.
#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "piezobench/bench/experiments.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/file.hpp"
#include "piezobench/rt/measure.hpp"
#include "piezobench/station/phase_runner.hpp"

namespace piezobench::station {

namespace fs = std::filesystem;

namespace {

// A pipe holding `lines` confirmations, for in-record operator steps answered in advance.
class ConfirmationPipe {
 public:
  explicit ConfirmationPipe(int lines) {
    if (::pipe(fd_) != 0) throw InputError("qualify", "operator", "a pipe for the answered confirmations", "pipe() failed");
    const std::string text(static_cast<std::size_t>(lines), '\n');
    if (::write(fd_[1], text.data(), text.size()) != static_cast<ssize_t>(text.size())) {
      throw InputError("qualify", "operator", "a pipe for the answered confirmations", "write() failed");
    }
    ::close(fd_[1]);
  }
  ~ConfirmationPipe() { ::close(fd_[0]); }
  ConfirmationPipe(const ConfirmationPipe&) = delete;
  ConfirmationPipe& operator=(const ConfirmationPipe&) = delete;
  [[nodiscard]] int read_fd() const { return fd_[0]; }

 private:
  int fd_[2] = {-1, -1};
};

bench::ExperimentOptions experiment_options(const PhaseSpec& p, const rt::BenchDescription& bench) {
  bench::ExperimentOptions eo;
  eo.bench = rt::bench_options(bench);
  eo.amplitude = p.amplitude_V;
  eo.duration = p.duration_s;
  eo.gain = p.gain;
  // Open circuit: the stacks off the amplifier and no resistor on the sensor (as the demo's k_oc record).
  eo.bench.actuator_open_circuit = p.open_circuit;
  eo.bench.hpf_resistor = !(p.no_resistor || p.open_circuit);
  return eo;
}

Acquired write_values(const PhaseSpec& p, const PhaseValues& v, const fs::path& stem) {
  if (p.source == ValueSource::kFile) {
    if (!v.file) throw InputError("qualify", "phase " + p.name, "the file of the phase", "none");
    const fs::path target = fs::path(stem.string() + v.file->extension().string());
    write_text_atomically(target, read_file(*v.file));  // the operator's file, as it was
    return {target, {}};
  }
  if (!v.sensor_uF || !v.actuator_uF) throw InputError("qualify", "phase " + p.name, "the typed capacitances", "none");
  io::TimeSeries ts;
  ts.names = {"C_sensor", "C_actuator"};
  ts.units = {"F", "F"};
  ts.data.resize(1, 2);
  ts.data << *v.sensor_uF * 1e-6, *v.actuator_uF * 1e-6;
  ts.sample_rate = 1.0;
  ts.settings["experiment"] = std::string("capacitance");
  ts.settings["source"] = std::string("typed by the operator");
  const fs::path target = fs::path(stem.string() + ".mat");
  io::write_timeseries(ts, target);
  return {target, ts.settings};
}

}  // namespace

BenchInstrument::BenchInstrument(BenchInstrumentOptions options) : options_(std::move(options)) {}

void BenchInstrument::check(const StationFile& station) const {
  for (const PhaseSpec& p : station.phases) {
    const bench::Experiment e = bench::experiment_from_string(p.experiment);
    if (options_.bench.hardware() && !bench::runs_on_bench(e) && p.source == ValueSource::kBench) {
      throw InputError(fmt::format("{}: line {}", station.file.string(), p.line), "phases." + p.name,
                       "a phase the " + options_.bench.backend + " bench can measure (" + p.experiment +
                           " needs its own instrument: source = \"file\" or \"typed\")",
                       "source = \"bench\"");
    }
  }
}

Acquired BenchInstrument::acquire(const PhaseSpec& p, const PhaseValues& values, const fs::path& stem) {
  if (p.source != ValueSource::kBench) return write_values(p, values, stem);
  const bench::Experiment e = bench::experiment_from_string(p.experiment);
  const bench::ExperimentOptions eo = experiment_options(p, options_.bench);
  const auto start = std::chrono::steady_clock::now();
  io::TimeSeries ts;
  if (!options_.bench.hardware()) {
    ts = bench::simulate(e, bench::batch_unit(options_.unit, options_.seed), eo, options_.seed);
    const double duration = static_cast<double>(ts.samples()) / ts.sample_rate;
    if (options_.on_record && bench::runs_on_bench(e)) {
      options_.on_record(ts, options_.paced ? start : std::chrono::steady_clock::now() - std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                                                       std::chrono::duration<double>(duration)));
    }
    if (options_.paced && bench::runs_on_bench(e)) {
      // The virtual bench computes faster than real time: the phase takes the record's duration.
      const auto end = start + std::chrono::duration<double>(duration);
      while (std::chrono::steady_clock::now() < end && !(options_.stop && options_.stop->load())) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      if (options_.stop && options_.stop->load()) {
        throw InputError("qualify", "phase " + p.name, "a record not interrupted", "Ctrl-C");
      }
    }
  } else {
    std::unique_ptr<rt::Backend> backend = options_.make_backend(options_.bench);
    std::optional<ConfirmationPipe> pipe;
    if (options_.operator_fd < 0) pipe.emplace(8);
    rt::MeasureOptions mo;
    mo.bench = options_.bench;
    mo.stop = options_.stop;
    mo.operator_fd = pipe ? pipe->read_fd() : options_.operator_fd;
    if (options_.log) mo.on_warning = [this](const std::string& w) { options_.log("warning: " + w); };
    mo.log_tap = options_.live_tap;
    rt::BackendRunner runner(*backend, mo);
    bench::UnitTruth unit;
    unit.id = options_.unit;  // a real unit: only its number is known
    ts = bench::run_experiment(e, runner, unit, eo, options_.seed);
    if (options_.on_record && ts.sample_rate > 0.0) {
      const double duration = static_cast<double>(ts.samples()) / ts.sample_rate;
      options_.on_record(ts, std::chrono::steady_clock::now() -
                                 std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(duration)));
    }
  }
  const fs::path target = fs::path(stem.string() + ".mat");
  io::write_timeseries(ts, target);
  return {target, ts.settings};
}

}  // namespace piezobench::station
