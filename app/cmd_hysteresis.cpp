// `piezobench hysteresis fit` (a Prandtl-Ishlinskii model with creep from a Va -> d_e record, written
// as TOML for `rt --feedforward`) and `piezobench hysteresis creep` (a Prony creep fit of a step record).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <memory>
#include <utility>
#include <variant>
#include <vector>

#include "cli_common.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/ident/hysteresis.hpp"
#include "piezobench/io/fields_json.hpp"
#include "piezobench/io/hysteresis_toml.hpp"
#include "piezobench/io/timeseries.hpp"

namespace piezobench::app {
namespace {

struct HysteresisFitArgs {
  std::string file;
  std::string input = "Va";
  std::string output = "de";
  double fs = 0.0;
  int operators = 10;
  double threshold_range = 0.0;
  int dead_zones = 0;
  std::string creep_tau;
  double max_residual = 0.02;
  std::string out;
  bool json = false;
};

// What a command reads a record for: the kinds of record it analyses (a record's own
// settings.experiment, when it says, must be one: issue 35) and the SI unit each channel must
// have ("" = any; a channel without a unit is taken as SI with a warning).
struct RecordUse {
  std::string command;
  std::vector<std::string> kinds;
  std::string input_unit, output_unit;
};

// The input and output channels of `file` in SI; exit 3 for a record of another kind or a channel
// in a unit of another quantity. The reader's warnings (a channel without a unit) go to stderr.
io::TimeSeries read_pair(const std::string& file, const std::string& input, const std::string& output, double fs, bool quiet,
                         const RecordUse& use) {
  io::ReadOptions read;
  read.fs = fs;
  read.channels = {input, output};
  if (!quiet) log_line("reading " + file);
  io::TimeSeries ts = io::read_timeseries(file, read);
  const auto kind = ts.settings.find("experiment");
  if (kind != ts.settings.end() && std::holds_alternative<std::string>(kind->second)) {
    const std::string& k = std::get<std::string>(kind->second);
    if (std::find(use.kinds.begin(), use.kinds.end(), k) == use.kinds.end()) {
      throw InputError(file, "settings.experiment", fmt::format("a {} record (what `{}` analyses)", fmt::join(use.kinds, ", "), use.command),
                       "'" + k + "', a " + k + " record");
    }
  }
  for (const auto& [name, si] : {std::pair{input, use.input_unit}, std::pair{output, use.output_unit}}) {
    const std::string unit = ts.unit(name);
    if (!si.empty() && !unit.empty() && unit != si) {
      throw InputError(file, "channel " + name, fmt::format("a channel in {} (or a unit of that quantity)", si), "unit '" + unit + "'");
    }
  }
  print_warnings(ts.warnings);
  return ts;
}

// A channel's unit for the summary: its SI symbol, or `si` marked as assumed when the file gives none.
std::string shown_unit(const io::TimeSeries& ts, const std::string& name, const std::string& si) {
  const std::string unit = ts.unit(name);
  return unit.empty() ? (si.empty() ? "(SI, no unit in the file)" : si + " (assumed: no unit in the file)") : unit;
}

int run_hysteresis_fit(const HysteresisFitArgs& o) {
  ident::HysteresisFitOptions fo;
  fo.operators = o.operators;
  fo.threshold_range = o.threshold_range;
  fo.dead_zones = o.dead_zones;
  if (!o.creep_tau.empty()) fo.creep_time_constants = parse_number_list(o.creep_tau, "--creep-tau");
  fo.max_relative_residual = o.max_residual;
  fo.validate();
  const io::TimeSeries ts =
      read_pair(o.file, o.input, o.output, o.fs, o.json, {"hysteresis fit", {"hysteresis", "stroke", "tracking"}, "V", "m"});
  const Eigen::VectorXd va = ts.channel(o.input), de = ts.channel(o.output);
  if (!o.json) log_line(fmt::format("{} samples at {:g} Hz, {} play operators", ts.samples(), ts.sample_rate, fo.operators));
  const ident::HysteresisFit fit = ident::fit_hysteresis({va.data(), static_cast<std::size_t>(va.size())},
                                                         {de.data(), static_cast<std::size_t>(de.size())}, ts.sample_rate, fo);
  const std::vector<double> va_v(va.data(), va.data() + va.size()), de_v(de.data(), de.data() + de.size());
  const ident::LoopMetrics loop = ident::loop_metrics(va_v, de_v);
  if (!o.out.empty()) {
    io::write_hysteresis_model(o.out, fit.model, &fit, o.file);
    if (!o.json) log_line("wrote " + o.out);
  }
  if (o.json) {
    // The declared HysteresisFit (docs/fields.md), with the record it comes from.
    nlohmann::json doc = io::results_object(fit);
    doc["source"] = o.file;
    doc["sample_rate_Hz"] = ts.sample_rate;
    doc["hysteresis_width"] = loop.width;
    doc["warnings"] = ts.warnings;
    print_json(doc);
  } else {
    const ident::HysteresisModel& m = fit.model;
    fmt::print("Prandtl-Ishlinskii model of {} -> {} ({} samples)\n", o.input, o.output, fit.samples);
    fmt::print("  d_e = {:.6g} m + {:.6g} m/V * {}(H[Va] + creep)\n", m.offset, m.gain, m.output.identity() ? "" : "S");
    fmt::print("  thresholds (V): {:.4g}\n", fmt::join(m.hysteresis.thresholds, ", "));
    fmt::print("  weights (V/V):  {:.4g}\n", fmt::join(m.hysteresis.weights, ", "));
    if (!m.output.identity()) {
      fmt::print("  S (dead-zone superposition, knots V -> V): x {:.4g}; y {:.4g}; end slopes {:.4g}, {:.4g}\n", fmt::join(m.output.x, ", "),
                 fmt::join(m.output.y, ", "), m.output.slope_below, m.output.slope_above);
    }
    if (!m.creep_time_constants.empty()) {
      fmt::print("  creep: time constants (s) {:.4g}; coefficients (dimensionless) {:.4g}\n", fmt::join(m.creep_time_constants, ", "),
                 fmt::join(m.creep_coefficients, ", "));
    }
    fmt::print("  compensated line: {:.6g} V/V, {:.6g} V\n", m.reference_slope, m.reference_intercept);
    fmt::print("  record: stroke {:.6g} um, hysteresis width {:.3g} % of the stroke\n", 1e6 * fit.stroke, 100.0 * loop.width);
    fmt::print("  fit: rms residual {:.4g} nm, {:.3g} % of the stroke ({})\n", 1e9 * fit.rms_residual, 100.0 * fit.relative_residual,
               fit.quality.summary());
  }
  return report_quality(fit.quality);
}

struct CreepOptions {
  std::string file;
  std::string input = "added_mass";
  std::string output = "de";
  double fs = 0.0;
  std::string tau;
  double max_residual = 0.05;
  bool json = false;
};

int run_creep(const CreepOptions& o) {
  const std::vector<double> tau = o.tau.empty() ? std::vector<double>{} : parse_number_list(o.tau, "--tau");
  const io::TimeSeries ts = read_pair(o.file, o.input, o.output, o.fs, o.json, {"hysteresis creep", {"stiffness"}, "", ""});
  const Eigen::VectorXd x = ts.channel(o.input), y = ts.channel(o.output);
  const ident::CreepFit c = ident::fit_creep({x.data(), static_cast<std::size_t>(x.size())}, {y.data(), static_cast<std::size_t>(y.size())},
                                             ts.sample_rate, tau, o.max_residual);
  if (o.json) {
    // The declared CreepFit (SI: the channels' units), with the record it comes from.
    nlohmann::json doc = io::results_object(c);
    doc["source"] = o.file;
    doc["units"] = {{"input", ts.unit(o.input)}, {"output", ts.unit(o.output)}};
    doc["warnings"] = ts.warnings;
    print_json(doc);
  } else {
    const std::string in_unit = shown_unit(ts, o.input, ""), out_unit = shown_unit(ts, o.output, "");
    fmt::print("Creep of {} [{}] -> {} [{}]: y = {:.6g} + {:.6g} (x + sum_j c_j F_j[x])\n", o.input, in_unit, o.output, out_unit, c.offset,
               c.gain);
    fmt::print("  offset in the unit of {}, gain in {} per {}\n", o.output, out_unit, in_unit);
    fmt::print("  time constants (s): {:.4g}\n  coefficients (dimensionless): {:.4g}\n", fmt::join(c.time_constants, ", "),
               fmt::join(c.coefficients, ", "));
    fmt::print("  creep per decade {:.4g} %; rms residual {:.3g} % of the range ({})\n", 100.0 * c.creep_per_decade,
               100.0 * c.relative_residual, c.quality.summary());
  }
  return report_quality(c.quality);
}

}  // namespace

void add_hysteresis_commands(CLI::App& app, Action& action) {
  CLI::App* h = app.add_subcommand("hysteresis", "Hysteresis and creep of the stacks: identification for the inverse feedforward");
  h->require_subcommand(1);
  auto o = std::make_shared<HysteresisFitArgs>();
  CLI::App* fit = h->add_subcommand("fit", "Prandtl-Ishlinskii model (+ creep) of a Va -> d_e record, written as TOML (rt --feedforward)");
  fit->add_option("file", o->file, "time-series file (.mat, .csv) with the stack voltage and the displacement")->required();
  fit->add_option("--input", o->input, "channel of the stack voltage, V")->capture_default_str();
  fit->add_option("--output", o->output, "channel of the displacement, m")->capture_default_str();
  fit->add_option("--fs", o->fs, "sample rate, Hz (default: from the file)");
  fit->add_option("--operators", o->operators, "play operators")->check(CLI::Range(1, 200))->capture_default_str();
  fit->add_option("--dead-zones", o->dead_zones,
                  "Kuhnen's modified PI for asymmetric loops: dead zones on each side of the output map S (0: plain PI)")
      ->check(CLI::Range(0, 50))
      ->capture_default_str();
  fit->add_option("--threshold-range", o->threshold_range, "largest threshold range R, V (thresholds (i - 1/2) R / n; default: half the range of Va)");
  fit->add_option("--creep-tau", o->creep_tau, "comma-separated creep time constants, s (default: no creep states)");
  fit->add_option("--max-residual", o->max_residual, "largest rms residual / stroke of a good fit")->capture_default_str();
  fit->add_option("-o,--out", o->out, "write the model (TOML)");
  fit->add_flag("--json", o->json, "print one JSON document on stdout");
  fit->callback([o, &action] { action = [o] { return run_hysteresis_fit(*o); }; });

  auto c = std::make_shared<CreepOptions>();
  CLI::App* creep = h->add_subcommand("creep", "Prony-series creep of a step record (the stiffness test: added_mass -> de)");
  creep->add_option("file", c->file, "time-series file (.mat, .csv)")->required();
  creep->add_option("--input", c->input, "channel of the step")->capture_default_str();
  creep->add_option("--output", c->output, "channel of the response")->capture_default_str();
  creep->add_option("--fs", c->fs, "sample rate, Hz (default: from the file)");
  creep->add_option("--tau", c->tau, "comma-separated time constants, s (default: 1, 10, 100 ... up to half the record)");
  creep->add_option("--max-residual", c->max_residual, "largest rms residual / range of a good fit")->capture_default_str();
  creep->add_flag("--json", c->json, "print one JSON document on stdout");
  creep->callback([c, &action] { action = [c] { return run_creep(*c); }; });
}

}  // namespace piezobench::app
