#include "piezobench/rt/bench_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <toml++/toml.h>
#include <vector>

#include "piezobench/core/checked_number.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/io/toml_reader.hpp"
#include "piezobench/io/toml_table.hpp"
#include "piezobench/rt/udp.hpp"

namespace piezobench::rt {

namespace {

using io::TomlReader;

// A time in seconds in [min_s, max_s] (core/checked_number.hpp), absent: nullopt.
std::optional<double> read_duration(const TomlReader& t, const std::string& k, double min_s, double max_s) {
  const auto v = t.number(k);
  if (!v) return std::nullopt;
  return checked_duration_s(*v, min_s, max_s, NumberOrigin::file(t.where(t.get(k)), t.key(k)));
}

SignalChannel read_signal(const TomlReader& t, const std::string& default_device) {
  t.only({"device", "subdevice", "channel", "range", "scale", "unit", "kind", "aref"});
  SignalChannel s;
  s.device = t.string("device").value_or(default_device);
  s.subdevice = static_cast<int>(t.integer("subdevice", 0, 255).value_or(-1));
  s.channel = static_cast<int>(t.integer("channel", 0, 65535).value_or(-1));
  if (const auto r = t.pair("range", "[lo, hi] in volts")) {
    s.range_min = r->first;
    s.range_max = r->second;
  }
  s.scale = t.number("scale").value_or(0.0);
  s.unit = t.string("unit").value_or("");
  s.kind = t.string("kind").value_or("analog");
  s.aref = t.string("aref").value_or("ground");
  return s;
}

std::string interval(double lo, double hi) { return "[" + format_number(lo) + ", " + format_number(hi) + "]"; }

void check_signal(const SignalChannel& s, const std::string& name, const std::string& unit, const std::string& source,
                  bool counter_allowed) {
  const std::string k = "signals." + name;
  if (s.subdevice < 0) throw InputError(source, k + ".subdevice", "a subdevice number >= 0", "nothing or a negative number");
  if (s.channel < 0) throw InputError(source, k + ".channel", "a channel number >= 0", "nothing or a negative number");
  if (s.kind != "analog" && !(counter_allowed && s.kind == "counter")) {
    throw InputError(source, k + ".kind", counter_allowed ? "\"analog\" or \"counter\"" : "\"analog\"", "'" + s.kind + "'");
  }
  if (s.kind == "analog" && !(s.range_min < s.range_max)) {
    throw InputError(source, k + ".range", "[lo, hi] with lo < hi (V at the converter)", interval(s.range_min, s.range_max));
  }
  if (!(std::isfinite(s.scale) && s.scale != 0.0)) {
    throw InputError(source, k + ".scale", "a finite non-zero number", format_number_exact(s.scale));
  }
  if (s.unit != unit) throw InputError(source, k + ".unit", "\"" + unit + "\"", "'" + s.unit + "'");
  if (s.aref != "ground" && s.aref != "common" && s.aref != "diff") {
    throw InputError(source, k + ".aref", "\"ground\", \"common\" or \"diff\"", "'" + s.aref + "'");
  }
}

const char* const kHardwareWhy = "a hardware backend never starts without it";

// [bench]: name, backend, sample_rate_Hz.
void read_bench_table(const TomlReader& top, BenchDescription& d) {
  const TomlReader bench = top.required_table("bench", "a [bench] table with backend and sample_rate_Hz");
  bench.only({"name", "backend", "sample_rate_Hz"});
  d.name = bench.string("name").value_or("");
  const auto backend = bench.choice("backend", {"virtual", "udp", "comedi"});
  if (!backend) bench.fail("backend", "\"virtual\", \"udp\" or \"comedi\"", "nothing");
  d.backend = *backend;
  d.sample_rate = bench.required_number("sample_rate_Hz", {}, "a number (the loop's rate, Hz)");
}

// [amplifier] and [limits]: required for a hardware backend.
void read_limits(const TomlReader& top, BenchDescription& d) {
  const bool hardware = d.hardware();
  const std::string why = kHardwareWhy;
  const TomlReader amp = top.table_or_empty("amplifier");
  amp.only({"gain_V_per_V"});
  if (hardware) {
    d.limits.amplifier_gain = amp.required_number("gain_V_per_V", {}, "a number (stack volts per DAC volt; " + why + ")");
  } else {
    d.limits.amplifier_gain = amp.number("gain_V_per_V").value_or(d.limits.amplifier_gain);
  }
  if (d.limits.amplifier_gain < 0.0) {
    amp.fail("gain_V_per_V", "a positive gain (Va must rise with u: the limits are mapped to the DAC through it)",
             format_number_exact(d.limits.amplifier_gain));
  }
  if (hardware && !top.has("limits")) top.fail("limits", "a [limits] table (" + why + ")", "nothing");
  const TomlReader lim = top.table_or_empty("limits");
  lim.only({"actuator", "va_min_V", "va_max_V", "va_safe_V", "slew_rate_V_per_s", "ramp_s", "stale_cycles", "stale_budget",
            "watchdog_s", "de_range_m", "vs_range_V"});
  ActuatorLimits& l = d.limits;
  l.actuator = lim.string("actuator").value_or(l.actuator);
  const auto value = [&](const char* k, double fallback) {
    return hardware ? lim.required_number(k, {}, "a number (" + why + ")") : lim.number(k).value_or(fallback);
  };
  l.va_min = value("va_min_V", l.va_min);
  l.va_max = value("va_max_V", l.va_max);
  l.slew_rate = value("slew_rate_V_per_s", l.slew_rate);
  l.va_safe = lim.number("va_safe_V").value_or(l.va_safe);
  if (const auto r = read_duration(lim, "ramp_s", 0.0, ActuatorLimits::kMaxTime)) l.ramp_in = l.ramp_out = *r;
  if (const auto s = lim.integer("stale_cycles", 0, ActuatorLimits::kMaxStaleCycles)) l.stale_cycles = static_cast<int>(*s);
  l.stale_budget = lim.number("stale_budget").value_or(l.stale_budget);
  l.watchdog_timeout = read_duration(lim, "watchdog_s", 1e-6, ActuatorLimits::kMaxTime).value_or(l.watchdog_timeout);
  l.de_range = lim.number("de_range_m").value_or(l.de_range);
  l.vs_range = lim.number("vs_range_V").value_or(l.vs_range);
}

// [encoder], [virtual], [udp], [comedi].
void read_backends(const TomlReader& top, BenchDescription& d) {
  const TomlReader enc = top.table_or_empty("encoder");
  enc.only({"resolution_m"});
  d.encoder_resolution = enc.number("resolution_m").value_or(d.encoder_resolution);
  const std::filesystem::path folder = std::filesystem::path(d.source).parent_path();
  const TomlReader virt = top.table_or_empty("virtual");
  virt.only({"unit", "seed", "twin"});
  if (const auto twin = virt.string("twin")) {
    if (twin->empty()) virt.fail("twin", "a twin file", "an empty path");
    d.twin = (folder / *twin).string();
  }
  d.unit = static_cast<int>(virt.integer("unit", 1, 7).value_or(1));
  if (const auto s = virt.integer("seed", 0, std::numeric_limits<std::int64_t>::max())) d.seed = static_cast<std::uint64_t>(*s);
  const TomlReader udp = top.table_or_empty("udp");
  udp.only({"address", "timeout_s", "key_file"});
  d.udp_address = udp.string("address").value_or("");
  if (const auto k = udp.string("key_file")) {
    std::filesystem::path file(*k);
    if (file.is_relative()) file = folder / file;
    d.udp_key = read_udp_key(file, d.source, "udp.key_file");
  }
  d.udp_timeout = udp.number("timeout_s").value_or(d.udp_timeout);
  const TomlReader com = top.table_or_empty("comedi");
  com.only({"device", "calibration"});
  d.comedi_device = com.string("device").value_or(d.comedi_device);
  d.calibration = com.string("calibration").value_or(d.calibration);
}

// [signals.u], [signals.d_e], [signals.Vs], [signals.Va]: a Comedi card's wiring.
void read_signals(const TomlReader& top, BenchDescription& d) {
  if (!top.has("signals")) {
    if (d.backend == "comedi") top.fail("signals.u", "the signal's channel (subdevice, channel, range, scale, unit)", "nothing (missing channel)");
    return;
  }
  const TomlReader sig = top.required_table("signals");
  sig.only({"u", "d_e", "Vs", "Va"});
  if (d.backend != "comedi") sig.fail("", "no [signals] for backend " + d.backend + " (they wire a Comedi card)", "a [signals] table");
  const auto channel = [&](const char* name) {
    const auto t = sig.table(name);
    if (!t) sig.fail(name, "the signal's channel (subdevice, channel, range, scale, unit)", "nothing (missing channel)");
    return read_signal(*t, d.comedi_device);
  };
  d.u = channel("u");
  d.de = channel("d_e");
  if (d.de.kind == "counter" && !sig.table("d_e")->has("scale")) d.de.scale = d.encoder_resolution;
  d.vs = channel("Vs");
  if (sig.has("Va")) d.va = channel("Va");
}

}  // namespace

void BenchDescription::validate() const {
  if (backend != "virtual" && backend != "udp" && backend != "comedi") {
    throw InputError(source, "bench.backend", "\"virtual\", \"udp\" or \"comedi\"", "'" + backend + "'");
  }
  if (!(std::isfinite(sample_rate) && sample_rate > 0.0 && sample_rate <= 1e6)) {
    throw InputError(source, "bench.sample_rate_Hz", "a rate in (0, 1e6] Hz", format_number(sample_rate));
  }
  try {
    limits.validate();
  } catch (const InputError& e) {
    throw e.with_source(source);
  }
  check_plausible(limits, source);
  if (!(std::isfinite(encoder_resolution) && encoder_resolution > 0.0)) {
    throw InputError(source, "encoder.resolution_m", "a resolution > 0 m", format_number(encoder_resolution));
  }
  if (backend == "virtual" && (unit < 1 || unit > 7)) {
    throw InputError(source, "virtual.unit", "a unit of the batch, 1 to 7", std::to_string(unit));
  }
  if (backend == "udp") {
    if (udp_address.empty()) throw InputError(source, "udp.address", "\"HOST:PORT\" of the I/O target", "nothing");
    if (!(std::isfinite(udp_timeout) && udp_timeout > 0.0 && udp_timeout <= 1.0)) {
      throw InputError(source, "udp.timeout_s", "a timeout in (0, 1] s", format_number(udp_timeout));
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
                     format_number(u.scale));
  }
  const double lo = limits.u_min() * u.scale, hi = limits.u_max() * u.scale;
  if (lo < u.range_min - 1e-12 || hi > u.range_max + 1e-12) {
    throw InputError(source, "signals.u.range",
                     fmt::format("a DAC range that covers the limits: {} .. {} V at the stacks need {} .. {} V at the DAC (gain {} V/V, scale {})",
                                 format_number(limits.va_min), format_number(limits.va_max), format_number(lo), format_number(hi),
                                 format_number(limits.amplifier_gain), format_number(u.scale)),
                     interval(u.range_min, u.range_max));
  }
}

BenchDescription parse_bench_description(const std::string& text, const std::string& source) {
  const toml::table root = io::parse_toml(text, source);
  const TomlReader top(root, source);
  top.only({"bench", "amplifier", "limits", "encoder", "virtual", "udp", "comedi", "signals"});
  BenchDescription d;
  d.source = source;
  read_bench_table(top, d);
  read_limits(top, d);
  read_backends(top, d);
  read_signals(top, d);
  d.validate();
  return d;
}

BenchDescription read_bench_file(const std::filesystem::path& file) {
  return parse_bench_description(io::read_toml_text(file), file.string());
}

}  // namespace piezobench::rt
