#include "piezobench/bench/twin.hpp"

#include <fmt/format.h>

#include <cmath>
#include <set>
#include <sstream>
#include <toml++/toml.h>

#include "piezobench/core/error.hpp"
#include "piezobench/io/atomic_file.hpp"
#include "piezobench/io/toml_describe.hpp"
#include "piezobench/io/toml_table.hpp"

namespace piezobench::bench {

namespace {

std::string list(const std::vector<double>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + fmt::format("{:.10g}", v[i]);
  return s + "]";
}

std::string quoted(const std::string& text) {
  std::ostringstream out;
  out << toml::value<std::string>(text);  // TOML's escaping
  return out.str();
}

// One table of the file: its keys checked against a list, numbers read with the key named.
class Table {
 public:
  Table(const toml::table& t, std::string source, std::string prefix) : t_(t), source_(std::move(source)), prefix_(std::move(prefix)) {}
  void only(const std::set<std::string>& keys) const {
    for (const auto& [k, v] : t_) {
      if (keys.count(std::string(k.str())) == 0) {
        throw InputError(source_, prefix_ + std::string(k.str()), "a key of the twin file (docs/twin.md)", "an unknown key");
      }
    }
  }
  [[nodiscard]] const toml::node* find(const std::string& key) const { return t_.get(key); }
  [[nodiscard]] const toml::node& node(const std::string& key) const {
    const toml::node* n = t_.get(key);
    if (n == nullptr) throw InputError(source_, prefix_ + key, "a value", "nothing (missing)");
    return *n;
  }
  [[nodiscard]] double number(const std::string& key) const { return number(prefix_ + key, node(key)); }
  [[nodiscard]] std::vector<double> numbers(const std::string& key) const {
    const toml::node& n = node(key);
    const toml::array* a = n.as_array();
    if (a == nullptr) throw InputError(source_, prefix_ + key, "an array of numbers", io::describe_toml(n));
    std::vector<double> v;
    for (std::size_t i = 0; i < a->size(); ++i) v.push_back(number(fmt::format("{}{}[{}]", prefix_, key, i), (*a)[i]));
    return v;
  }
  [[nodiscard]] std::string text(const std::string& key) const {
    const toml::node& n = node(key);
    if (!n.is_string()) throw InputError(source_, prefix_ + key, "a string", io::describe_toml(n));
    return *n.value<std::string>();
  }
  [[nodiscard]] Table table(const std::string& key) const {
    const toml::node& n = node(key);
    if (!n.is_table()) throw InputError(source_, prefix_ + key, "a table [" + key + "]", io::describe_toml(n));
    return {*n.as_table(), source_, key + "."};
  }
  [[nodiscard]] const toml::table& raw() const { return t_; }

 private:
  [[nodiscard]] double number(const std::string& key, const toml::node& n) const {
    const std::optional<double> value = io::toml_number(n);
    if (!value) throw InputError(source_, key, "a number", io::describe_toml(n));
    if (!std::isfinite(*value)) throw InputError(source_, key, "a finite number", fmt::format("{}", *value));
    // -0.0 is read as 0: written back it would be "-0", a TOML integer, which reads as 0, so a twin
    // read and written would not read the same (fuzz/regression/twin_toml/valid_negative_zero.toml).
    return *value == 0.0 ? 0.0 : *value;
  }
  const toml::table& t_;
  std::string source_, prefix_;
};

void read_spectrum(const Table& noise, const std::string& key, const std::vector<double>& freq, NoiseSpectrum& out,
                   const std::string& source) {
  if (noise.find(key) == nullptr) return;
  out.freq_Hz = freq;
  out.psd = noise.numbers(key);
  if (out.psd.size() != freq.size()) {
    throw InputError(source, "noise." + key, fmt::format("{} values (as noise.freq_Hz)", freq.size()), fmt::format("{}", out.psd.size()));
  }
}

}  // namespace

void Twin::validate(const std::string& source) const {
  const std::string s = source.empty() ? "twin" : source;
  try {
    unit.validate();
    options.validate();
  } catch (const InputError& e) {
    throw e.with_source(s);
  }
}

void apply_chain(const Twin& twin, BenchOptions& options) {
  const BenchOptions& c = twin.options;
  options.amplifier_gain = c.amplifier_gain;
  options.suspended_mass = c.suspended_mass;
  options.delay = c.delay;
  options.hpf_resistance = c.hpf_resistance;
  options.ground_resistance = c.ground_resistance;
  options.adc_bandwidth_Hz = c.adc_bandwidth_Hz;
  options.sample_rate = c.sample_rate;
  options.encoder_noise = c.encoder_noise;
  options.vs_noise = c.vs_noise;
}

std::string twin_toml(const Twin& t) {
  t.validate();
  const apa::TwoDofParams& p = t.unit.model;
  const BenchOptions& c = t.options;
  std::string s;
  s += "# A digital twin of one unit: its virtual bench (piezobench twin; docs/twin.md)\n";
  s += fmt::format("format = \"{}\"\nname = {}\nunit = {}\n", kTwinFormat, quoted(t.name), t.unit.id);
  s += "\n[model]  # the 2-DoF model (docs/models.md), SI; the moving mass is chain.suspended_mass_kg\n";
  s += fmt::format("k1 = {:.10g}\nc1 = {:.10g}\nke = {:.10g}\nce = {:.10g}\nka = {:.10g}\nca = {:.10g}\nga = {:.10g}\ngs = {:.10g}\n", p.k1,
                   p.c1, p.ke, p.ce, p.ka, p.ca, p.ga, p.gs);
  s += "\n[chain]\n";
  s += fmt::format("amplifier_gain_V_per_V = {:.10g}\nsuspended_mass_kg = {:.10g}\ndelay_s = {:.10g}\nhpf_resistance_ohm = {:.10g}\n",
                   c.amplifier_gain, c.suspended_mass, c.delay, c.hpf_resistance);
  s += fmt::format("ground_resistance_ohm = {:.10g}\nadc_bandwidth_Hz = {:.10g}\nsample_rate_Hz = {:.10g}\n", c.ground_resistance,
                   c.adc_bandwidth_Hz, c.sample_rate);
  s += fmt::format("capacitance_sensor_F = {:.10g}\ncapacitance_actuator_F = {:.10g}\n", t.unit.capacitance_sensor,
                   t.unit.capacitance_actuator);
  s += "\n[hysteresis]  # effective stack voltage = Va + sum_i weights[i] P_{thresholds_V[i]}[Va]\n";
  s += "thresholds_V = " + list(t.unit.hysteresis_thresholds) + "\n";
  s += "weights = " + list(t.unit.hysteresis_weights) + "\n";
  s += "\n[creep]  # relative, per decade of time (docs/virtual-bench.md)\n";
  s += fmt::format("voltage_per_decade = {:.10g}\nload_per_decade = {:.10g}\n", t.unit.creep_coefficient, t.unit.load_creep_coefficient);
  s += "\n[noise]  # white, rms, quantization apart; the spectra measured on the quiet segments\n";
  s += fmt::format("de_m_rms = {:.10g}\nVs_V_rms = {:.10g}\n", c.encoder_noise, c.vs_noise);
  const std::vector<double>& f = !t.de_noise.freq_Hz.empty() ? t.de_noise.freq_Hz : t.vs_noise.freq_Hz;
  if (!f.empty()) s += "freq_Hz = " + list(f) + "\n";
  if (!t.de_noise.psd.empty()) s += "de_psd_m2_per_Hz = " + list(t.de_noise.psd) + "\n";
  if (!t.vs_noise.psd.empty()) s += "Vs_psd_V2_per_Hz = " + list(t.vs_noise.psd) + "\n";
  if (!t.sources.empty()) {
    s += "\n[sources]\n";
    for (const auto& [experiment, file] : t.sources) s += quoted(experiment) + " = " + quoted(file) + "\n";
  }
  return s;
}

void write_twin(const std::filesystem::path& path, const Twin& twin) { io::write_text_atomically(path, twin_toml(twin)); }

Twin parse_twin(const std::string& text, const std::string& source) {
  const toml::table root = io::parse_toml(text, source);
  const Table top(root, source, "");
  top.only({"format", "name", "unit", "model", "chain", "hysteresis", "creep", "noise", "sources"});
  const toml::node& format = top.node("format");
  if (format.value<std::string>() != std::string(kTwinFormat)) {
    throw InputError(source, "format", std::string("\"") + kTwinFormat + "\"", io::describe_toml(format));
  }
  Twin t;
  t.name = top.text("name");
  const double id = top.number("unit");
  if (!(id == std::floor(id) && id >= 0.0 && id < 1e9)) throw InputError(source, "unit", "a unit id (integer >= 0)", fmt::format("{}", id));
  t.unit.id = static_cast<int>(id);

  const Table model = top.table("model");
  model.only({"k1", "c1", "ke", "ce", "ka", "ca", "ga", "gs"});
  for (const char* k : {"k1", "c1", "ke", "ce", "ka", "ca", "ga", "gs"}) t.unit.model.set(k, model.number(k), source);

  const Table chain = top.table("chain");
  chain.only({"amplifier_gain_V_per_V", "suspended_mass_kg", "delay_s", "hpf_resistance_ohm", "ground_resistance_ohm", "adc_bandwidth_Hz",
              "sample_rate_Hz", "capacitance_sensor_F", "capacitance_actuator_F"});
  t.options.amplifier_gain = chain.number("amplifier_gain_V_per_V");
  t.options.suspended_mass = chain.number("suspended_mass_kg");
  t.unit.model.m = t.options.suspended_mass;
  t.options.delay = chain.number("delay_s");
  t.options.hpf_resistance = chain.number("hpf_resistance_ohm");
  t.options.ground_resistance = chain.number("ground_resistance_ohm");
  t.options.adc_bandwidth_Hz = chain.number("adc_bandwidth_Hz");
  t.options.sample_rate = chain.number("sample_rate_Hz");
  t.unit.capacitance_sensor = chain.number("capacitance_sensor_F");
  t.unit.capacitance_actuator = chain.number("capacitance_actuator_F");

  const Table hysteresis = top.table("hysteresis");
  hysteresis.only({"thresholds_V", "weights"});
  t.unit.hysteresis_thresholds = hysteresis.numbers("thresholds_V");
  t.unit.hysteresis_weights = hysteresis.numbers("weights");

  const Table creep = top.table("creep");
  creep.only({"voltage_per_decade", "load_per_decade"});
  t.unit.creep_coefficient = creep.number("voltage_per_decade");
  t.unit.load_creep_coefficient = creep.number("load_per_decade");

  const Table noise = top.table("noise");
  noise.only({"de_m_rms", "Vs_V_rms", "freq_Hz", "de_psd_m2_per_Hz", "Vs_psd_V2_per_Hz"});
  t.options.encoder_noise = noise.number("de_m_rms");
  t.options.vs_noise = noise.number("Vs_V_rms");
  if (noise.find("freq_Hz") != nullptr) {
    const std::vector<double> f = noise.numbers("freq_Hz");
    read_spectrum(noise, "de_psd_m2_per_Hz", f, t.de_noise, source);
    read_spectrum(noise, "Vs_psd_V2_per_Hz", f, t.vs_noise, source);
  }
  if (top.find("sources") != nullptr) {
    const Table sources = top.table("sources");
    for (const auto& [k, v] : sources.raw()) t.sources.emplace_back(std::string(k.str()), sources.text(std::string(k.str())));
  }
  t.validate(source);
  return t;
}

Twin read_twin(const std::filesystem::path& path) { return parse_twin(io::read_toml_text(path), path.string()); }

}  // namespace piezobench::bench
