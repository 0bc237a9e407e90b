#pragma once
// The experiments of the report, run on the virtual bench, each giving the measurement record a
// real bench would write (`piezobench simulate`, CLI.md). Every record is an io::TimeSeries with
// SI units, its channels' units, and settings that say how it was made: `experiment`, `unit`,
// `seed`, and the experiment's parameters below (written to .mat by io::write_timeseries).
//
// Channels per experiment (the contract the campaign reads; docs/virtual-bench.md shows examples):
//   stroke       t, u, Va, de     slow ramp of Va from va_min to va_max and back; de from a
//                                 low-bandwidth probe (m). Settings: va_min_V, va_max_V, ramp_s.
//   hysteresis   t, u, Va, de     1 Hz sine on Va around 65 V. Settings: amplitude_V, offset_V,
//                                 frequency_Hz, periods.
//   stiffness    t, de, added_mass  de (m) while a mass is put on at ~3 s and taken off at ~13 s;
//                                 added_mass (kg) is the operator's log. Settings: added_mass_kg,
//                                 t_on_s, t_off_s, gravity_m_per_s2.
//   frf-noise    t, u, Va, de, Vs band-limited white noise on u. Settings: duration_s, rms_V, band_Hz.
//   frf-sweep    t, u, Va, de, Vs logarithmic sine sweep on u. Settings: duration_s, f0_Hz, f1_Hz, amplitude_V.
//   iff          t, u_prime, u, Va, de, Vs  closed loop u = u' + g K0 Vs (report's controller,
//                                 eq. 2.4, discretized), noise on u'. Settings: gain, duration_s.
//   hammer       t, F, v          fixed-free actuator: impact force (N) and vibrometer velocity
//                                 (m/s) that shows both bending modes. Settings: impacts.
//   flatness     x, y, z, interface  8 probe points (m; interface 1 = bottom, 2 = top, 4 each),
//                                 one point per sample (sample_rate 1). Settings: probe_noise_m.
//   capacitance  C_sensor, C_actuator  LCR readings (F), one sample. Settings: frequency_Hz.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "piezobench/bench/virtual_bench.hpp"
#include "piezobench/io/timeseries.hpp"

namespace piezobench::bench {

enum class Experiment { kStroke, kHysteresis, kStiffness, kFrfNoise, kFrfSweep, kIff, kHammer, kFlatness, kCapacitance };

// "stroke", "hysteresis", "stiffness", "frf-noise", "frf-sweep", "iff", "hammer", "flatness", "capacitance".
std::string to_string(Experiment e);
// InputError (field "experiment") listing the known names.
Experiment experiment_from_string(const std::string& name);
const std::vector<Experiment>& all_experiments();

struct ExperimentOptions {
  // Unset values take the experiment's default (the report's settings).
  std::optional<double> amplitude;   // V at the stacks (hysteresis; default 20 V); refused, with
                                     // the limit named, when offset +- amplitude leaves [va_min, va_max]
  std::optional<double> duration;    // s (frf-noise 20 s, frf-sweep 20 s, iff 10 s), > 0
  std::optional<double> gain;        // IFF gain g (iff; default 280000 -> near the optimum)
  BenchOptions bench;
  void validate() const;             // InputError naming the field
};

// Progress in [0, 1], called from the simulating thread now and then (may be empty).
using Progress = std::function<void(double)>;

// Runs one experiment on `unit` and returns its record. The same (experiment, unit, options, seed)
// gives the same record. InputError for bad options.
io::TimeSeries simulate(Experiment experiment, const UnitTruth& unit, const ExperimentOptions& options,
                        std::uint64_t seed, const Progress& progress = {});

}  // namespace piezobench::bench
