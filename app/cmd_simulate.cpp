// `piezobench simulate`: one experiment of the report on the virtual bench, written as the
// measurement file a real bench would give (bench/experiments.hpp, docs/virtual-bench.md).
#include <memory>

#include "cli_common.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/usage_error.hpp"
#include "measure_common.hpp"

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
  std::string twin;
  std::string hysteresis_law = "prandtl-ishlinskii";
  std::string feedforward;
  bool json = false;
};

// simulate is measure on the virtual bench, with the bench's options from the command line.
int run_simulate(const SimulateOptions& o) {
  MeasureRequest r;
  r.experiment = o.experiment;
  if (!o.twin.empty()) {
    r.twin = bench::read_twin(o.twin);
    bench::apply_chain(*r.twin, r.options.bench);  // the switches below act on the twin's chain
  }
  if (o.amplitude_option->count() > 0) r.options.amplitude = o.amplitude;
  if (o.duration_option->count() > 0) r.options.duration = o.duration;
  if (o.gain_option->count() > 0) r.options.gain = o.gain;
  if (o.no_delay) r.options.bench.delay = 0.0;
  r.options.bench.nonminimum_phase_zero = !o.no_nmp_zero;
  r.options.bench.hysteresis = !o.no_hysteresis;
  r.options.bench.creep = !o.no_creep;
  r.options.bench.noise = !o.no_noise;
  r.options.bench.hpf_resistor = !o.no_resistor;
  r.options.bench.actuator_open_circuit = o.open_circuit;
  if (!o.superelement.empty()) r.options.bench.superelement = o.superelement;
  r.options.bench.hysteresis_law = hysteresis_law_option(o.hysteresis_law);
  set_feedforward(r.options, o.feedforward);
  r.unit = r.twin ? r.twin->unit.id : o.unit;
  r.seed = o.seed;
  r.out = o.out;
  r.json = o.json;
  return run_measurement(r);
}

}  // namespace

void add_simulate_commands(CLI::App& app, Action& action) {
  auto o = std::make_shared<SimulateOptions>();
  CLI::App* sim = app.add_subcommand("simulate", "One experiment of the report on the virtual bench, written as a measurement file");
  sim->add_option("experiment", o->experiment,
                  "stroke, hysteresis, stiffness, frf-noise, frf-sweep, iff, hammer, flatness, capacitance or tracking")
      ->required();
  sim->add_option("--unit", o->unit, "unit of the batch, 1..7 (3 is defective)")->capture_default_str();
  sim->add_option("--seed", o->seed, "seed of the batch and of the noise (same seed, same file)")->capture_default_str();
  sim->add_option("--out", o->out, "output file, .mat (default) or .csv (default: EXPERIMENT-unitN.mat)");
  o->amplitude_option = sim->add_option("--amplitude", o->amplitude,
                                        "V at the stacks: hysteresis sine amplitude (20), tracking amplitude (80), frf-noise/iff rms (2), "
                                        "frf-sweep amplitude (1); refused beyond the -20..150 V range");
  o->duration_option = sim->add_option("--duration", o->duration, "s: frf-noise (20), frf-sweep (20), iff (10)");
  o->gain_option = sim->add_option("--gain", o->gain, "IFF gain g of the report's controller (280000)");
  sim->add_flag("--no-delay", o->no_delay, "no measurement delay beyond the DAC's hold");
  sim->add_flag("--no-nmp-zero", o->no_nmp_zero, "a minimum-phase anti-resonance on u -> Vs");
  sim->add_flag("--no-hysteresis", o->no_hysteresis, "no hysteresis of the stacks");
  sim->add_flag("--no-creep", o->no_creep, "no creep of the stacks");
  sim->add_option("--hysteresis-law", o->hysteresis_law, kHysteresisLawHelp)
      ->capture_default_str();
  sim->add_option("--feedforward", o->feedforward,
                  "tracking: the hysteresis model (TOML, `hysteresis fit`) of the compensated run (default: identified from the open run)")
      ->check(input_file());
  sim->add_option("--twin", o->twin, "a unit's digital twin (TOML, `piezobench twin`) instead of the batch unit --unit")
      ->check(input_file());
  sim->add_flag("--no-noise", o->no_noise, "no measurement noise (quantization stays)");
  sim->add_flag("--no-resistor", o->no_resistor, "no resistor across the sensor stack (only the ADC's input resistance)");
  sim->add_flag("--open-circuit", o->open_circuit,
                "actuator stacks disconnected from the amplifier (open circuit; for the stiffness test)");
  sim->add_option("--superelement", o->superelement, "TOML describing a super element to use instead of the 2-DoF model")
      ->check(input_file());
  sim->add_flag("--json", o->json, "print one JSON document (file, settings, the unit's truth) on stdout");
  sim->callback([o, &action] { action = [o] { return run_simulate(*o); }; });
}

}  // namespace piezobench::app
