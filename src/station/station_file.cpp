#include "piezobench/station/station_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <sstream>

#include "piezobench/bench/experiments.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/io/toml_table.hpp"
#include "piezobench/io/toml_reader.hpp"

namespace piezobench::station {

namespace fs = std::filesystem;
using io::TomlReader;

const PhaseSpec* StationFile::phase(const std::string& phase_name) const {
  const auto it = std::find_if(phases.begin(), phases.end(), [&](const PhaseSpec& p) { return p.name == phase_name; });
  return it == phases.end() ? nullptr : &*it;
}

namespace {

const std::vector<std::string> kExperiments = {"flatness", "capacitance", "stroke", "hysteresis", "stiffness",
                                               "frf-noise", "iff", "hammer", "tracking"};

campaign::Experiment record_of(const PhaseSpec& p) {
  using E = campaign::Experiment;
  if (p.experiment == "flatness") return E::kFlatness;
  if (p.experiment == "capacitance") return E::kCapacitance;
  if (p.experiment == "stroke") return E::kStroke;
  if (p.experiment == "hysteresis") return E::kHysteresis;
  if (p.experiment == "stiffness") return p.open_circuit ? E::kStiffnessOpen : E::kStiffness;
  if (p.experiment == "frf-noise") return p.no_resistor ? E::kFrfNoResistor : E::kFrf;
  if (p.experiment == "iff") return E::kIff;
  if (p.experiment == "hammer") return E::kHammer;
  return E::kTracking;
}

bool valid_name(const std::string& s) {
  return !s.empty() && s.size() <= 64 &&
         std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_'; });
}

MeasurementSpec read_measurement(const TomlReader& r, const PhaseSpec& p) {
  r.only({"name", "min", "max", "stop_on_fail"});
  MeasurementSpec m;
  m.name = r.required_string("name");
  m.line = static_cast<int>(r.table().source().begin.line);
  const MeasurementKind* kind = find_measurement(m.name);
  if (kind == nullptr || kind->experiment != p.record) {
    std::string names;
    for (const auto& k : measurement_catalog()) {
      if (k.experiment == p.record) names += (names.empty() ? "" : ", ") + k.name;
    }
    r.fail("name", "a measurement of the catalog for " + campaign::to_string(p.record) + " (" + names + ")", "'" + m.name + "'");
  }
  m.limit.min = r.number("min");
  m.limit.max = r.number("max");
  if (m.limit.min && m.limit.max && *m.limit.min > *m.limit.max) {
    r.fail("max", "a maximum >= the minimum " + format_number_exact(*m.limit.min), format_number_exact(*m.limit.max));
  }
  m.stop_on_fail = r.boolean("stop_on_fail").value_or(false);
  return m;
}

void read_settings(const TomlReader& r, PhaseSpec& p) {
  p.amplitude_V = r.number("amplitude_V");
  p.duration_s = r.number("duration_s");
  p.gain = r.number("gain");
  p.open_circuit = r.boolean("open_circuit").value_or(false);
  p.no_resistor = r.boolean("no_resistor").value_or(false);
  if (p.open_circuit && p.experiment != "stiffness") r.fail("open_circuit", "only in a stiffness phase", "experiment " + p.experiment);
  if (p.no_resistor && p.experiment != "frf-noise") r.fail("no_resistor", "only in a frf-noise phase", "experiment " + p.experiment);
  if (p.experiment == "iff" && !p.gain) r.fail("gain", "the IFF gain g of the phase (the campaign needs it)", "nothing");
  if (bench::runs_on_bench(bench::experiment_from_string(p.experiment))) {
    bench::ExperimentOptions eo;
    eo.amplitude = p.amplitude_V;
    eo.duration = p.duration_s;
    eo.gain = p.gain;
    try {
      eo.validate(bench::experiment_from_string(p.experiment));
    } catch (const InputError& e) {
      throw InputError(r.where(), r.key("settings"), "settings the experiment takes", e.what());
    }
  } else if (p.amplitude_V || p.duration_s || p.gain) {
    r.fail("amplitude_V", "no amplitude, duration or gain for " + p.experiment, "one of them");
  }
  const auto source = r.string("source");
  if (source) {
    if (p.experiment != "flatness" && p.experiment != "capacitance") r.fail("source", "only in flatness and capacitance phases", *source);
    if (*source == "bench") {
      p.source = ValueSource::kBench;
    } else if (*source == "file") {
      p.source = ValueSource::kFile;
    } else if (*source == "typed" && p.experiment == "capacitance") {
      p.source = ValueSource::kTyped;
    } else {
      r.fail("source", p.experiment == "capacitance" ? "bench, file or typed" : "bench or file", "'" + *source + "'");
    }
  }
  // Each try is a whole experiment the operator sits through, kept in the record: a bound an
  // operator could reach, not a counter that never ends.
  constexpr long kMaxRetries = 20;
  p.retries = static_cast<long>(r.integer("retries", 0, kMaxRetries).value_or(2));
  p.min_coherence = r.number("min_coherence", io::NumberBounds::closed(0.0, 1.0)).value_or(0.0);
  if (p.min_coherence > 0.0 && p.record != campaign::Experiment::kFrf) r.fail("min_coherence", "only in a frf-noise phase with the resistor", p.experiment);
  p.max_clamped_samples = static_cast<long>(r.integer("max_clamped_samples", 0).value_or(0));
}

PhaseSpec read_phase(const TomlReader& r) {
  r.only({"name", "experiment", "amplitude_V", "duration_s", "gain", "open_circuit", "no_resistor", "source", "steps", "retries",
          "min_coherence", "max_clamped_samples", "measurements"});
  PhaseSpec p;
  p.line = static_cast<int>(r.table().source().begin.line);
  p.name = r.required_string("name");
  if (!valid_name(p.name)) r.fail("name", "a name of letters, digits, '-' and '_' (at most 64)", "'" + p.name + "'");
  p.experiment = r.required_string("experiment");
  if (std::find(kExperiments.begin(), kExperiments.end(), p.experiment) == kExperiments.end()) {
    r.fail("experiment", "one of flatness, capacitance, stroke, hysteresis, stiffness, frf-noise, iff, hammer, tracking",
           "'" + p.experiment + "'");
  }
  p.open_circuit = r.boolean("open_circuit").value_or(false);
  p.no_resistor = r.boolean("no_resistor").value_or(false);
  p.record = record_of(p);
  read_settings(r, p);
  p.steps = r.strings("steps");
  for (const TomlReader& m : r.tables("measurements")) p.measurements.push_back(read_measurement(m, p));
  return p;
}

std::string campaign_tables(const TomlReader& r) {
  r.only({"bench", "analysis"});
  toml::table out;
  for (const char* k : {"bench", "analysis"}) {
    if (const auto sub = r.table(k)) out.insert(k, sub->table());
  }
  std::ostringstream s;
  s << toml::toml_formatter(out) << "\n";
  return s.str();
}

}  // namespace

std::string StationFile::campaign_specs() const {
  std::map<std::string, Limit> limits;
  for (const PhaseSpec& p : phases) {
    for (const MeasurementSpec& m : p.measurements) limits[m.name] = m.limit;
  }
  std::string s = "[specs]\n";
  const auto range = [&](const char* measurement, const char* key) {
    const auto it = limits.find(measurement);
    if (it != limits.end() && it->second.min && it->second.max) {
      s += fmt::format("{} = [{}, {}]\n", key, *it->second.min, *it->second.max);
    }
  };
  if (const auto it = limits.find("flatness_um"); it != limits.end() && it->second.max) s += fmt::format("flatness_um = {}\n", *it->second.max);
  range("capacitance_sensor_uF", "capacitance_sensor_uF");
  range("capacitance_actuator_uF", "capacitance_actuator_uF");
  if (const auto it = limits.find("stroke_um"); it != limits.end() && it->second.min) s += fmt::format("stroke_min_um = {}\n", *it->second.min);
  // The campaign has one stiffness range for k1, k2 and the resonance stiffness: set when the
  // station's ranges of those it limits agree (otherwise only the station judges them).
  std::optional<std::pair<double, double>> k;
  bool same = true;
  for (const char* measurement : {"k1_N_per_um", "k2_N_per_um", "k_resonance_N_per_um"}) {
    const auto it = limits.find(measurement);
    if (it == limits.end()) continue;
    if (!(it->second.min && it->second.max)) {
      same = false;
      continue;
    }
    const std::pair<double, double> r{*it->second.min, *it->second.max};
    if (k && *k != r) same = false;
    k = r;
  }
  if (k && same) s += fmt::format("stiffness_N_per_um = [{}, {}]\n", k->first, k->second);
  return s;
}

StationFile parse_station_file(const std::string& text, const fs::path& file) {
  const toml::table root = io::parse_toml(text, file.string());
  const TomlReader r(root, file.string(), "");
  r.only({"name", "margin_relative", "campaign", "phases"});
  StationFile st;
  st.file = file;
  st.name = r.required_string("name");
  st.margin_relative = r.number("margin_relative", io::NumberBounds::half_open(0.0, 0.5)).value_or(0.01);
  if (const auto c = r.table("campaign")) st.campaign_tables = campaign_tables(*c);
  std::map<campaign::Experiment, std::string> single;
  for (const TomlReader& pr : r.tables("phases")) {
    PhaseSpec p = read_phase(pr);
    if (st.phase(p.name) != nullptr) pr.fail("name", "a phase name not used before", "'" + p.name + "' twice");
    if (p.record != campaign::Experiment::kHysteresis && p.record != campaign::Experiment::kIff) {
      const auto [it, fresh] = single.emplace(p.record, p.name);
      if (!fresh) {
        pr.fail("experiment", "one phase per record of the campaign (" + campaign::to_string(p.record) + " is phase '" + it->second + "')",
                "a second one");
      }
    }
    st.phases.push_back(std::move(p));
  }
  if (st.phases.empty()) r.fail("phases", "at least one [[phases]] table", "none");
  // The campaign's tables and the specs must make a valid campaign (checked now, not after the
  // unit was measured).
  try {
    (void)campaign::parse_campaign(st.campaign_tables + st.campaign_specs() + "\n[[units]]\nid = 1\n", file, false);
  } catch (const InputError& e) {
    throw InputError(file.string(), "campaign", "[campaign.bench] and [campaign.analysis] as in a campaign file", e.what());
  }
  return st;
}

StationFile read_station_file(const fs::path& file) { return parse_station_file(io::read_toml_text(file), file); }

}  // namespace piezobench::station
