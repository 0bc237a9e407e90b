// Hysteresis and creep: piezobench.ident (fit_hysteresis, fit_creep, prandtl_ishlinskii,
// inverse_prandtl_ishlinskii, loop_metrics), piezobench.control (hysteresis_feedforward) and
// piezobench.io (read/write_hysteresis_model): include/piezobench/ident/hysteresis.hpp,
// control/hysteresis_feedforward.hpp, io/hysteresis_toml.hpp.
#include "common.hpp"
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

py::object model_result(const HysteresisModel& m) {
  py::dict d;
  d["thresholds"] = numbers(m.hysteresis.thresholds);
  d["weights"] = numbers(m.hysteresis.weights);
  d["creep_time_constants"] = numbers(m.creep_time_constants);
  d["creep_coefficients"] = numbers(m.creep_coefficients);
  d["gain"] = m.gain;
  d["offset"] = m.offset;
  d["reference_slope"] = m.reference_slope;
  d["reference_intercept"] = m.reference_intercept;
  d["input_min"] = m.input_min;
  d["input_max"] = m.input_max;
  // Kuhnen's output map S (empty knots: the plain PI model).
  d["output_x"] = numbers(m.output.x);
  d["output_y"] = numbers(m.output.y);
  d["output_slope_below"] = m.output.slope_below;
  d["output_slope_above"] = m.output.slope_above;
  return result("HysteresisModel", d);
}

// The quality verdict of a fit as the result's quality, quality_problems and advice fields.
void put_quality(py::dict& d, const core::FitQuality& q) {
  d["quality"] = core::to_string(q.verdict);
  d["quality_problems"] = q.problems;
  d["advice"] = q.advice;
}

// A HysteresisModel result (or a dict with its fields; creep_*, reference_*, input_* optional).
HysteresisModel model_arg(py::handle obj, const std::string& source) {
  py::dict d;
  if (py::hasattr(obj, "to_dict") && !py::isinstance<py::dict>(obj)) {
    d = obj.attr("to_dict")();
  } else if (py::isinstance<py::dict>(obj)) {
    d = py::reinterpret_borrow<py::dict>(obj);
  } else {
    throw InputError(source, "model", "a HysteresisModel (ident.fit_hysteresis(...).model) or a dict", short_repr(obj));
  }
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

py::object operator_result(const ident::PrandtlIshlinskii& h) {
  py::dict d;
  d["linear_weight"] = h.linear_weight;
  d["thresholds"] = numbers(h.thresholds);
  d["weights"] = numbers(h.weights);
  return result("PrandtlIshlinskii", d);
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

}  // namespace

void bind_hysteresis(py::module_& ident_m, py::module_& control_m, py::module_& io_m) {
  using py::arg;
  ident_m.def(
      "fit_hysteresis",
      [](py::object va, py::object de, double sample_rate, const py::kwargs& kw) {
        const std::string src = "ident.fit_hysteresis";
        auto o = fit_options().from_kwargs(kwargs_dict(kw), src);
        auto v = vector_arg(va, src, "va");
        auto y = vector_arg(de, src, "de");
        auto f = without_gil([&] { return ident::fit_hysteresis(span(v), span(y), sample_rate, o); });
        py::dict d;
        d["model"] = model_result(f.model);
        d["rms_residual"] = f.rms_residual;
        d["relative_residual"] = f.relative_residual;
        d["stroke"] = f.stroke;
        d["samples"] = f.samples;
        put_quality(d, f.quality);
        return result("HysteresisFit", d);
      },
      arg("va"), arg("de"), arg("sample_rate"),
      ("Prandtl-Ishlinskii model (+ creep states) of a record of the stack voltage va (V) and the\n"
       "displacement de (m) starting at rest: d_e = offset + gain (H[Va] + sum_j c_j F_j[Va]), weights and\n"
       "creep coefficients >= 0 by constrained least squares (ident/hysteresis.hpp). Returns a\n"
       "HysteresisFit (model, rms_residual, relative_residual, stroke, quality, quality_problems, advice).\n\nKeywords:\n" +
       fit_options().doc())
          .c_str());
  ident_m.def(
      "fit_creep",
      [](py::object input, py::object output, double sample_rate, py::object time_constants, double max_relative_residual) {
        const std::string src = "ident.fit_creep";
        auto x = vector_arg(input, src, "input");
        auto y = vector_arg(output, src, "output");
        std::vector<double> tau = time_constants.is_none() ? std::vector<double>{} : vector_of(time_constants, src, "time_constants");
        auto c = without_gil([&] { return ident::fit_creep(span(x), span(y), sample_rate, tau, max_relative_residual); });
        py::dict d;
        d["time_constants"] = numbers(c.time_constants);
        d["coefficients"] = numbers(c.coefficients);
        d["gain"] = c.gain;
        d["offset"] = c.offset;
        d["creep_per_decade"] = c.creep_per_decade;
        d["rms_residual"] = c.rms_residual;
        d["relative_residual"] = c.relative_residual;
        put_quality(d, c.quality);
        return result("CreepFit", d);
      },
      arg("input"), arg("output"), arg("sample_rate"), arg("time_constants") = py::none(), arg("max_relative_residual") = 0.05,
      "Prony-series creep of a step record: y = offset + gain (x + sum_j c_j F_j[x]), c_j >= 0 (time constants\n"
      "default 1, 10, 100 s up to half the record). Returns a CreepFit.");
  ident_m.def(
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
  ident_m.def(
      "inverse_prandtl_ishlinskii",
      [](py::object thresholds, py::object weights, double linear_weight) {
        return operator_result(ident::inverse(operator_arg(thresholds, weights, linear_weight, "ident.inverse_prandtl_ishlinskii")));
      },
      arg("thresholds"), arg("weights"), arg("linear_weight") = 1.0,
      "The exact inverse of a Prandtl-Ishlinskii operator (a PI operator: linear_weight, thresholds, weights).");
  ident_m.def(
      "loop_metrics",
      [](py::object command, py::object output) {
        const std::string src = "ident.loop_metrics";
        auto c = vector_arg(command, src, "command");
        auto y = vector_arg(output, src, "output");
        auto m = ident::loop_metrics(span(c), span(y));
        py::dict d;
        d["slope"] = m.slope;
        d["intercept"] = m.intercept;
        d["stroke"] = m.stroke;
        d["width"] = m.width;
        d["rms_deviation"] = m.rms_deviation;
        d["asymmetry"] = m.asymmetry;
        return result("LoopMetrics", d);
      },
      arg("command"), arg("output"),
      "Best straight line of output against command, hysteresis width (peak-to-peak deviation from it / stroke)\n"
      "and rms deviation.");
  ident_m.def(
      "predict_hysteresis",
      [](py::object model, py::object va, double sample_rate) {
        const std::string src = "ident.predict_hysteresis";
        auto m = model_arg(model, src);
        auto v = vector_arg(va, src, "va");
        return numbers(m.predict(span(v), sample_rate));
      },
      arg("model"), arg("va"), arg("sample_rate"), "d_e (m) the model gives for the stack voltage va (V), from rest.");

  control_m.def(
      "hysteresis_feedforward",
      [](py::object model, py::object command, double sample_rate) {
        const std::string src = "control.hysteresis_feedforward";
        auto m = model_arg(model, src);
        auto c = vector_arg(command, src, "command");
        return numbers(control::apply_feedforward(m, sample_rate, std::vector<double>(c.data(), c.data() + c.size())));
      },
      arg("model"), arg("command"), arg("sample_rate"),
      "The stack voltage (V) the inverse feedforward of `model` (a HysteresisModel) applies for the command\n"
      "c (V), from rest: Va = H^-1[reference_slope c + reference_intercept - creep] (control/hysteresis_feedforward.hpp).");

  io_m.def(
      "read_hysteresis_model", [](const std::string& path) { return model_result(io::read_hysteresis_model(path)); }, arg("path"),
      "A hysteresis model TOML file (`piezobench hysteresis fit --out`) as a HysteresisModel.");
  io_m.def(
      "write_hysteresis_model",
      [](const std::string& path, py::object model) { io::write_hysteresis_model(path, model_arg(model, "io.write_hysteresis_model")); },
      arg("path"), arg("model"), "Writes a HysteresisModel as TOML (read by `rt --feedforward`).");
}

}  // namespace piezobench::python
