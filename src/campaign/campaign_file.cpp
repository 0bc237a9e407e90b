#include "piezobench/campaign/campaign_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <toml++/toml.h>

#include "piezobench/io/toml_reader.hpp"
#include "piezobench/io/toml_table.hpp"
#include "piezobench/io/units.hpp"
#include "piezobench/core/checked_number.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/timestamp.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::campaign {

namespace fs = std::filesystem;

std::string to_string(Experiment e) {
  switch (e) {
    case Experiment::kFlatness: return "flatness";
    case Experiment::kCapacitance: return "capacitance";
    case Experiment::kStroke: return "stroke";
    case Experiment::kHysteresis: return "hysteresis";
    case Experiment::kStiffness: return "stiffness";
    case Experiment::kStiffnessOpen: return "stiffness_open_circuit";
    case Experiment::kFrf: return "frf";
    case Experiment::kFrfNoResistor: return "frf_without_resistor";
    case Experiment::kIff: return "iff";
    case Experiment::kHammer: return "hammer";
    case Experiment::kTracking: return "tracking";
  }
  return "unknown";
}

const std::vector<Experiment>& all_experiments() {
  static const std::vector<Experiment> all = {Experiment::kFlatness, Experiment::kCapacitance, Experiment::kStroke,
                                              Experiment::kHysteresis, Experiment::kStiffness, Experiment::kStiffnessOpen,
                                              Experiment::kFrf, Experiment::kFrfNoResistor, Experiment::kIff,
                                              Experiment::kHammer, Experiment::kTracking};
  return all;
}

Experiment experiment_from_string(const std::string& name, const std::string& source) {
  for (const Experiment e : all_experiments()) {
    if (to_string(e) == name) return e;
  }
  std::string names;
  for (const Experiment e : all_experiments()) names += (names.empty() ? "" : ", ") + to_string(e);
  throw InputError(source, "experiment", "one of " + names, "'" + name + "'");
}

const std::vector<std::string>& required_roles(Experiment e) {
  static const std::map<Experiment, std::vector<std::string>> roles = {
      {Experiment::kFlatness, {"x", "y", "z"}},         {Experiment::kCapacitance, {"C_sensor", "C_actuator"}},
      {Experiment::kStroke, {"Va", "de"}},              {Experiment::kHysteresis, {"Va", "de"}},
      {Experiment::kStiffness, {"de"}},                 {Experiment::kFrf, {"u", "de", "Vs"}},
      {Experiment::kStiffnessOpen, {"de"}},             {Experiment::kFrfNoResistor, {"u", "Vs"}},
      {Experiment::kIff, {"u_prime", "de"}},            {Experiment::kHammer, {"F", "v"}},
      {Experiment::kTracking, {"c", "de_open", "de_ff"}}};
  return roles.at(e);
}

const std::vector<std::string>& optional_roles(Experiment e) {
  static const std::vector<std::string> none;
  static const std::vector<std::string> interface = {"interface"};
  static const std::vector<std::string> mass = {"added_mass"};
  if (e == Experiment::kFlatness) return interface;
  if (e == Experiment::kStiffness || e == Experiment::kStiffnessOpen) return mass;
  return none;
}

bool UnitSpec::has(Experiment e) const {
  switch (e) {
    case Experiment::kFlatness: return flatness.has_value();
    case Experiment::kCapacitance: return capacitance.has_value() || capacitance_sensor.has_value();
    case Experiment::kStroke: return stroke.has_value();
    case Experiment::kHysteresis: return !hysteresis.empty();
    case Experiment::kStiffness: return stiffness.has_value();
    case Experiment::kStiffnessOpen: return stiffness_open.has_value();
    case Experiment::kFrf: return frf.has_value();
    case Experiment::kFrfNoResistor: return frf_no_resistor.has_value();
    case Experiment::kIff: return !iff.empty();
    case Experiment::kHammer: return hammer.has_value();
    case Experiment::kTracking: return tracking.has_value();
  }
  return false;
}

namespace {

using io::describe_toml;
using io::NumberBounds;
using io::TomlReader;

const std::vector<std::string>& all_roles() {
  static const std::vector<std::string> roles = [] {
    std::vector<std::string> r;
    for (const Experiment e : all_experiments()) {
      for (const auto& v : {required_roles(e), optional_roles(e)}) {
        for (const auto& role : v) {
          if (std::find(r.begin(), r.end(), role) == r.end()) r.push_back(role);
        }
      }
    }
    return r;
  }();
  return roles;
}

// A table role -> channel name (or unit symbol) of `allowed` roles.
std::map<std::string, std::string> read_channels(const TomlReader& c, const std::vector<std::string>& allowed) {
  c.only(allowed);
  std::map<std::string, std::string> out;
  for (const auto& [role, node] : c.table()) {
    const std::string k(role.str());
    const std::string name = *c.string(k);
    if (name.empty()) c.fail(k, "a channel name", "an empty string");
    out[k] = name;
  }
  return out;
}

// [min, max] with min <= max, scaled by `scale`.
std::optional<metrology::Range> read_range(const TomlReader& r, std::string_view k, double scale) {
  const auto p = r.pair(k);
  if (!p) return std::nullopt;
  if (!(p->first <= p->second)) {
    r.fail(k, "[min, max] with min <= max", "[" + format_number_exact(p->first) + ", " + format_number_exact(p->second) + "]");
  }
  return metrology::Range{p->first * scale, p->second * scale};
}

struct Context {
  fs::path folder;
  bool check_files = true;
  std::map<std::string, std::string> channels;  // campaign-wide
};

// The file `given` at key k of r. `must_exist`: refused here when missing (the super element's
// files); a unit's measurement file is not, so that a missing one leaves that unit out of the batch
// (not analysed), never the batch.
fs::path resolve(const Context& ctx, const TomlReader& r, std::string_view k, const std::string& given, bool must_exist = true) {
  if (given.empty()) r.fail(k, "a file name", "an empty string");
  const fs::path p(given);
  const fs::path full = p.is_absolute() ? p : ctx.folder / p;
  if (ctx.check_files && must_exist) {
    std::error_code ec;
    if (!fs::is_regular_file(full, ec)) {
      r.fail(k, "an existing measurement file",
             fmt::format("'{}' ({}){}", given, full.string(), fs::exists(full, ec) ? " is not a file" : " does not exist"));
    }
  }
  return full;
}

// A file entry's table {file, channels, units, sample_rate_Hz, gain}.
void read_file_table(const Context& ctx, const TomlReader& r, Experiment e, const std::vector<std::string>& roles, FileSpec& f) {
  std::vector<std::string> known = {"file", "channels", "units", "sample_rate_Hz"};
  if (e == Experiment::kIff) known.push_back("gain");
  r.only(known);
  f.given = r.required_string("file", "the measurement file of this entry");
  if (const auto c = r.table("channels")) {
    for (const auto& [role, name] : read_channels(*c, roles)) {
      f.channels[role] = name;
      if (std::find(f.explicit_roles.begin(), f.explicit_roles.end(), role) == f.explicit_roles.end()) f.explicit_roles.push_back(role);
    }
  }
  // Units of channels the file does not label, checked against the one unit table.
  if (const auto u = r.table("units")) {
    for (const auto& [role, symbol] : read_channels(*u, roles)) f.units[role] = io::unit_from_string(symbol, u->where(u->get(role)), u->key(role)).symbol;
  }
  f.sample_rate = r.number("sample_rate_Hz", NumberBounds::positive()).value_or(f.sample_rate);
  if (e == Experiment::kIff) f.gain = r.number("gain", NumberBounds::non_negative()).value_or(f.gain);
  f.path = resolve(ctx, r, "file", f.given, /*must_exist=*/false);
}

// A file entry at key k of the unit: "path" or {file, channels, sample_rate_Hz, gain}.
FileSpec read_file_spec(const Context& ctx, const TomlReader& unit, const std::string& k, const toml::node& node, Experiment e,
                        const std::map<std::string, std::string>& unit_channels, const std::vector<std::string>& unit_explicit) {
  FileSpec f;
  f.key = unit.key(k);
  std::vector<std::string> roles = required_roles(e);
  for (const auto& r : optional_roles(e)) roles.push_back(r);
  for (const auto& role : roles) {
    f.channels[role] = role;
    if (const auto it = ctx.channels.find(role); it != ctx.channels.end()) f.channels[role] = it->second;
    if (const auto it = unit_channels.find(role); it != unit_channels.end()) f.channels[role] = it->second;
    if (std::find(unit_explicit.begin(), unit_explicit.end(), role) != unit_explicit.end()) f.explicit_roles.push_back(role);
  }
  if (node.is_string()) {
    f.given = node.as_string()->get();
    f.path = resolve(ctx, unit, k, f.given, /*must_exist=*/false);
  } else if (const toml::table* t = node.as_table()) {
    read_file_table(ctx, TomlReader(*t, unit.file(), f.key), e, roles, f);
  } else {
    unit.fail(k, "a file name or a table {file = ..., channels = {...}}", describe_toml(node), &node);
  }
  return f;
}

void set_record(UnitSpec& u, Experiment e, FileSpec f) {
  switch (e) {
    case Experiment::kFlatness: u.flatness = std::move(f); break;
    case Experiment::kCapacitance: u.capacitance = std::move(f); break;
    case Experiment::kStroke: u.stroke = std::move(f); break;
    case Experiment::kStiffness: u.stiffness = std::move(f); break;
    case Experiment::kStiffnessOpen: u.stiffness_open = std::move(f); break;
    case Experiment::kFrf: u.frf = std::move(f); break;
    case Experiment::kFrfNoResistor: u.frf_no_resistor = std::move(f); break;
    case Experiment::kHammer: u.hammer = std::move(f); break;
    case Experiment::kTracking: u.tracking = std::move(f); break;
    case Experiment::kHysteresis: u.hysteresis.push_back(std::move(f)); break;
    case Experiment::kIff: u.iff.push_back(std::move(f)); break;
  }
}

// The capacitances typed in a unit's capacitance_uF = {sensor, actuator}.
void read_typed_capacitance(const TomlReader& c, UnitSpec& u) {
  c.only({"sensor", "actuator"});
  u.capacitance_sensor = c.required_number("sensor", NumberBounds::positive(), "a value in uF") * 1e-6;
  u.capacitance_actuator = c.required_number("actuator", NumberBounds::positive(), "a value in uF") * 1e-6;
}

UnitSpec read_unit(const Context& ctx, const TomlReader& r) {
  UnitSpec u;
  u.key = r.path();
  std::vector<std::string> known = {"id", "name", "serial", "channels", "capacitance_uF"};
  for (const Experiment e : all_experiments()) known.push_back(to_string(e));
  r.only(known);
  const auto id = r.integer("id", 0, 1000000);
  if (!id) r.fail("id", "the unit's number (id = 1, 2, ...)", "nothing (the key is required)");
  u.id = static_cast<int>(*id);
  u.name = r.string("name").value_or(fmt::format("APA {}", u.id));
  u.serial = r.string("serial");
  std::map<std::string, std::string> channels;
  std::vector<std::string> explicit_roles;
  if (const auto c = r.table("channels")) {
    channels = read_channels(*c, all_roles());
    for (const auto& [role, name] : channels) explicit_roles.push_back(role);
  }
  for (const auto& [role, name] : ctx.channels) {
    if (std::find(explicit_roles.begin(), explicit_roles.end(), role) == explicit_roles.end()) explicit_roles.push_back(role);
  }
  for (const Experiment e : all_experiments()) {
    const std::string k = to_string(e);
    const toml::node* n = r.get(k);
    if (!n) continue;
    const toml::array* a = (e == Experiment::kHysteresis || e == Experiment::kIff) ? n->as_array() : nullptr;
    if (a == nullptr) {
      set_record(u, e, read_file_spec(ctx, r, k, *n, e, channels, explicit_roles));
      continue;
    }
    for (std::size_t i = 0; i < a->size(); ++i) {
      set_record(u, e, read_file_spec(ctx, r, k + "[" + std::to_string(i) + "]", *a->get(i), e, channels, explicit_roles));
    }
  }
  if (const auto c = r.table("capacitance_uF")) {
    if (u.capacitance) r.fail("capacitance_uF", "either a capacitance file or capacitance_uF", "both");
    read_typed_capacitance(*c, u);
  }
  return u;
}

// A TOML date or date-time as seconds since the epoch, UTC: a date's first second (`end`: its last),
// a date-time with its offset applied, one without an offset taken as UTC.
long long read_time(const TomlReader& r, const std::string& k, bool end) {
  const toml::node* n = r.get(k);
  const std::string expected = "a date (2026-11-27) or a date-time (2026-11-27T08:00:00Z)";
  toml::date date;
  toml::time time{end ? 23 : 0, end ? 59 : 0, end ? 59 : 0, 0};
  long long offset_s = 0;
  if (const auto* d = n->as_date()) {
    date = d->get();
  } else if (const auto* dt = n->as_date_time()) {
    date = dt->get().date;
    time = dt->get().time;
    if (dt->get().offset) offset_s = 60LL * dt->get().offset->minutes;
  } else {
    r.fail(k, expected, describe_toml(*n));
  }
  const auto s = utc_seconds(date.year, date.month, date.day, time.hour, time.minute, time.second);
  if (!s) r.fail(k, expected, fmt::format("{:04}-{:02}-{:02}", date.year, date.month, date.day));
  return *s - offset_s;
}

void read_bench(const TomlReader& r, BenchConstants& b) {
  r.only({"amplifier_gain", "suspended_mass_kg", "added_mass_kg", "gravity_m_per_s2", "hpf_resistance_ohm", "probe_accuracy_um",
          "name", "recorded_from", "recorded_until", "added_mass_uncertainty_kg", "gravity_uncertainty_m_per_s2",
          "suspended_mass_uncertainty_kg", "encoder_resolution_um", "capacitance_uncertainty_relative",
          "displacement_scale_uncertainty_relative"});
  if (const auto name = r.string("name")) {
    if (name->empty()) r.fail("name", "the name of the bench (what its records say in settings.bench)", "''");
    b.name = *name;
  }
  if (r.has("recorded_from")) b.recorded_from_s = read_time(r, "recorded_from", false);
  if (r.has("recorded_until")) b.recorded_until_s = read_time(r, "recorded_until", true);
  if (b.recorded_from_s && b.recorded_until_s && *b.recorded_from_s > *b.recorded_until_s) {
    r.fail("recorded_until", "a time not before recorded_from (" + utc_timestamp(*b.recorded_from_s) + ")", utc_timestamp(*b.recorded_until_s));
  }
  if (const auto g = r.number("amplifier_gain")) {
    if (*g == 0.0) r.fail("amplifier_gain", "a non-zero gain (V/V)", "0");
    b.amplifier_gain = *g;
  }
  b.suspended_mass = r.number("suspended_mass_kg", NumberBounds::positive()).value_or(b.suspended_mass);
  b.added_mass = r.number("added_mass_kg", NumberBounds::positive()).value_or(b.added_mass);
  b.gravity = r.number("gravity_m_per_s2", NumberBounds::positive()).value_or(b.gravity);
  const double resistance = r.number("hpf_resistance_ohm", NumberBounds::non_negative()).value_or(0.0);
  if (resistance > 0.0) b.hpf_resistance = resistance;
  b.probe_accuracy = r.number("probe_accuracy_um", NumberBounds::non_negative()).value_or(b.probe_accuracy * 1e6) * 1e-6;
  metrology::StaticTestUncertainties& u = b.uncertainty;
  u.added_mass_kg = r.number("added_mass_uncertainty_kg", NumberBounds::non_negative()).value_or(u.added_mass_kg);
  u.gravity_m_per_s2 = r.number("gravity_uncertainty_m_per_s2", NumberBounds::non_negative()).value_or(u.gravity_m_per_s2);
  u.suspended_mass_kg = r.number("suspended_mass_uncertainty_kg", NumberBounds::non_negative()).value_or(u.suspended_mass_kg);
  u.encoder_resolution_m = r.number("encoder_resolution_um", NumberBounds::non_negative()).value_or(u.encoder_resolution_m * 1e6) * 1e-6;
  u.capacitance_relative = r.number("capacitance_uncertainty_relative", NumberBounds::half_open(0.0, 1.0)).value_or(u.capacitance_relative);
  u.displacement_scale_relative =
      r.number("displacement_scale_uncertainty_relative", NumberBounds::half_open(0.0, 1.0)).value_or(u.displacement_scale_relative);
}

void read_specs(const TomlReader& r, Specs& s) {
  r.only({"flatness_um", "flatness_method", "capacitance_sensor_uF", "capacitance_actuator_uF", "stroke_min_um",
          "stiffness_N_per_um", "outlier_threshold", "outlier_min_relative_deviation", "reject_outliers"});
  if (const auto f = r.number("flatness_um", NumberBounds::positive())) s.flatness_max = *f * 1e-6;
  if (const auto m = r.string("flatness_method")) {
    try {
      s.flatness_method = metrology::flatness_method_from_string(*m, r.file());
    } catch (const InputError&) {
      r.fail("flatness_method", "least-squares or minimum-zone", "'" + *m + "'");
    }
  }
  s.capacitance_sensor = read_range(r, "capacitance_sensor_uF", 1e-6);
  s.capacitance_actuator = read_range(r, "capacitance_actuator_uF", 1e-6);
  if (const auto v = r.number("stroke_min_um", NumberBounds::positive())) s.stroke_min = *v * 1e-6;
  s.stiffness = read_range(r, "stiffness_N_per_um", 1e6);
  s.outliers.threshold = r.number("outlier_threshold", NumberBounds::positive()).value_or(s.outliers.threshold);
  s.outliers.min_relative_deviation =
      r.number("outlier_min_relative_deviation", NumberBounds::non_negative()).value_or(s.outliers.min_relative_deviation);
  if (const auto b = r.boolean("reject_outliers")) s.reject_outliers = *b;
}

// fmax_Hz (read) must lie above fmin_Hz.
void check_band(const TomlReader& r, const std::string& fmin_key, double fmin_Hz, const std::string& fmax_key, double fmax_Hz) {
  if (fmax_Hz <= fmin_Hz) r.fail(fmax_key, "a frequency above " + fmin_key + " = " + format_number(fmin_Hz) + " Hz", format_number_exact(fmax_Hz));
}

// iff_controller = {gain, hpf_Hz, lpf_Hz, robust_Hz}.
void read_controller(const TomlReader& c, control::IffControllerParams& p) {
  c.only({"gain", "hpf_Hz", "lpf_Hz", "robust_Hz"});
  if (const auto g = c.number("gain")) {
    if (*g == 0.0) c.fail("gain", "a non-zero gain", "0");
    p.gain = *g;
  }
  p.w_hpf = kTwoPi * c.number("hpf_Hz", NumberBounds::positive()).value_or(p.w_hpf / kTwoPi);
  p.w_lpf = kTwoPi * c.number("lpf_Hz", NumberBounds::positive()).value_or(p.w_lpf / kTwoPi);
  p.w_robust = kTwoPi * c.number("robust_Hz", NumberBounds::positive()).value_or(p.w_robust / kTwoPi);
}

void read_analysis(const TomlReader& r, AnalysisSettings& a) {
  r.only({"window", "nfft", "overlap", "fmin_Hz", "fmax_Hz", "hpf_fmax_Hz", "damped_fmin_Hz", "damped_fmax_Hz",
          "hammer_fmin_Hz", "hammer_fmax_Hz", "fit_order", "window_resolution", "iff_unit", "iff_controller", "threads"});
  if (const auto w = r.string("window")) {
    try {
      a.window = dsp::window_type_from_string(*w);
    } catch (const InputError&) {
      r.fail("window", "a window name (hann-periodic, hamming-periodic, ...)", "'" + *w + "'");
    }
  }
  if (const auto n = r.integer("nfft", 0, 1L << 30)) {
    if (*n != 0 && *n < 16) r.fail("nfft", "0 (automatic) or at least 16 samples", std::to_string(*n));
    a.nfft = *n;
  }
  a.overlap = r.number("overlap", NumberBounds::half_open(0.0, 1.0)).value_or(a.overlap);
  const auto band = [&](const char* lo, double& fmin_Hz, const char* hi, double& fmax_Hz) {
    fmin_Hz = r.number(lo, NumberBounds::positive()).value_or(fmin_Hz);
    fmax_Hz = r.number(hi, NumberBounds::positive()).value_or(fmax_Hz);
  };
  band("fmin_Hz", a.fmin_Hz, "fmax_Hz", a.fmax_Hz);
  check_band(r, "fmin_Hz", a.fmin_Hz, "fmax_Hz", a.fmax_Hz);
  a.hpf_fmax_Hz = r.number("hpf_fmax_Hz", NumberBounds::positive()).value_or(a.hpf_fmax_Hz);
  band("damped_fmin_Hz", a.damped_fmin_Hz, "damped_fmax_Hz", a.damped_fmax_Hz);
  check_band(r, "damped_fmin_Hz", a.damped_fmin_Hz, "damped_fmax_Hz", a.damped_fmax_Hz);
  band("hammer_fmin_Hz", a.hammer_fmin_Hz, "hammer_fmax_Hz", a.hammer_fmax_Hz);
  check_band(r, "hammer_fmin_Hz", a.hammer_fmin_Hz, "hammer_fmax_Hz", a.hammer_fmax_Hz);
  if (const auto n = r.integer("fit_order", 2, 40)) a.fit_order = *n;
  if (const auto b = r.boolean("window_resolution")) a.window_resolution = *b;
  // A unit id (ids are 0 .. 1000000) or 0 = the first unit with IFF data.
  if (const auto n = r.integer("iff_unit", 0, 1000000)) a.iff_unit = static_cast<int>(*n);
  if (const auto c = r.table("iff_controller")) read_controller(*c, a.controller);
  if (const auto n = r.integer("threads", 0, 256)) a.threads = static_cast<int>(*n);  // 0: all cores
}

// The super element's actuator, output, sensor, masses and damping (fem's own syntax).
void read_superelement_ports(const TomlReader& r, CampaignSuperElement& c) {
  fem::SuperElementSetup& s = c.setup;
  const std::string act = r.required_string("actuator", "the actuator force pair \"A:B:DIR\"");
  const std::string out = r.required_string("output", "the displacement output \"NODE:DIR\"");
  const std::string sen = r.required_string("sensor", "the sensor stack \"A:B:DIR\"");
  try {
    s.model.forces = {fem::ForcePair::parse(act, r.key("actuator"))};
    s.model.outputs = {fem::DisplacementOutput::parse(out, r.key("output")), fem::DisplacementOutput::parse(sen, r.key("sensor"))};
    const std::vector<std::string> masses = r.strings("masses");
    for (std::size_t k = 0; k < masses.size(); ++k) {
      const std::string field = r.key("masses[" + std::to_string(k) + "]");
      s.model.masses.push_back(fem::PointMass::parse(masses[k], field));
      s.mass_fields.push_back(field);
    }
    const std::string damping = r.string("damping").value_or("modal:0.02");
    const fem::Damping d = fem::Damping::parse(damping, r.key("damping"));
    if (d.kind != fem::DampingKind::kModal || !(d.zeta > 0.0 && d.zeta < 1.0)) r.fail("damping", "modal:ZETA with 0 < ZETA < 1", "'" + damping + "'");
    c.modal_damping = d.zeta;
  } catch (const InputError& e) {
    throw e.with_source(r.where());
  }
  if (s.model.outputs[0].node_a >= 0) r.fail("output", "one node NODE:DIR (the moving interface)", "a node pair");
  if (s.model.outputs[1].node_a < 0) r.fail("sensor", "a node pair A:B:DIR", "one node");
  if (s.model.forces[0].node_a < 0) r.fail("actuator", "a force pair A:B:DIR", "one node");
  s.force_fields = {r.key("actuator")};
  s.output_fields = {r.key("output"), r.key("sensor")};
}

CampaignSuperElement read_superelement(const Context& ctx, const TomlReader& r) {
  r.only({"format", "k_file", "m_file", "nodes_file", "coordinates_file", "fix", "actuator", "output", "sensor", "masses", "damping", "stack_modulus_Pa"});
  CampaignSuperElement c;
  fem::SuperElementSetup& s = c.setup;
  s.source = r.file();
  s.format = r.string("format").value_or("auto");
  if (s.format != "auto" && !fem::super_element_format_from_string(s.format)) {
    r.fail("format", "auto, ansys, calculix or matrix-market", "'" + s.format + "'");
  }
  const auto file = [&](const char* k) { return resolve(ctx, r, k, r.required_string(k, "a file of the super element")); };
  c.given = r.required_string("k_file", "a file of the super element");
  s.k_file = file("k_file");
  s.m_file = file("m_file");
  s.nodes_file = file("nodes_file");
  if (const auto given = r.string("coordinates_file")) s.coordinates_file = resolve(ctx, r, "coordinates_file", *given);
  s.fix_field = r.key("fix");
  for (const std::int64_t n : r.integers("fix", 0, std::numeric_limits<long>::max()).value_or(std::vector<std::int64_t>{})) {
    s.model.fixed_nodes.push_back(static_cast<long>(n));
  }
  read_superelement_ports(r, c);
  if (const auto e = r.number("stack_modulus_Pa", NumberBounds::open(0.0, 1e13))) c.stack_modulus = *e;
  return c;
}

}  // namespace

Campaign parse_campaign(const std::string& text, const fs::path& file, bool check_files) {
  const std::string source = file.string();
  const toml::table root = io::parse_toml(text, source);
  Campaign c;
  c.file = file;
  c.folder = file.has_parent_path() ? file.parent_path() : fs::path(".");
  const TomlReader r(root, source);
  r.only({"title", "bench", "specs", "analysis", "channels", "units", "superelement"});
  c.title = r.string("title").value_or("APA characterization campaign");
  if (const auto t = r.table("bench")) read_bench(*t, c.bench);
  if (const auto t = r.table("specs")) read_specs(*t, c.specs);
  if (const auto t = r.table("analysis")) read_analysis(*t, c.analysis);
  if (const auto t = r.table("channels")) c.channels = read_channels(*t, all_roles());
  const Context ctx{c.folder, check_files, c.channels};
  if (!r.has("units")) r.fail("units", "at least one [[units]] entry", "none");
  const std::vector<TomlReader> units = r.tables("units");
  if (units.empty()) r.fail("units", "an array of [[units]] tables", "an array of 0");
  std::map<int, std::string> seen;
  for (const TomlReader& t : units) {
    UnitSpec u = read_unit(ctx, t);
    if (const auto it = seen.find(u.id); it != seen.end()) {
      t.fail("id", fmt::format("a unit id not listed before ({} has id {})", it->second, u.id), fmt::format("unit {} listed twice", u.id));
    }
    seen[u.id] = u.key;
    c.units.push_back(std::move(u));
  }
  if (c.analysis.iff_unit != 0 && seen.count(c.analysis.iff_unit) == 0) {
    const TomlReader analysis = r.required_table("analysis");
    analysis.fail("iff_unit", "the id of a listed unit", std::to_string(c.analysis.iff_unit));
  }
  if (const auto t = r.table("superelement")) c.superelement = read_superelement(ctx, *t);
  return c;
}

Campaign read_campaign(const fs::path& file) {
  return parse_campaign(io::read_toml_text(file), file, true);
}

}  // namespace piezobench::campaign
