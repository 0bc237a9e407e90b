#include "piezobench/io/hysteresis_toml.hpp"

#include <fmt/format.h>

#include <sstream>
#include <toml++/toml.h>

#include "piezobench/core/error.hpp"
#include "piezobench/io/atomic_file.hpp"
#include "piezobench/io/toml_describe.hpp"
#include "piezobench/io/toml_reader.hpp"
#include "piezobench/io/toml_table.hpp"

namespace piezobench::io {

namespace {

constexpr const char* kFormat = "piezobench-hysteresis-1";

std::string list(const std::vector<double>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + fmt::format("{:.17g}", v[i]);
  return s + "]";
}

}  // namespace

std::string hysteresis_model_toml(const ident::HysteresisModel& m, const ident::HysteresisFit* fit, const std::string& source) {
  m.validate();
  std::string s;
  s += "# Hysteresis and creep of an actuator: d_e = offset + gain S(H[Va] + sum_j c_j F_j[Va]) (piezobench hysteresis fit;\n"
       "# S the identity unless [output] gives the modified PI's dead-zone superposition by its knots)\n";
  s += fmt::format("format = \"{}\"\n", kFormat);
  s += fmt::format("gain_m_per_V = {:.17g}\n", m.gain);
  s += fmt::format("offset_m = {:.17g}\n", m.offset);
  s += fmt::format("reference_slope = {:.17g}\n", m.reference_slope);
  s += fmt::format("reference_intercept_V = {:.17g}\n", m.reference_intercept);
  s += fmt::format("input_min_V = {:.17g}\n", m.input_min);
  s += fmt::format("input_max_V = {:.17g}\n", m.input_max);
  s += "\n[hysteresis]\n";
  s += "thresholds_V = " + list(m.hysteresis.thresholds) + "\n";
  s += "weights = " + list(m.hysteresis.weights) + "\n";
  if (!m.creep_time_constants.empty()) {
    s += "\n[creep]\n";
    s += "time_constants_s = " + list(m.creep_time_constants) + "\n";
    s += "coefficients = " + list(m.creep_coefficients) + "\n";
  }
  if (!m.output.identity()) {
    s += "\n[output]\n";
    s += "x_V = " + list(m.output.x) + "\n";
    s += "y_V = " + list(m.output.y) + "\n";
    s += fmt::format("slope_below = {:.17g}\nslope_above = {:.17g}\n", m.output.slope_below, m.output.slope_above);
  }
  if (fit != nullptr) {
    s += "\n[fit]\n";
    s += fmt::format("rms_residual_m = {:.6g}\n", fit->rms_residual);
    s += fmt::format("relative_residual = {:.6g}\n", fit->relative_residual);
    s += fmt::format("stroke_m = {:.6g}\n", fit->stroke);
    s += fmt::format("samples = {}\n", fit->samples);
    s += fmt::format("quality = \"{}\"\n", core::to_string(fit->quality.verdict));
    if (!source.empty()) {
      std::ostringstream quoted;
      quoted << toml::value<std::string>(source);  // TOML's escaping
      s += "source = " + quoted.str() + "\n";
    }
  }
  return s;
}

void write_hysteresis_model(const std::filesystem::path& path, const ident::HysteresisModel& model, const ident::HysteresisFit* fit,
                            const std::string& source) {
  write_text_atomically(path, hysteresis_model_toml(model, fit, source));
}

namespace {

// [hysteresis], [creep] and [output] of a model file.
void read_model_tables(const TomlReader& top, ident::HysteresisModel& m) {
  const TomlReader h = top.required_table("hysteresis");
  h.only({"thresholds_V", "weights"});
  m.hysteresis.linear_weight = 1.0;
  m.hysteresis.thresholds = h.required_numbers("thresholds_V");
  m.hysteresis.weights = h.required_numbers("weights");
  if (const auto c = top.table("creep")) {
    c->only({"time_constants_s", "coefficients"});
    m.creep_time_constants = c->required_numbers("time_constants_s");
    m.creep_coefficients = c->required_numbers("coefficients");
  }
  if (const auto o = top.table("output")) {
    o->only({"x_V", "y_V", "slope_below", "slope_above"});
    m.output.x = o->required_numbers("x_V");
    m.output.y = o->required_numbers("y_V");
    m.output.slope_below = o->required_number("slope_below");
    m.output.slope_above = o->required_number("slope_above");
  }
  (void)top.table("fit");  // informative; only its type is checked
}

}  // namespace

ident::HysteresisModel parse_hysteresis_model(const std::string& text, const std::string& source) {
  const toml::table table = parse_toml(text, source);
  const TomlReader top(table, source);
  top.only({"format", "gain_m_per_V", "offset_m", "reference_slope", "reference_intercept_V", "input_min_V", "input_max_V",
            "hysteresis", "creep", "output", "fit"});
  const std::string format_words = std::string("\"") + kFormat + "\"";
  if (const toml::node* format = top.get("format"); format == nullptr || format->value<std::string>() != std::string(kFormat)) {
    top.fail("format", format_words, format == nullptr ? "nothing (the key is required)"
                                     : format->is_string() ? "\"" + *format->value<std::string>() + "\"" : describe_toml(*format));
  }
  ident::HysteresisModel m;
  m.gain = top.required_number("gain_m_per_V");
  m.offset = top.required_number("offset_m");
  m.reference_slope = top.required_number("reference_slope");
  m.reference_intercept = top.required_number("reference_intercept_V");
  m.input_min = top.required_number("input_min_V");
  m.input_max = top.required_number("input_max_V");
  read_model_tables(top, m);
  m.validate(source);
  return m;
}

ident::HysteresisModel read_hysteresis_model(const std::filesystem::path& path) {
  return parse_hysteresis_model(read_toml_text(path), path.string());
}

}  // namespace piezobench::io
