// piezobench.ident: include/piezobench/ident/{vector_fitting,vector_fit_uncertainty,features,modal,plant_fit}.hpp and the
// fits' quality verdict (core/fit_quality.hpp)
#include <cmath>

#include "common.hpp"
#include "described.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/core/fit_quality.hpp"
#include "piezobench/dsp/frf.hpp"
#include "piezobench/ident/features.hpp"
#include "piezobench/ident/hysteresis.hpp"
#include "piezobench/ident/modal.hpp"
#include "piezobench/ident/plant_fit.hpp"
#include "piezobench/ident/vector_fit_uncertainty.hpp"
#include "piezobench/ident/vector_fitting.hpp"
#include "piezobench/lti/transfer_function.hpp"

namespace piezobench::python {
namespace {

using namespace piezobench::ident;

const Options<VectorFittingOptions>& vf_options() {
  static const Options<VectorFittingOptions> t = [] {
    Options<VectorFittingOptions> o("VectorFittingOptions");
    o.add("order", &VectorFittingOptions::order, "number of poles N (a complex pair counts two)")
        .add_enum("asymptote", &VectorFittingOptions::asymptote, &ident::to_string, &asymptote_from_string,
                  "\"none\", \"d\" or \"de\" (d + s e)")
        .add("relaxed", &VectorFittingOptions::relaxed, "relaxed non-triviality constraint (Gustavsen 2006)")
        .add("enforce_stable_poles", &VectorFittingOptions::enforce_stable_poles, "mirror unstable poles")
        .add("max_iterations", &VectorFittingOptions::max_iterations, "pole relocations")
        .add("pole_tolerance", &VectorFittingOptions::pole_tolerance, "relative pole change that ends the relocations")
        .add("significance_floor", &VectorFittingOptions::significance_floor, "poles below this peak share are not compared")
        .add("residual_tolerance", &VectorFittingOptions::residual_tolerance, "relative change of the rms error that ends them")
        .add("fail_if_not_converged", &VectorFittingOptions::fail_if_not_converged,
             "True: NumericalError (retry_may_help) when the poles do not settle")
        .add("starting_poles", &VectorFittingOptions::starting_poles, "rad/s; empty = automatic")
        .add_enum("starting_spacing", &VectorFittingOptions::starting_spacing, &ident::to_string,
                  &pole_spacing_from_string, "\"log\" or \"lin\"")
        .add("starting_damping", &VectorFittingOptions::starting_damping, "damping of the automatic starting poles")
        .add_enum("weighting", &VectorFittingOptions::weighting, &ident::to_string, &weighting_from_string,
                  "\"unit\", \"output-scale\", \"inverse-magnitude\", \"inverse-sqrt-magnitude\" or \"inverse-std\" "
                  "(vector_fit(frf) of an FRF with std_H: each point by 1/its standard deviation)")
        .add("point_weights", &VectorFittingOptions::point_weights,
             "one weight per frequency point (e.g. 1/std), multiplying the row weights; empty = none")
        .add("frequency_scale", &VectorFittingOptions::frequency_scale, "rad/s; 0 = the highest omega");
    return o;
  }();
  return t;
}

const Options<FrfFeatureOptions>& feature_options() {
  static const Options<FrfFeatureOptions> t = [] {
    Options<FrfFeatureOptions> o("FrfFeatureOptions");
    o.add_nested("fit", &FrfFeatureOptions::fit, vf_options(), "the rational model (ident.vector_fit keywords)")
        .add("max_damping", &FrfFeatureOptions::max_damping, "lightly damped below this damping ratio")
        .add("min_significance", &FrfFeatureOptions::min_significance, "modal peak / fitted response for a resonance")
        .add("cancellation_tolerance", &FrfFeatureOptions::cancellation_tolerance, "a zero and a pole this close cancel")
        .add("phase_band", &FrfFeatureOptions::phase_band, "relative half-width of the band of the phase verdict")
        .add("phase_threshold_deg", &FrfFeatureOptions::phase_threshold_deg, "deg, |phase change| that gives a verdict")
        .add("high_pass_ratio", &FrfFeatureOptions::high_pass_ratio, "DC gain / |H(lowest)| below which there is a high-pass");
    return o;
  }();
  return t;
}

const Options<SecondOrderFitOptions>& second_order_options() {
  static const Options<SecondOrderFitOptions> t = [] {
    Options<SecondOrderFitOptions> o("SecondOrderFitOptions");
    o.add_enum("method", &SecondOrderFitOptions::method, &ident::to_string, &second_order_method_from_string,
               "\"nls\" (Levy then Levenberg-Marquardt) or \"vector-fitting\"")
        .add("max_iterations", &SecondOrderFitOptions::max_iterations, "Levenberg-Marquardt steps");
    return o;
  }();
  return t;
}

const Options<PeakPickingOptions>& peak_options() {
  static const Options<PeakPickingOptions> t = [] {
    Options<PeakPickingOptions> o("PeakPickingOptions");
    o.add("min_omega", &PeakPickingOptions::min_omega, "rad/s; 0 = from the first point")
        .add("max_omega", &PeakPickingOptions::max_omega, "rad/s; 0 = to the last point")
        .add("min_prominence", &PeakPickingOptions::min_prominence, "peak / the higher separating minimum")
        .add("max_modes", &PeakPickingOptions::max_modes, "keep the most prominent; 0 = all");
    return o;
  }();
  return t;
}

const Options<LscfOptions>& lscf_options() {
  static const Options<LscfOptions> t = [] {
    Options<LscfOptions> o("LscfOptions");
    o.add("min_omega", &LscfOptions::min_omega, "rad/s; 0 = from the first point")
        .add("max_omega", &LscfOptions::max_omega, "rad/s; 0 = to the last point")
        .add("min_order", &LscfOptions::min_order, "lowest denominator order")
        .add("max_order", &LscfOptions::max_order, "highest denominator order")
        .add("frequency_tolerance", &LscfOptions::frequency_tolerance, "stabilization: relative frequency change")
        .add("damping_tolerance", &LscfOptions::damping_tolerance, "stabilization: relative damping change")
        .add("min_stable_orders", &LscfOptions::min_stable_orders, "consecutive stable orders for a mode")
        .add("max_damping", &LscfOptions::max_damping, "physical poles: 0 < zeta < max_damping");
    return o;
  }();
  return t;
}

const Options<IffPlantFitOptions>& plant_fit_options() {
  static const Options<IffPlantFitOptions> t = [] {
    Options<IffPlantFitOptions> o("IffPlantFitOptions");
    o.add("fmin_Hz", &IffPlantFitOptions::fmin_Hz, "Hz, band used; 0 = from the lowest positive frequency")
        .add("fmax_Hz", &IffPlantFitOptions::fmax_Hz, "Hz; 0 = up to the highest")
        .add("hpf_fmax_Hz", &IffPlantFitOptions::hpf_fmax_Hz, "Hz, points below this start the high-pass corner")
        .add("min_coherence", &IffPlantFitOptions::min_coherence, "points with a known coherence below this are left out")
        .add("fit_delay", &IffPlantFitOptions::fit_delay, "False: delay fixed at 0")
        .add("fixed_w_hpf", &IffPlantFitOptions::fixed_w_hpf, "rad/s; > 0: the high-pass corner is known (1 / (R C)), not fitted")
        .add("max_iterations", &IffPlantFitOptions::max_iterations, "Levenberg-Marquardt steps")
        .add("effective_averages", &IffPlantFitOptions::effective_averages,
             "Welch's n_d of the FRF (> 0 with a coherence: points weighted by their variance, standard errors from it); "
             "taken from an Frf's provenance when 0");
    return o;
  }();
  return t;
}

const Options<ActuatorPlantOptions>& actuator_plant_options() {
  static const Options<ActuatorPlantOptions> t = [] {
    Options<ActuatorPlantOptions> o("ActuatorPlantOptions");
    o.add("fmin_Hz", &ActuatorPlantOptions::fmin_Hz, "Hz, lowest frequency of the d_e fit")
        .add("fmax_Hz", &ActuatorPlantOptions::fmax_Hz, "Hz, highest frequency of both fits")
        .add("iff_fmin_Hz", &ActuatorPlantOptions::iff_fmin_Hz, "Hz, lowest frequency of the Vs fit")
        .add("hpf_fmax_Hz", &ActuatorPlantOptions::hpf_fmax_Hz, "Hz, points below this start the high-pass corner")
        .add("fixed_w_hpf", &ActuatorPlantOptions::fixed_w_hpf, "rad/s; > 0: the high-pass corner is known (1 / (R C_sensor))")
        .add("min_coherence", &ActuatorPlantOptions::min_coherence, "points with a known coherence below this are left out")
        .add("effective_averages", &ActuatorPlantOptions::effective_averages,
             "Welch's n_d of the FRF (weights and standard errors); taken from the Frf's provenance when 0");
    return o;
  }();
  return t;
}

// (omega, h, coherence) of fit_iff_plant / fit_delayed_second_order: arrays, or (frf, output name)
// with the FRF's coherence.
struct PlantData {
  Vector omega;
  CVector h;
  Vector coherence;
  double effective_averages = 0.0;  // of an Frf's provenance
  dsp::ResolutionKernel resolution;  // of an Frf's provenance (dsp::resolution_kernel); inactive for arrays
};

// The keyword window_resolution (default True) of the plant fits, taken out of kw: True, the model is
// seen through the Frf's Welch resolution kernel (from its provenance), False: the model itself.
bool take_window_resolution(py::dict& kw, const std::string& source) {
  if (!kw.contains("window_resolution")) return true;
  const bool on = bool_arg(kw["window_resolution"], source, "window_resolution");
  PyDict_DelItemString(kw.ptr(), "window_resolution");
  return on;
}
constexpr const char* kWindowResolutionDoc =
    "    window_resolution: bool = True  (the model seen through the Frf's Welch resolution kernel, from its provenance; "
    "False: the model itself; arrays have none)\n";
PlantData plant_data(py::handle omega_or_frf, py::handle h_or_output, py::handle coherence, const std::string& source) {
  PlantData d;
  if (py::isinstance<dsp::Frf>(omega_or_frf)) {
    const auto& f = frf_arg(omega_or_frf, source, "frf");
    const auto i = static_cast<std::size_t>(f.output_index(string_arg(h_or_output, source, "output")));
    d.omega = kTwoPi * f.freq_Hz;
    d.h = f.H[i];
    if (i < f.coherence.size()) d.coherence = f.coherence[i];
    d.effective_averages = f.provenance.effective_averages;
    d.resolution = dsp::resolution_kernel(f.provenance);
    return d;
  }
  d.omega = to_vector(omega_or_frf, source, "omega");
  d.h = to_complex_vector(h_or_output, source, "h");
  if (!coherence.is_none()) d.coherence = to_vector(coherence, source, "coherence");
  return d;
}

py::object vf_result(VectorFittingResult r) { return py::cast(std::move(r)); }

// omega and the response(s): h is (points,) or (points, outputs).
std::pair<Vector, CMatrix> data_args(py::handle omega, py::handle h, const std::string& source) {
  return {to_vector(omega, source, "omega"), to_complex_matrix(h, source, "h")};
}

// ident.FitQuality and ident.ParameterUncertainty, the verdict and the standard errors every fit
// carries, from their declarations (core/fit_quality.hpp, core/fit_covariance.hpp).
void bind_fit_quality(py::module_& m) {
  using py::arg;
  bind_described<core::FitQuality>(m);
  auto q = bound_class<core::FitQuality>();
  q.attr("__doc__") = R"(The quality verdict of a fit (core/fit_quality.hpp).

verdict is "good" or "poor" (an output's relative rms error above 0.2, a resonance outside the band,
the iterations exhausted, ...); impossible: a parameter has a value no actuator can have (negative
stiffness, delay, ...), so the fit's parameters are not a result. problems name the output or
parameter and its number; advice says what to try.)";
  q.def_property_readonly("poor", &core::FitQuality::poor, "verdict == \"poor\"")
      .def_property_readonly("summary", &core::FitQuality::summary, "\"good\" or \"poor: PROBLEM; ... Try: ADVICE\"");
  bind_described<core::ParameterUncertainty>(m);
  auto u = bound_class<core::ParameterUncertainty>();
  u.attr("__doc__") = R"(A fit's parameters with their standard errors (core/fit_covariance.hpp): linearized at
the solution, from the FRF's variance when known, else from the residuals' scatter. A 95 % interval is
value +- 1.96 standard_error.)";
  u.def("standard_error_of", &core::ParameterUncertainty::standard_error_of, arg("name"), "NaN when unknown")
      .def("relative_standard_error_of", &core::ParameterUncertainty::relative_standard_error_of, arg("name"),
           "standard_error / |value| (inf for a zero value)");
}

// ident.IffPlantFit and ident.DelayedSecondOrderFit (ident/plant_fit.hpp): one property per declared
// field (described.hpp), then the derived figures and methods that are not fields.
void bind_plant_fit_classes(py::module_& m) {
  using py::arg;
  bind_described<IffPlantFit>(m);
  auto iff = bound_class<IffPlantFit>();
  iff.attr("__doc__") = R"(The IFF plant of eq. 2.3 fitted to a u -> Vs FRF (ident/plant_fit.hpp):

  G(s) = g0 (1 + 2 xz s/wz + s^2/wz^2) / (1 + 2 xp s/wp + s^2/wp^2) * s / (w_hpf + s) * exp(-s delay)

xz < 0 is a non-minimum-phase zero pair. Fields in SI (rad/s, s); params() gives the control.iff_plant
keywords; fields() lists the declaration.)";
  iff.def_property_readonly("wz_Hz", [](const IffPlantFit& f) { return f.wz / kTwoPi; }, "Hz, anti-resonance")
      .def_property_readonly("wp_Hz", [](const IffPlantFit& f) { return f.wp / kTwoPi; }, "Hz, resonance")
      .def_property_readonly("w_hpf_Hz", [](const IffPlantFit& f) { return f.w_hpf / kTwoPi; }, "Hz, high-pass corner")
      .def_property_readonly("zero_is_nonminimum_phase", &IffPlantFit::zero_is_nonminimum_phase, "xz < 0")
      .def("params", [](const IffPlantFit& f) {
        py::dict d;
        d["g0"] = f.g0; d["wz"] = f.wz; d["xz"] = f.xz; d["wp"] = f.wp; d["xp"] = f.xp; d["w_hpf"] = f.w_hpf; d["delay"] = f.delay;
        return d;
      }, "The plant's parameters as the keywords of control.iff_plant / control.iff_root_locus (SI, rad/s).")
      .def("transfer_function", &IffPlantFit::transfer_function, "G(s) with its delay (lti.TransferFunction).")
      .def("response", [](const IffPlantFit& f, py::object omega) {
        return to_numpy(f.response(to_vector(omega, "IffPlantFit.response", "omega")));
      }, arg("omega"), "G(j omega) at omega (rad/s), complex.");

  bind_described<DelayedSecondOrderFit>(m);
  auto so = bound_class<DelayedSecondOrderFit>();
  so.attr("__doc__") = R"(The mass-spring-damper u -> d_e with the measurement delay (ident/plant_fit.hpp):
H(s) = k wn^2 / (s^2 + 2 zeta wn s + wn^2) * exp(-s delay). Fields in SI (natural_frequency in rad/s);
fields() lists the declaration.)";
  so.def_property_readonly("frequency_Hz", [](const DelayedSecondOrderFit& f) { return f.natural_frequency / kTwoPi; }, "wn in Hz")
      .def_property_readonly("pole", &DelayedSecondOrderFit::pole, "rad/s, -zeta wn + j wn sqrt(1 - zeta^2)")
      .def("response", [](const DelayedSecondOrderFit& f, py::object omega) {
        return to_numpy(f.response(to_vector(omega, "DelayedSecondOrderFit.response", "omega")));
      }, arg("omega"), "H(j omega) at omega (rad/s), complex.");
}

// ident.VectorFittingResult (ident/vector_fitting.hpp) from its declaration, with the state space
// (not declared: rebuilt from the poles and residues) and the model's evaluation.
void bind_vector_fitting_result(py::module_& m) {
  using py::arg;
  bind_described<VectorFittingResult>(m);
  bound_class<VectorFittingResult>()
      .def_readonly("model", &VectorFittingResult::model, "the proper part as an lti.StateSpace (the s e term left out)")
      .def("evaluate", [](const VectorFittingResult& r, py::object omega) {
        return to_numpy(r.evaluate(to_vector(omega, "VectorFittingResult.evaluate", "omega")));
      }, arg("omega"), "The fitted model at j omega (rad/s): (len(omega), outputs) complex.")
      .def("brief_report", &VectorFittingResult::brief_report, "One line: order, iterations, converged, rms.");
}

// The results of frf_features, fit_high_pass, fit_second_order, peak_picking, lscf and
// fit_actuator_plants (ident/features.hpp, modal.hpp, plant_fit.hpp) from their declarations, with
// the frequencies in Hz that their structs compute.
void bind_feature_classes(py::module_& m) {
  bind_described<FrfFeatures>(m);
  bound_class<ModalFeature>().def_property_readonly("frequency_Hz", &ModalFeature::frequency_Hz, "Hz, natural_frequency / 2 pi");
  bound_class<AntiResonance>().def_property_readonly("frequency_Hz", &AntiResonance::frequency_Hz, "Hz, natural_frequency / 2 pi");
  bind_described<HighPassFit>(m);
  bound_class<HighPassFit>().def_property_readonly("corner_Hz", &HighPassFit::corner_Hz, "Hz, corner / 2 pi");
  bind_described<SecondOrderFit>(m);
  bound_class<SecondOrderFit>().def_property_readonly("frequency_Hz", &SecondOrderFit::frequency_Hz, "Hz, natural_frequency / 2 pi");
  bind_described<LscfResult>(m);
  bound_class<Mode>().def_property_readonly("frequency_Hz", &Mode::frequency_Hz, "Hz, natural_frequency / 2 pi");
  bind_described<ActuatorPlants>(m);
}

// fit_iff_plant, fit_delayed_second_order and fit_actuator_plants.
void bind_plant_fits(py::module_& m) {
  using py::arg;
  m.def(
      "fit_iff_plant",
      [](py::object omega_or_frf, py::object h_or_output, py::object coherence, const py::kwargs& kw) {
        const std::string src = "ident.fit_iff_plant";
        py::dict k = kwargs_dict(kw);
        const bool window_resolution = take_window_resolution(k, src);
        auto o = plant_fit_options().from_kwargs(k, src);
        auto d = plant_data(omega_or_frf, h_or_output, coherence, src);
        if (o.effective_averages == 0.0) o.effective_averages = d.effective_averages;
        if (window_resolution) o.resolution = d.resolution;
        return without_gil([&] { return fit_iff_plant(d.omega, d.h, d.coherence, o, src); });
      },
      arg("omega"), arg("h"), arg("coherence") = py::none(),
      ("The IFF plant of eq. 2.3 (report section 2.6) with its delay fitted to u -> Vs by Levenberg-Marquardt on\n"
       "the relative complex error: (omega (rad/s), h (V/V), coherence=None) or (frf, output_name). Returns an\n"
       "ident.IffPlantFit (g0, wz, xz, wp, xp, w_hpf, delay, errors, quality).\n\nKeywords (IffPlantFitOptions):\n" +
       plant_fit_options().doc() + kWindowResolutionDoc)
          .c_str());
  m.def(
      "fit_delayed_second_order",
      [](py::object omega_or_frf, py::object h_or_output, py::object coherence, const py::kwargs& kw) {
        const std::string src = "ident.fit_delayed_second_order";
        py::dict k = kwargs_dict(kw);
        const bool window_resolution = take_window_resolution(k, src);
        auto o = plant_fit_options().from_kwargs(k, src);
        auto d = plant_data(omega_or_frf, h_or_output, coherence, src);
        if (o.effective_averages == 0.0) o.effective_averages = d.effective_averages;
        if (window_resolution) o.resolution = d.resolution;
        return without_gil([&] { return fit_delayed_second_order(d.omega, d.h, d.coherence, o, src); });
      },
      arg("omega"), arg("h"), arg("coherence") = py::none(),
      ("k wn^2 / (s^2 + 2 zeta wn s + wn^2) exp(-s delay) fitted to u -> d_e (or a damped plant u' -> d_e):\n"
       "(omega (rad/s), h, coherence=None) or (frf, output_name). Returns an ident.DelayedSecondOrderFit.\n"
       "Keywords: fmin_Hz, fmax_Hz, min_coherence, fit_delay, max_iterations of IffPlantFitOptions:\n" +
       plant_fit_options().doc() + kWindowResolutionDoc)
          .c_str());
  m.def(
      "fit_actuator_plants",
      [](py::object frf, const std::string& de_output, const std::string& vs_output, const py::kwargs& kw) {
        const std::string src = "ident.fit_actuator_plants";
        py::dict k = kwargs_dict(kw);
        const bool window_resolution = take_window_resolution(k, src);
        auto o = actuator_plant_options().from_kwargs(k, src);
        const auto& f = frf_arg(frf, src, "frf");
        const auto ide = static_cast<std::size_t>(f.output_index(de_output));
        const auto ivs = static_cast<std::size_t>(f.output_index(vs_output));
        const auto coh = [&](std::size_t i) { return i < f.coherence.size() ? f.coherence[i] : Vector(); };
        const std::string source = f.provenance.source.empty() ? src : f.provenance.source;
        if (o.effective_averages == 0.0) o.effective_averages = f.provenance.effective_averages;
        if (window_resolution) o.resolution = dsp::resolution_kernel(f.provenance);
        return without_gil([&] {
          return fit_actuator_plants(kTwoPi * f.freq_Hz, f.H[ide], coh(ide), f.H[ivs], coh(ivs), o, source);
        });
      },
      arg("frf"), arg("de_output") = "de", arg("vs_output") = "Vs",
      ("Both plants of an actuator's FRF u -> [d_e, Vs] fitted as `piezobench run` and `model tune` do:\n"
       "ident.ActuatorPlants(de (ident.DelayedSecondOrderFit or None), vs (ident.IffPlantFit or None), de_options,\n"
       "vs_options (ident.IffPlantFitOptions), "
       "failures (a fit that failed numerically)). Pass de and vs to apa.tune_two_dof_measured.\n\n"
       "Keywords (ActuatorPlantOptions):\n" + actuator_plant_options().doc() + kWindowResolutionDoc)
          .c_str());
}

// vector_fit and frf_features (ident/vector_fitting.hpp, ident/features.hpp).
void bind_vector_fitting(py::module_& m) {
  using py::arg;
  m.def(
      "vector_fit",
      [](py::object omega_or_frf, py::object data, py::object weights, const py::kwargs& kw) {
        const std::string src = "ident.vector_fit";
        auto o = vf_options().from_kwargs(kwargs_dict(kw), src);
        if (py::isinstance<dsp::Frf>(omega_or_frf)) {
          const auto& f = frf_arg(omega_or_frf, src, "frf");
          return vf_result(without_gil([&] { return vector_fit(f, o); }));
        }
        auto [w, h] = data_args(omega_or_frf, data, src);
        Matrix wt = weights.is_none() ? Matrix() : to_matrix(weights, src, "weights", true);
        return vf_result(without_gil([&] { return vector_fit(w, h, wt, o); }));
      },
      arg("omega"), arg("data") = py::none(), arg("weights") = py::none(),
      ("Vector fitting (Gustavsen & Semlyen 1999, relaxed 2006, fast QR): common poles fitted to\n"
       "data (points,) or (points, outputs) at s = j omega (rad/s); or vector_fit(frf) for every\n"
       "output of a dsp.Frf. Returns a Result: poles, residues, d, e, model (lti.StateSpace), rms_error,\n"
       "relative_rms_error, iterations, converged, convergence, quality (ident.FitQuality), evaluate(omega).\n\nKeywords:\n" +
       vf_options().doc())
          .c_str());
  m.def(
      "frf_features",
      [](py::object omega_or_frf, py::object h_or_output, const py::kwargs& kw) {
        const std::string src = "ident.frf_features";
        auto o = feature_options().from_kwargs(kwargs_dict(kw), src);
        if (py::isinstance<dsp::Frf>(omega_or_frf)) {
          const auto& f = frf_arg(omega_or_frf, src, "frf");
          auto name = string_arg(h_or_output, src, "output");
          return without_gil([&] { return frf_features(f, name, o); });
        }
        auto w = to_vector(omega_or_frf, src, "omega");
        auto h = to_complex_vector(h_or_output, src, "h");
        return without_gil([&] { return frf_features(w, h, o); });
      },
      arg("omega"), arg("h"),
      ("Static gain, resonances and anti-resonances (rad/s, damping) of one response, with the\n"
       "non-minimum-phase verdicts (fitted zero and measured phase; report section 2.3). Call with\n"
       "(omega, h) or (frf, output_name). Returns an ident.FrfFeatures: static_gain, static_gain_source,\n"
       "plateau_frequency, resonances (ident.ModalFeature), antiresonances (ident.AntiResonance: phase_verdict,\n"
       "nonminimum_phase_model, ...), fit.\n\n"
       "Keywords:\n" + feature_options().doc())
          .c_str());
}

// vector_fit_uncertainty, zero_uncertainty and response_covariance (ident/vector_fit_uncertainty.hpp).
void bind_vector_fit_uncertainty(py::module_& m) {
  using py::arg;
  bind_described<VectorFitUncertainty>(m);
  bound_class<VectorFitUncertainty>().attr("__doc__") = R"(A vector fit's covariance (ident/vector_fit_uncertainty.hpp):
covariance (core.FitCovariance: covariance, standard_error, correlation, condition_number, chi2_per_dof,
singular, high_correlations) of the model's real parameters named in names; poles (ident.RootUncertainty:
root, natural_frequency, natural_frequency_se, damping, damping_se, real_se, imag_se; rad/s), one per
pole of the fit; from_data_variance. A 95 % interval is value +- 1.96 standard error.)";
  m.def(
      "vector_fit_uncertainty",
      [](py::object omega_or_frf, py::object data_or_fit, py::object fit, py::object weights, py::object std_H,
         py::object adjacent_correlation, const py::kwargs& kw) {
        const std::string src = "ident.vector_fit_uncertainty";
        auto o = vf_options().from_kwargs(kwargs_dict(kw), src);
        if (py::isinstance<dsp::Frf>(omega_or_frf)) {
          const auto& f = frf_arg(omega_or_frf, src, "frf");
          if (!py::isinstance<VectorFittingResult>(data_or_fit)) {
            throw InputError(src, "fit", "the ident.vector_fit result of this FRF", py::str(py::type::of(data_or_fit).attr("__name__")).cast<std::string>());
          }
          const auto& r = data_or_fit.cast<const VectorFittingResult&>();
          return without_gil([&] { return vector_fit_uncertainty(f, r, o); });
        }
        auto [w, h] = data_args(omega_or_frf, data_or_fit, src);
        if (!py::isinstance<VectorFittingResult>(fit)) {
          throw InputError(src, "fit", "the ident.vector_fit result of (omega, data)", py::str(py::type::of(fit).attr("__name__")).cast<std::string>());
        }
        const auto& r = fit.cast<const VectorFittingResult&>();
        Matrix wt = weights.is_none() ? Matrix() : to_matrix(weights, src, "weights", true);
        Matrix sd = std_H.is_none() ? Matrix() : to_matrix(std_H, src, "std_H", true);
        Vector rho = adjacent_correlation.is_none() ? Vector() : to_vector(adjacent_correlation, src, "adjacent_correlation");
        return without_gil([&] { return vector_fit_uncertainty(w, h, r, o, wt, sd, rho); });
      },
      arg("omega"), arg("data"), arg("fit") = py::none(), arg("weights") = py::none(), arg("std_H") = py::none(),
      arg("adjacent_correlation") = py::none(),
      "Standard errors of a vector fit: vector_fit_uncertainty(omega, data, fit, weights=None, std_H=None,\n"
       "adjacent_correlation=None, **options) with the data (points,) or (points, outputs), weights and options as\n"
       "given to vector_fit, std_H the data's standard deviation per part (Re and Im; same shape as data; None:\n"
       "the noise estimated from the fit's residuals, additive plus proportional) and adjacent_correlation the real\n"
       "correlation of the data's error between points k and k+1 (len(omega) - 1 values, with std_H); or\n"
       "vector_fit_uncertainty(frf, fit, **options) (the FRF's std_H when it has one, with the correlation of\n"
       "neighbouring lines its Welch provenance gives). The covariance of the model's real parameters, linearized at the solution\n"
       "(core/fit_covariance.hpp), and each pole's natural frequency and damping with their standard errors by\n"
       "the delta method. Returns an ident.VectorFitUncertainty.\n\nKeywords: as ident.vector_fit.");
  m.def(
      "zero_uncertainty",
      [](const VectorFittingResult& fit, const VectorFitUncertainty& u, Index output, py::object zeros) {
        return zero_uncertainty(fit, u, output, to_complex_vector(zeros, "ident.zero_uncertainty", "zeros"));
      },
      arg("fit"), arg("uncertainty"), arg("output"), arg("zeros"),
      "The zeros (rad/s, complex) of output `output` of the fit with their standard errors (implicit function\n"
      "theorem, from vector_fit_uncertainty's covariance): a list of ident.RootUncertainty.");
  m.def(
      "response_covariance",
      [](const VectorFittingResult& fit, const VectorFitUncertainty& u, Index output, std::complex<double> s) {
        return to_numpy(Eigen::MatrixXd(response_covariance(fit, u, output, s)));
      },
      arg("fit"), arg("uncertainty"), arg("output"), arg("s"),
      "The 2 x 2 covariance of (Re, Im) of output `output` of the fit at s (rad/s, complex; 0: the DC gain).");
}

// fit_high_pass and fit_second_order (ident/features.hpp).
void bind_low_order_fits(py::module_& m) {
  using py::arg;
  m.def(
      "fit_high_pass",
      [](py::object omega, py::object h, double max_omega) {
        auto w = to_vector(omega, "ident.fit_high_pass", "omega");
        auto hv = to_complex_vector(h, "ident.fit_high_pass", "h");
        return fit_high_pass(w, hv, max_omega);
      },
      arg("omega"), arg("h"), arg("max_omega") = 0.0,
      "First-order high-pass g s / (s + corner) fitted to the points with omega <= max_omega (rad/s; 0 = all):\n"
      "ident.HighPassFit(corner (rad/s), corner_Hz, gain, relative_rms_error).");
  m.def(
      "fit_second_order",
      [](py::object omega, py::object h, const py::kwargs& kw) {
        const std::string src = "ident.fit_second_order";
        auto o = second_order_options().from_kwargs(kwargs_dict(kw), src);
        auto w = to_vector(omega, src, "omega");
        auto hv = to_complex_vector(h, src, "h");
        return without_gil([&] { return fit_second_order(w, hv, o); });
      },
      arg("omega"), arg("h"),
      ("k wn^2 / (s^2 + 2 zeta wn s + wn^2) fitted to h at j omega (rad/s): ident.SecondOrderFit(static_gain,\n"
       "natural_frequency (rad/s), frequency_Hz, damping, poles, feedthrough, relative_rms_error, iterations).\n\n"
       "Keywords:\n" + second_order_options().doc())
          .c_str());
}

// peak_picking and lscf (ident/modal.hpp).
void bind_modal(py::module_& m) {
  using py::arg;
  m.def(
      "peak_picking",
      [](py::object omega, py::object h, const py::kwargs& kw) {
        const std::string src = "ident.peak_picking";
        auto o = peak_options().from_kwargs(kwargs_dict(kw), src);
        auto [w, hm] = data_args(omega, h, src);
        return peak_picking(w, hm, o);
      },
      arg("omega"), arg("h"),
      ("Modes from the peaks of sum |H|^2 (h: (points,) or (points, outputs)), damping from the half-power\n"
       "bandwidth: a list of ident.Mode(pole, natural_frequency (rad/s), frequency_Hz, damping, stable_orders).\n\nKeywords:\n" +
       peak_options().doc())
          .c_str());
  m.def(
      "lscf",
      [](py::object omega, py::object h, const py::kwargs& kw) {
        const std::string src = "ident.lscf";
        auto o = lscf_options().from_kwargs(kwargs_dict(kw), src);
        auto [w, hm] = data_args(omega, h, src);
        return without_gil([&] { return lscf(w, hm, o); });
      },
      arg("omega"), arg("h"),
      ("Least-squares complex-frequency estimator (PolyMAX-like, single reference) over a range of\n"
       "orders with a stabilization diagram: ident.LscfResult(modes (ident.Mode), diagram (a list of\n"
       "ident.StabilizationPole: order, pole, natural_frequency, damping, stable), quality (ident.FitQuality)).\n\n"
       "Keywords:\n" + lscf_options().doc())
          .c_str());
}

}  // namespace

void bind_ident(py::module_& m) {
  bind_fit_quality(m);
  bind_vector_fitting_result(m);
  bind_plant_fit_classes(m);
  bind_feature_classes(m);
  bind_plant_fits(m);
  bind_vector_fitting(m);
  bind_vector_fit_uncertainty(m);
  bind_low_order_fits(m);
  bind_modal(m);
  m.def("declarations", [] {
    return declarations_of<IffPlantFit, DelayedSecondOrderFit, VectorFittingResult, VectorFitUncertainty, FrfFeatures, HighPassFit, SecondOrderFit,
                           LscfResult, ActuatorPlants, HysteresisFit, CreepFit, LoopMetrics>();
  }, "{declared struct: (its Python class, [field names])} for every declared result ident returns (ident/*.hpp).");
}

}  // namespace piezobench::python
