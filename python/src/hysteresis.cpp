// Hysteresis and creep: piezobench.ident (fit_hysteresis, fit_creep, prandtl_ishlinskii,
// inverse_prandtl_ishlinskii, loop_metrics), piezobench.control (hysteresis_feedforward) and
// piezobench.io (read/write_hysteresis_model): include/piezobench/ident/hysteresis.hpp,
// control/hysteresis_feedforward.hpp, io/hysteresis_toml.hpp.
#include "common.hpp"
#include "described.hpp"
#include "piezobench/control/hysteresis_feedforward.hpp"
#include "piezobench/ident/hysteresis.hpp"
#include "piezobench/io/hysteresis_toml.hpp"

namespace piezobench::python {
namespace {

using ident::HysteresisModel;

py::array numbers(const std::vector<double>& v) {
  return to_numpy(Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()))));
}

std::vector<double> vector_of(py::handle obj, const std::string& source, const std::string& key) {
  auto a = vector_arg(obj, source, key);
  return {a.data(), a.data() + a.size()};
}

// An ident.HysteresisModel, or a dict of its numbers with the operator and the output map flattened
// (thresholds, weights, gain, offset; creep_*, reference_*, input_*, output_x, output_y,
// output_slope_below, output_slope_above optional).
HysteresisModel model_arg(py::handle obj, const std::string& source) {
  if (py::isinstance<HysteresisModel>(obj)) {
    auto m = obj.cast<HysteresisModel>();
    m.validate(source);
    return m;
  }
  if (!py::isinstance<py::dict>(obj))
    throw InputError(source, "model", "an ident.HysteresisModel (ident.fit_hysteresis(...).model) or a dict", short_repr(obj));
  const auto d = py::reinterpret_borrow<py::dict>(obj);
  auto get = [&](const char* key) -> py::object {
    if (!d.contains(key)) throw InputError(source, std::string("model.") + key, "a value", "nothing (missing)");
    return d[key];
  };
  HysteresisModel m;
  m.hysteresis.thresholds = vector_of(get("thresholds"), source, "model.thresholds");
  m.hysteresis.weights = vector_of(get("weights"), source, "model.weights");
  if (d.contains("creep_time_constants")) m.creep_time_constants = vector_of(d["creep_time_constants"], source, "model.creep_time_constants");
  if (d.contains("creep_coefficients")) m.creep_coefficients = vector_of(d["creep_coefficients"], source, "model.creep_coefficients");
  m.gain = number_arg(get("gain"), source, "model.gain");
  m.offset = number_arg(get("offset"), source, "model.offset");
  if (d.contains("reference_slope")) m.reference_slope = number_arg(d["reference_slope"], source, "model.reference_slope");
  if (d.contains("reference_intercept")) m.reference_intercept = number_arg(d["reference_intercept"], source, "model.reference_intercept");
  if (d.contains("input_min")) m.input_min = number_arg(d["input_min"], source, "model.input_min");
  if (d.contains("input_max")) m.input_max = number_arg(d["input_max"], source, "model.input_max");
  if (d.contains("output_x")) m.output.x = vector_of(d["output_x"], source, "model.output_x");
  if (d.contains("output_y")) m.output.y = vector_of(d["output_y"], source, "model.output_y");
  if (d.contains("output_slope_below")) m.output.slope_below = number_arg(d["output_slope_below"], source, "model.output_slope_below");
  if (d.contains("output_slope_above")) m.output.slope_above = number_arg(d["output_slope_above"], source, "model.output_slope_above");
  m.validate(source);
  return m;
}

ident::PrandtlIshlinskii operator_arg(py::handle thresholds, py::handle weights, double linear_weight, const std::string& source) {
  ident::PrandtlIshlinskii h;
  h.linear_weight = linear_weight;
  h.thresholds = vector_of(thresholds, source, "thresholds");
  h.weights = vector_of(weights, source, "weights");
  h.validate(source);
  return h;
}

const Options<ident::HysteresisFitOptions>& fit_options() {
  static const Options<ident::HysteresisFitOptions> t = [] {
    Options<ident::HysteresisFitOptions> o("HysteresisFitOptions");
    o.add("operators", &ident::HysteresisFitOptions::operators, "play operators n")
        .add("threshold_range", &ident::HysteresisFitOptions::threshold_range,
             "V, R: thresholds (i - 1/2) R / n; 0 = half the range of Va")
        .add("creep_time_constants", &ident::HysteresisFitOptions::creep_time_constants, "s; empty = no creep states")
        .add("dead_zones", &ident::HysteresisFitOptions::dead_zones,
             "Kuhnen's modified PI (asymmetric loops): dead zones per side of the output map S; 0 = plain PI")
        .add("max_relative_residual", &ident::HysteresisFitOptions::max_relative_residual, "rms residual / stroke of a good fit");
    return o;
  }();
  return t;
}

// fit_hysteresis and fit_creep: the declared ident.HysteresisFit and ident.CreepFit (ident/hysteresis.hpp).
void bind_fits(py::module_& m) {
  using py::arg;
  bind_described<ident::HysteresisFit>(m);
  bind_described<ident::CreepFit>(m);
  m.def(
      "fit_hysteresis",
      [](py::object va, py::object de, double sample_rate, const py::kwargs& kw) {
        const std::string src = "ident.fit_hysteresis";
        auto o = fit_options().from_kwargs(kwargs_dict(kw), src);
        auto v = vector_arg(va, src, "va");
        auto y = vector_arg(de, src, "de");
        return without_gil([&] { return ident::fit_hysteresis(span(v), span(y), sample_rate, o); });
      },
      arg("va"), arg("de"), arg("sample_rate"),
      ("Prandtl-Ishlinskii model (+ creep states) of a record of the stack voltage va (V) and the\n"
       "displacement de (m) starting at rest: d_e = offset + gain S(H[Va] + sum_j c_j F_j[Va]), weights and\n"
       "creep coefficients >= 0 by constrained least squares (ident/hysteresis.hpp). Returns an\n"
       "ident.HysteresisFit (model: ident.HysteresisModel with model.hysteresis the PI operator and\n"
       "model.output Kuhnen's output map; rms_residual, relative_residual, stroke, samples, quality).\n\nKeywords:\n" +
       fit_options().doc())
          .c_str());
  m.def(
      "fit_creep",
      [](py::object input, py::object output, double sample_rate, py::object time_constants, double max_relative_residual) {
        const std::string src = "ident.fit_creep";
        auto x = vector_arg(input, src, "input");
        auto y = vector_arg(output, src, "output");
        std::vector<double> tau = time_constants.is_none() ? std::vector<double>{} : vector_of(time_constants, src, "time_constants");
        return without_gil([&] { return ident::fit_creep(span(x), span(y), sample_rate, tau, max_relative_residual); });
      },
      arg("input"), arg("output"), arg("sample_rate"), arg("time_constants") = py::none(), arg("max_relative_residual") = 0.05,
      "Prony-series creep of a step record: y = offset + gain (x + sum_j c_j F_j[x]), c_j >= 0 (time constants\n"
      "default 1, 10, 100 s up to half the record). Returns an ident.CreepFit (time_constants, coefficients,\n"
      "gain, offset, creep_per_decade, rms_residual, relative_residual, quality).");
}

// The operator itself: prandtl_ishlinskii, its inverse, a model's prediction and loop_metrics.
void bind_operators(py::module_& m) {
  using py::arg;
  bind_described<ident::LoopMetrics>(m);
  m.def(
      "prandtl_ishlinskii",
      [](py::object v, py::object thresholds, py::object weights, double linear_weight) {
        const std::string src = "ident.prandtl_ishlinskii";
        auto h = operator_arg(thresholds, weights, linear_weight, src);
        auto x = vector_arg(v, src, "v");
        const std::vector<double> y = ident::evaluate(h, span(x));
        return numbers(y);
      },
      arg("v"), arg("thresholds"), arg("weights"), arg("linear_weight") = 1.0,
      "H[v] = linear_weight v + sum_i weights[i] P_{thresholds[i]}[v] for the samples v, from rest.");
  m.def(
      "inverse_prandtl_ishlinskii",
      [](py::object thresholds, py::object weights, double linear_weight) {
        return ident::inverse(operator_arg(thresholds, weights, linear_weight, "ident.inverse_prandtl_ishlinskii"));
      },
      arg("thresholds"), arg("weights"), arg("linear_weight") = 1.0,
      "The exact inverse of a Prandtl-Ishlinskii operator: an ident.PrandtlIshlinskii (linear_weight, thresholds, weights).");
  m.def(
      "loop_metrics",
      [](py::object command, py::object output) {
        const std::string src = "ident.loop_metrics";
        auto c = vector_arg(command, src, "command");
        auto y = vector_arg(output, src, "output");
        return ident::loop_metrics(span(c), span(y));
      },
      arg("command"), arg("output"),
      "Best straight line of output against command, hysteresis width (peak-to-peak deviation from it / stroke),\n"
      "rms deviation and asymmetry: an ident.LoopMetrics.");
  m.def(
      "predict_hysteresis",
      [](py::object model, py::object va, double sample_rate) {
        const std::string src = "ident.predict_hysteresis";
        auto hm = model_arg(model, src);
        auto v = vector_arg(va, src, "va");
        return numbers(hm.predict(span(v), sample_rate));
      },
      arg("model"), arg("va"), arg("sample_rate"), "d_e (m) the model gives for the stack voltage va (V), from rest.");
}

// control.hysteresis_feedforward and io's model files.
void bind_feedforward_and_files(py::module_& control_m, py::module_& io_m) {
  using py::arg;
  control_m.def(
      "hysteresis_feedforward",
      [](py::object model, py::object command, double sample_rate) {
        const std::string src = "control.hysteresis_feedforward";
        auto hm = model_arg(model, src);
        auto c = vector_arg(command, src, "command");
        return numbers(control::apply_feedforward(hm, sample_rate, std::vector<double>(c.data(), c.data() + c.size())));
      },
      arg("model"), arg("command"), arg("sample_rate"),
      "The stack voltage (V) the inverse feedforward of `model` (an ident.HysteresisModel) applies for the command\n"
      "c (V), from rest: Va = H^-1[reference_slope c + reference_intercept - creep] (control/hysteresis_feedforward.hpp).");
  io_m.def(
      "read_hysteresis_model", [](const std::string& path) { return io::read_hysteresis_model(path); }, arg("path"),
      "A hysteresis model TOML file (`piezobench hysteresis fit --out`) as an ident.HysteresisModel.");
  io_m.def(
      "write_hysteresis_model",
      [](const std::string& path, py::object model) { io::write_hysteresis_model(path, model_arg(model, "io.write_hysteresis_model")); },
      arg("path"), arg("model"), "Writes an ident.HysteresisModel as TOML (read by `rt --feedforward`).");
}

}  // namespace

void bind_hysteresis(py::module_& ident_m, py::module_& control_m, py::module_& io_m) {
  bind_fits(ident_m);
  bind_operators(ident_m);
  bind_feedforward_and_files(control_m, io_m);
}

}  // namespace piezobench::python
