// `piezobench measure`: one experiment of the report on the bench a bench file describes (the
// virtual bench, a Comedi card, a UDP I/O target), written as the same measurement file `simulate`
// writes; `piezobench bench serve`: the virtual bench behind the UDP protocol (docs/hardware.md).
#include <fmt/format.h>

#include <csignal>
#include <cmath>
#include <iostream>
#include <memory>
#include <optional>
#include <variant>

#include "cli_common.hpp"
#include "measure_common.hpp"
#include "piezobench/bench/tracking.hpp"
#include "piezobench/bench/truth.hpp"
#include "piezobench/core/checked_number.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/usage_error.hpp"
#include "piezobench/io/fields_json.hpp"
#include "piezobench/io/hysteresis_toml.hpp"
#include "piezobench/io/timeseries.hpp"
#include "piezobench/rt/comedi_backend.hpp"
#include "piezobench/rt/measure.hpp"
#include "piezobench/rt/udp.hpp"
#include "piezobench/rt/udp_target.hpp"
#include "piezobench/rt/virtual_backend.hpp"

namespace piezobench::app {

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_sigint(int) { g_stop.store(true); }

nlohmann::json settings_json(const io::TimeSeries& ts) {
  nlohmann::json s = nlohmann::json::object();
  for (const auto& [key, value] : ts.settings) {
    if (const double* d = std::get_if<double>(&value)) {
      s[key] = *d;
    } else {
      s[key] = std::get<std::string>(value);
    }
  }
  return s;
}

// "experiment options: amplitude: expected ..., found ..." -> "--amplitude: expected ..., found ...":
// the message names the command-line option the user typed, and the exit code is a usage error's.
[[noreturn]] void throw_as_option_error(const InputError& e) {
  const std::string prefix = "experiment options: ";
  const std::string what = e.what();
  if (what.rfind(prefix, 0) != 0) throw e;
  throw UsageError("--" + what.substr(prefix.size()));
}

}  // namespace

nlohmann::json loop_report_json(const rt::LoopReport& r) {
  nlohmann::json doc = io::results_object(r);
  doc["host"]["overruns_late_wakeup"] = r.overruns_late_wakeup;
  doc["host"]["skipped_deadlines"] = r.skipped_deadlines;
  doc["code"] = {{"overruns_long_step", r.overruns_long_step}, {"step_time_us", doc["step_time_us"]}};
  if (!r.realtime) doc["period_jitter_us"] = doc["wake_latency_us"] = nullptr;
  return doc;
}

const std::atomic<bool>* stop_on_sigint() {
  g_stop.store(false);
  std::signal(SIGINT, on_sigint);
  std::signal(SIGTERM, on_sigint);
  return &g_stop;
}

// The operator's confirmation on stdin that a target's latched safe state may be cleared.
bool confirm_target_reset(const std::string& target) {
  log_line("operator: " + target + " is in its latched safe state (a fault of an earlier session); check the bench, then "
           "press Enter to clear it (the end of the input refuses)");
  std::string line;
  return static_cast<bool>(std::getline(std::cin, line));
}

std::unique_ptr<rt::Backend> make_backend(const rt::BenchDescription& b, bool reset_target) {
  if (b.backend == "udp") {
    rt::UdpBackendOptions o;
    o.key = b.udp_key;
    if (reset_target) o.confirm_reset = confirm_target_reset;
    return std::make_unique<rt::UdpBackend>(b.udp_address, b.sample_rate, b.udp_timeout, o);
  }
  if (b.backend == "comedi") return std::make_unique<rt::ComediBackend>(b);
  if (!b.twin.empty()) {
    const bench::Twin twin = bench::read_twin(b.twin);
    bench::BenchOptions options = rt::bench_options(b);
    bench::apply_chain(twin, options);
    options.sample_rate = b.sample_rate;  // the loop's rate
    return std::make_unique<rt::VirtualBenchBackend>(twin.unit, options, b.seed);
  }
  return std::make_unique<rt::VirtualBenchBackend>(bench::batch_unit(b.unit, b.seed), rt::bench_options(b), b.seed);
}

void set_feedforward(bench::ExperimentOptions& options, const std::string& file) {
  if (!file.empty()) options.feedforward = io::read_hysteresis_model(file);
}

bench::HysteresisLaw hysteresis_law_option(const std::string& name) {
  try {
    return bench::hysteresis_law_from_string(name);
  } catch (const InputError&) {
    throw UsageError("--hysteresis-law", bench::kHysteresisLaws, "'" + name + "'");
  }
}

namespace {

bench::Experiment requested_experiment(const MeasureRequest& r) {
  try {
    return bench::experiment_from_string(r.experiment);
  } catch (const InputError& e) {
    throw UsageError(e.what());  // "experiment: expected one of stroke, ..., found 'frf'"
  }
}

// The unit measured: a real unit (only its number is known), the twin's, or one of the batch.
bench::UnitTruth unit_under_test(const MeasureRequest& r, bool hardware) {
  bench::UnitTruth unit;
  if (hardware) {
    if (r.unit < 1) throw UsageError("--unit", "the number of the unit under test (>= 1)", std::to_string(r.unit));
    unit.id = r.unit;  // a real unit: only its number is known
  } else if (r.twin) {
    unit = r.twin->unit;
  } else {
    try {
      unit = bench::batch_unit(r.unit, r.seed);
    } catch (const InputError& e) {
      throw UsageError("--" + std::string(e.what()));  // "--unit: expected a unit of the batch, 1 to 7, ..."
    }
  }
  return unit;
}

// The record, and on hardware the backend and the runner that took it (their report).
struct Measurement {
  io::TimeSeries ts;
  std::unique_ptr<rt::Backend> backend;
  std::unique_ptr<rt::BackendRunner> runner;
};

// The virtual bench's record, with progress every quarter for the long simulations.
io::TimeSeries simulate_measurement(const MeasureRequest& r, bench::Experiment experiment, const bench::UnitTruth& unit,
                                    const bench::ExperimentOptions& eo) {
  int quarter = 0;
  const bench::Progress progress = [&quarter](double fraction) {
    if (fraction >= 0.25 * (quarter + 1) && fraction < 1.0) {
      quarter = static_cast<int>(fraction / 0.25);
      log_line(fmt::format("simulating: {:.0f} %", 100.0 * fraction));
    }
  };
  const bool long_run = eo.duration.value_or(0.0) >= 50.0;
  try {
    return bench::simulate(experiment, unit, eo, r.seed, long_run ? progress : bench::Progress{});
  } catch (const InputError& e) {
    throw_as_option_error(e);
  }
}

// The experiment run through the bench file's backend.
void measure_on_bench(const MeasureRequest& r, bench::Experiment experiment, const bench::UnitTruth& unit,
                      const bench::ExperimentOptions& eo, Measurement& m) {
  if (!bench::runs_on_bench(experiment)) {
    throw UsageError("experiment",
                     "an experiment that runs on the bench's I/O (stroke, hysteresis, stiffness, frf-noise, frf-sweep, "
                     "iff, tracking); record " + r.experiment + " with its own instruments and give the file to `piezobench run`",
                     "'" + r.experiment + "'");
  }
  m.backend = make_backend(*r.bench, r.reset_target);
  rt::MeasureOptions mo;
  mo.bench = *r.bench;
  mo.realtime_priority = r.realtime;
  mo.stop = stop_on_sigint();
  if (!r.log.empty()) mo.raw_log = r.log;
  mo.on_warning = [](const std::string& w) { log_line("warning: " + w); };
  m.runner = std::make_unique<rt::BackendRunner>(*m.backend, mo);
  log_line(fmt::format("measure: {} on unit {} through the {} backend ({}), {:g} Hz", r.experiment, r.unit,
                       m.backend->name(), r.bench->source, r.bench->sample_rate));
  try {
    m.ts = bench::run_experiment(experiment, *m.runner, unit, eo, r.seed);
  } catch (const InputError& e) {
    throw_as_option_error(e);
  }
}

void print_tracking(const bench::TrackingSummary& tracking) {
  for (const auto& [name, f] : {std::pair<const char*, const bench::TrackingFigures&>{"sine", tracking.sine},
                                {"triangle", tracking.triangle}}) {
    fmt::print("{:8} hysteresis width {:.2f} % -> {:.2f} % of the stroke ({:.1f} um); rms tracking error {:.3f} um -> "
               "{:.3f} um ({:.1f}x)\n",
               name, 100.0 * f.width_open, 100.0 * f.width_ff, 1e6 * f.stroke_open, 1e6 * f.rms_open, 1e6 * f.rms_ff,
               f.rms_reduction());
  }
  fmt::print("feedforward: {}{}; {} samples clamped to the stack range\n",
             tracking.identified ? "identified from the open run" : "the given model",
             tracking.identified ? fmt::format(" (fit residual {:.3g} % of the stroke)", 100.0 * tracking.fit_relative_residual) : "",
             tracking.clamped_samples);
}

// The text summary: the file with every channel and its unit (issue 33: a summary prints the unit
// of every number), the tracking figures, the I/O.
void print_measurement(const MeasureRequest& r, const std::string& out, const bench::UnitTruth& unit, const Measurement& m,
                       const std::optional<bench::TrackingSummary>& tracking) {
  const io::TimeSeries& ts = m.ts;
  std::vector<std::string> channels;
  for (const std::string& name : ts.names) {
    const std::string u = ts.unit(name);
    channels.push_back(name + " [" + (u.empty() ? "no unit" : u) + "]");
  }
  fmt::print("wrote {}: {} on unit {}{} ({} samples at {:g} Hz; channels {}{})\n", out, r.experiment, r.unit,
             unit.defective ? " (defective)" : "", ts.samples(), ts.sample_rate, ts.t.size() > 0 ? "t [s], " : "",
             fmt::join(channels, ", "));
  if (tracking) print_tracking(*tracking);
  if (m.runner) {
    const rt::IoStats io = m.runner->report().io();
    fmt::print("I/O: {} exchanges, {} lost, {} late, {} stale inputs, {} errors; round trip p50 {:.1f} us, p99 {:.1f} us\n",
               io.exchanges, io.lost, io.late, io.timeouts, io.errors, io.round_trip_us.p50, io.round_trip_us.p99);
  }
}

// bench::TrackingSummary's declared view (rms and stroke in um, as results.json's tracking), with
// each waveform's rms_reduction (a method of TrackingFigures, added as results.json adds it).
nlohmann::json tracking_json(const bench::TrackingSummary& tracking) {
  nlohmann::json t = io::results_object(tracking);
  t["sine"]["rms_reduction"] = io::to_json(tracking.sine.rms_reduction());
  t["triangle"]["rms_reduction"] = io::to_json(tracking.triangle.rms_reduction());
  return t;
}

// What the hardware run reports: backend, I/O, the loop runs and the operator's steps.
void add_hardware_json(const MeasureRequest& r, const Measurement& m, nlohmann::json& doc) {
  const rt::MeasureReport& rep = m.runner->report();
  const rt::IoStats io = rep.io();
  doc["backend"] = m.backend->name();
  doc["bench_file"] = r.bench->source;
  doc["cycles"] = rep.cycles();
  doc["io"] = io::results_object(io);
  // Each run: its loop report as `rt --json` writes it (loop_report_json: rt::LoopReport's declared
  // view, its own I/O included).
  nlohmann::json runs = nlohmann::json::array();
  for (const rt::LoopReport& lr : rep.runs) runs.push_back(loop_report_json(lr));
  doc["runs"] = runs;
  nlohmann::json steps = nlohmann::json::array();
  for (const rt::OperatorConfirmation& c : rep.operator_steps) {
    steps.push_back({{"prompt", c.prompt}, {"asked_s", c.asked_s}, {"confirmed_s", c.confirmed_s}});
  }
  doc["operator_steps"] = steps;
}

// The --json document: the file, its channels and settings, the tracking figures, and the truth
// (virtual bench) or the hardware run's report.
nlohmann::json measurement_json(const MeasureRequest& r, const std::string& out, const bench::UnitTruth& unit,
                                const bench::ExperimentOptions& eo, const Measurement& m,
                                const std::optional<bench::TrackingSummary>& tracking, bool hardware) {
  const io::TimeSeries& ts = m.ts;
  nlohmann::json units = nlohmann::json::object();
  for (std::size_t i = 0; i < ts.names.size(); ++i) units[ts.names[i]] = i < ts.units.size() ? ts.units[i] : "";
  nlohmann::json doc = {{"file", out},
                        {"experiment", r.experiment},
                        {"unit", r.unit},
                        {"seed", r.seed},
                        {"samples", ts.samples()},
                        {"sample_rate_Hz", ts.sample_rate},
                        {"channels", ts.names},
                        {"units", units},
                        {"settings", settings_json(ts)}};
  if (tracking) doc["tracking"] = tracking_json(*tracking);
  if (!hardware) {
    doc["truth"] = bench::truth_json(unit, eo.bench);
  } else {
    add_hardware_json(r, m, doc);
  }
  return doc;
}

}  // namespace

int run_measurement(const MeasureRequest& r) {
  const bench::Experiment experiment = requested_experiment(r);
  bench::ExperimentOptions eo = r.options;
  try {
    eo.validate(experiment);
  } catch (const InputError& e) {
    throw_as_option_error(e);
  }
  const bool hardware = r.bench && r.bench->hardware();
  const bench::UnitTruth unit = unit_under_test(r, hardware);
  const std::string out = r.out.empty() ? fmt::format("{}-unit{}.mat", r.experiment, r.unit) : r.out;
  Measurement m;
  if (!hardware) {
    m.ts = simulate_measurement(r, experiment, unit, eo);
  } else {
    measure_on_bench(r, experiment, unit, eo, m);
  }
  if (!r.serial.empty()) m.ts.settings["serial"] = r.serial;  // checked by `run` against the campaign's units[].serial
  io::write_timeseries(m.ts, out);
  std::optional<bench::TrackingSummary> tracking;
  if (experiment == bench::Experiment::kTracking) tracking = bench::tracking_summary(m.ts);
  if (!r.json) {
    print_measurement(r, out, unit, m, tracking);
    return 0;
  }
  print_json(measurement_json(r, out, unit, eo, m, tracking, hardware));
  return 0;
}

namespace {

struct MeasureCli {
  std::string experiment, bench, out, log, serial;
  int unit = 1;
  std::uint64_t seed = 1;
  double amplitude = 0.0, duration = 0.0, gain = 0.0;
  CLI::Option *amplitude_option = nullptr, *duration_option = nullptr, *gain_option = nullptr, *seed_option = nullptr,
              *unit_option = nullptr;
  std::string feedforward;
  std::string hysteresis_law = "prandtl-ishlinskii";  // virtual bench
  CLI::Option* hysteresis_law_option = nullptr;
  bool realtime = false, json = false, open_circuit = false, no_resistor = false, reset_target = false;
};

int run_measure(const MeasureCli& o) {
  MeasureRequest r;
  r.experiment = o.experiment;
  const rt::BenchDescription desc = rt::read_bench_file(o.bench);
  r.options.bench = rt::bench_options(desc);
  if (o.amplitude_option->count() > 0) r.options.amplitude = o.amplitude;
  if (o.duration_option->count() > 0) r.options.duration = o.duration;
  if (o.gain_option->count() > 0) r.options.gain = o.gain;
  r.options.bench.actuator_open_circuit = o.open_circuit;
  r.options.bench.hpf_resistor = !o.no_resistor;
  r.options.bench.hysteresis_law = hysteresis_law_option(o.hysteresis_law);
  if (desc.hardware() && o.hysteresis_law_option->count() > 0) {
    throw UsageError("--hysteresis-law", "the virtual bench (a bench file with backend \"virtual\"; for `bench serve`, its own option)",
                     "backend " + desc.backend);
  }
  set_feedforward(r.options, o.feedforward);
  if (!desc.hardware() && !desc.twin.empty()) {
    r.twin = bench::read_twin(desc.twin);
    bench::apply_chain(*r.twin, r.options.bench);
    r.options.bench.sample_rate = desc.sample_rate;
  }
  r.unit = o.unit_option->count() > 0 || desc.hardware() ? o.unit : r.twin ? r.twin->unit.id : desc.unit;
  r.seed = o.seed_option->count() > 0 || desc.hardware() ? o.seed : desc.seed;
  r.out = o.out;
  r.json = o.json;
  r.realtime = o.realtime;
  r.log = o.log;
  r.reset_target = o.reset_target;
  r.serial = o.serial;
  if (desc.hardware()) {
    r.bench = desc;
  } else if (o.realtime || !o.log.empty()) {
    throw InputError(o.bench, "bench.backend", "a hardware backend (udp or comedi) for --realtime and --log",
                     "virtual (simulated, not paced)");
  }
  return run_measurement(r);
}

struct ServeCli {
  std::string udp = "127.0.0.1:5600";
  int unit = 1;
  std::uint64_t seed = 1;
  double rate = 10e3;
  int sessions = 0;
  double idle_timeout = 60.0, session_timeout = 10.0;
  std::uint64_t drop_every = 0;
  std::string key_file;
  std::string hysteresis_law = "prandtl-ishlinskii";
  std::string twin;
  bool json = false;
};

int run_serve(const ServeCli& o) {
  bench::BenchOptions bo;
  bo.sample_rate = o.rate;
  bo.hysteresis_law = hysteresis_law_option(o.hysteresis_law);
  bench::UnitTruth unit;
  if (!o.twin.empty()) {
    const bench::Twin twin = bench::read_twin(o.twin);
    bench::apply_chain(twin, bo);
    bo.sample_rate = o.rate;  // the clients' rate
    unit = twin.unit;
  } else {
    try {
      unit = bench::batch_unit(o.unit, o.seed);
    } catch (const InputError& e) {
      throw InputError("--" + std::string(e.what()));
    }
  }
  checked_duration_s(o.idle_timeout, 1e-3, 1e6, NumberOrigin::command_line("--idle-timeout"));
  checked_duration_s(o.session_timeout, 1e-3, 3600.0, NumberOrigin::command_line("--session-timeout"));
  rt::UdpServerOptions so;
  so.address = o.udp;
  so.sessions = o.sessions;
  so.idle_timeout = o.idle_timeout;
  so.target.session_timeout = o.session_timeout;
  so.target.drop_every = o.drop_every;
  if (!o.key_file.empty()) so.target.key = rt::read_udp_key(o.key_file, "--key-file", "key");
  so.stop = stop_on_sigint();
  so.on_warning = [](const std::string& w) { log_line("warning: " + w); };
  so.on_listening = [&](const std::string& address) {
    // First line on stdout, flushed: a script (or a test) reads the port from it.
    fmt::print("listening on {}\n", address);
    std::fflush(stdout);
    log_line(fmt::format("bench serve: virtual bench, unit {}, seed {}, {:g} Hz on udp {}", o.unit, o.seed, o.rate, address));
  };
  const rt::UdpServerReport rep = rt::serve_udp(unit, bo, o.seed, so);
  if (o.json) {
    print_json({{"sessions", rep.sessions},
                {"requests", rep.requests},
                {"replies", rep.replies},
                {"dropped", rep.dropped},
                {"rejected", rep.rejected},
                {"refused", rep.refused},
                {"limited", rep.limited},
                {"expired", rep.expired},
                {"target_safe", rep.target_safe},
                {"safe_reason", rep.safe_reason}});
  } else {
    fmt::print("served {} sessions: {} io requests, {} replies ({} dropped on purpose), {} datagrams rejected, {} hellos "
               "refused (busy), {} commands limited by the target{}\n",
               rep.sessions, rep.requests, rep.replies, rep.dropped, rep.rejected, rep.refused, rep.limited,
               rep.target_safe ? "; safe state latched: " + rep.safe_reason : std::string());
  }
  return 0;
}

}  // namespace

void add_measure_commands(CLI::App& app, Action& action) {
  auto o = std::make_shared<MeasureCli>();
  CLI::App* m = app.add_subcommand("measure", "One experiment of the report on the bench a bench file describes, written as a measurement file");
  m->add_option("experiment", o->experiment, "stroke, hysteresis, stiffness, frf-noise, frf-sweep, iff or tracking (virtual "
                                             "bench: also hammer, flatness, capacitance)")
      ->required();
  m->add_option("--bench", o->bench, "bench file (TOML): backend, channels, amplifier, limits (docs/hardware.md)")
      ->required()
      ->check(input_file());
  o->unit_option = m->add_option("--unit", o->unit, "number of the unit under test (virtual bench: 1..7 of the batch)");
  m->add_option("--serial", o->serial, "the unit's serial number, recorded in the file (`run` checks it against the campaign's)");
  o->seed_option = m->add_option("--seed", o->seed, "virtual bench: seed of the batch and of the noise; excitation seed");
  m->add_option("--out", o->out, "output file, .mat (default) or .csv (default: EXPERIMENT-unitN.mat)");
  o->amplitude_option = m->add_option("--amplitude", o->amplitude, "V at the stacks, as for simulate");
  o->duration_option = m->add_option("--duration", o->duration, "s: frf-noise (20), frf-sweep (20), iff (10)");
  o->gain_option = m->add_option("--gain", o->gain, "IFF gain g (280000)");
  m->add_option("--feedforward", o->feedforward,
                "tracking: the hysteresis model (TOML, `hysteresis fit`) of the compensated run (default: identified from the open run)")
      ->check(input_file());
  m->add_flag("--open-circuit", o->open_circuit,
              "actuator stacks disconnected from the amplifier (stiffness k_oc; a real bench asks the operator first)");
  m->add_flag("--no-resistor", o->no_resistor, "no resistor across the sensor stack (a real bench asks the operator first)");
  o->hysteresis_law_option = m->add_option("--hysteresis-law", o->hysteresis_law, kHysteresisLawHelp)->capture_default_str();
  m->add_flag("--realtime", o->realtime, "SCHED_FIFO priority and locked memory for the loop (a message when not permitted)");
  m->add_option("--log", o->log, "also write the loop's raw log (every cycle, with safety flags) to this file");
  m->add_flag("--json", o->json, "print one JSON document (file, settings, I/O counts) on stdout");
  m->add_flag("--reset-target", o->reset_target,
              "udp: a target in its latched safe state is reset once the operator presses Enter (docs/hardware.md \"UDP protocol\")");
  m->callback([o, &action] { action = [o] { return run_measure(*o); }; });

  auto s = std::make_shared<ServeCli>();
  CLI::App* bench = app.add_subcommand("bench", "The bench as a remote I/O target");
  bench->require_subcommand(1);
  CLI::App* serve = bench->add_subcommand("serve", "Expose the virtual bench through the UDP I/O protocol (docs/hardware.md)");
  serve->add_option("--udp", s->udp, "HOST:PORT to listen on (port 0: any free port; the first line says which)")
      ->capture_default_str();
  serve->add_option("--unit", s->unit, "unit of the batch, 1..7")->capture_default_str();
  serve->add_option("--seed", s->seed, "seed of the batch and of the noise")->capture_default_str();
  serve->add_option("--rate", s->rate, "sample rate, Hz (clients must use the same)")->capture_default_str();
  serve->add_option("--sessions", s->sessions, "exit after this many client sessions (0: serve until Ctrl-C)")
      ->capture_default_str();
  serve->add_option("--idle-timeout", s->idle_timeout, "exit after this long without a datagram, s")->capture_default_str();
  serve->add_option("--drop-every", s->drop_every, "testing: leave every N-th io request unanswered (0: none)")
      ->capture_default_str();
  serve->add_option("--session-timeout", s->session_timeout,
                    "s of silence that end a client's session (after its first command: the safe state latches)")
      ->capture_default_str();
  serve->add_option("--key-file", s->key_file, "shared key (>= 16 bytes): every datagram carries its HMAC-SHA256 (docs/hardware.md)")
      ->check(CLI::ExistingFile);
  serve->add_option("--hysteresis-law", s->hysteresis_law, kHysteresisLawHelp)->capture_default_str();
  serve->add_option("--twin", s->twin, "serve a unit's digital twin (TOML, `piezobench twin`) instead of the batch unit")
      ->check(input_file());
  serve->add_flag("--json", s->json, "print the session counts as JSON at the end");
  serve->callback([s, &action] { action = [s] { return run_serve(*s); }; });
}

}  // namespace piezobench::app
