#include "piezobench/campaign/campaign_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <toml++/toml.h>

#include "piezobench/io/toml_table.hpp"
#include "piezobench/io/units.hpp"
#include "piezobench/core/checked_number.hpp"
#include "piezobench/core/error.hpp"
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

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) out += (i ? ", " : "") + items[i];
  return out;
}

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

// Reads one TOML table; every error names the campaign file and the full key.
class Reader {
 public:
  Reader(const toml::table& table, std::string source, std::string prefix)
      : table_(table), source_(std::move(source)), prefix_(std::move(prefix)) {}

  [[nodiscard]] std::string key(const std::string& k) const { return prefix_.empty() ? k : prefix_ + "." + k; }
  [[nodiscard]] const std::string& source() const { return source_; }
  [[nodiscard]] const toml::node* get(const std::string& k) const { return table_.get(k); }

  // Unknown keys are errors.
  void only(const std::vector<std::string>& known) const {
    for (const auto& [k, node] : table_) {
      const std::string name(k.str());
      if (std::find(known.begin(), known.end(), name) == known.end()) {
        throw InputError(source_, key(name), "one of " + join(known), "an unknown key");
      }
    }
  }

  [[nodiscard]] double number(const std::string& k, const toml::node& node) const {
    const auto v = io::toml_number(node);
    if (!v) throw InputError(source_, key(k), "a number", describe_toml(node));
    if (!std::isfinite(*v)) throw InputError(source_, key(k), "a finite number", fmt::format("{}", *v));
    return *v;
  }
  [[nodiscard]] std::optional<double> number(const std::string& k) const {
    const toml::node* n = get(k);
    return n ? std::optional<double>(number(k, *n)) : std::nullopt;
  }
  // A number > 0 (or >= 0).
  void positive(const std::string& k, double& out, bool allow_zero = false) const {
    if (const auto v = number(k)) {
      if (!(*v > 0.0 || (allow_zero && *v == 0.0))) {
        throw InputError(source_, key(k), allow_zero ? "a number >= 0" : "a number > 0", fmt::format("{}", *v));
      }
      out = *v;
    }
  }
  // An integer in [lo, hi]: a float (even 92233720368547758e07) is refused before any conversion,
  // an integer outside is refused, not clamped (core/checked_number.hpp).
  [[nodiscard]] std::optional<long> integer(const std::string& k, long lo, long hi) const {
    const toml::node* n = get(k);
    if (!n) return std::nullopt;
    if (!n->is_integer()) throw InputError(source_, key(k), "an integer", describe_toml(*n));
    return static_cast<long>(checked_integer(n->as_integer()->get(), lo, hi, NumberOrigin::file(source_, key(k))));
  }
  [[nodiscard]] std::string string(const std::string& k, const toml::node& node) const {
    const auto v = node.value<std::string>();
    if (!node.is_string() || !v) throw InputError(source_, key(k), "a string", describe_toml(node));
    return *v;
  }
  [[nodiscard]] std::optional<std::string> string(const std::string& k) const {
    const toml::node* n = get(k);
    return n ? std::optional<std::string>(string(k, *n)) : std::nullopt;
  }
  [[nodiscard]] std::optional<bool> boolean(const std::string& k) const {
    const toml::node* n = get(k);
    if (!n) return std::nullopt;
    const auto v = n->value<bool>();
    if (!n->is_boolean() || !v) throw InputError(source_, key(k), "true or false", describe_toml(*n));
    return *v;
  }
  [[nodiscard]] const toml::table* table(const std::string& k) const {
    const toml::node* n = get(k);
    if (!n) return nullptr;
    if (!n->is_table()) throw InputError(source_, key(k), "a table", describe_toml(*n));
    return n->as_table();
  }
  // [min, max] scaled by `scale`.
  [[nodiscard]] std::optional<metrology::Range> range(const std::string& k, double scale) const {
    const toml::node* n = get(k);
    if (!n) return std::nullopt;
    const toml::array* a = n->as_array();
    if (!a || a->size() != 2) throw InputError(source_, key(k), "[min, max]", describe_toml(*n));
    metrology::Range r{number(k + "[0]", (*a)[0]) * scale, number(k + "[1]", (*a)[1]) * scale};
    if (!(r.min <= r.max)) throw InputError(source_, key(k), "[min, max] with min <= max", fmt::format("[{}, {}]", r.min / scale, r.max / scale));
    return r;
  }
  [[nodiscard]] std::vector<std::string> strings(const std::string& k) const {
    std::vector<std::string> out;
    const toml::node* n = get(k);
    if (!n) return out;
    const toml::array* a = n->as_array();
    if (!a) throw InputError(source_, key(k), "an array of strings", describe_toml(*n));
    for (std::size_t i = 0; i < a->size(); ++i) out.push_back(string(k + "[" + std::to_string(i) + "]", (*a)[i]));
    return out;
  }

 private:
  const toml::table& table_;
  std::string source_;
  std::string prefix_;
};

std::map<std::string, std::string> read_channels(const Reader& r, const toml::table& t, const std::string& k,
                                                 const std::vector<std::string>& allowed) {
  const Reader c(t, r.source(), r.key(k));
  c.only(allowed);
  std::map<std::string, std::string> out;
  for (const auto& [role, node] : t) {
    const std::string name = c.string(std::string(role.str()), node);
    if (name.empty()) throw InputError(r.source(), c.key(std::string(role.str())), "a channel name", "an empty string");
    out[std::string(role.str())] = name;
  }
  return out;
}

struct Context {
  std::string source;
  fs::path folder;
  bool check_files = true;
  std::map<std::string, std::string> channels;  // campaign-wide
};

// `must_exist`: refused here when missing (the super element's files); a unit's measurement file is
// not, so that a missing one leaves that unit out of the batch (not analysed), never the batch.
fs::path resolve(const Context& ctx, const std::string& given, const std::string& key, bool must_exist = true) {
  if (given.empty()) throw InputError(ctx.source, key, "a file name", "an empty string");
  const fs::path p(given);
  const fs::path full = p.is_absolute() ? p : ctx.folder / p;
  if (ctx.check_files && must_exist) {
    std::error_code ec;
    if (!fs::is_regular_file(full, ec)) {
      throw InputError(ctx.source, key, "an existing measurement file",
                       fmt::format("'{}' ({}){}", given, full.string(), fs::exists(full, ec) ? " is not a file" : " does not exist"));
    }
  }
  return full;
}

// A file entry: "path" or {file, channels, sample_rate_Hz, gain}.
FileSpec read_file_spec(const Context& ctx, const Reader& unit, const std::string& k, const toml::node& node,
                        Experiment e, const std::map<std::string, std::string>& unit_channels,
                        const std::vector<std::string>& unit_explicit) {
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
    f.given = *node.value<std::string>();
  } else if (const toml::table* t = node.as_table()) {
    const Reader r(*t, ctx.source, f.key);
    std::vector<std::string> known = {"file", "channels", "units", "sample_rate_Hz"};
    if (e == Experiment::kIff) known.push_back("gain");
    r.only(known);
    const auto file = r.string("file");
    if (!file) throw InputError(ctx.source, r.key("file"), "the measurement file of this entry", "no such key");
    f.given = *file;
    if (const toml::table* c = r.table("channels")) {
      for (const auto& [role, name] : read_channels(r, *c, "channels", roles)) {
        f.channels[role] = name;
        if (std::find(f.explicit_roles.begin(), f.explicit_roles.end(), role) == f.explicit_roles.end()) {
          f.explicit_roles.push_back(role);
        }
      }
    }
    // Units of channels the file does not label, checked against the one unit table.
    if (const toml::table* u = r.table("units")) {
      for (const auto& [role, symbol] : read_channels(r, *u, "units", roles)) {
        f.units[role] = io::unit_from_string(symbol, ctx.source, r.key("units." + role)).symbol;
      }
    }
    r.positive("sample_rate_Hz", f.sample_rate);
    if (e == Experiment::kIff) {
      if (const auto g = r.number("gain")) {
        if (*g < 0.0) throw InputError(ctx.source, r.key("gain"), "a controller gain >= 0", fmt::format("{}", *g));
        f.gain = *g;
      }
    }
  } else {
    throw InputError(ctx.source, f.key, "a file name or a table {file = ..., channels = {...}}", describe_toml(node));
  }
  f.path = resolve(ctx, f.given, f.key + (node.is_table() ? ".file" : ""), /*must_exist=*/false);
  return f;
}

UnitSpec read_unit(const Context& ctx, const toml::table& t, std::size_t index) {
  UnitSpec u;
  u.key = "units[" + std::to_string(index) + "]";
  const Reader r(t, ctx.source, u.key);
  std::vector<std::string> known = {"id", "name", "serial", "channels", "capacitance_uF"};
  for (const Experiment e : all_experiments()) known.push_back(to_string(e));
  r.only(known);
  const auto id = r.integer("id", 0, 1000000);
  if (!id) throw InputError(ctx.source, r.key("id"), "the unit's number (id = 1, 2, ...)", "no such key");
  u.id = static_cast<int>(*id);
  u.name = r.string("name").value_or(fmt::format("APA {}", u.id));
  u.serial = r.string("serial");
  std::map<std::string, std::string> channels;
  std::vector<std::string> explicit_roles;
  if (const toml::table* c = r.table("channels")) {
    channels = read_channels(r, *c, "channels", all_roles());
    for (const auto& [role, name] : channels) explicit_roles.push_back(role);
  }
  for (const auto& [role, name] : ctx.channels) {
    if (std::find(explicit_roles.begin(), explicit_roles.end(), role) == explicit_roles.end()) explicit_roles.push_back(role);
  }
  for (const Experiment e : all_experiments()) {
    const std::string k = to_string(e);
    const toml::node* n = r.get(k);
    if (!n) continue;
    if (e == Experiment::kHysteresis || e == Experiment::kIff) {
      std::vector<FileSpec>& list = e == Experiment::kIff ? u.iff : u.hysteresis;
      if (const toml::array* a = n->as_array()) {
        for (std::size_t i = 0; i < a->size(); ++i) {
          list.push_back(read_file_spec(ctx, r, k + "[" + std::to_string(i) + "]", (*a)[i], e, channels, explicit_roles));
        }
      } else {
        list.push_back(read_file_spec(ctx, r, k, *n, e, channels, explicit_roles));
      }
      continue;
    }
    FileSpec f = read_file_spec(ctx, r, k, *n, e, channels, explicit_roles);
    switch (e) {
      case Experiment::kFlatness: u.flatness = f; break;
      case Experiment::kCapacitance: u.capacitance = f; break;
      case Experiment::kStroke: u.stroke = f; break;
      case Experiment::kStiffness: u.stiffness = f; break;
      case Experiment::kStiffnessOpen: u.stiffness_open = f; break;
      case Experiment::kFrf: u.frf = f; break;
      case Experiment::kFrfNoResistor: u.frf_no_resistor = f; break;
      case Experiment::kHammer: u.hammer = f; break;
      case Experiment::kTracking: u.tracking = f; break;
      default: break;
    }
  }
  if (const toml::table* c = r.table("capacitance_uF")) {
    if (u.capacitance) {
      throw InputError(ctx.source, r.key("capacitance_uF"), "either a capacitance file or capacitance_uF", "both");
    }
    const Reader cr(*c, ctx.source, r.key("capacitance_uF"));
    cr.only({"sensor", "actuator"});
    const auto s = cr.number("sensor");
    const auto a = cr.number("actuator");
    if (!s || !a) throw InputError(ctx.source, cr.key(s ? "actuator" : "sensor"), "a value in uF", "no such key");
    if (!(*s > 0.0)) throw InputError(ctx.source, cr.key("sensor"), "a capacitance > 0 uF", fmt::format("{}", *s));
    if (!(*a > 0.0)) throw InputError(ctx.source, cr.key("actuator"), "a capacitance > 0 uF", fmt::format("{}", *a));
    u.capacitance_sensor = *s * 1e-6;
    u.capacitance_actuator = *a * 1e-6;
  }
  return u;
}

// A TOML date or date-time as seconds since the epoch, UTC: a date's first second (`end`: its last),
// a date-time with its offset applied, one without an offset taken as UTC.
long long read_time(const Reader& r, const std::string& k, bool end) {
  const toml::node* n = r.get(k);
  const auto fail = [&](const std::string& found) -> long long {
    throw InputError(r.source(), r.key(k), "a date (2026-11-27) or a date-time (2026-11-27T08:00:00Z)", found);
  };
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
    return fail(describe_toml(*n));
  }
  const auto s = utc_seconds(date.year, date.month, date.day, time.hour, time.minute, time.second);
  if (!s) return fail(fmt::format("{:04}-{:02}-{:02}", date.year, date.month, date.day));
  return *s - offset_s;
}

void read_bench(const Reader& r, BenchConstants& b) {
  r.only({"amplifier_gain", "suspended_mass_kg", "added_mass_kg", "gravity_m_per_s2", "hpf_resistance_ohm", "probe_accuracy_um",
          "name", "recorded_from", "recorded_until"});
  if (const auto name = r.string("name")) {
    if (name->empty()) throw InputError(r.source(), r.key("name"), "the name of the bench (what its records say in settings.bench)", "''");
    b.name = *name;
  }
  if (r.get("recorded_from")) b.recorded_from_s = read_time(r, "recorded_from", false);
  if (r.get("recorded_until")) b.recorded_until_s = read_time(r, "recorded_until", true);
  if (b.recorded_from_s && b.recorded_until_s && *b.recorded_from_s > *b.recorded_until_s) {
    throw InputError(r.source(), r.key("recorded_until"), "a time not before recorded_from (" + utc_timestamp(*b.recorded_from_s) + ")",
                     utc_timestamp(*b.recorded_until_s));
  }
  if (const auto g = r.number("amplifier_gain")) {
    if (*g == 0.0) throw InputError(r.source(), r.key("amplifier_gain"), "a non-zero gain (V/V)", "0");
    b.amplifier_gain = *g;
  }
  r.positive("suspended_mass_kg", b.suspended_mass);
  r.positive("added_mass_kg", b.added_mass);
  r.positive("gravity_m_per_s2", b.gravity);
  double resistance = 0.0;
  r.positive("hpf_resistance_ohm", resistance, true);
  if (resistance > 0.0) b.hpf_resistance = resistance;
  double probe_um = b.probe_accuracy * 1e6;
  r.positive("probe_accuracy_um", probe_um, true);
  b.probe_accuracy = probe_um * 1e-6;
}

void read_specs(const Reader& r, Specs& s) {
  r.only({"flatness_um", "flatness_method", "capacitance_sensor_uF", "capacitance_actuator_uF", "stroke_min_um",
          "stiffness_N_per_um", "outlier_threshold", "outlier_min_relative_deviation", "reject_outliers"});
  if (const auto f = r.number("flatness_um")) {
    if (!(*f > 0.0)) throw InputError(r.source(), r.key("flatness_um"), "a flatness limit > 0 um", fmt::format("{}", *f));
    s.flatness_max = *f * 1e-6;
  }
  if (const auto m = r.string("flatness_method")) {
    try {
      s.flatness_method = metrology::flatness_method_from_string(*m, r.source());
    } catch (const InputError&) {
      throw InputError(r.source(), r.key("flatness_method"), "least-squares or minimum-zone", "'" + *m + "'");
    }
  }
  s.capacitance_sensor = r.range("capacitance_sensor_uF", 1e-6);
  s.capacitance_actuator = r.range("capacitance_actuator_uF", 1e-6);
  if (const auto v = r.number("stroke_min_um")) {
    if (!(*v > 0.0)) throw InputError(r.source(), r.key("stroke_min_um"), "a stroke > 0 um", fmt::format("{}", *v));
    s.stroke_min = *v * 1e-6;
  }
  s.stiffness = r.range("stiffness_N_per_um", 1e6);
  r.positive("outlier_threshold", s.outliers.threshold);
  r.positive("outlier_min_relative_deviation", s.outliers.min_relative_deviation, true);
  if (const auto b = r.boolean("reject_outliers")) s.reject_outliers = *b;
}

void read_analysis(const Reader& r, AnalysisSettings& a) {
  r.only({"window", "nfft", "overlap", "fmin_Hz", "fmax_Hz", "hpf_fmax_Hz", "damped_fmin_Hz", "damped_fmax_Hz",
          "hammer_fmin_Hz", "hammer_fmax_Hz", "fit_order", "iff_unit", "iff_controller", "threads"});
  if (const auto w = r.string("window")) {
    try {
      a.window = dsp::window_type_from_string(*w);
    } catch (const InputError& e) {
      throw InputError(r.source(), r.key("window"), "a window name (hann-periodic, hamming-periodic, ...)", "'" + *w + "'");
    }
  }
  if (const auto n = r.integer("nfft", 0, 1L << 30)) {
    if (*n != 0 && *n < 16) throw InputError(r.source(), r.key("nfft"), "0 (automatic) or at least 16 samples", std::to_string(*n));
    a.nfft = *n;
  }
  if (const auto o = r.number("overlap")) {
    if (!(*o >= 0.0 && *o < 1.0)) throw InputError(r.source(), r.key("overlap"), "a fraction in [0, 1)", fmt::format("{}", *o));
    a.overlap = *o;
  }
  r.positive("fmin_Hz", a.fmin_Hz);
  r.positive("fmax_Hz", a.fmax_Hz);
  if (a.fmax_Hz <= a.fmin_Hz) throw InputError(r.source(), r.key("fmax_Hz"), fmt::format("a frequency above fmin_Hz = {} Hz", a.fmin_Hz), fmt::format("{}", a.fmax_Hz));
  r.positive("hpf_fmax_Hz", a.hpf_fmax_Hz);
  r.positive("damped_fmin_Hz", a.damped_fmin_Hz);
  r.positive("damped_fmax_Hz", a.damped_fmax_Hz);
  if (a.damped_fmax_Hz <= a.damped_fmin_Hz) throw InputError(r.source(), r.key("damped_fmax_Hz"), "a frequency above damped_fmin_Hz", fmt::format("{}", a.damped_fmax_Hz));
  r.positive("hammer_fmin_Hz", a.hammer_fmin_Hz);
  r.positive("hammer_fmax_Hz", a.hammer_fmax_Hz);
  if (a.hammer_fmax_Hz <= a.hammer_fmin_Hz) throw InputError(r.source(), r.key("hammer_fmax_Hz"), "a frequency above hammer_fmin_Hz", fmt::format("{}", a.hammer_fmax_Hz));
  if (const auto n = r.integer("fit_order", 2, 40)) a.fit_order = *n;
  // A unit id (ids are 0 .. 1000000) or 0 = the first unit with IFF data.
  if (const auto n = r.integer("iff_unit", 0, 1000000)) a.iff_unit = static_cast<int>(*n);
  if (const toml::table* c = r.table("iff_controller")) {
    const Reader cr(*c, r.source(), r.key("iff_controller"));
    cr.only({"gain", "hpf_Hz", "lpf_Hz", "robust_Hz"});
    if (const auto g = cr.number("gain")) {
      if (*g == 0.0) throw InputError(r.source(), cr.key("gain"), "a non-zero gain", "0");
      a.controller.gain = *g;
    }
    double hz = a.controller.w_hpf / (kTwoPi);
    cr.positive("hpf_Hz", hz);
    a.controller.w_hpf = kTwoPi * hz;
    hz = a.controller.w_lpf / (kTwoPi);
    cr.positive("lpf_Hz", hz);
    a.controller.w_lpf = kTwoPi * hz;
    hz = a.controller.w_robust / (kTwoPi);
    cr.positive("robust_Hz", hz);
    a.controller.w_robust = kTwoPi * hz;
  }
  if (const auto n = r.integer("threads", 0, 256)) a.threads = static_cast<int>(*n);  // 0: all cores
}

CampaignSuperElement read_superelement(const Context& ctx, const Reader& r) {
  r.only({"format", "k_file", "m_file", "nodes_file", "coordinates_file", "fix", "actuator", "output", "sensor", "masses", "damping", "stack_modulus_Pa"});
  CampaignSuperElement c;
  fem::SuperElementSetup& s = c.setup;
  s.source = ctx.source;
  s.format = r.string("format").value_or("auto");
  if (s.format != "auto" && !fem::super_element_format_from_string(s.format)) {
    throw InputError(ctx.source, r.key("format"), "auto, ansys, calculix or matrix-market", "'" + s.format + "'");
  }
  auto file = [&](const char* k, bool required) -> std::optional<fs::path> {
    const auto given = r.string(k);
    if (!given) {
      if (required) throw InputError(ctx.source, r.key(k), "a file of the super element", "no such key");
      return std::nullopt;
    }
    if (std::string(k) == "k_file") c.given = *given;
    return resolve(ctx, *given, r.key(k));
  };
  s.k_file = *file("k_file", true);
  s.m_file = *file("m_file", true);
  s.nodes_file = *file("nodes_file", true);
  s.coordinates_file = file("coordinates_file", false).value_or(fs::path());
  s.fix_field = r.key("fix");
  if (const toml::node* n = r.get("fix")) {
    const toml::array* a = n->as_array();
    if (!a) throw InputError(ctx.source, r.key("fix"), "an array of node numbers", describe_toml(*n));
    for (std::size_t i = 0; i < a->size(); ++i) {
      const std::string field = r.key("fix") + "[" + std::to_string(i) + "]";
      if (!(*a)[i].is_integer()) throw InputError(ctx.source, field, "a node number", describe_toml((*a)[i]));
      s.model.fixed_nodes.push_back(static_cast<long>(
          checked_integer((*a)[i].as_integer()->get(), 0, std::numeric_limits<long>::max(), NumberOrigin::file(ctx.source, field))));
    }
  }
  const auto act = r.string("actuator");
  const auto out = r.string("output");
  const auto sen = r.string("sensor");
  if (!act) throw InputError(ctx.source, r.key("actuator"), "the actuator force pair \"A:B:DIR\"", "no such key");
  if (!out) throw InputError(ctx.source, r.key("output"), "the displacement output \"NODE:DIR\"", "no such key");
  if (!sen) throw InputError(ctx.source, r.key("sensor"), "the sensor stack \"A:B:DIR\"", "no such key");
  try {
    s.model.forces = {fem::ForcePair::parse(*act, r.key("actuator"))};
    s.model.outputs = {fem::DisplacementOutput::parse(*out, r.key("output")), fem::DisplacementOutput::parse(*sen, r.key("sensor"))};
    std::size_t k = 0;
    for (const auto& m : r.strings("masses")) {
      s.model.masses.push_back(fem::PointMass::parse(m, r.key("masses") + "[" + std::to_string(k) + "]"));
      s.mass_fields.push_back(r.key("masses") + "[" + std::to_string(k++) + "]");
    }
    const fem::Damping d = fem::Damping::parse(r.string("damping").value_or("modal:0.02"), r.key("damping"));
    if (d.kind != fem::DampingKind::kModal || !(d.zeta > 0.0 && d.zeta < 1.0)) {
      throw InputError("", r.key("damping"), "modal:ZETA with 0 < ZETA < 1", "'" + r.string("damping").value_or("") + "'");
    }
    c.modal_damping = d.zeta;
  } catch (const InputError& e) {
    throw e.with_source(ctx.source);
  }
  if (s.model.outputs[0].node_a >= 0) throw InputError(ctx.source, r.key("output"), "one node NODE:DIR (the moving interface)", "a node pair");
  if (s.model.outputs[1].node_a < 0) throw InputError(ctx.source, r.key("sensor"), "a node pair A:B:DIR", "one node");
  if (s.model.forces[0].node_a < 0) throw InputError(ctx.source, r.key("actuator"), "a force pair A:B:DIR", "one node");
  s.force_fields = {r.key("actuator")};
  s.output_fields = {r.key("output"), r.key("sensor")};
  if (const auto e = r.number("stack_modulus_Pa")) {
    if (!(*e > 0.0 && *e < 1e13)) throw InputError(ctx.source, r.key("stack_modulus_Pa"), "a modulus in (0, 1e13) Pa", fmt::format("{}", *e));
    c.stack_modulus = *e;
  }
  return c;
}

}  // namespace

Campaign parse_campaign(const std::string& text, const fs::path& file, bool check_files) {
  const std::string source = file.string();
  const toml::table root = io::parse_toml(text, source);
  Campaign c;
  c.file = file;
  c.folder = file.has_parent_path() ? file.parent_path() : fs::path(".");
  const Reader r(root, source, "");
  r.only({"title", "bench", "specs", "analysis", "channels", "units", "superelement"});
  c.title = r.string("title").value_or("APA characterization campaign");
  if (const toml::table* t = r.table("bench")) read_bench(Reader(*t, source, "bench"), c.bench);
  if (const toml::table* t = r.table("specs")) read_specs(Reader(*t, source, "specs"), c.specs);
  if (const toml::table* t = r.table("analysis")) read_analysis(Reader(*t, source, "analysis"), c.analysis);
  if (const toml::table* t = r.table("channels")) c.channels = read_channels(r, *t, "channels", all_roles());
  Context ctx{source, c.folder, check_files, c.channels};
  const toml::node* units = r.get("units");
  if (!units) throw InputError(source, "units", "at least one [[units]] entry", "none");
  const toml::array* list = units->as_array();
  if (!list || list->empty()) throw InputError(source, "units", "an array of [[units]] tables", describe_toml(*units));
  std::map<int, std::string> seen;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const toml::table* t = (*list)[i].as_table();
    if (!t) throw InputError(source, "units[" + std::to_string(i) + "]", "a table", describe_toml((*list)[i]));
    UnitSpec u = read_unit(ctx, *t, i);
    if (const auto it = seen.find(u.id); it != seen.end()) {
      throw InputError(source, u.key + ".id", fmt::format("a unit id not listed before ({} has id {})", it->second, u.id),
                       fmt::format("unit {} listed twice", u.id));
    }
    seen[u.id] = u.key;
    c.units.push_back(std::move(u));
  }
  if (c.analysis.iff_unit != 0 && seen.count(c.analysis.iff_unit) == 0) {
    throw InputError(source, "analysis.iff_unit", "the id of a listed unit", std::to_string(c.analysis.iff_unit));
  }
  if (const toml::table* t = r.table("superelement")) c.superelement = read_superelement(ctx, Reader(*t, source, "superelement"));
  return c;
}

Campaign read_campaign(const fs::path& file) {
  return parse_campaign(io::read_toml_text(file), file, true);
}

}  // namespace piezobench::campaign
