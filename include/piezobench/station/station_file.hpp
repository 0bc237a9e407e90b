#pragma once
// The station file (TOML; docs/station.md, example docs/examples/station.toml): the acceptance
// sequence of one unit as phases in order, each with its experiment settings, its operator steps
// (prompts before the phase: "place the 6.4 kg mass", "open the actuator circuit"), its own
// checks (saturation, lost samples, coherence) with the retries allowed, and its measurements with
// the specification limits and whether a failure stops the qualification. [campaign.bench] and
// [campaign.analysis] are the campaign's [bench] and [analysis] tables (docs/campaign.md): the
// per-unit analysis is the campaign pipeline's.
//
// Every problem is an InputError naming the file, the line and the full key
// ("station.toml: line 40: phases[4].measurements[1].name: expected a measurement of the
// catalog for stiffness, found 'k3_N_per_um'"): unknown keys at every level, wrong types, a phase
// name used twice, a measurement that is not its experiment's, a limit with min > max.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "piezobench/campaign/campaign_file.hpp"
#include "piezobench/station/measurements.hpp"

namespace piezobench::station {

// Where the values of flatness and capacitance come from: the bench (the virtual bench simulates
// its probe and LCR meter; a hardware bench has none), a file the answers name, or typed in by the
// operator (capacitance: sensor and actuator, uF).
enum class ValueSource { kBench, kFile, kTyped };

struct MeasurementSpec {
  std::string name;          // in the catalog (measurements.hpp), of the phase's experiment
  Limit limit;
  bool stop_on_fail = false; // a fail verdict ends the qualification after this phase
  int line = 0;
};

struct PhaseSpec {
  std::string name;          // unique within the station; letters, digits, '-', '_'
  std::string experiment;    // "flatness", "capacitance", "stroke", "hysteresis", "stiffness",
                             // "frf-noise", "iff", "hammer", "tracking" (bench/experiments.hpp)
  campaign::Experiment record = campaign::Experiment::kStroke;  // the campaign key of its record
  std::optional<double> amplitude_V, duration_s, gain;          // gain: V/V (IFF gain g), bench::ExperimentOptions
  bool open_circuit = false;  // stiffness: every stack open (k_oc)
  bool no_resistor = false;   // frf-noise: no resistor across the sensor stack
  ValueSource source = ValueSource::kBench;
  std::vector<std::string> steps;  // operator steps, prompted in order before the phase
  long retries = 2;                // tries allowed after the first when its checks fail
  double min_coherence = 0.0;      // frf-noise: mean coherence of u -> d_e in the FRF band (0: not checked)
  long max_clamped_samples = 0;    // saturation: samples clamped to the stack range allowed
  std::vector<MeasurementSpec> measurements;
  int line = 0;
};

struct StationFile {
  std::filesystem::path file;
  std::string name;
  double margin_relative = 0.01;    // marginal band until measurements carry uncertainties
  std::string campaign_tables;      // "[bench] ... [analysis] ..." as TOML text for the campaign
  std::vector<PhaseSpec> phases;    // in order
  [[nodiscard]] const PhaseSpec* phase(const std::string& name) const;
  // [specs] of the campaign from the limits the campaign can express (flatness_um max,
  // capacitance ranges, stroke_um min, one range for k1, k2 and k_resonance): TOML text.
  [[nodiscard]] std::string campaign_specs() const;
};

StationFile read_station_file(const std::filesystem::path& file);
// The same from text; `file` names it in messages.
StationFile parse_station_file(const std::string& text, const std::filesystem::path& file);

}  // namespace piezobench::station
