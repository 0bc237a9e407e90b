#include "piezobench/bench/experiments.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <utility>

#include "flatness.hpp"
#include "piezobench/bench/tracking.hpp"
#include "piezobench/control/discrete_iff.hpp"
#include "piezobench/control/hysteresis_feedforward.hpp"
#include "piezobench/core/checked_number.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/memory.hpp"
#include "piezobench/core/timestamp.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/dsp/excitation.hpp"
#include "piezobench/lti/discretize.hpp"
#include "random.hpp"

namespace piezobench::bench {

namespace {

constexpr const char* kSource = "experiment options";

struct Named {
  Experiment e;
  const char* name;
};
constexpr Named kNames[] = {{Experiment::kStroke, "stroke"},     {Experiment::kHysteresis, "hysteresis"},
                            {Experiment::kStiffness, "stiffness"}, {Experiment::kFrfNoise, "frf-noise"},
                            {Experiment::kFrfSweep, "frf-sweep"},  {Experiment::kIff, "iff"},
                            {Experiment::kHammer, "hammer"},       {Experiment::kFlatness, "flatness"},
                            {Experiment::kCapacitance, "capacitance"}, {Experiment::kTracking, "tracking"}};

std::string known_names() {
  std::string s;
  for (const Named& n : kNames) s += (s.empty() ? "" : ", ") + std::string(n.name);
  return s;
}

bool uses_amplitude(Experiment e) {
  return e == Experiment::kHysteresis || e == Experiment::kTracking || e == Experiment::kFrfNoise || e == Experiment::kFrfSweep || e == Experiment::kIff;
}
bool uses_duration(Experiment e) {
  return e == Experiment::kFrfNoise || e == Experiment::kFrfSweep || e == Experiment::kIff;
}

// The settings every record carries; `runner` adds where it was made (bench experiments).
void common_settings(io::TimeSeries& ts, Experiment e, const UnitTruth& unit, const BenchOptions& b, std::uint64_t seed,
                     const BenchRunner* runner) {
  // Provenance (checked by `run` against the campaign): what, which unit, where, when.
  ts.settings["experiment"] = to_string(e);
  ts.settings["unit"] = static_cast<double>(unit.id);
  ts.settings["bench"] = std::string("virtual");  // a bench runner's describe() names its bench
  ts.settings["recorded_at"] = utc_timestamp_now();
  // Seeds up to 2^53 are numbers; larger ones would lose digits as doubles, so they are text.
  if (seed <= (std::uint64_t{1} << 53)) {
    ts.settings["seed"] = static_cast<double>(seed);
  } else {
    ts.settings["seed"] = std::to_string(seed);
  }
  ts.settings["defective"] = unit.defective ? 1.0 : 0.0;
  if (runner != nullptr) {
    ts.settings["amplifier_gain_V_per_V"] = b.amplifier_gain;
    ts.settings["va_min_V"] = b.va_min;
    ts.settings["va_max_V"] = b.va_max;
    ts.settings["suspended_mass_kg"] = b.suspended_mass;
    ts.settings["hpf_resistance_ohm"] = b.hpf_resistance;
    ts.settings["hpf_resistor"] = b.hpf_resistor ? 1.0 : 0.0;
    ts.settings["sensor_shunt_ohm"] = b.sensor_shunt_resistance();
    ts.settings["actuator_circuit"] = std::string(b.actuator_open_circuit ? "open" : "short");
  }
  ts.settings["noise"] = b.noise ? 1.0 : 0.0;
  if (runner != nullptr) runner->describe(ts);
}

io::TimeSeries make_record(const std::vector<std::string>& names, const std::vector<std::string>& units, Eigen::Index rows,
                           double fs, bool with_t) {
  io::TimeSeries ts;
  ts.names = names;
  ts.units = units;
  ts.data.resize(rows, static_cast<Eigen::Index>(names.size()));
  ts.sample_rate = fs;
  if (with_t) ts.t = Eigen::VectorXd::LinSpaced(rows, 0.0, static_cast<double>(rows - 1) / fs);
  return ts;
}

// Calls progress now and then: at most every 2^16 samples.
struct Progressor {
  const Progress& progress;
  Eigen::Index total;
  mutable Eigen::Index next = 0;
  void operator()(Eigen::Index k) const {
    if (progress && k >= next) {
      progress(static_cast<double>(k) / static_cast<double>(std::max<Eigen::Index>(total, 1)));
      next = k + 65536;
    }
  }
  void done() const {
    if (progress) progress(1.0);
  }
};

// Refuses an excitation whose stack voltage G u leaves [va_min, va_max], naming the limit.
void check_range(const Eigen::VectorXd& u, const BenchOptions& b, const std::string& what) {
  const double lo = b.amplifier_gain * u.minCoeff();
  const double hi = b.amplifier_gain * u.maxCoeff();
  if (lo < b.va_min - 1e-9 || hi > b.va_max + 1e-9) {
    throw InputError(
        kSource, "amplitude",
        fmt::format("{} whose stack voltage stays within the actuator's range {} V .. {} V", what,
                    format_number_exact(b.va_min), format_number_exact(b.va_max)),
        fmt::format("a stack voltage from {} V to {} V (limit {} V exceeded)", format_number(lo, 4),
                    format_number(hi, 4), format_number_exact(hi > b.va_max + 1e-9 ? b.va_max : b.va_min)));
  }
}

std::uint64_t stream(Experiment e, std::uint64_t which) { return 1000 * (static_cast<std::uint64_t>(e) + 1) + which; }

// ---------------------------------------------------------------------------------------------

io::TimeSeries stroke(BenchRunner& runner, const UnitTruth& unit, const ExperimentOptions& o, std::uint64_t seed,
                      const Progress& progress) {
  const BenchOptions& b = o.bench;
  const double fs = b.sample_rate;
  const double ramp_s = 10.0;  // s for va_min -> va_max
  const double rate = (b.va_max - b.va_min) / ramp_s;
  const double hold = 1.0;
  // 0 -> va_min -> va_max -> va_min -> 0, holds at both ends.
  const double t1 = hold, t2 = t1 - b.va_min / rate, t3 = t2 + ramp_s, t4 = t3 + ramp_s, t5 = t4 - b.va_min / rate;
  const double total = t5 + hold;
  const auto n = static_cast<Eigen::Index>(std::ceil(total * fs));
  Eigen::VectorXd u(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / fs;
    double va = 0.0;
    if (t < t1) {
      va = 0.0;
    } else if (t < t2) {
      va = -rate * (t - t1);
    } else if (t < t3) {
      va = b.va_min + rate * (t - t2);
    } else if (t < t4) {
      va = b.va_max - rate * (t - t3);
    } else if (t < t5) {
      va = b.va_min + rate * (t - t4);
    }
    u(k) = va / b.amplifier_gain;
  }
  Eigen::MatrixXd y;  // u, Va, de, Vs at the bench's rate
  runner.open_loop(u, experiment_bench_seed(Experiment::kStroke, seed), y, progress);
  // The displacement probe (Millimar 1318): first-order bandwidth, noise; recorded at 1 kHz.
  const double probe_bw = 2.0;      // Hz
  const double probe_noise = 10e-9;  // m rms
  const auto decimation = std::max<Eigen::Index>(1, static_cast<Eigen::Index>(std::llround(fs / 1000.0)));
  const double a = -std::expm1(-kTwoPi * probe_bw / fs);
  detail::Xoshiro256 rng(detail::derive_seed(seed, stream(Experiment::kStroke, 1)));
  const Eigen::Index rows = (n + decimation - 1) / decimation;
  io::TimeSeries ts = make_record({"u", "Va", "de"}, {"V", "V", "m"}, rows, fs / static_cast<double>(decimation), true);
  double probe = 0.0;
  for (Eigen::Index k = 0; k < n; ++k) {
    probe += a * (y(k, 2) - probe);
    if (k % decimation == 0) {
      const Eigen::Index r = k / decimation;
      ts.data(r, 0) = y(k, 0);
      ts.data(r, 1) = y(k, 1);
      ts.data(r, 2) = probe + (b.noise ? probe_noise * rng.normal() : 0.0);
    }
  }
  common_settings(ts, Experiment::kStroke, unit, b, seed, &runner);
  ts.settings["ramp_s"] = ramp_s;
  ts.settings["probe_bandwidth_Hz"] = probe_bw;
  ts.settings["probe_noise_m"] = probe_noise;
  return ts;
}

// A record of the open-loop channels u, Va, de (and Vs when `with_vs`) from the runner's columns.
io::TimeSeries open_loop_record(Eigen::MatrixXd&& y, double fs, bool with_vs) {
  io::TimeSeries ts = with_vs ? make_record({"u", "Va", "de", "Vs"}, {"V", "V", "m", "V"}, 0, fs, false)
                              : make_record({"u", "Va", "de"}, {"V", "V", "m"}, 0, fs, false);
  ts.t.resize(y.rows());
  core::advise_huge_pages(ts.t.data(), static_cast<std::size_t>(y.rows()) * sizeof(double));
  ts.t = Eigen::VectorXd::LinSpaced(y.rows(), 0.0, static_cast<double>(y.rows() - 1) / fs);
  if (with_vs) {
    ts.data = std::move(y);  // a 100 s record is 32 MB: moved, not copied
  } else {
    ts.data = y.leftCols(3);
  }
  return ts;
}

io::TimeSeries hysteresis(BenchRunner& runner, const UnitTruth& unit, const ExperimentOptions& o, std::uint64_t seed,
                          const Progress& progress) {
  const BenchOptions& b = o.bench;
  const double amplitude = o.amplitude.value_or(20.0);
  const double offset = 0.5 * (b.va_min + b.va_max);  // 65 V for -20..150 V
  if (offset - amplitude < b.va_min - 1e-12 || offset + amplitude > b.va_max + 1e-12) {
    throw InputError(
        kSource, "amplitude",
        fmt::format("an amplitude <= {} V (offset {} V, stack range {} V .. {} V)",
                    format_number(std::min(offset - b.va_min, b.va_max - offset)), format_number_exact(offset),
                    format_number_exact(b.va_min), format_number_exact(b.va_max)),
        fmt::format("{} V", format_number_exact(amplitude)));
  }
  dsp::OffsetSineOptions s;
  s.sample_rate = b.sample_rate;
  s.rest = 0.0;
  s.offset = offset / b.amplifier_gain;
  s.amplitude = amplitude / b.amplifier_gain;
  s.frequency = 1.0;
  s.cycles = 3.0;
  s.ramp_time = 1.0;
  dsp::VoltageBounds bounds{b.va_min / b.amplifier_gain - 1e-9, b.va_max / b.amplifier_gain + 1e-9, dsp::BoundsPolicy::kReject};
  const dsp::Excitation ex = dsp::offset_sine(s, bounds);
  Eigen::MatrixXd y;
  runner.open_loop(ex.u, experiment_bench_seed(Experiment::kHysteresis, seed), y, progress);
  io::TimeSeries ts = open_loop_record(std::move(y), b.sample_rate, false);
  common_settings(ts, Experiment::kHysteresis, unit, b, seed, &runner);
  ts.settings["amplitude_V"] = amplitude;
  ts.settings["offset_V"] = offset;
  ts.settings["frequency_Hz"] = s.frequency;
  ts.settings["periods"] = s.cycles;
  ts.settings["ramp_s"] = s.ramp_time;
  return ts;
}

io::TimeSeries stiffness(BenchRunner& runner, const UnitTruth& unit, const ExperimentOptions& o, std::uint64_t seed,
                         const Progress& progress) {
  const BenchOptions& b = o.bench;
  if (!(b.added_mass > 0.0)) throw InputError(kSource, "bench.added_mass", "a mass > 0 kg for the stiffness test", "0");
  const double fs = b.sample_rate;
  const double duration = 20.0, t_on = 3.0, t_off = 13.0, ramp = 0.5;
  const auto n = static_cast<Eigen::Index>(std::llround(duration * fs));
  const std::vector<OperatorStep> steps = {
      {t_on, fmt::format("put the {:g} kg mass on the suspended mass", b.added_mass), b.added_mass, ramp},
      {t_off, fmt::format("take the {:g} kg mass off", b.added_mass), 0.0, ramp}};
  Eigen::MatrixXd y;
  const std::vector<double> done =
      runner.hold(n, steps, experiment_bench_seed(Experiment::kStiffness, seed), y, progress);
  io::TimeSeries ts = make_record({"de", "added_mass"}, {"m", "kg"}, n, fs, true);
  ts.data = y;
  common_settings(ts, Experiment::kStiffness, unit, b, seed, &runner);
  ts.settings["added_mass_kg"] = b.added_mass;
  ts.settings["t_on_s"] = done.at(0);
  ts.settings["t_off_s"] = done.at(1);
  ts.settings["ramp_s"] = ramp;
  ts.settings["gravity_m_per_s2"] = b.gravity;
  ts.settings["duration_s"] = duration;
  return ts;
}

// Band-limited noise on u (0.1 Hz or 1/duration .. 2 kHz) of va_rms volts rms at the stacks, checked
// against the stack voltage range, with the options that made it. Shared by frf-noise and iff.
struct StackNoise {
  dsp::NoiseOptions options;
  dsp::Excitation excitation;
};
StackNoise stack_noise(const BenchOptions& b, double duration, double va_rms, std::uint64_t noise_seed) {
  dsp::NoiseOptions no;
  no.sample_rate = b.sample_rate;
  no.samples = static_cast<Eigen::Index>(std::llround(duration * b.sample_rate));
  no.f_low = std::max(0.1, b.sample_rate / static_cast<double>(std::max<Eigen::Index>(no.samples, 1)));
  no.f_high = std::min(2000.0, 0.4 * b.sample_rate);
  no.rms = va_rms / b.amplifier_gain;
  no.seed = noise_seed;
  if (no.samples < 2 || no.f_low >= no.f_high) {
    throw InputError(kSource, "duration", "a record long enough for the noise band (at least 2 samples)",
                     fmt::format("{} s", format_number_exact(duration)));
  }
  dsp::Excitation ex = dsp::band_limited_noise(no, {-1e300, 1e300, dsp::BoundsPolicy::kReject});
  check_range(ex.u, b, fmt::format("a noise of {:g} V rms at the stacks", va_rms));
  return {no, std::move(ex)};
}

io::TimeSeries frf_noise(BenchRunner& runner, const UnitTruth& unit, const ExperimentOptions& o, std::uint64_t seed,
                         const Progress& progress) {
  const BenchOptions& b = o.bench;
  const double duration = o.duration.value_or(20.0);
  const double va_rms = o.amplitude.value_or(2.0);
  const StackNoise noise = stack_noise(b, duration, va_rms, detail::derive_seed(seed, stream(Experiment::kFrfNoise, 1)));
  const dsp::NoiseOptions& no = noise.options;
  const dsp::Excitation& ex = noise.excitation;
  Eigen::MatrixXd y;
  runner.open_loop(ex.u, experiment_bench_seed(Experiment::kFrfNoise, seed), y, progress);
  io::TimeSeries ts = open_loop_record(std::move(y), b.sample_rate, true);
  common_settings(ts, Experiment::kFrfNoise, unit, b, seed, &runner);
  ts.settings["duration_s"] = duration;
  ts.settings["rms_V"] = no.rms;
  ts.settings["va_rms_V"] = va_rms;
  ts.settings["band_low_Hz"] = no.f_low;
  ts.settings["band_high_Hz"] = no.f_high;
  return ts;
}

io::TimeSeries frf_sweep(BenchRunner& runner, const UnitTruth& unit, const ExperimentOptions& o, std::uint64_t seed,
                         const Progress& progress) {
  const BenchOptions& b = o.bench;
  const double duration = o.duration.value_or(20.0);
  const double va_amplitude = o.amplitude.value_or(1.0);
  if (va_amplitude > std::min(-b.va_min, b.va_max) + 1e-12) {
    throw InputError(kSource, "amplitude",
                     fmt::format("an amplitude <= {} V (a sweep about 0 V within the stack range {} V .. {} V)",
                                 format_number(std::min(-b.va_min, b.va_max)), format_number_exact(b.va_min),
                                 format_number_exact(b.va_max)),
                     fmt::format("{} V", format_number_exact(va_amplitude)));
  }
  dsp::SweepOptions so;
  so.sample_rate = b.sample_rate;
  so.duration = duration;
  so.f_start = 1.0;
  so.f_end = std::min(2000.0, 0.4 * b.sample_rate);
  so.amplitude = va_amplitude / b.amplifier_gain;
  so.ramp_time = std::min(0.1, 0.25 * duration);
  so.type = dsp::SweepType::kLogarithmic;
  const dsp::Excitation ex = dsp::sine_sweep(so, {-1e300, 1e300, dsp::BoundsPolicy::kReject});
  check_range(ex.u, b, fmt::format("a sweep of {:g} V amplitude at the stacks", va_amplitude));
  Eigen::MatrixXd y;
  runner.open_loop(ex.u, experiment_bench_seed(Experiment::kFrfSweep, seed), y, progress);
  io::TimeSeries ts = open_loop_record(std::move(y), b.sample_rate, true);
  common_settings(ts, Experiment::kFrfSweep, unit, b, seed, &runner);
  ts.settings["duration_s"] = duration;
  ts.settings["f0_Hz"] = so.f_start;
  ts.settings["f1_Hz"] = so.f_end;
  ts.settings["amplitude_V"] = so.amplitude;
  ts.settings["va_amplitude_V"] = va_amplitude;
  ts.settings["sweep"] = std::string("log");
  return ts;
}

io::TimeSeries iff(BenchRunner& runner, const UnitTruth& unit, const ExperimentOptions& o, std::uint64_t seed,
                   const Progress& progress) {
  const BenchOptions& b = o.bench;
  const double duration = o.duration.value_or(10.0);
  const double va_rms = o.amplitude.value_or(2.0);
  const double gain = o.gain.value_or(280000.0);
  const StackNoise noise = stack_noise(b, duration, va_rms, detail::derive_seed(seed, stream(Experiment::kIff, 1)));
  const dsp::NoiseOptions& no = noise.options;
  const dsp::Excitation& ex = noise.excitation;
  const Eigen::Index n = ex.u.size();
  Eigen::MatrixXd y;
  const std::uint64_t clamped = runner.iff(ex.u, gain, experiment_bench_seed(Experiment::kIff, seed), y, progress);
  io::TimeSeries ts = make_record({"u_prime", "u", "Va", "de", "Vs"}, {"V", "V", "V", "m", "V"}, n, b.sample_rate, true);
  ts.data.col(0) = ex.u;
  ts.data.rightCols(4) = y;
  common_settings(ts, Experiment::kIff, unit, b, seed, &runner);
  ts.settings["gain"] = gain;
  ts.settings["duration_s"] = duration;
  ts.settings["rms_V"] = no.rms;
  ts.settings["va_rms_V"] = va_rms;
  ts.settings["band_low_Hz"] = no.f_low;
  ts.settings["band_high_Hz"] = no.f_high;
  ts.settings["clamped_samples"] = static_cast<double>(clamped);
  ts.settings["controller"] = std::string("K(s) = -10 g s/(s + 2 pi 2) / (s + 2 pi 20) / (s + 2 pi 2000), Tustin prewarped at 95.2 Hz");
  return ts;
}

// The tracking experiment's waveform: a raised-cosine ramp to the offset, `kTrackingPeriods` sine
// periods, as many triangle periods, a ramp back to 0 V.
constexpr double kTrackingFrequency = 1.0;  // Hz
constexpr double kTrackingRamp = 1.0;       // s
constexpr int kTrackingPeriods = 3;

void check_tracking_amplitude(const BenchOptions& b, double amplitude, double offset) {
  if (offset - amplitude < b.va_min - 1e-12 || offset + amplitude > b.va_max + 1e-12) {
    throw InputError(
        kSource, "amplitude",
        fmt::format("an amplitude <= {} V (offset {} V, stack range {} V .. {} V)",
                    format_number(std::min(offset - b.va_min, b.va_max - offset)), format_number_exact(offset),
                    format_number_exact(b.va_min), format_number_exact(b.va_max)),
        fmt::format("{} V", format_number_exact(amplitude)));
  }
}

// Command (V at the stacks) and the weight of the feedforward: the raised-cosine ramps' w.
struct TrackingCommand {
  std::vector<double> c;
  Eigen::VectorXd weight;
};

TrackingCommand tracking_command(double offset, double amplitude, double fs) {
  const double frequency = kTrackingFrequency, ramp = kTrackingRamp;
  const int periods = kTrackingPeriods;
  const auto n_ramp = static_cast<Eigen::Index>(std::llround(ramp * fs));
  const auto n_wave = static_cast<Eigen::Index>(std::llround(periods / frequency * fs));
  const Eigen::Index n = 2 * n_ramp + 2 * n_wave;
  TrackingCommand cmd{std::vector<double>(static_cast<std::size_t>(n)), Eigen::VectorXd::Ones(n)};
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / fs;
    double v = 0.0, w = 1.0;
    if (k < n_ramp) {
      w = 0.5 - 0.5 * std::cos(std::numbers::pi * t / ramp);
      v = offset * w;
    } else if (k < n_ramp + n_wave) {
      v = offset + amplitude * std::sin(kTwoPi * frequency * (t - ramp));
    } else if (k < n_ramp + 2 * n_wave) {
      // Triangle from the offset upwards: 0 -> 1 -> -1 -> 0 per period.
      double phase = frequency * (t - ramp) - periods;
      phase -= std::floor(phase);
      const double tri = phase < 0.25 ? 4.0 * phase : phase < 0.75 ? 2.0 - 4.0 * phase : 4.0 * phase - 4.0;
      v = offset + amplitude * tri;
    } else {
      w = 0.5 + 0.5 * std::cos(std::numbers::pi * (t - ramp - 2.0 * periods / frequency) / ramp);
      v = offset * w;
    }
    cmd.c[static_cast<std::size_t>(k)] = v;
    cmd.weight(k) = w;
  }
  return cmd;
}

// The hysteresis model of the open run (its fit's relative residual in fit_residual).
ident::HysteresisModel identify_tracking_model(const Eigen::MatrixXd& open, std::size_t n, double fs, double& fit_residual) {
  const Eigen::VectorXd va = open.col(1), de = open.col(2);
  ident::HysteresisFitOptions fo;
  fo.creep_time_constants = {1.0, 10.0};
  const ident::HysteresisFit fit = ident::fit_hysteresis({va.data(), n}, {de.data(), n}, fs, fo);
  fit_residual = fit.relative_residual;
  return fit.model;
}

// The figures over the last periods - 1 periods of each waveform (the first one settles the loop).
void add_tracking_figures(io::TimeSeries& ts) {
  const TrackingLayout layout = tracking_layout(ts);
  const auto figures = [&](Eigen::Index begin, Eigen::Index end) {
    const auto col = [&](Eigen::Index j) { return std::span<const double>(ts.data.col(j).data() + begin, static_cast<std::size_t>(end - begin)); };
    return tracking_figures(col(0), col(2), col(4), layout.target_slope, layout.target_intercept);
  };
  const TrackingFigures sine = figures(layout.sine_begin, layout.sine_end);
  const TrackingFigures tri = figures(layout.triangle_begin, layout.triangle_end);
  for (const auto& [name, f] : {std::pair<const char*, const TrackingFigures&>{"sine", sine}, {"triangle", tri}}) {
    const std::string w(name);
    ts.settings["width_open_" + w] = f.width_open;
    ts.settings["width_ff_" + w] = f.width_ff;
    ts.settings["rms_open_" + w + "_m"] = f.rms_open;
    ts.settings["rms_ff_" + w + "_m"] = f.rms_ff;
    ts.settings["stroke_open_" + w + "_m"] = f.stroke_open;
  }
  ts.settings["window_sine_samples"] = fmt::format("{}..{}", layout.sine_begin, layout.sine_end);
  ts.settings["window_triangle_samples"] = fmt::format("{}..{}", layout.triangle_begin, layout.triangle_end);
}

// The tracking experiment (bench/tracking.hpp).
io::TimeSeries tracking(BenchRunner& runner, const UnitTruth& unit, const ExperimentOptions& o, std::uint64_t seed,
                        const Progress& progress) {
  const BenchOptions& b = o.bench;
  const double fs = b.sample_rate;
  const double amplitude = o.amplitude.value_or(80.0);
  const double offset = 0.5 * (b.va_min + b.va_max);
  check_tracking_amplitude(b, amplitude, offset);
  const TrackingCommand cmd = tracking_command(offset, amplitude, fs);
  const auto n = static_cast<Eigen::Index>(cmd.c.size());
  auto progress_part = [&](double from, double span) -> Progress {
    if (!progress) return {};
    return [&progress, from, span](double p) { progress(from + span * p); };
  };
  Eigen::VectorXd u(n);
  for (Eigen::Index k = 0; k < n; ++k) u(k) = cmd.c[static_cast<std::size_t>(k)] / b.amplifier_gain;
  Eigen::MatrixXd open, comp;  // u, Va, de, Vs
  runner.open_loop(u, experiment_bench_seed(Experiment::kTracking, seed), open, progress_part(0.0, 0.5));

  double fit_residual = 0.0;
  const bool identified = !o.feedforward.has_value();
  const ident::HysteresisModel model = identified ? identify_tracking_model(open, static_cast<std::size_t>(n), fs, fit_residual) : *o.feedforward;
  // The compensated run: the same command through the runner's live feedforward stage, blended in
  // and out over the ramps (the run starts and ends at 0 V).
  const std::uint64_t clamped = runner.open_loop_feedforward(u, cmd.weight, model, detail::derive_seed(seed, stream(Experiment::kTracking, 1)),
                                                             comp, progress_part(0.5, 0.5));

  io::TimeSeries ts = make_record({"c", "Va_open", "de_open", "Va_ff", "de_ff"}, {"V", "V", "m", "V", "m"}, n, fs, true);
  ts.data.col(0) = Eigen::Map<const Eigen::VectorXd>(cmd.c.data(), n);
  ts.data.col(1) = open.col(1);
  ts.data.col(2) = open.col(2);
  ts.data.col(3) = comp.col(1);
  ts.data.col(4) = comp.col(2);
  common_settings(ts, Experiment::kTracking, unit, b, seed, &runner);
  ts.settings["amplitude_V"] = amplitude;
  ts.settings["offset_V"] = offset;
  ts.settings["frequency_Hz"] = kTrackingFrequency;
  ts.settings["periods"] = static_cast<double>(kTrackingPeriods);
  ts.settings["ramp_s"] = kTrackingRamp;
  ts.settings["feedforward"] = std::string(identified ? "identified" : "given");
  if (identified) ts.settings["fit_relative_residual"] = fit_residual;
  ts.settings["clamped_samples"] = static_cast<double>(clamped);
  ts.settings["target_slope_m_per_V"] = model.gain * model.reference_slope;
  ts.settings["target_intercept_m"] = model.offset + model.gain * model.reference_intercept;
  add_tracking_figures(ts);
  return ts;
}

io::TimeSeries hammer(const UnitTruth& unit, const ExperimentOptions& o, std::uint64_t seed, const Progress& progress) {
  const BenchOptions& b = o.bench;
  const double fs = b.sample_rate;
  const int impacts = 5;
  const double spacing = 2.0, first = 0.5, width = 1e-3;
  const auto n = static_cast<Eigen::Index>(std::llround((first + spacing * impacts) * fs));
  detail::Xoshiro256 rng(experiment_bench_seed(Experiment::kHammer, seed));
  // Impact force: half-sine pulses of 1 ms, 50..150 N.
  Eigen::VectorXd force = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < impacts; ++i) {
    const double peak = 50.0 + 100.0 * rng.uniform();
    const double t0 = first + spacing * i;
    for (Eigen::Index k = static_cast<Eigen::Index>(std::floor(t0 * fs)); k < n; ++k) {
      const double t = static_cast<double>(k) / fs - t0;
      if (t > width) break;
      if (t >= 0.0) force(k) = peak * std::sin(std::numbers::pi * t / width);
    }
  }
  // Fixed-free actuator: two bending modes seen by the vibrometer, v = sum F / m_j s / (s^2 + 2 z w s + w^2).
  const double modal_mass[2] = {0.35, 0.5};  // kg, at the impact and measurement points
  const double freq[2] = {unit.mode_y_Hz, unit.mode_x_Hz};
  Eigen::VectorXd v = Eigen::VectorXd::Zero(n);
  for (int j = 0; j < 2; ++j) {
    const double w = kTwoPi * freq[j];
    lti::Matrix a(2, 2), bm(2, 1), c(1, 2), d = lti::Matrix::Zero(1, 1);
    a << 0.0, 1.0, -w * w, -2.0 * unit.mode_damping * w;
    bm << 0.0, 1.0 / modal_mass[j];
    c << 0.0, 1.0;
    const lti::StateSpace sd = lti::c2d(lti::StateSpace(a, bm, c, d), 1.0 / fs);
    double x0 = 0.0, x1 = 0.0;
    for (Eigen::Index k = 0; k < n; ++k) {
      v(k) += x1;
      const double n0 = sd.A(0, 0) * x0 + sd.A(0, 1) * x1 + sd.B(0, 0) * force(k);
      const double n1 = sd.A(1, 0) * x0 + sd.A(1, 1) * x1 + sd.B(1, 0) * force(k);
      x0 = n0;
      x1 = n1;
    }
  }
  const double force_noise = 0.02, velocity_noise = 1e-5;  // N rms, m/s rms
  io::TimeSeries ts = make_record({"F", "v"}, {"N", "m/s"}, n, fs, true);
  for (Eigen::Index k = 0; k < n; ++k) {
    ts.data(k, 0) = force(k) + (b.noise ? force_noise * rng.normal() : 0.0);
    ts.data(k, 1) = v(k) + (b.noise ? velocity_noise * rng.normal() : 0.0);
  }
  if (progress) progress(1.0);
  common_settings(ts, Experiment::kHammer, unit, b, seed, nullptr);
  ts.settings["impacts"] = static_cast<double>(impacts);
  ts.settings["pulse_width_s"] = width;
  ts.settings["impact_spacing_s"] = spacing;
  ts.settings["force_noise_N"] = force_noise;
  ts.settings["velocity_noise_m_per_s"] = velocity_noise;
  return ts;
}

io::TimeSeries flatness(const UnitTruth& unit, const ExperimentOptions& o, std::uint64_t seed) {
  const double probe_noise = 0.5e-6;  // m: the probe's specified accuracy, a uniform error within +-
  detail::Xoshiro256 rng(experiment_bench_seed(Experiment::kFlatness, seed));
  const Eigen::Matrix<double, 8, 3> layout = detail::probe_layout();
  const Eigen::Matrix<double, 8, 1> z = detail::probe_heights(unit);
  // The part sits in its clamp with some tilt and height of its own (removed by the plane fit).
  const double ax = 2e-4 * rng.symmetric(), ay = 2e-4 * rng.symmetric(), z0 = 1e-3 * rng.symmetric();
  io::TimeSeries ts = make_record({"x", "y", "z", "interface"}, {"m", "m", "m", ""}, 8, 1.0, false);
  for (int i = 0; i < 8; ++i) {
    ts.data(i, 0) = layout(i, 0);
    ts.data(i, 1) = layout(i, 1);
    ts.data(i, 2) = z0 + ax * layout(i, 0) + ay * layout(i, 1) + z(i) + (o.bench.noise ? probe_noise * rng.symmetric() : 0.0);
    ts.data(i, 3) = layout(i, 2);
  }
  common_settings(ts, Experiment::kFlatness, unit, o.bench, seed, nullptr);
  ts.settings["probe_noise_m"] = probe_noise;
  return ts;
}

io::TimeSeries capacitance(const UnitTruth& unit, const ExperimentOptions& o, std::uint64_t seed) {
  const double accuracy = 5e-4;  // LCR-819: 0.05 %, a uniform error within +-
  detail::Xoshiro256 rng(experiment_bench_seed(Experiment::kCapacitance, seed));
  io::TimeSeries ts = make_record({"C_sensor", "C_actuator"}, {"F", "F"}, 1, 1.0, false);
  const double e1 = o.bench.noise ? accuracy * rng.symmetric() : 0.0;
  const double e2 = o.bench.noise ? accuracy * rng.symmetric() : 0.0;
  ts.data(0, 0) = unit.capacitance_sensor * (1.0 + e1);
  ts.data(0, 1) = unit.capacitance_actuator * (1.0 + e2);
  common_settings(ts, Experiment::kCapacitance, unit, o.bench, seed, nullptr);
  ts.settings["frequency_Hz"] = 1000.0;
  ts.settings["accuracy_relative"] = accuracy;
  return ts;
}

}  // namespace

std::uint64_t experiment_bench_seed(Experiment experiment, std::uint64_t seed) noexcept {
  return detail::derive_seed(seed, stream(experiment, 0));
}

VirtualRunner::VirtualRunner(const UnitTruth& unit, const BenchOptions& options) : unit_(unit), options_(options) {}
VirtualRunner::~VirtualRunner() = default;

VirtualBench& VirtualRunner::bench(std::uint64_t seed) {
  bench_ = std::make_unique<VirtualBench>(unit_, options_, seed);
  return *bench_;
}

void VirtualRunner::open_loop(const Eigen::VectorXd& u, std::uint64_t seed, Eigen::MatrixXd& out, const Progress& progress) {
  VirtualBench& b = bench(seed);
  const Eigen::Index n = u.size();
  out.resize(n, 4);
  core::advise_huge_pages(out.data(), static_cast<std::size_t>(out.size()) * sizeof(double));
  out.col(0) = u;
  const Progressor p{progress, n};
  constexpr Eigen::Index kBlock = 4096;
  std::vector<BenchSample> block(static_cast<std::size_t>(kBlock));
  const auto record = [&](Eigen::Index k, const BenchSample& s) {
    out(k, 1) = s.va;
    out(k, 2) = s.de;
    out(k, 3) = s.vs;
  };
  const BenchSample rest = b.step(0.0);
  if (n > 0) record(0, rest);
  for (Eigen::Index k = 0; k + 1 < n; k += kBlock) {
    const Eigen::Index count = std::min(kBlock, n - 1 - k);
    b.run(std::span<const double>(u.data() + k, static_cast<std::size_t>(count)),
          std::span<BenchSample>(block.data(), static_cast<std::size_t>(count)));
    for (Eigen::Index i = 0; i < count; ++i) record(k + 1 + i, block[static_cast<std::size_t>(i)]);
    p(k);
  }
  p.done();
}

std::uint64_t VirtualRunner::open_loop_feedforward(const Eigen::VectorXd& u_prime, const Eigen::VectorXd& w, const ident::HysteresisModel& model,
                                                   std::uint64_t seed, Eigen::MatrixXd& out, const Progress& progress) {
  if (w.size() != u_prime.size()) {
    throw InputError("virtual bench", "feedforward weight", fmt::format("{} samples (the command's)", u_prime.size()), std::to_string(w.size()));
  }
  // The stage sample by sample (causal: what it gives at k depends on u'[0..k] only, as in the loop),
  // then the real-time target's clamp; the virtual bench has no feedback to wait for.
  control::HysteresisFeedforward ff(model, options_.sample_rate);
  const double amp = options_.amplifier_gain, u_min = options_.va_min / amp, u_max = options_.va_max / amp;
  Eigen::VectorXd u(u_prime.size());
  std::uint64_t clamped = 0;
  for (Eigen::Index k = 0; k < u.size(); ++k) {
    const double v = ff.step(u_prime(k) * amp, w(k)) / amp;
    u(k) = std::clamp(v, u_min, u_max);
    if (u(k) != v) ++clamped;
  }
  open_loop(u, seed, out, progress);
  return clamped;
}

std::uint64_t VirtualRunner::iff(const Eigen::VectorXd& u_prime, double gain, std::uint64_t seed, Eigen::MatrixXd& out,
                                 const Progress& progress) {
  VirtualBench& b = bench(seed);
  control::DiscreteIffOptions co;
  co.sample_rate = options_.sample_rate;
  control::DiscreteIff controller(control::IffControllerParams{}, co, gain);
  // The real-time target's safety clamp: u stays inside the stack range seen at the DAC.
  const double u_min = options_.va_min / options_.amplifier_gain, u_max = options_.va_max / options_.amplifier_gain;
  const Eigen::Index n = u_prime.size();
  out.resize(n, 4);
  const Progressor p{progress, n};
  BenchSample m = b.step(0.0);
  std::uint64_t clamped = 0;
  for (Eigen::Index k = 0; k < n; ++k) {
    const double y = controller.step(m.vs);
    double u = u_prime(k) + y;
    if (u < u_min || u > u_max) {
      u = std::clamp(u, u_min, u_max);
      controller.applied(u - u_prime(k));
      ++clamped;
    }
    out(k, 0) = u;
    out(k, 1) = m.va;
    out(k, 2) = m.de;
    out(k, 3) = m.vs;
    m = b.step(u);
    p(k);
  }
  p.done();
  return clamped;
}

std::vector<double> VirtualRunner::hold(Eigen::Index n, const std::vector<OperatorStep>& steps, std::uint64_t seed,
                                        Eigen::MatrixXd& out, const Progress& progress) {
  VirtualBench& b = bench(seed);
  const double fs = options_.sample_rate;
  out.resize(n, 2);
  // The virtual operator lowers (lifts) the weight with a raised cosine over each step's ramp; the
  // mass rides on the bench from the moment it touches it until it is lifted off.
  const auto raised = [](double x) { return 0.5 - 0.5 * std::cos(std::numbers::pi * std::clamp(x, 0.0, 1.0)); };
  const Progressor p{progress, n};
  BenchSample m = b.step(0.0);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / fs;
    double mass = 0.0, fraction = 0.0, before = 0.0;
    for (const OperatorStep& s : steps) {
      if (t < s.t) break;
      const double x = s.ramp > 0.0 ? (t - s.t) / s.ramp : 1.0;
      if (s.added_mass > 0.0) {
        mass = s.added_mass;
        fraction = raised(x);
      } else {
        mass = x < 1.0 ? before : 0.0;
        fraction = x < 1.0 ? 1.0 - raised(x) : 0.0;
      }
      before = s.added_mass;
    }
    b.set_added_mass(mass);
    b.set_load_fraction(fraction);
    out(k, 0) = m.de;
    out(k, 1) = fraction * mass;
    m = b.step(0.0);
    p(k);
  }
  p.done();
  std::vector<double> done;
  for (const OperatorStep& s : steps) done.push_back(s.t);
  return done;
}

void VirtualRunner::describe(io::TimeSeries& ts) const {
  if (!bench_) return;
  ts.settings["model"] = bench_->model_name();
  if (options_.superelement) ts.settings["superelement"] = options_.superelement->string();
  ts.settings["delay_s"] = bench_->effective_delay();
  ts.settings["nmp_zero"] = options_.nonminimum_phase_zero ? 1.0 : 0.0;
  ts.settings["hysteresis"] = options_.hysteresis ? 1.0 : 0.0;
  ts.settings["creep"] = options_.creep ? 1.0 : 0.0;
  // Only for the second law, so that the default bench's records stay as they were.
  if (options_.hysteresis_law != HysteresisLaw::kPrandtlIshlinskii) ts.settings["hysteresis_law"] = to_string(options_.hysteresis_law);
}

bool runs_on_bench(Experiment e) {
  return e == Experiment::kStroke || e == Experiment::kHysteresis || e == Experiment::kStiffness ||
         e == Experiment::kFrfNoise || e == Experiment::kFrfSweep || e == Experiment::kIff || e == Experiment::kTracking;
}

io::TimeSeries run_experiment(Experiment experiment, BenchRunner& runner, const UnitTruth& unit,
                              const ExperimentOptions& options, std::uint64_t seed, const Progress& progress) {
  options.validate(experiment);
  std::vector<std::string> setup;
  if (options.bench.actuator_open_circuit) setup.emplace_back("disconnect the amplifier from the actuator stacks (open circuit)");
  if (!options.bench.hpf_resistor) {
    setup.push_back(fmt::format("take the {:g} kOhm resistor off the sensor stack", options.bench.hpf_resistance / 1e3));
  }
  if (!setup.empty() && runs_on_bench(experiment)) runner.prepare(setup);
  io::TimeSeries ts;
  switch (experiment) {
    case Experiment::kStroke: ts = stroke(runner, unit, options, seed, progress); break;
    case Experiment::kHysteresis: ts = hysteresis(runner, unit, options, seed, progress); break;
    case Experiment::kStiffness: ts = stiffness(runner, unit, options, seed, progress); break;
    case Experiment::kFrfNoise: ts = frf_noise(runner, unit, options, seed, progress); break;
    case Experiment::kFrfSweep: ts = frf_sweep(runner, unit, options, seed, progress); break;
    case Experiment::kIff: ts = iff(runner, unit, options, seed, progress); break;
    case Experiment::kTracking: ts = tracking(runner, unit, options, seed, progress); break;
    default:
      throw InputError("", "experiment", "an experiment that runs on the bench (stroke, hysteresis, stiffness, frf-noise, "
                       "frf-sweep, iff, tracking)", "'" + to_string(experiment) + "'");
  }
  ts.validate();
  return ts;
}

std::string to_string(Experiment e) {
  for (const Named& n : kNames) {
    if (n.e == e) return n.name;
  }
  return "unknown";
}

Experiment experiment_from_string(const std::string& name) {
  for (const Named& n : kNames) {
    if (name == n.name) return n.e;
  }
  throw InputError("", "experiment", "one of " + known_names(), "'" + name + "'");
}

const std::vector<Experiment>& all_experiments() {
  static const std::vector<Experiment> all = [] {
    std::vector<Experiment> v;
    for (const Named& n : kNames) v.push_back(n.e);
    return v;
  }();
  return all;
}

void ExperimentOptions::validate() const {
  if (amplitude && !(std::isfinite(*amplitude) && *amplitude > 0.0)) {
    throw InputError(kSource, "amplitude", "an amplitude > 0 V", format_number_exact(*amplitude));
  }
  if (duration) checked_duration_s(*duration, 1e-3, 1e5, NumberOrigin::file(kSource, "duration"));
  if (gain && !(std::isfinite(*gain) && *gain >= 0.0)) {
    throw InputError(kSource, "gain", "an IFF gain >= 0", format_number_exact(*gain));
  }
  bench.validate();
}

void ExperimentOptions::validate(Experiment e) const {
  validate();
  const std::string name = to_string(e);
  if (amplitude && !uses_amplitude(e)) {
    throw InputError(kSource, "amplitude", "no amplitude: only hysteresis, tracking, frf-noise, frf-sweep and iff take one",
                     "an amplitude for " + name);
  }
  if (duration && !uses_duration(e)) {
    throw InputError(kSource, "duration", "no duration: only frf-noise, frf-sweep and iff take one", "a duration for " + name);
  }
  if (gain && e != Experiment::kIff) throw InputError(kSource, "gain", "no gain: only iff takes one", "a gain for " + name);
  if (feedforward && e != Experiment::kTracking) {
    throw InputError(kSource, "feedforward", "no feedforward model: only tracking takes one", "a model for " + name);
  }
  if (feedforward) feedforward->validate("feedforward");
}

io::TimeSeries simulate(Experiment experiment, const UnitTruth& unit, const ExperimentOptions& options, std::uint64_t seed,
                        const Progress& progress) {
  options.validate(experiment);
  unit.validate();
  if (runs_on_bench(experiment)) {
    VirtualRunner runner(unit, options.bench);
    return run_experiment(experiment, runner, unit, options, seed, progress);
  }
  io::TimeSeries ts;
  switch (experiment) {
    case Experiment::kHammer: ts = hammer(unit, options, seed, progress); break;
    case Experiment::kFlatness: ts = flatness(unit, options, seed); break;
    case Experiment::kCapacitance: ts = capacitance(unit, options, seed); break;
    default: break;
  }
  ts.validate();
  return ts;
}

}  // namespace piezobench::bench
