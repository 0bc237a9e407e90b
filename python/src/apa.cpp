// piezobench.apa: include/piezobench/apa/{two_dof,tuning,piezo}.hpp
#include "common.hpp"
#include "described.hpp"
#include "piezobench/apa/piezo.hpp"
#include "piezobench/apa/tuning.hpp"
#include "piezobench/apa/two_dof.hpp"
#include "piezobench/dsp/frf.hpp"

namespace piezobench::python {
namespace {

using namespace piezobench::apa;

const Options<TwoDofParams>& params_options() {
  static const Options<TwoDofParams> t = [] {
    Options<TwoDofParams> o("TwoDofParams");
    o.add("m", &TwoDofParams::m, "kg, mass carried by the APA")
        .add("k1", &TwoDofParams::k1, "N/m, shell stiffness")
        .add("c1", &TwoDofParams::c1, "N s/m, shell damping")
        .add("ke", &TwoDofParams::ke, "N/m, sensor stack stiffness")
        .add("ce", &TwoDofParams::ce, "N s/m, sensor stack damping")
        .add("ka", &TwoDofParams::ka, "N/m, actuator stacks stiffness (the two in series)")
        .add("ca", &TwoDofParams::ca, "N s/m, actuator stacks damping")
        .add("ga", &TwoDofParams::ga, "N/V, actuator sensitivity f = ga Va (negative in the report)")
        .add("gs", &TwoDofParams::gs, "V/m, sensor sensitivity Vs = gs e");
    return o;
  }();
  return t;
}

const Options<TwoDofBench>& two_dof_bench_options() {
  static const Options<TwoDofBench> t = [] {
    Options<TwoDofBench> o("TwoDofBench");
    o.add("amplifier_gain", &TwoDofBench::amplifier_gain, "V/V, Va = G u")
        .add("suspended_mass", &TwoDofBench::suspended_mass, "kg; > 0 replaces m, 0 = m")
        .add("added_mass", &TwoDofBench::added_mass, "kg, added on top")
        .add("hpf_resistance", &TwoDofBench::hpf_resistance, "Ohm, resistor across the sensor stack (0 = no high-pass)")
        .add("hpf_capacitance", &TwoDofBench::hpf_capacitance, "F, sensor stack capacitance for the high-pass")
        .add("delay", &TwoDofBench::delay, "s, pure delay on u");
    return o;
  }();
  return t;
}

const Options<PiezoConstants>& piezo_options() {
  static const Options<PiezoConstants> t = [] {
    Options<PiezoConstants> o("PiezoConstants");
    o.add("d33", &PiezoConstants::d33, "m/V, piezoelectric charge constant")
        .add("eps_t", &PiezoConstants::eps_t, "F/m, permittivity at constant stress")
        .add("s_d", &PiezoConstants::s_d, "m^2/N, compliance at constant electric displacement")
        .add("c_e", &PiezoConstants::c_e, "N/m^2, Young's modulus at constant field")
        .add("length", &PiezoConstants::length, "m, stack length")
        .add("area", &PiezoConstants::area, "m^2, stack cross-section")
        .add("layers", &PiezoConstants::layers, "number of layers (an integer >= 1)");
    return o;
  }();
  return t;
}

const Options<TuningOptions>& tuning_options() {
  static const Options<TuningOptions> t = [] {
    Options<TuningOptions> o("TuningOptions");
    o.add("mass", &TuningOptions::mass, "kg, the known moving mass")
        .add_nested("bench", &TuningOptions::bench, two_dof_bench_options(),
                    "measurement chain removed before fitting (apa.two_dof_bench keywords; masses 0)")
        .add("fmin_Hz", &TuningOptions::fmin_Hz, "Hz, band used; 0 = from the lowest point")
        .add("fmax_Hz", &TuningOptions::fmax_Hz, "Hz; 0 = to the highest point")
        .add("min_coherence", &TuningOptions::min_coherence, "points below this coherence are left out")
        .add("stack_stiffness_ratio", &TuningOptions::stack_stiffness_ratio, "ke / ka imposed in the refinement; 0 = free")
        .add("stack_damping_ratio", &TuningOptions::stack_damping_ratio, "ce / ca imposed in the refinement; 0 = free")
        .add("refine", &TuningOptions::refine, "False: stop after the report's procedure")
        .add("window_resolution", &TuningOptions::window_resolution,
             "the model seen through the FRF's Welch resolution kernel (from its provenance); False: the model itself")
        .add("max_iterations", &TuningOptions::max_iterations, "Levenberg-Marquardt steps")
        .add("de_output", &TuningOptions::de_output, "name of the u -> d_e output in the FRF")
        .add("vs_output", &TuningOptions::vs_output, "name of the u -> Vs output in the FRF");
    return o;
  }();
  return t;
}

// Parameters and bench from one set of keywords (both tables), leftovers refused.
std::pair<TwoDofParams, TwoDofBench> model_kwargs(const py::kwargs& kw, const std::string& source) {
  py::dict d = kwargs_dict(kw);
  auto p = params_options().take(d, source);
  auto b = two_dof_bench_options().take(d, source);
  reject_leftovers(d, source, params_options().names() + ", " + two_dof_bench_options().names());
  return {p, b};
}

const std::string& model_doc() {
  static const std::string s = "\nKeywords (TwoDofParams, Table 3.1):\n" + params_options().doc() +
                               "Keywords (TwoDofBench):\n" + two_dof_bench_options().doc();
  return s;
}

// two_dof_actuator, two_dof_bench and two_dof_response (apa/two_dof.hpp).
void bind_two_dof_models(py::module_& m) {
  using py::arg;
  m.def(
      "two_dof_actuator",
      [](const py::kwargs& kw) { return two_dof_actuator(params_options().from_kwargs(kwargs_dict(kw), "apa.two_dof_actuator")); },
      ("The 2-DoF actuator alone (report section 3): input Va (V), outputs [d_e (m), Vs (V)], states\n"
       "[x, x', xn]. Returns an lti.StateSpace.\n\nKeywords (TwoDofParams, Table 3.1):\n" + params_options().doc())
          .c_str());
  m.def(
      "two_dof_bench",
      [](const py::kwargs& kw) {
        auto [p, b] = model_kwargs(kw, "apa.two_dof_bench");
        return two_dof_bench(p, b);
      },
      ("The actuator on the bench: input u (V at the DAC), outputs [d_e (m), Vs (V)] with the amplifier,\n"
       "the moving mass, the high-pass on Vs and the delay (input_delay). Returns an lti.StateSpace." + model_doc())
          .c_str());
  m.def(
      "two_dof_response",
      [](py::object omega, const py::kwargs& kw) {
        auto [p, b] = model_kwargs(kw, "apa.two_dof_response");
        auto w = to_vector(omega, "apa.two_dof_response", "omega");
        return to_numpy(two_dof_response(p, b, w));
      },
      arg("omega"),
      ("Closed-form response of two_dof_bench at j omega (rad/s): (len(omega), 2) complex, columns d_e (m/V)\n"
       "and Vs (V/V)." + model_doc()).c_str());
}

// characterize, default_params and piezo_sensitivities.
void bind_characterization(py::module_& m) {
  bind_described<TwoDofCharacteristics>(m);
  bind_described<PiezoSensitivities>(m);
  m.def(
      "characterize",
      [](const py::kwargs& kw) {
        auto [p, b] = model_kwargs(kw, "apa.characterize");
        return characterize(p, b);
      },
      ("Poles, zeros of u -> Vs (rad/s), static gains (m/V, V/V), resonance and anti-resonance (rad/s)\n"
       "with damping: what `piezobench model 2dof` reports." + model_doc()).c_str());
  m.def(
      "default_params", [] { return params_options().to_dict(TwoDofParams{}); },
      "The 9 parameters of Table 3.1 (SI) as a dict: the defaults of every TwoDofParams keyword.");
  m.def(
      "piezo_sensitivities",
      [](const py::kwargs& kw) {
        return piezo_sensitivities(piezo_options().from_kwargs(kwargs_dict(kw), "apa.piezo_sensitivities"));
      },
      ("Eq. 4.1: ka = cE A / L (N/m), ga = d33 n ka (N/V), gs = d33 / (eps_T sD n) (V/m).\n"
       "Defaults: Table 4.1 (ga = 26.11 N/V, gs = 5.06e6 V/m, ka = 2.4e8 N/m).\n\nKeywords (PiezoConstants):\n" +
       piezo_options().doc())
          .c_str());
}

// tune_two_dof and tune_two_dof_measured (apa/tuning.hpp); apa.TwoDofTuning (and the parameters,
// features and bench it holds) from its declaration.
void bind_tuning(py::module_& m) {
  using py::arg;
  bind_described<TwoDofTuning>(m);
  bound_class<TwoDofTuning>().def_property_readonly("brief_report", &TwoDofTuning::brief_report,
                                                     "One line with the status, the iterations and the errors.");
  m.def(
      "tune_two_dof",
      [](py::object frf, const py::kwargs& kw) {
        const std::string src = "apa.tune_two_dof";
        const auto& f = frf_arg(frf, src, "frf");
        auto o = tuning_options().from_kwargs(kwargs_dict(kw), src);
        return without_gil([&] { return tune_two_dof(f, o); });
      },
      arg("frf"),
      ("Tunes the 2-DoF model to a measured FRF u -> [d_e, Vs] (report section 3): the report's procedure,\n"
       "then Levenberg-Marquardt on the relative complex error. Returns an apa.TwoDofTuning: params and\n"
       "initial (apa.TwoDofParams, the 9 parameters in SI; p[\"k1\"], dict(p)), features (rad/s), fit errors\n"
       "(rms relative), points, iterations, status, message, bench (apa.TwoDofBench, the measurement chain\n"
       "removed), quality (ident.FitQuality), uncertainty, undetermined, brief_report.\n\n"
       "Keywords (TuningOptions):\n" + tuning_options().doc())
          .c_str());
  m.def(
      "tune_two_dof_measured",
      [](py::object frf, py::object de_plant, py::object vs_plant, const py::kwargs& kw) {
        const std::string src = "apa.tune_two_dof_measured";
        const auto& f = frf_arg(frf, src, "frf");
        auto o = tuning_options().from_kwargs(kwargs_dict(kw), src);
        const ident::DelayedSecondOrderFit* de = nullptr;
        const ident::IffPlantFit* vs = nullptr;
        if (!de_plant.is_none()) {
          if (!py::isinstance<ident::DelayedSecondOrderFit>(de_plant)) {
            throw InputError(src, "de_plant", "an ident.DelayedSecondOrderFit or None", short_repr(de_plant));
          }
          de = &de_plant.cast<const ident::DelayedSecondOrderFit&>();
        }
        if (!vs_plant.is_none()) {
          if (!py::isinstance<ident::IffPlantFit>(vs_plant)) {
            throw InputError(src, "vs_plant", "an ident.IffPlantFit or None", short_repr(vs_plant));
          }
          vs = &vs_plant.cast<const ident::IffPlantFit&>();
        }
        return without_gil([&] { return tune_two_dof_measured(f, o, de, vs); });
      },
      arg("frf"), arg("de_plant") = py::none(), arg("vs_plant") = py::none(),
      ("The campaign's tuning on measured FRFs (`piezobench run` and `model tune`): the measurement chain\n"
       "found by the plant fits (ident.fit_actuator_plants: de_plant gives the delay, vs_plant the high-pass\n"
       "corner and Vs's extra lag) removed, then apa.tune_two_dof. A plant that is None leaves the `bench`\n"
       "keyword's part as given. Returns an apa.TwoDofTuning as tune_two_dof does (bench = the chain removed).\n\n"
       "Keywords (TuningOptions):\n" + tuning_options().doc())
          .c_str());
}

}  // namespace

void bind_apa(py::module_& m) {
  bind_two_dof_models(m);
  bind_characterization(m);
  bind_tuning(m);
}

}  // namespace piezobench::python
