#include "piezobench/rt/bench_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <toml++/toml.h>
#include <vector>

#include "piezobench/core/checked_number.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/io/toml_table.hpp"
#include "piezobench/rt/udp.hpp"

namespace piezobench::rt {

namespace {

using io::describe_toml;

// One table of the bench file; every error names the file and the full key.
class Table {
 public:
  Table(const toml::table* table, std::string source, std::string prefix)
      : table_(table), source_(std::move(source)), prefix_(std::move(prefix)) {}

  [[nodiscard]] bool present() const { return table_ != nullptr; }
  [[nodiscard]] std::string key(const std::string& k) const { return prefix_.empty() ? k : prefix_ + "." + k; }
  [[nodiscard]] const toml::node* get(const std::string& k) const { return table_ ? table_->get(k) : nullptr; }

  void only(const std::vector<std::string>& known) const {
    if (!table_) return;
    for (const auto& [k, node] : *table_) {
      const std::string name(k.str());
      if (std::find(known.begin(), known.end(), name) == known.end()) {
        std::string list;
        for (const auto& s : known) list += (list.empty() ? "" : ", ") + s;
        throw InputError(source_, key(name), "one of " + list, "an unknown key");
      }
    }
  }
  [[nodiscard]] Table table(const std::string& k) const {
    const toml::node* n = get(k);
    if (n && !n->is_table()) throw InputError(source_, key(k), "a table", describe_toml(*n));
    return {n ? n->as_table() : nullptr, source_, key(k)};
  }
  [[nodiscard]] std::optional<double> number(const std::string& k) const {
    const toml::node* n = get(k);
    if (!n) return std::nullopt;
    const auto v = io::toml_number(*n);
    if (!v) throw InputError(source_, key(k), "a number", describe_toml(*n));
    if (!std::isfinite(*v)) throw InputError(source_, key(k), "a finite number", fmt::format("{}", *v));
    return *v;
  }
  [[nodiscard]] double required_number(const std::string& k, const std::string& why) const {
    const auto v = number(k);
    if (!v) throw InputError(source_, key(k), "a number (" + why + ")", "nothing");
    return *v;
  }
  // An integer in [lo, hi] (a float is refused before any conversion; core/checked_number.hpp).
  [[nodiscard]] std::optional<std::int64_t> integer(const std::string& k, std::int64_t lo, std::int64_t hi) const {
    const toml::node* n = get(k);
    if (!n) return std::nullopt;
    if (!n->is_integer()) throw InputError(source_, key(k), "an integer", describe_toml(*n));
    return checked_integer(n->as_integer()->get(), lo, hi, NumberOrigin::file(source_, key(k)));
  }
  // A time in seconds in [min_s, max_s].
  [[nodiscard]] std::optional<double> duration(const std::string& k, double min_s, double max_s) const {
    const auto v = number(k);
    if (!v) return std::nullopt;
    return checked_duration_s(*v, min_s, max_s, NumberOrigin::file(source_, key(k)));
  }
  [[nodiscard]] std::optional<std::string> string(const std::string& k) const {
    const toml::node* n = get(k);
    if (!n) return std::nullopt;
    const auto v = n->value<std::string>();
    if (!n->is_string() || !v) throw InputError(source_, key(k), "a string", describe_toml(*n));
    return *v;
  }
  [[nodiscard]] std::optional<std::pair<double, double>> range(const std::string& k) const {
    const toml::node* n = get(k);
    if (!n) return std::nullopt;
    const toml::array* a = n->as_array();
    if (!a || a->size() != 2 || !(*a)[0].is_number() || !(*a)[1].is_number()) {
      throw InputError(source_, key(k), "[lo, hi] in volts", describe_toml(*n));
    }
    return std::pair{*(*a)[0].value<double>(), *(*a)[1].value<double>()};
  }

 private:
  const toml::table* table_;
  std::string source_;
  std::string prefix_;
};

SignalChannel read_signal(const Table& t, const std::string& default_device) {
  t.only({"device", "subdevice", "channel", "range", "scale", "unit", "kind", "aref"});
  SignalChannel s;
  s.device = t.string("device").value_or(default_device);
  s.subdevice = static_cast<int>(t.integer("subdevice", 0, 255).value_or(-1));
  s.channel = static_cast<int>(t.integer("channel", 0, 65535).value_or(-1));
  if (const auto r = t.range("range")) {
    s.range_min = r->first;
    s.range_max = r->second;
  }
  s.scale = t.number("scale").value_or(0.0);
  s.unit = t.string("unit").value_or("");
  s.kind = t.string("kind").value_or("analog");
  s.aref = t.string("aref").value_or("ground");
  return s;
}

void check_signal(const SignalChannel& s, const std::string& name, const std::string& unit, const std::string& source,
                  bool counter_allowed) {
  const std::string k = "signals." + name;
  if (s.subdevice < 0) throw InputError(source, k + ".subdevice", "a subdevice number >= 0", "nothing or a negative number");
  if (s.channel < 0) throw InputError(source, k + ".channel", "a channel number >= 0", "nothing or a negative number");
  if (s.kind != "analog" && !(counter_allowed && s.kind == "counter")) {
    throw InputError(source, k + ".kind", counter_allowed ? "\"analog\" or \"counter\"" : "\"analog\"", "'" + s.kind + "'");
  }
  if (s.kind == "analog" && !(s.range_min < s.range_max)) {
    throw InputError(source, k + ".range", "[lo, hi] with lo < hi (V at the converter)",
                     fmt::format("[{:g}, {:g}]", s.range_min, s.range_max));
  }
  if (!(std::isfinite(s.scale) && s.scale != 0.0)) {
    throw InputError(source, k + ".scale", "a finite non-zero number", fmt::format("{:g}", s.scale));
  }
  if (s.unit != unit) throw InputError(source, k + ".unit", "\"" + unit + "\"", "'" + s.unit + "'");
  if (s.aref != "ground" && s.aref != "common" && s.aref != "diff") {
    throw InputError(source, k + ".aref", "\"ground\", \"common\" or \"diff\"", "'" + s.aref + "'");
  }
}

}  // namespace

void BenchDescription::validate() const {
  if (backend != "virtual" && backend != "udp" && backend != "comedi") {
    throw InputError(source, "bench.backend", "\"virtual\", \"udp\" or \"comedi\"", "'" + backend + "'");
  }
  if (!(std::isfinite(sample_rate) && sample_rate > 0.0 && sample_rate <= 1e6)) {
    throw InputError(source, "bench.sample_rate_Hz", "a rate in (0, 1e6] Hz", fmt::format("{:g}", sample_rate));
  }
  try {
    limits.validate();
  } catch (const InputError& e) {
    throw e.with_source(source);
  }
  check_plausible(limits, source);
  if (!(std::isfinite(encoder_resolution) && encoder_resolution > 0.0)) {
    throw InputError(source, "encoder.resolution_m", "a resolution > 0 m", fmt::format("{:g}", encoder_resolution));
  }
  if (backend == "virtual" && (unit < 1 || unit > 7)) {
    throw InputError(source, "virtual.unit", "a unit of the batch, 1 to 7", std::to_string(unit));
  }
  if (backend == "udp") {
    if (udp_address.empty()) throw InputError(source, "udp.address", "\"HOST:PORT\" of the I/O target", "nothing");
    if (!(std::isfinite(udp_timeout) && udp_timeout > 0.0 && udp_timeout <= 1.0)) {
      throw InputError(source, "udp.timeout_s", "a timeout in (0, 1] s", fmt::format("{:g}", udp_timeout));
    }
  }
  if (backend != "comedi") return;
  if (calibration != "auto" && calibration != "soft" && calibration != "hard" && calibration != "none") {
    throw InputError(source, "comedi.calibration", "\"auto\", \"soft\", \"hard\" or \"none\"", "'" + calibration + "'");
  }
  check_signal(u, "u", "V", source, false);
  check_signal(de, "d_e", "m", source, true);
  check_signal(vs, "Vs", "V", source, false);
  if (va) check_signal(*va, "Va", "V", source, false);
  // u -> Va must increase: the limits [va_min, va_max] are mapped to the DAC through it.
  if (u.scale < 0.0) {
    throw InputError(source, "signals.u.scale",
                     "a positive scale (converter volts per volt of u: Va = amplifier gain x u must rise with u, the "
                     "limits are mapped to the DAC through it)",
                     fmt::format("{:g}", u.scale));
  }
  const double lo = limits.u_min() * u.scale, hi = limits.u_max() * u.scale;
  if (lo < u.range_min - 1e-12 || hi > u.range_max + 1e-12) {
    throw InputError(source, "signals.u.range",
                     fmt::format("a DAC range that covers the limits: {:g} .. {:g} V at the stacks need {:g} .. {:g} V "
                                 "at the DAC (gain {:g} V/V, scale {:g})",
                                 limits.va_min, limits.va_max, lo, hi, limits.amplifier_gain, u.scale),
                     fmt::format("[{:g}, {:g}]", u.range_min, u.range_max));
  }
}

BenchDescription parse_bench_description(const std::string& text, const std::string& source) {
  const toml::table root = io::parse_toml(text, source);
  const Table top(&root, source, "");
  top.only({"bench", "amplifier", "limits", "encoder", "virtual", "udp", "comedi", "signals"});
  BenchDescription d;
  d.source = source;
  const Table bench = top.table("bench");
  if (!bench.present()) throw InputError(source, "bench", "a [bench] table with backend and sample_rate_Hz", "nothing");
  bench.only({"name", "backend", "sample_rate_Hz"});
  d.name = bench.string("name").value_or("");
  d.backend = bench.string("backend").value_or("");
  if (d.backend != "virtual" && d.backend != "udp" && d.backend != "comedi") {
    throw InputError(source, "bench.backend", "\"virtual\", \"udp\" or \"comedi\"",
                     d.backend.empty() ? std::string("nothing") : "'" + d.backend + "'");
  }
  d.sample_rate = bench.required_number("sample_rate_Hz", "the loop's rate, Hz");
  const bool hardware = d.hardware();
  const std::string why = "a hardware backend never starts without it";

  const Table amp = top.table("amplifier");
  amp.only({"gain_V_per_V"});
  if (hardware) {
    d.limits.amplifier_gain = amp.required_number("gain_V_per_V", "stack volts per DAC volt; " + why);
  } else if (const auto g = amp.number("gain_V_per_V")) {
    d.limits.amplifier_gain = *g;
  }
  if (d.limits.amplifier_gain < 0.0) {
    throw InputError(source, "amplifier.gain_V_per_V",
                     "a positive gain (Va must rise with u: the limits are mapped to the DAC through it)",
                     fmt::format("{:g}", d.limits.amplifier_gain));
  }
  const Table lim = top.table("limits");
  lim.only({"actuator", "va_min_V", "va_max_V", "va_safe_V", "slew_rate_V_per_s", "ramp_s", "stale_cycles", "stale_budget",
            "watchdog_s", "de_range_m", "vs_range_V"});
  if (hardware && !lim.present()) throw InputError(source, "limits", "a [limits] table (" + why + ")", "nothing");
  d.limits.actuator = lim.string("actuator").value_or(d.limits.actuator);
  if (hardware) {
    d.limits.va_min = lim.required_number("va_min_V", why);
    d.limits.va_max = lim.required_number("va_max_V", why);
    d.limits.slew_rate = lim.required_number("slew_rate_V_per_s", why);
  } else {
    d.limits.va_min = lim.number("va_min_V").value_or(d.limits.va_min);
    d.limits.va_max = lim.number("va_max_V").value_or(d.limits.va_max);
    d.limits.slew_rate = lim.number("slew_rate_V_per_s").value_or(d.limits.slew_rate);
  }
  d.limits.va_safe = lim.number("va_safe_V").value_or(d.limits.va_safe);
  if (const auto r = lim.duration("ramp_s", 0.0, ActuatorLimits::kMaxTime)) d.limits.ramp_in = d.limits.ramp_out = *r;
  if (const auto s = lim.integer("stale_cycles", 0, ActuatorLimits::kMaxStaleCycles)) d.limits.stale_cycles = static_cast<int>(*s);
  d.limits.stale_budget = lim.number("stale_budget").value_or(d.limits.stale_budget);
  d.limits.watchdog_timeout = lim.duration("watchdog_s", 1e-6, ActuatorLimits::kMaxTime).value_or(d.limits.watchdog_timeout);
  d.limits.de_range = lim.number("de_range_m").value_or(d.limits.de_range);
  d.limits.vs_range = lim.number("vs_range_V").value_or(d.limits.vs_range);

  const Table enc = top.table("encoder");
  enc.only({"resolution_m"});
  d.encoder_resolution = enc.number("resolution_m").value_or(d.encoder_resolution);

  const Table virt = top.table("virtual");
  virt.only({"unit", "seed", "twin"});
  if (const auto twin = virt.string("twin")) {
    if (twin->empty()) throw InputError(source, "virtual.twin", "a twin file", "an empty path");
    d.twin = (std::filesystem::path(source).parent_path() / *twin).string();
  }
  d.unit = static_cast<int>(virt.integer("unit", 1, 7).value_or(1));
  if (const auto s = virt.integer("seed", 0, std::numeric_limits<std::int64_t>::max())) d.seed = static_cast<std::uint64_t>(*s);
  const Table udp = top.table("udp");
  udp.only({"address", "timeout_s", "key_file"});
  d.udp_address = udp.string("address").value_or("");
  if (const auto k = udp.string("key_file")) {
    std::filesystem::path file(*k);
    if (file.is_relative()) file = std::filesystem::path(source).parent_path() / file;
    d.udp_key = read_udp_key(file, source, "udp.key_file");
  }
  d.udp_timeout = udp.number("timeout_s").value_or(d.udp_timeout);

  const Table com = top.table("comedi");
  com.only({"device", "calibration"});
  d.comedi_device = com.string("device").value_or(d.comedi_device);
  d.calibration = com.string("calibration").value_or(d.calibration);

  const Table sig = top.table("signals");
  sig.only({"u", "d_e", "Vs", "Va"});
  if (sig.present() && d.backend != "comedi") {
    throw InputError(source, "signals", "no [signals] for backend " + d.backend + " (they wire a Comedi card)",
                     "a [signals] table");
  }
  if (d.backend == "comedi") {
    for (const char* name : {"u", "d_e", "Vs"}) {
      if (!sig.table(name).present()) {
        throw InputError(source, std::string("signals.") + name, "the signal's channel (subdevice, channel, range, scale, unit)",
                         "nothing (missing channel)");
      }
    }
    d.u = read_signal(sig.table("u"), d.comedi_device);
    d.de = read_signal(sig.table("d_e"), d.comedi_device);
    if (d.de.kind == "counter" && !sig.table("d_e").number("scale")) d.de.scale = d.encoder_resolution;
    d.vs = read_signal(sig.table("Vs"), d.comedi_device);
    if (sig.table("Va").present()) d.va = read_signal(sig.table("Va"), d.comedi_device);
  }
  d.validate();
  return d;
}

BenchDescription read_bench_file(const std::filesystem::path& file) {
  return parse_bench_description(io::read_toml_text(file), file.string());
}

}  // namespace piezobench::rt
