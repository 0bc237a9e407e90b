// `piezobench simulate`: one experiment of the report on the virtual bench, written as the
// measurement file a real bench would give (bench/experiments.hpp, docs/virtual-bench.md).
#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <variant>

#include "cli_common.hpp"
#include "piezobench/bench/experiments.hpp"
#include "piezobench/bench/truth.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/io/timeseries.hpp"

namespace piezobench::app {
namespace {

struct SimulateOptions {
  std::string experiment;
  int unit = 1;
  std::uint64_t seed = 1;
  std::string out;
  double amplitude = 0.0, duration = 0.0, gain = 0.0;
  CLI::Option* amplitude_option = nullptr;
  CLI::Option* duration_option = nullptr;
  CLI::Option* gain_option = nullptr;
  bool no_delay = false, no_nmp_zero = false, no_resistor = false, open_circuit = false, no_hysteresis = false, no_creep = false, no_noise = false;
  std::string superelement;
  bool json = false;
};

nlohmann::json settings_json(const io::TimeSeries& ts) {
  nlohmann::json s = nlohmann::json::object();
  for (const auto& [key, value] : ts.settings) {
    if (const double* d = std::get_if<double>(&value)) {
      s[key] = *d;
    } else {
      s[key] = std::get<std::string>(value);
    }
  }
  return s;
}

// "experiment options: amplitude: expected ..., found ..." -> "--amplitude: expected ..., found ...":
// the message names the command-line option the user typed.
InputError as_option_error(const InputError& e) {
  const std::string prefix = "experiment options: ";
  const std::string what = e.what();
  if (what.rfind(prefix, 0) != 0) return e;
  return InputError("--" + what.substr(prefix.size()));
}

int run_simulate(const SimulateOptions& o) {
  const bench::Experiment experiment = bench::experiment_from_string(o.experiment);
  bench::ExperimentOptions eo;
  if (o.amplitude_option->count() > 0) eo.amplitude = o.amplitude;
  if (o.duration_option->count() > 0) eo.duration = o.duration;
  if (o.gain_option->count() > 0) eo.gain = o.gain;
  if (o.no_delay) eo.bench.delay = 0.0;
  eo.bench.nonminimum_phase_zero = !o.no_nmp_zero;
  eo.bench.hysteresis = !o.no_hysteresis;
  eo.bench.creep = !o.no_creep;
  eo.bench.noise = !o.no_noise;
  eo.bench.hpf_resistor = !o.no_resistor;
  eo.bench.actuator_open_circuit = o.open_circuit;
  if (!o.superelement.empty()) eo.bench.superelement = o.superelement;
  try {
    eo.validate(experiment);
  } catch (const InputError& e) {
    throw as_option_error(e);
  }
  bench::UnitTruth unit;
  try {
    unit = bench::batch_unit(o.unit, o.seed);
  } catch (const InputError& e) {
    throw InputError("--" + std::string(e.what()));  // "--unit: expected a unit of the batch, 1 to 7, ..."
  }
  const std::string out = o.out.empty() ? fmt::format("{}-unit{}.mat", o.experiment, o.unit) : o.out;

  // Progress for the long runs, every quarter.
  int quarter = 0;
  const bench::Progress progress = [&quarter](double fraction) {
    if (fraction >= 0.25 * (quarter + 1) && fraction < 1.0) {
      quarter = static_cast<int>(fraction / 0.25);
      log_line(fmt::format("simulating: {:.0f} %", 100.0 * fraction));
    }
  };
  const bool long_run = eo.duration.value_or(0.0) >= 50.0;
  io::TimeSeries ts;
  try {
    ts = bench::simulate(experiment, unit, eo, o.seed, long_run ? progress : bench::Progress{});
  } catch (const InputError& e) {
    throw as_option_error(e);
  }
  io::write_timeseries(ts, out);
  if (!o.json) {
    fmt::print("wrote {}: {} on unit {}{} ({} samples at {:g} Hz; channels {}{})\n", out, o.experiment, o.unit,
               unit.defective ? " (defective)" : "", ts.samples(), ts.sample_rate, ts.t.size() > 0 ? "t, " : "",
               fmt::join(ts.names, ", "));
    return 0;
  }
  nlohmann::json units = nlohmann::json::object();
  for (std::size_t i = 0; i < ts.names.size(); ++i) units[ts.names[i]] = i < ts.units.size() ? ts.units[i] : "";
  print_json({{"file", out},
              {"experiment", o.experiment},
              {"unit", o.unit},
              {"seed", o.seed},
              {"samples", ts.samples()},
              {"sample_rate_Hz", ts.sample_rate},
              {"channels", ts.names},
              {"units", units},
              {"settings", settings_json(ts)},
              {"truth", bench::truth_json(unit, eo.bench)}});
  return 0;
}

}  // namespace

void add_simulate_commands(CLI::App& app, Action& action) {
  auto o = std::make_shared<SimulateOptions>();
  CLI::App* sim = app.add_subcommand("simulate", "One experiment of the report on the virtual bench, written as a measurement file");
  sim->add_option("experiment", o->experiment,
                  "stroke, hysteresis, stiffness, frf-noise, frf-sweep, iff, hammer, flatness or capacitance")
      ->required();
  sim->add_option("--unit", o->unit, "unit of the batch, 1..7 (3 is defective)")->capture_default_str();
  sim->add_option("--seed", o->seed, "seed of the batch and of the noise (same seed, same file)")->capture_default_str();
  sim->add_option("--out", o->out, "output file, .mat (default) or .csv (default: EXPERIMENT-unitN.mat)");
  o->amplitude_option = sim->add_option("--amplitude", o->amplitude,
                                        "V at the stacks: hysteresis sine amplitude (20), frf-noise/iff rms (2), "
                                        "frf-sweep amplitude (1); refused beyond the -20..150 V range");
  o->duration_option = sim->add_option("--duration", o->duration, "s: frf-noise (20), frf-sweep (20), iff (10)");
  o->gain_option = sim->add_option("--gain", o->gain, "IFF gain g of the report's controller (280000)");
  sim->add_flag("--no-delay", o->no_delay, "no measurement delay beyond the DAC's hold");
  sim->add_flag("--no-nmp-zero", o->no_nmp_zero, "a minimum-phase anti-resonance on u -> Vs");
  sim->add_flag("--no-hysteresis", o->no_hysteresis, "no hysteresis of the stacks");
  sim->add_flag("--no-creep", o->no_creep, "no creep of the stacks");
  sim->add_flag("--no-noise", o->no_noise, "no measurement noise (quantization stays)");
  sim->add_flag("--no-resistor", o->no_resistor, "no resistor across the sensor stack (only the ADC's input resistance)");
  sim->add_flag("--open-circuit", o->open_circuit,
                "actuator stacks disconnected from the amplifier (open circuit; for the stiffness test)");
  sim->add_option("--superelement", o->superelement, "TOML describing a super element to use instead of the 2-DoF model")
      ->check(CLI::ExistingFile);
  sim->add_flag("--json", o->json, "print one JSON document (file, settings, the unit's truth) on stdout");
  sim->callback([o, &action] { action = [o] { return run_simulate(*o); }; });
}

}  // namespace piezobench::app
