#pragma once
// The experiments of the report, run on the virtual bench, each giving the measurement record a
// real bench would write (`piezobench simulate`, CLI.md). Every record is an io::TimeSeries with
// SI units, its channels' units, and settings that say how it was made: `experiment`, `unit`,
// `seed`, and the experiment's parameters below (written to .mat by io::write_timeseries).
//
// Every record also carries the settings `experiment`, `unit`, `seed` (a number up to 2^53, text
// above), `defective`, `noise`, and for bench experiments `model` ("2dof" or "superelement"),
// `superelement` (its TOML), `delay_s` (effective), `nmp_zero`, `hysteresis`, `creep` (1 or 0),
// `hysteresis_law` (only when "bouc-wen"),
// `amplifier_gain_V_per_V`, `va_min_V`, `va_max_V`, `suspended_mass_kg`, `hpf_resistance_ohm`,
// `hpf_resistor` (1 or 0), `sensor_shunt_ohm` (what discharges the sensor stack), `actuator_circuit`
// ("short": on the amplifier, "open": disconnected; the stiffness test measures k_sc and k_oc).
// Row k holds the instruments at t = k / fs, read before u[k] is applied (row 0: the bench at rest).
//
// Channels per experiment (the contract the campaign reads; docs/virtual-bench.md shows examples):
//   stroke       t, u, Va, de     slow ramp of Va 0 -> va_min -> va_max -> va_min -> 0 (10 s for
//                                 va_min -> va_max, 1 s holds); de from a low-bandwidth probe (m,
//                                 first order 2 Hz, 10 nm rms noise), recorded at 1 kHz.
//                                 Settings: ramp_s, probe_bandwidth_Hz, probe_noise_m.
//   hysteresis   t, u, Va, de     1 Hz sine on Va around (va_min + va_max)/2 = 65 V, 3 periods
//                                 between 1 s raised-cosine ramps from and to 0 V. Settings:
//                                 amplitude_V, offset_V, frequency_Hz, periods, ramp_s.
//   stiffness    t, de, added_mass  de (m) at u = 0 while a mass is put on at 3 s and taken off at
//                                 13 s (its weight ramped over 0.5 s each time; 20 s in all);
//                                 added_mass (kg) is the operator's log of the weight carried.
//                                 Settings: added_mass_kg, t_on_s, t_off_s, ramp_s,
//                                 gravity_m_per_s2, duration_s.
//   frf-noise    t, u, Va, de, Vs Gaussian noise on u, flat over [band_low_Hz, band_high_Hz]
//                                 (0.1 .. 2000 Hz), periodic over the record. Settings: duration_s,
//                                 rms_V (u), va_rms_V (at the stacks), band_low_Hz, band_high_Hz.
//   frf-sweep    t, u, Va, de, Vs logarithmic sine sweep on u, 1 -> 2000 Hz. Settings: duration_s,
//                                 f0_Hz, f1_Hz, amplitude_V (u), va_amplitude_V, sweep ("log").
//   iff          t, u_prime, u, Va, de, Vs  closed loop u = u' + g K0 Vs (report's controller,
//                                 eq. 2.4, control::DiscreteIff), noise on u' as in frf-noise, u
//                                 clamped to the stack range. Settings: gain, duration_s, rms_V,
//                                 va_rms_V, band_low_Hz, band_high_Hz, clamped_samples, controller.
//   hammer       t, F, v          fixed-free actuator: 5 impacts (half-sine, 1 ms, 50..150 N, every
//                                 2 s from 0.5 s), force (N) and vibrometer velocity (m/s) showing
//                                 both bending modes. Settings: impacts, pulse_width_s,
//                                 impact_spacing_s, force_noise_N, velocity_noise_m_per_s.
//   flatness     x, y, z, interface  8 probe points (m; interface 1 = bottom, 2 = top, 4 each),
//                                 one point per sample (sample_rate 1, no t), probe error uniform
//                                 within +-probe_noise_m. Settings: probe_noise_m.
//   capacitance  C_sensor, C_actuator  LCR readings (F), one sample (no t), error uniform within
//                                 +-accuracy_relative. Settings: frequency_Hz, accuracy_relative.
//   tracking     t, c, Va_open, de_open, Va_ff, de_ff  a 1 Hz sine and triangle of `amplitude`
//                                 (default 80 V) about 65 V, without and with the inverse hysteresis
//                                 feedforward; bench/tracking.hpp (settings: the figures).
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "piezobench/bench/virtual_bench.hpp"
#include "piezobench/ident/hysteresis.hpp"
#include "piezobench/io/timeseries.hpp"

namespace piezobench::bench {

enum class Experiment { kStroke, kHysteresis, kStiffness, kFrfNoise, kFrfSweep, kIff, kHammer, kFlatness, kCapacitance, kTracking };

// "stroke", "hysteresis", "stiffness", "frf-noise", "frf-sweep", "iff", "hammer", "flatness", "capacitance",
// "tracking".
std::string to_string(Experiment e);
// InputError (field "experiment") listing the known names.
Experiment experiment_from_string(const std::string& name);
const std::vector<Experiment>& all_experiments();

struct ExperimentOptions {
  // Unset values take the experiment's default (the report's settings).
  std::optional<double> amplitude;   // V at the stacks, > 0: hysteresis (sine amplitude, default
                                     // 20 V), tracking (default 80 V), frf-noise and iff (rms, default 2 V), frf-sweep
                                     // (amplitude, default 1 V). Refused, with the limit named, when
                                     // the stack voltage would leave [va_min, va_max]: never clipped.
  std::optional<double> duration;    // s (frf-noise 20 s, frf-sweep 20 s, iff 10 s), in (0, 1e5]
  std::optional<double> gain;        // IFF gain g (iff; default 280000 -> near the optimum)
  // tracking: the feedforward's model (unset: identified from the open run).
  std::optional<ident::HysteresisModel> feedforward;
  BenchOptions bench;
  void validate() const;             // InputError naming the field
  // Also refuses an option the experiment does not take (e.g. --duration for stroke).
  void validate(Experiment experiment) const;
};

// Progress in [0, 1], called from the simulating thread now and then (may be empty).
using Progress = std::function<void(double)>;

// Where the bench experiments (stroke, hysteresis, stiffness, frf-noise, frf-sweep, iff) run: each
// experiment is defined once, as commands for these primitives and the record made of what they
// measure; VirtualRunner runs them on the virtual bench, rt::BackendRunner on any rt backend (a
// DAQ card, a remote I/O target: `piezobench measure`). Every primitive fills `out` with one row per
// sample at the bench's rate, row k holding the instruments at t = k / fs read before the k-th
// command is applied (row 0: the bench at rest). `seed` seeds the virtual bench's noise (ignored
// by real hardware).
struct OperatorStep {
  double t = 0.0;           // s from the start of the record: when the operator is asked
  std::string prompt;       // what the operator is asked to do ("put the 6.4 kg mass on ...")
  double added_mass = 0.0;  // kg on the bench once the step is done (0: taken off)
  double ramp = 0.0;        // s the virtual operator takes to lower or lift the weight
};

class BenchRunner {
 public:
  virtual ~BenchRunner() = default;
  // Open loop with the DAC commands u (V): out is n x 4, columns u (applied), Va, de, Vs.
  virtual void open_loop(const Eigen::VectorXd& u, std::uint64_t seed, Eigen::MatrixXd& out, const Progress& progress) = 0;
  // Open loop through the inverse hysteresis feedforward of `model` (control::HysteresisFeedforward),
  // live: each command u'[k] (V at the DAC) is read as c = amplifier_gain u'[k] and the stage's
  // stack voltage / amplifier_gain is applied with the weight w[k] in [0, 1]
  // (u'[k] + w[k] (stage - u'[k]): blended in and out), then clamped to the stack range (a real-time
  // loop also slew-limits it: rt::LoopOptions::feedforward, feedforward_weight). w has u's size. out
  // as open_loop's (column u: what was applied). Returns the number of clamped samples.
  // u_prime: V at the DAC; w: dimensionless.
  virtual std::uint64_t open_loop_feedforward(const Eigen::VectorXd& u_prime, const Eigen::VectorXd& w, const ident::HysteresisModel& model,
                                              std::uint64_t seed, Eigen::MatrixXd& out, const Progress& progress) = 0;
  // IFF closed loop u = u' + g K0 Vs (report's controller, control::DiscreteIff), u clamped to the
  // stack range: out is n x 4, columns u, Va, de, Vs. Returns the number of clamped samples.
  // u_prime: V at the DAC; gain g: V/V.
  virtual std::uint64_t iff(const Eigen::VectorXd& u_prime, double gain, std::uint64_t seed, Eigen::MatrixXd& out,
                            const Progress& progress) = 0;
  // u = 0 for n samples while the operator carries out `steps` (in order): out is n x 2, columns
  // de, added_mass (kg carried, the operator's log). Returns when each step took effect (s).
  virtual std::vector<double> hold(Eigen::Index n, const std::vector<OperatorStep>& steps, std::uint64_t seed,
                                   Eigen::MatrixXd& out, const Progress& progress) = 0;
  // Adds the settings that say where the record was made (bench model, delay; backend, device).
  virtual void describe(io::TimeSeries& record) const = 0;
  // Operator steps before the record starts, with nothing moving (disconnect the amplifier for the
  // open-circuit test, take the resistor off the sensor stack): a real bench asks and waits for the
  // confirmation; the virtual bench has them in its options already (default: nothing to do).
  virtual void prepare(const std::vector<std::string>& steps) { (void)steps; }
};

// The virtual bench of `unit` with `options` (a fresh bench, seeded per primitive, for each call).
class VirtualRunner final : public BenchRunner {
 public:
  VirtualRunner(const UnitTruth& unit, const BenchOptions& options);
  ~VirtualRunner() override;
  // u: V at the DAC.
  void open_loop(const Eigen::VectorXd& u, std::uint64_t seed, Eigen::MatrixXd& out, const Progress& progress) override;
  // The loop's stages without its timing: the feedforward, then the clamp (the slew limit never
  // acts on the tracking commands at the default 1e5 V/s).
  // u_prime: V at the DAC; w: dimensionless.
  std::uint64_t open_loop_feedforward(const Eigen::VectorXd& u_prime, const Eigen::VectorXd& w, const ident::HysteresisModel& model,
                                      std::uint64_t seed, Eigen::MatrixXd& out, const Progress& progress) override;
  // u_prime: V at the DAC; gain g: V/V.
  std::uint64_t iff(const Eigen::VectorXd& u_prime, double gain, std::uint64_t seed, Eigen::MatrixXd& out,
                    const Progress& progress) override;
  std::vector<double> hold(Eigen::Index n, const std::vector<OperatorStep>& steps, std::uint64_t seed, Eigen::MatrixXd& out,
                           const Progress& progress) override;
  void describe(io::TimeSeries& record) const override;

 private:
  VirtualBench& bench(std::uint64_t seed);
  UnitTruth unit_;
  BenchOptions options_;
  std::unique_ptr<VirtualBench> bench_;
};

// True for the experiments that run on the bench (a BenchRunner): stroke, hysteresis, stiffness,
// frf-noise, frf-sweep, iff, tracking.
bool runs_on_bench(Experiment experiment);

// Runs one bench experiment (runs_on_bench) through `runner` and returns its record: the same
// channels, units and settings whatever the runner. options.bench gives the rates, the amplifier
// gain and the stack range; `unit` and `seed` are recorded. InputError for bad options or an
// experiment that does not run on a bench.
io::TimeSeries run_experiment(Experiment experiment, BenchRunner& runner, const UnitTruth& unit,
                              const ExperimentOptions& options, std::uint64_t seed, const Progress& progress = {});

// Runs one experiment on `unit` and returns its record. The same (experiment, unit, options, seed)
// gives the same record. InputError for bad options.
io::TimeSeries simulate(Experiment experiment, const UnitTruth& unit, const ExperimentOptions& options,
                        std::uint64_t seed, const Progress& progress = {});

// The noise seed of the virtual bench in the main run of `experiment` recorded with `seed`: a
// rt::VirtualBenchBackend seeded with it and driven by run_experiment gives simulate()'s record.
std::uint64_t experiment_bench_seed(Experiment experiment, std::uint64_t seed) noexcept;

}  // namespace piezobench::bench
