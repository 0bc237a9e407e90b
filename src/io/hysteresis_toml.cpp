#include "piezobench/io/hysteresis_toml.hpp"

#include <fmt/format.h>

#include <set>
#include <sstream>
#include <toml++/toml.h>

#include "piezobench/core/error.hpp"
#include "piezobench/io/atomic_file.hpp"
#include "piezobench/io/toml_describe.hpp"
#include "piezobench/io/toml_table.hpp"

namespace piezobench::io {

namespace {

constexpr const char* kFormat = "piezobench-hysteresis-1";

std::string list(const std::vector<double>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + fmt::format("{:.17g}", v[i]);
  return s + "]";
}

class ModelTableReader {
 public:
  ModelTableReader(const toml::table& table, std::string source, std::string prefix)
      : table_(table), source_(std::move(source)), prefix_(std::move(prefix)) {}

  void only(const std::set<std::string>& keys) const {
    for (const auto& [k, v] : table_) {
      if (keys.count(std::string(k.str())) == 0) {
        throw InputError(source_, prefix_ + std::string(k.str()), "one of the model's keys (docs/formats.md)", "an unknown key");
      }
    }
  }
  [[nodiscard]] const toml::node& node(const std::string& key) const {
    const toml::node* n = table_.get(key);
    if (n == nullptr) throw InputError(source_, prefix_ + key, "a value", "nothing (missing)");
    return *n;
  }
  [[nodiscard]] double number(const std::string& key, const toml::node& n) const {
    const std::optional<double> value =
        n.is_integer() ? std::optional<double>(static_cast<double>(n.as_integer()->get())) : n.value<double>();
    if (!n.is_number() || !value) throw InputError(source_, key, "a number", describe_toml(n));
    if (!std::isfinite(*value)) throw InputError(source_, key, "a finite number", fmt::format("{}", *value));
    return *value;
  }
  [[nodiscard]] double number(const std::string& key) const { return number(prefix_ + key, node(key)); }
  [[nodiscard]] std::vector<double> numbers(const std::string& key) const {
    const toml::node& n = node(key);
    const toml::array* a = n.as_array();
    if (a == nullptr) throw InputError(source_, prefix_ + key, "an array of numbers", describe_toml(n));
    std::vector<double> v;
    for (std::size_t i = 0; i < a->size(); ++i) v.push_back(number(fmt::format("{}{}[{}]", prefix_, key, i), (*a)[i]));
    return v;
  }
  [[nodiscard]] const toml::table* table(const std::string& key, bool required) const {
    const toml::node* n = table_.get(key);
    if (n == nullptr) {
      if (required) throw InputError(source_, key, "a table [" + key + "]", "nothing (missing)");
      return nullptr;
    }
    if (!n->is_table()) throw InputError(source_, key, "a table [" + key + "]", describe_toml(*n));
    return n->as_table();
  }

 private:
  const toml::table& table_;
  std::string source_, prefix_;
};

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

ident::HysteresisModel parse_hysteresis_model(const std::string& text, const std::string& source) {
  const toml::table table = parse_toml(text, source);
  const ModelTableReader top(table, source, "");
  top.only({"format", "gain_m_per_V", "offset_m", "reference_slope", "reference_intercept_V", "input_min_V", "input_max_V",
            "hysteresis", "creep", "output", "fit"});
  const toml::node& format = top.node("format");
  if (format.value<std::string>() != std::string(kFormat)) {
    throw InputError(source, "format", std::string("\"") + kFormat + "\"",
                     format.is_string() ? "\"" + *format.value<std::string>() + "\"" : describe_toml(format));
  }
  ident::HysteresisModel m;
  m.gain = top.number("gain_m_per_V");
  m.offset = top.number("offset_m");
  m.reference_slope = top.number("reference_slope");
  m.reference_intercept = top.number("reference_intercept_V");
  m.input_min = top.number("input_min_V");
  m.input_max = top.number("input_max_V");
  const ModelTableReader h(*top.table("hysteresis", true), source, "hysteresis.");
  h.only({"thresholds_V", "weights"});
  m.hysteresis.linear_weight = 1.0;
  m.hysteresis.thresholds = h.numbers("thresholds_V");
  m.hysteresis.weights = h.numbers("weights");
  if (const toml::table* c = top.table("creep", false)) {
    const ModelTableReader cr(*c, source, "creep.");
    cr.only({"time_constants_s", "coefficients"});
    m.creep_time_constants = cr.numbers("time_constants_s");
    m.creep_coefficients = cr.numbers("coefficients");
  }
  if (const toml::table* o = top.table("output", false)) {
    const ModelTableReader orr(*o, source, "output.");
    orr.only({"x_V", "y_V", "slope_below", "slope_above"});
    m.output.x = orr.numbers("x_V");
    m.output.y = orr.numbers("y_V");
    m.output.slope_below = orr.number("slope_below");
    m.output.slope_above = orr.number("slope_above");
  }
  (void)top.table("fit", false);  // informative; only its type is checked
  m.validate(source);
  return m;
}

ident::HysteresisModel read_hysteresis_model(const std::filesystem::path& path) {
  return parse_hysteresis_model(read_toml_text(path), path.string());
}

}  // namespace piezobench::io
