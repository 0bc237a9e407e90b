#pragma once
// Every analysis of the report for one unit of a campaign (report sections 1 and 2):
//
//   flatness      least-squares and minimum-zone, per interface too (metrology::analyze_flatness,
//                 metrology/interface_flatness.hpp); the spec's method is the unit's flatness_um
//   capacitance   mean of the LCR readings (or the values typed into the campaign)
//   stroke        slow ramp (metrology/stroke.hpp)
//   hysteresis    one result per amplitude (loop width at the offset relative to the loop's stroke)
//                 and the hysteresis model of the largest loop (ident::identify_hysteresis_model,
//                 ident/hysteresis_model_choice.hpp)
//   stiffness     k1, k2 at the report's reading times, creep fitted, and the Prony creep of the
//                 record (ident::analyze_added_mass, ident/added_mass.hpp)
//   frf           Welch H1 u -> d_e and u -> Vs with coherence, read by ident::analyze_actuator_frf
//                 (ident/actuator_frf.hpp): features of both by vector fitting
//                 (ident/features.hpp): static gain, resonance and damping, anti-resonance and
//                 damping, the non-minimum-phase verdict (phase of the data across the zero, the
//                 fitted zero, and the sign of xz in the IFF plant fit); the high-pass corner; the
//                 IFF plant fit (eq. 2.3 with delay, ident/plant_fit.hpp); the stiffness from the
//                 resonance k = m_sus w^2; the tuned 2-DoF model (apa/tuning.hpp, with the fitted
//                 high-pass and delay as the measurement chain)
//                 u -> d_e is also fitted as a mass-spring-damper with its own delay
//                 (ident/plant_fit.hpp): the d_e and Vs read-outs lag differently
//   stiffness_open_circuit  the same with every stack open: k_oc (k_sc = k1)
//   frf_without_resistor    u -> Vs without the resistor: the high-pass corner with and without it
//                 (ident::fit_low_frequency_high_pass, ident/low_frequency_high_pass.hpp)
//   iff           per gain g: the damped plant u' -> d_e (Welch) and its pole, the dominant pair of
//                 a vector fit (after removing the delay of d_e found on the open-loop FRF); the
//                 report's second-order fit for comparison (ident::analyze_damped_plant,
//                 ident/damped_plant.hpp)
//   hammer        F -> v (Welch), flexible modes by peak picking and by LSCF
//                 (ident::identify_flexible_modes, ident/flexible_modes.hpp)
// The campaign reads the records, estimates the FRFs (Welch) and wires these domain functions,
// which take the measurement (samples, or the dsp::Frf in Hz) and return typed results; it adds the
// records' provenance and the report's curves.
//
// Data problems (a file missing or unreadable, a channel that is not in a file, NaN, too short a
// record, a dead sensor's constant signal, ...) are InputErrors naming the campaign file and the key
// of the file entry; analyze_unit records the first in UnitAnalysis::not_analysed (file, key,
// reason) and leaves every other result of the unit out, so one bad unit never stops a batch. A method that fails
// on valid data (NumericalError) is recorded in `failed` and the analysis is left out; the unit is
// then not accepted (pipeline.hpp). An experiment the campaign does not list is `not_measured`.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "piezobench/campaign/campaign_file.hpp"
#include "piezobench/campaign/results.hpp"
#include "piezobench/dsp/frf.hpp"
#include "piezobench/ident/features.hpp"
#include "piezobench/io/timeseries.hpp"

namespace piezobench::campaign {

// A measurement file read for one experiment, its channels found by role.
struct Record {
  io::TimeSeries ts;
  FileSpec spec;
  [[nodiscard]] bool has(const std::string& role) const;
  // The samples of a role's channel (the role must be present).
  [[nodiscard]] Eigen::VectorXd channel(const std::string& role) const;
  // t from the file, else k / sample_rate.
  [[nodiscard]] Eigen::VectorXd time() const;
};

// Reads the file of `spec` with the channels its experiment needs (required roles, and optional
// ones that the file has or that the campaign mapped explicitly). InputError (source = campaign
// file, field = spec.key) wrapping the reader's message: missing channel, NaN, bad time vector, ...
// Then checks the record's provenance against `unit`: a record whose settings name another unit
// (settings.unit), another serial (settings.serial, when both are known) or another kind of
// experiment (settings.experiment) is an InputError naming both.
Record load_record(const Campaign& campaign, const UnitSpec& unit, const FileSpec& spec, Experiment experiment);

using Log = std::function<void(const std::string&)>;

// All analyses of one unit (results.hpp; the acceptance is left to the pipeline) (single-threaded; the
// pipeline runs units in parallel). Never throws InputError: a unit whose data cannot be analysed
// comes back with `not_analysed` set.
UnitAnalysis analyze_unit(const Campaign& campaign, const UnitSpec& unit, const Log& log = {});

// Welch segment length used for a record of `samples` at `fs`: the campaign's nfft, or
// dsp::segment_length_for_record (4 s of data limited to a quarter of the record, at least 256
// samples; the `frf` command's default too).
long frf_segment_length(const AnalysisSettings& settings, long samples, double fs);

}  // namespace piezobench::campaign
