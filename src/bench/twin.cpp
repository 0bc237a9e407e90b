#include "piezobench/bench/twin.hpp"

#include <fmt/format.h>

#include <cmath>
#include <sstream>
#include <toml++/toml.h>

#include "piezobench/core/error.hpp"
#include "piezobench/io/atomic_file.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/io/toml_reader.hpp"
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

// A number of the twin file. -0.0 is read as 0: written back it would be "-0", a TOML integer, which
// reads as 0, so a twin read and written would not read the same
// (fuzz/regression/twin_toml/valid_negative_zero.toml).
double twin_number(const io::TomlReader& t, const char* key) {
  const double v = t.required_number(key);
  return v == 0.0 ? 0.0 : v;
}

std::vector<double> twin_numbers(const io::TomlReader& t, const char* key) {
  std::vector<double> v = t.required_numbers(key);
  for (double& x : v) x = x == 0.0 ? 0.0 : x;
  return v;
}

void read_spectrum(const io::TomlReader& noise, const char* key, const std::vector<double>& freq, NoiseSpectrum& out) {
  if (!noise.has(key)) return;
  out.freq_Hz = freq;
  out.psd = twin_numbers(noise, key);
  if (out.psd.size() != freq.size()) noise.fail(key, fmt::format("{} values (as noise.freq_Hz)", freq.size()), std::to_string(out.psd.size()));
}

void read_chain(const io::TomlReader& chain, Twin& t) {
  chain.only({"amplifier_gain_V_per_V", "suspended_mass_kg", "delay_s", "hpf_resistance_ohm", "ground_resistance_ohm", "adc_bandwidth_Hz",
              "sample_rate_Hz", "capacitance_sensor_F", "capacitance_actuator_F"});
  t.options.amplifier_gain = twin_number(chain, "amplifier_gain_V_per_V");
  t.options.suspended_mass = twin_number(chain, "suspended_mass_kg");
  t.unit.model.m = t.options.suspended_mass;
  t.options.delay = twin_number(chain, "delay_s");
  t.options.hpf_resistance = twin_number(chain, "hpf_resistance_ohm");
  t.options.ground_resistance = twin_number(chain, "ground_resistance_ohm");
  t.options.adc_bandwidth_Hz = twin_number(chain, "adc_bandwidth_Hz");
  t.options.sample_rate = twin_number(chain, "sample_rate_Hz");
  t.unit.capacitance_sensor = twin_number(chain, "capacitance_sensor_F");
  t.unit.capacitance_actuator = twin_number(chain, "capacitance_actuator_F");
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
  const io::TomlReader top(root, source);
  top.only({"format", "name", "unit", "model", "chain", "hysteresis", "creep", "noise", "sources"});
  const std::string format_words = std::string("\"") + kTwinFormat + "\"";
  if (const std::string format = top.required_string("format", format_words); format != kTwinFormat) top.fail("format", format_words, "'" + format + "'");
  Twin t;
  t.name = top.required_string("name");
  const double id = twin_number(top, "unit");
  if (!(id == std::floor(id) && id >= 0.0 && id < 1e9)) top.fail("unit", "a unit id (integer >= 0)", format_number_exact(id));
  t.unit.id = static_cast<int>(id);

  const io::TomlReader model = top.required_table("model");
  model.only({"k1", "c1", "ke", "ce", "ka", "ca", "ga", "gs"});
  for (const char* k : {"k1", "c1", "ke", "ce", "ka", "ca", "ga", "gs"}) t.unit.model.set(k, twin_number(model, k), source);
  read_chain(top.required_table("chain"), t);

  const io::TomlReader hysteresis = top.required_table("hysteresis");
  hysteresis.only({"thresholds_V", "weights"});
  t.unit.hysteresis_thresholds = twin_numbers(hysteresis, "thresholds_V");
  t.unit.hysteresis_weights = twin_numbers(hysteresis, "weights");

  const io::TomlReader creep = top.required_table("creep");
  creep.only({"voltage_per_decade", "load_per_decade"});
  t.unit.creep_coefficient = twin_number(creep, "voltage_per_decade");
  t.unit.load_creep_coefficient = twin_number(creep, "load_per_decade");

  const io::TomlReader noise = top.required_table("noise");
  noise.only({"de_m_rms", "Vs_V_rms", "freq_Hz", "de_psd_m2_per_Hz", "Vs_psd_V2_per_Hz"});
  t.options.encoder_noise = twin_number(noise, "de_m_rms");
  t.options.vs_noise = twin_number(noise, "Vs_V_rms");
  if (noise.has("freq_Hz")) {
    const std::vector<double> f = twin_numbers(noise, "freq_Hz");
    read_spectrum(noise, "de_psd_m2_per_Hz", f, t.de_noise);
    read_spectrum(noise, "Vs_psd_V2_per_Hz", f, t.vs_noise);
  }
  if (const auto sources = top.table("sources")) {
    for (const auto& [k, v] : sources->table()) t.sources.emplace_back(std::string(k.str()), sources->required_string(k.str()));
  }
  t.validate(source);
  return t;
}

Twin read_twin(const std::filesystem::path& path) { return parse_twin(io::read_toml_text(path), path.string()); }

}  // namespace piezobench::bench
