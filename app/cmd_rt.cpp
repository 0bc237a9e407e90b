// `piezobench rt`: the real-time IFF loop (report section 2.6, Figure 2.9) on the virtual bench or
// on a replayed record, with the actuator's safety limits, a signal log and a timing report.
#include <fmt/format.h>

#include <cmath>
#include <memory>

#include "cli_common.hpp"
#include "measure_common.hpp"
#include "piezobench/bench/virtual_bench.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/core/usage_error.hpp"
#include "piezobench/dsp/excitation.hpp"
#include "piezobench/io/fields_json.hpp"
#include "piezobench/io/hysteresis_toml.hpp"
#include "piezobench/io/json.hpp"
#include "piezobench/rt/bench_file.hpp"
#include "piezobench/rt/loop.hpp"
#include "piezobench/rt/replay_backend.hpp"
#include "piezobench/rt/virtual_backend.hpp"

namespace piezobench::app {
namespace {

struct RtOptions {
  std::string bench = "virtual";
  std::string controller = "iff";
  double gain = 0.0;
  double rate = 10e3;
  bool rate_given = false;
  double duration = 1.0;
  std::string log;
  int unit = 1;
  std::uint64_t seed = 1;
  std::string excitation = "none";
  double amplitude = 0.05;
  std::string band = "1,1000";
  double frequency = 1.0;     // sine excitation, Hz
  double offset = 0.0;        // sine excitation, V at the DAC
  std::string feedforward;    // hysteresis model (TOML)
  std::string hysteresis_law = "prandtl-ishlinskii";  // virtual bench
  std::string replay;
  bool realtime = true;
  rt::ActuatorLimits limits;
  double ramp = 0.1;
  int priority = 80;
  bool fifo = false;          // with a bench file: SCHED_FIFO and mlockall only when asked
  bool limits_given = false;
  bool json = false;
};

// The loop's backend with what the output records of it, and the limits that apply.
struct RtBench {
  std::unique_ptr<rt::Backend> backend;
  nlohmann::json source;
  rt::ActuatorLimits limits;
  bool bench_file = false;  // the backend, rate and limits come from a bench file
};

// A bench file: its backend, rate and limits (a hardware backend never starts without them).
void open_bench_file(const RtOptions& o, RtBench& b) {
  if (!o.replay.empty()) throw UsageError("--replay", "only with --bench replay", "'" + o.replay + "'");
  const rt::BenchDescription desc = rt::read_bench_file(o.bench);
  if (o.limits_given) {
    throw UsageError("--va-min/--va-max/--slew-rate/--watchdog/--ramp",
                     "no limit options with a bench file (its [limits] apply)", "limit options");
  }
  if (o.rate_given && std::abs(o.rate - desc.sample_rate) > 1e-9 * desc.sample_rate) {
    throw InputError(o.bench, "--rate",
                     fmt::format("the bench file's rate {} Hz", format_number_exact(desc.sample_rate)),
                     fmt::format("{} Hz", format_number_exact(o.rate)));
  }
  b.limits = desc.limits;
  if (desc.backend == "comedi" && !o.realtime) {
    throw UsageError("--realtime", "true with a card (its I/O is paced by the loop)", "false");
  }
  b.backend = make_backend(desc);
  b.source = {{"bench", desc.backend}, {"bench_file", o.bench}};
  if (!desc.hardware()) b.source.update({{"unit", desc.unit}, {"seed", desc.seed}});
}

void open_virtual_bench(const RtOptions& o, RtBench& b) {
  if (!o.replay.empty()) throw UsageError("--replay", "only with --bench replay", "'" + o.replay + "'");
  bench::BenchOptions bo;
  bo.sample_rate = o.rate;
  bo.va_min = o.limits.va_min;
  bo.va_max = o.limits.va_max;
  bo.amplifier_gain = o.limits.amplifier_gain;
  bo.hysteresis_law = hysteresis_law_option(o.hysteresis_law);
  b.backend = std::make_unique<rt::VirtualBenchBackend>(bench::batch_unit(o.unit, o.seed), bo, o.seed);
  b.source = {{"bench", "virtual"}, {"unit", o.unit}, {"seed", o.seed}};
}

void open_replay(const RtOptions& o, RtBench& b) {
  if (o.replay.empty()) throw UsageError("--replay", "a recorded file (.mat or .csv with de and Vs)", "nothing");
  auto replay = std::make_unique<rt::ReplayBackend>(std::filesystem::path(o.replay));
  if (o.rate_given && std::abs(o.rate - replay->sample_rate()) > 1e-6 * replay->sample_rate()) {
    throw InputError(o.replay, "--rate", "the record's sample rate " + format_number(replay->sample_rate(), 10) + " Hz",
                     format_number_exact(o.rate) + " Hz");
  }
  b.source = {{"bench", "replay"}, {"file", o.replay}, {"samples", replay->samples()}};
  b.backend = std::move(replay);
}

RtBench open_bench(const RtOptions& o) {
  RtBench b;
  b.limits = o.limits;
  b.limits.ramp_in = b.limits.ramp_out = o.ramp;
  b.bench_file = o.bench.size() > 5 && o.bench.substr(o.bench.size() - 5) == ".toml";
  if (b.bench_file) {
    open_bench_file(o, b);
  } else if (o.bench == "virtual") {
    open_virtual_bench(o, b);
  } else if (o.bench == "replay") {
    open_replay(o, b);
  } else {
    throw UsageError("--bench", "virtual, replay or a bench file (.toml)", "'" + o.bench + "'");
  }
  return b;
}

// Band-limited noise of --amplitude V rms: one period of at most 65,536 samples, played cyclically.
void add_noise_excitation(const RtOptions& o, double sample_rate, rt::LoopOptions& lo) {
  const std::vector<double> band = parse_number_list(o.band, "--band");
  if (band.size() != 2) throw UsageError("--band", "two frequencies LO,HI in Hz", "'" + o.band + "'");
  dsp::NoiseOptions no;
  no.sample_rate = sample_rate;
  const double cycles = std::max(2.0, std::round(o.duration * no.sample_rate));
  no.samples = static_cast<Eigen::Index>(std::min(cycles, 65536.0));  // one period, played cyclically
  no.f_low = band[0];
  no.f_high = band[1];
  no.rms = o.amplitude;
  no.seed = o.seed;
  dsp::VoltageBounds unlimited;  // the loop's safety layer limits the output, not the generator
  unlimited.min = -1e6;
  unlimited.max = 1e6;
  lo.excitation = dsp::band_limited_noise(no, unlimited).u;
  lo.log_settings["amplitude_rms"] = o.amplitude;
}

// A sine of --frequency Hz around --offset V: one period (rounded to whole samples), played cyclically.
void add_sine_excitation(const RtOptions& o, double sample_rate, rt::LoopOptions& lo) {
  if (!(std::isfinite(o.frequency) && o.frequency > 0.0 && o.frequency < 0.5 * sample_rate)) {
    throw UsageError("--frequency", "a frequency in (0, rate / 2) Hz", format_number_exact(o.frequency));
  }
  const auto n = static_cast<Eigen::Index>(std::max(2.0, std::round(sample_rate / o.frequency)));
  lo.excitation.resize(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    lo.excitation(k) = o.offset + o.amplitude * std::sin(kTwoPi * static_cast<double>(k) / static_cast<double>(n));
  }
  lo.log_settings["amplitude"] = o.amplitude;
  lo.log_settings["offset"] = o.offset;
  lo.log_settings["frequency_Hz"] = sample_rate / static_cast<double>(n);
}

rt::LoopOptions loop_options(const RtOptions& o, const RtBench& b) {
  rt::LoopOptions lo;
  lo.duration = o.duration;
  lo.realtime = o.realtime;
  lo.priority = o.priority;
  if (b.bench_file && !o.fifo) lo.sched_fifo = lo.lock_memory = false;  // --fifo asks for them
  lo.controller = o.controller == "iff";
  lo.gain = o.gain;
  lo.limits = b.limits;
  lo.stop = stop_on_sigint();  // Ctrl-C: the output ramps to the safe value, the log is written
  if (!o.log.empty()) lo.log_file = std::filesystem::path(o.log);
  lo.log_settings["command"] = std::string("rt");
  lo.log_settings["bench"] = o.bench;
  if (o.bench == "virtual") {
    lo.log_settings["unit"] = static_cast<double>(o.unit);
    lo.log_settings["seed"] = static_cast<double>(o.seed);
  }
  lo.log_settings["excitation"] = o.excitation;
  lo.on_warning = [](const std::string& w) { log_line("warning: " + w); };
  if (o.excitation == "noise") {
    add_noise_excitation(o, b.backend->sample_rate(), lo);
  } else if (o.excitation == "sine") {
    add_sine_excitation(o, b.backend->sample_rate(), lo);
  } else if (o.excitation != "none") {
    throw UsageError("--excitation", "none, noise or sine", "'" + o.excitation + "'");
  }
  if (!o.feedforward.empty()) {
    lo.feedforward = io::read_hysteresis_model(o.feedforward);
    lo.log_settings["feedforward"] = o.feedforward;
  }
  // The signals are kept in memory for the summary unless the run is long.
  lo.keep_log = o.duration <= 120.0;
  return lo;
}

// Extremes and rms of the logged signals (null when the log was not kept).
nlohmann::json signal_summary(const rt::LoopOptions& lo, const io::TimeSeries& log) {
  if (!lo.keep_log || log.samples() == 0) return nullptr;
  const auto rms = [](const Eigen::Ref<const Eigen::VectorXd>& v) { return std::sqrt(v.squaredNorm() / static_cast<double>(v.size())); };
  return {{"Va_min_V", log.channel("Va").minCoeff()},
          {"Va_max_V", log.channel("Va").maxCoeff()},
          {"Va_rms_V", rms(log.channel("Va"))},
          {"de_rms_um", rms(log.channel("de")) * 1e6},
          {"Vs_rms_V", rms(log.channel("Vs"))},
          {"u_prime_rms_V", rms(log.channel("u_prime"))},
          {"y_rms_V", rms(log.channel("y"))}};
}

// The --json document of a run: the loop's report (loop_report_json: rt::LoopReport's declared
// fields, its I/O rt::IoStats' as measure's, rejected included, its timing summaries rt::TimingSummary's), the limits
// (rt::ActuatorLimits' declared fields), and what only the command knows: the bench's source, the
// options, the log file and the signals computed from the log.
nlohmann::json rt_json(const RtOptions& o, const RtBench& b, const rt::LoopReport& r, const nlohmann::json& signals) {
  nlohmann::json doc = loop_report_json(r);
  doc.update({{"source", b.source},
              {"controller", o.controller},
              {"gain", o.gain},
              {"duration_s", o.duration},
              {"limits", io::results_object(b.limits)},
              {"log", o.log.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.log)},
              {"signals", signals}});
  return doc;
}

// The timing of the run: the cycles, where overruns come from, the latency percentiles.
void print_rt_timing(const rt::LoopReport& r) {
  fmt::print("real-time loop: {} backend, {:g} Hz, {} ({}SCHED_FIFO, {}mlockall)\n", r.backend, r.sample_rate,
             r.realtime ? "real time" : "lockstep", r.sched_fifo ? "" : "no ", r.memory_locked ? "" : "no ");
  fmt::print("cycles {}   overruns {}   skipped deadlines {}\n", r.cycles, r.overruns, r.skipped_deadlines);
  if (r.realtime) {
    // What the shared machine costs, then what this program costs (docs/realtime.md).
    fmt::print("host: {} overruns from late wake-ups, {} skipped deadlines", r.overruns_late_wakeup, r.skipped_deadlines);
    if (r.host_wait_ms >= 0.0) fmt::print(", loop thread waited {:.2f} ms for a core", r.host_wait_ms);
    if (r.host_preemptions >= 0) fmt::print(", preempted {} times", r.host_preemptions);
    fmt::print("\ncode: {} overruns from long steps, step time p50 {:.2f} us, max {:.2f} us of the {:.0f} us period\n",
               r.overruns_long_step, r.step_time_us.p50, r.step_time_us.max, 1e6 / r.sample_rate);
  }
  fmt::print("{:<16}{:>10}{:>10}{:>10}{:>10}   [us]\n", "", "p50", "p99", "p99.9", "max");
  auto row = [](const char* name, const rt::TimingSummary& s) {
    fmt::print("{:<16}{:>10.2f}{:>10.2f}{:>10.2f}{:>10.2f}\n", name, s.p50, s.p99, s.p999, s.max);
  };
  if (r.realtime) {
    row("period jitter", r.period_jitter_us);
    row("wake latency", r.wake_latency_us);
  }
  row("step time", r.step_time_us);
}

// The output and safety figures of the run, the I/O and the log.
void print_rt_outputs(const RtOptions& o, const rt::ActuatorLimits& limits, const rt::LoopReport& r) {
  fmt::print("output: Va commanded {:.2f} .. {:.2f} V (limits {:g} .. {:g} V), largest step {:.3g} V\n", r.va_cmd_min,
             r.va_cmd_max, limits.va_min, limits.va_max, r.max_va_cmd_step);
  fmt::print("clamped samples {}   slew-limited samples {}   safe state: {}{}   watchdog trips {}\n", r.clamped_samples,
             r.slew_limited_samples, r.safe_state_reason,
             r.safe_state_cycle >= 0 ? fmt::format(" (cycle {})", r.safe_state_cycle) : std::string(), r.watchdog_trips);
  if (r.io.exchanges > 0) {
    fmt::print("I/O: {} exchanges, {} lost, {} late, {} stale inputs, {} errors; round trip p50 {:.1f} us, p99 {:.1f} us\n",
               r.io.exchanges, r.io.lost, r.io.late, r.io.timeouts, r.io.errors, r.io.round_trip_us.p50,
               r.io.round_trip_us.p99);
  }
  if (r.safe_state_reason == rt::to_string(rt::Fault::kSaturation)) {
    fmt::print("the output was saturated for {:g} s (--saturation-time): the loop went to its safe state\n",
               limits.saturation_time);
  }
  if (!o.log.empty()) fmt::print("log: {} ({} samples, {} dropped)\n", o.log, r.logged_samples, r.dropped_log_samples);
}

int run_rt(const RtOptions& o) {
  if (o.controller != "iff" && o.controller != "off") {
    throw UsageError("--controller", "iff or off", "'" + o.controller + "'");
  }
  if (!(std::isfinite(o.rate) && o.rate > 0.0))
    throw UsageError("--rate", "a rate > 0 Hz", format_number_exact(o.rate));
  o.limits.validate();
  const RtBench b = open_bench(o);
  const rt::LoopOptions lo = loop_options(o, b);
  if (!o.json) {
    log_line(fmt::format("rt: {} backend, controller {}, g = {:g}, {:g} Hz, {:g} s, {}", b.backend->name(), o.controller,
                         o.gain, b.backend->sample_rate(), o.duration, o.realtime ? "real time" : "lockstep (as fast as possible)"));
  }
  io::TimeSeries log;
  const rt::LoopReport r = rt::run_loop(*b.backend, lo, &log);
  const nlohmann::json signals = signal_summary(lo, log);
  if (o.json) {
    print_json(rt_json(o, b, r, signals));
    return 0;
  }
  print_rt_timing(r);
  print_rt_outputs(o, b.limits, r);
  return 0;
}

bool parse_bool(const std::string& text, const std::string& option) {
  if (text == "true" || text == "1" || text == "yes" || text == "on") return true;
  if (text == "false" || text == "0" || text == "no" || text == "off") return false;
  throw UsageError(option, "true or false", "'" + text + "'");
}

}  // namespace

void add_rt_commands(CLI::App& app, Action& action) {
  auto o = std::make_shared<RtOptions>();
  auto realtime = std::make_shared<std::string>("true");
  CLI::App* rt = app.add_subcommand("rt", "Run the IFF loop u = u' + g K(z) Vs in real time on the virtual bench or a replayed record");
  rt->add_option("--bench", o->bench,
                 "I/O backend: virtual (the virtual bench in lockstep), replay (a recorded file) or a bench file "
                 "BENCH.toml (udp, comedi: its rate and limits; docs/hardware.md)")
      ->capture_default_str();
  rt->add_option("--controller", o->controller, "iff (eq. 2.4 discretized at the rate) or off (open loop)")->capture_default_str();
  rt->add_option("--gain", o->gain, "IFF gain g")->required();
  CLI::Option* rate = rt->add_option("--rate", o->rate, "loop rate, Hz (replay: the record's rate), at most 1e6")
                          ->check(number_in(0.0, rt::kMaxSampleRate))
                          ->capture_default_str();
  rt->add_option("--duration", o->duration, "run length, s")->capture_default_str();
  rt->add_option("--log", o->log, "write the signals of every cycle to this .mat (or .csv) file");
  rt->add_option("--unit", o->unit, "virtual bench: unit of the batch (1..7)")->capture_default_str();
  rt->add_option("--seed", o->seed, "virtual bench: unit and noise seed; excitation seed")->capture_default_str();
  rt->add_option("--excitation", o->excitation, "u': none, noise (band-limited, periodic) or sine")->capture_default_str();
  rt->add_option("--amplitude", o->amplitude, "noise rms or sine amplitude, V at the DAC")->capture_default_str();
  rt->add_option("--frequency", o->frequency, "sine frequency, Hz (a whole number of samples per period)")->capture_default_str();
  rt->add_option("--offset", o->offset, "sine offset, V at the DAC")->capture_default_str();
  rt->add_option("--hysteresis-law", o->hysteresis_law, kHysteresisLawHelp)->capture_default_str();
  rt->add_option("--feedforward", o->feedforward,
                 "hysteresis model (TOML, `hysteresis fit`): u' passes through its inverse before the safety clamp")
      ->check(input_file());
  rt->add_option("--band", o->band, "noise band LO,HI, Hz")->capture_default_str();
  rt->add_option("--replay", o->replay, "replay: the recorded file (.mat or .csv with channels de and Vs)");
  rt->add_option("--realtime", *realtime, "true: paced by absolute deadlines; false: lockstep, as fast as possible")
      ->capture_default_str();
  auto limit_options = std::make_shared<std::vector<CLI::Option*>>();
  limit_options->push_back(rt->add_option("--va-min", o->limits.va_min, "lowest stack voltage, V")->capture_default_str());
  limit_options->push_back(rt->add_option("--va-max", o->limits.va_max, "highest stack voltage, V")->capture_default_str());
  limit_options->push_back(
      rt->add_option("--slew-rate", o->limits.slew_rate, "largest stack-voltage slew rate, V/s")->capture_default_str());
  limit_options->push_back(rt->add_option("--ramp", o->ramp, "ramp in and out of the gain and output, s")->capture_default_str());
  limit_options->push_back(rt->add_option("--watchdog", o->limits.watchdog_timeout,
                                          "safe state when no cycle completes within this time, s")
                               ->capture_default_str());
  limit_options->push_back(rt->add_option("--saturation-time", o->limits.saturation_time,
                                          "safe state when the output has been saturated (clamped) this long, net, s")
                               ->capture_default_str());
  rt->add_flag("--fifo", o->fifo, "with a bench file: ask for SCHED_FIFO and mlockall (a message when not permitted)");
  rt->add_option("--priority", o->priority, "SCHED_FIFO priority of the loop thread (when permitted)")
      ->check(CLI::Range(1, 99))
      ->capture_default_str();
  rt->add_flag("--json", o->json, "print one JSON document on stdout");
  rt->callback([o, realtime, rate, limit_options, &action] {
    o->rate_given = rate->count() > 0;
    for (const CLI::Option* opt : *limit_options) o->limits_given = o->limits_given || opt->count() > 0;
    action = [o, realtime] {
      o->realtime = parse_bool(*realtime, "--realtime");
      return run_rt(*o);
    };
  });
}

}  // namespace piezobench::app
