// piezobench.bench: include/piezobench/bench/{virtual_bench,experiments,truth}.hpp
#include <nlohmann/json.hpp>

#include "common.hpp"
#include "described.hpp"
#include "piezobench/bench/experiments.hpp"
#include "piezobench/bench/truth.hpp"
#include "piezobench/bench/virtual_bench.hpp"
#include "piezobench/io/timeseries.hpp"

namespace piezobench::python {
namespace {

using namespace piezobench::bench;

const Options<BenchOptions>& bench_options() {
  static const Options<BenchOptions> t = [] {
    Options<BenchOptions> o("BenchOptions");
    o.add("sample_rate", &BenchOptions::sample_rate, "Hz, the real-time target's rate")
        .add("dac_bits", &BenchOptions::dac_bits, "DAC resolution")
        .add("dac_range", &BenchOptions::dac_range, "V, DAC range +-")
        .add("amplifier_gain", &BenchOptions::amplifier_gain, "V/V")
        .add("amplifier_bandwidth_Hz", &BenchOptions::amplifier_bandwidth_Hz, "Hz")
        .add("va_min", &BenchOptions::va_min, "V, lowest stack voltage")
        .add("va_max", &BenchOptions::va_max, "V, highest stack voltage")
        .add("suspended_mass", &BenchOptions::suspended_mass, "kg")
        .add("added_mass", &BenchOptions::added_mass, "kg, the mass of the stiffness test")
        .add("gravity", &BenchOptions::gravity, "m/s^2")
        .add("encoder_resolution", &BenchOptions::encoder_resolution, "m")
        .add("encoder_noise", &BenchOptions::encoder_noise, "m rms")
        .add("hpf_resistance", &BenchOptions::hpf_resistance, "Ohm, across the sensor stack")
        .add("adc_bits", &BenchOptions::adc_bits, "ADC resolution")
        .add("adc_range", &BenchOptions::adc_range, "V")
        .add("vs_noise", &BenchOptions::vs_noise, "V rms")
        .add("adc_bandwidth_Hz", &BenchOptions::adc_bandwidth_Hz, "Hz, anti-aliasing low-pass on Vs")
        .add("ground_resistance", &BenchOptions::ground_resistance, "Ohm, the origin of the NMP zero")
        .add("delay", &BenchOptions::delay, "s, total measurement delay (hold included)")
        .add("nonminimum_phase_zero", &BenchOptions::nonminimum_phase_zero, "the lightly damped NMP zero on u -> Vs")
        .add("hysteresis", &BenchOptions::hysteresis, "hysteresis of the stacks")
        .add_enum("hysteresis_law", &BenchOptions::hysteresis_law, &bench::to_string, &hysteresis_law_from_string,
                  "\"prandtl-ishlinskii\", \"bouc-wen\" or \"bouc-wen-asymmetric\"")
        .add("creep", &BenchOptions::creep, "creep of the stacks")
        .add("noise", &BenchOptions::noise, "measurement noise (quantization stays)")
        .add("superelement", &BenchOptions::superelement, "TOML file of a super element replacing the 2-DoF model");
    return o;
  }();
  return t;
}

const Options<ExperimentOptions>& experiment_options() {
  static const Options<ExperimentOptions> t = [] {
    Options<ExperimentOptions> o("ExperimentOptions");
    o.add("amplitude", &ExperimentOptions::amplitude, "V at the stacks (None = the experiment's default)")
        .add("duration", &ExperimentOptions::duration, "s (None = the experiment's default)")
        .add("gain", &ExperimentOptions::gain, "IFF gain g (iff)");
    return o;
  }();
  return t;
}

BenchOptions bench_kwargs(const py::kwargs& kw, const std::string& source) {
  return bench_options().from_kwargs(kwargs_dict(kw), source);
}

const std::string& bench_doc() {
  static const std::string s = "\nKeywords (BenchOptions):\n" + bench_options().doc();
  return s;
}

}  // namespace

void bind_bench(py::module_& m) {
  using py::arg;

  // The declared results (bench/virtual_bench.hpp); UnitTruth.model is an apa.TwoDofParams.
  bind_described<UnitTruth>(m);
  bind_described<BenchRun>(m);
  m.def("declarations", [] { return declarations_of<UnitTruth, BenchRun>(); },
        "{declared struct: (its Python class, [field names])} for every declared result bench returns (bench/*.hpp).");
  m.def("unit", [](int id, std::uint64_t seed) { return batch_unit(id, seed); }, arg("id"), arg("seed") = 1,
        "Unit `id` (1..7) of the report's batch drawn from `seed` (unit 3 defective): its true properties (SI), a bench.UnitTruth.");
  m.def(
      "truth",
      [](int id, std::uint64_t seed, const py::kwargs& kw) {
        auto o = bench_kwargs(kw, "bench.truth");
        auto u = batch_unit(id, seed);
        auto j = without_gil([&] { return truth_json(u, o); });
        return from_json(j, "Truth", true);
      },
      arg("id"), arg("seed") = 1,
      ("What a perfect characterization of unit `id` on this bench finds (resonance_Hz, antiresonance_Hz,\n"
       "zero_is_nonminimum_phase, stiffness_N_per_um, ...; keys as bench/truth.hpp)." + bench_doc()).c_str());
  m.def(
      "linear_model",
      [](int id, std::uint64_t seed, const py::kwargs& kw) {
        auto o = bench_kwargs(kw, "bench.linear_model");
        VirtualBench b(batch_unit(id, seed), o, seed);
        return b.linear_model();
      },
      arg("id"), arg("seed") = 1,
      ("The linear part of the bench of unit `id`, u (V) -> [d_e (m), Vs (V)], with the delay as input_delay:\n"
       "the \"true plant\" the identifications are checked against. An lti.StateSpace." + bench_doc()).c_str());
  m.def(
      "simulate",
      [](const std::string& experiment, int unit, std::uint64_t seed, const py::kwargs& kw) {
        const std::string src = "bench.simulate";
        py::dict d = kwargs_dict(kw);
        ExperimentOptions o = experiment_options().take(d, src);
        o.bench = bench_options().take(d, src);
        reject_leftovers(d, src, experiment_options().names() + ", " + bench_options().names());
        const Experiment e = experiment_from_string(experiment);
        auto u = batch_unit(unit, seed);
        return without_gil([&] { return simulate(e, u, o, seed); });
      },
      arg("experiment"), arg("unit") = 1, arg("seed") = 1,
      ("Runs one of the report's experiments (stroke, hysteresis, stiffness, frf-noise, frf-sweep, iff,\n"
       "hammer, flatness, capacitance, tracking) on unit `unit` of the batch and returns the record a real bench\n"
       "would write, as an io.TimeSeries (channels per experiment: bench/experiments.hpp).\n\n"
       "Keywords (ExperimentOptions):\n" + experiment_options().doc() + bench_doc())
          .c_str());

  py::class_<VirtualBench>(m, "VirtualBench", R"(The virtual test bench (bench/virtual_bench.hpp): one actuator with
hysteresis, creep, the NMP zero, DAC/amplifier/encoder/ADC, noise and delay, sample by sample.)")
      .def(py::init([](int unit, std::uint64_t seed, const py::kwargs& kw) {
             return VirtualBench(batch_unit(unit, seed), bench_kwargs(kw, "bench.VirtualBench"), seed);
           }),
           arg("unit") = 1, arg("seed") = 1, ("Unit `unit` of the batch drawn from `seed`." + bench_doc()).c_str())
      .def(
          "step",
          [](VirtualBench& b, double u) {
            auto s = b.step(u);
            return py::make_tuple(s.de, s.vs, s.va);
          },
          arg("u"), "One sample with DAC command u (V): returns (d_e (m), Vs (V), Va (V)).")
      .def(
          "run",
          [](VirtualBench& b, py::object u) {
            auto a = vector_arg(u, "bench.VirtualBench.run", "u", false);
            return without_gil([&] { return b.run(span(a)); });
          },
          arg("u"), "Runs the DAC commands u (1-D, V) in order: a bench.BenchRun of arrays de (m), vs (V), va (V).")
      .def("set_added_mass", &VirtualBench::set_added_mass, arg("kg"))
      .def("set_load_fraction", &VirtualBench::set_load_fraction, arg("fraction"))
      .def("reset", &VirtualBench::reset, arg("seed"), "Back to rest, noise reseeded.")
      .def("linear_model", &VirtualBench::linear_model, "u -> [d_e, Vs] linear part (lti.StateSpace).")
      .def_property_readonly("effective_delay", &VirtualBench::effective_delay, "s")
      .def_property_readonly("sample_rate", &VirtualBench::sample_rate, "Hz")
      .def_property_readonly("time", &VirtualBench::time, "s")
      .def_property_readonly("model_name", &VirtualBench::model_name);
}

}  // namespace piezobench::python
