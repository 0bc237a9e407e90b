#pragma once
// A digital twin of one unit: the virtual bench of that particular actuator, with the parameters
// `piezobench twin` identified on its records (campaign/twin.hpp, docs/twin.md), as one TOML file
// that `simulate --twin`, `measure --bench` (a virtual bench file with `twin = "FILE"`) and
// `bench serve --twin` accept.
//
//   format = "piezobench-twin-1"
//   name = "APA 9"                     # the unit
//   unit = 9                           # its id (written in the records the twin makes)
//   [model]                            # the 2-DoF model (docs/models.md), SI: k1, c1, ke, ce, ka, ca, ga, gs
//   [chain]                            # the bench around it
//   amplifier_gain_V_per_V, suspended_mass_kg, delay_s, hpf_resistance_ohm, ground_resistance_ohm,
//   adc_bandwidth_Hz, sample_rate_Hz, capacitance_sensor_F, capacitance_actuator_F
//   [hysteresis]                       # the Prandtl-Ishlinskii law's play operators (at most 8)
//   thresholds_V = [...], weights = [...]
//   [creep]
//   voltage_per_decade, load_per_decade
//   [noise]                            # white measurement noise of each channel, what the quiet
//   de_m_rms, Vs_V_rms                 #   segments' spectra give with the quantization taken off
//   freq_Hz, de_psd_m2_per_Hz, Vs_psd_V2_per_Hz   # optional, informative: the measured spectra
//   [sources]                          # optional, informative: experiment = "file" strings
//
// Every key of [model], [chain], [hysteresis], [creep] and [noise] (but the spectra) is required;
// unknown keys, wrong types and invalid values (UnitTruth::validate, BenchOptions::validate) are
// InputErrors naming the file and the key.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "piezobench/bench/virtual_bench.hpp"
#include "piezobench/core/fields.hpp"

namespace piezobench::bench {

inline constexpr const char* kTwinFormat = "piezobench-twin-1";

// A one-sided power spectral density (unit^2/Hz) at some frequencies.
struct NoiseSpectrum {
  std::vector<double> freq_Hz;
  std::vector<double> psd;  // unit^2/Hz
};

constexpr auto describe(core::Type<NoiseSpectrum>) {
  using S = NoiseSpectrum;
  using namespace core::shown;
  return core::fields<S>("NoiseSpectrum", "a one-sided power spectral density of a channel at some frequencies",
      core::field("freq_Hz", &S::freq_Hz, kHertz, "the frequencies"),
      core::field("psd", &S::psd, kNone, "one-sided PSD in the channel's SI unit squared per Hz (m^2/Hz for d_e, V^2/Hz for Vs)"));
}

struct Twin {
  std::string name;                   // the unit's name ("APA 9")
  UnitTruth unit;                     // model, capacitances, play operators, creep coefficients
  // The chain: amplifier_gain, suspended_mass, delay, hpf_resistance, ground_resistance,
  // adc_bandwidth_Hz, sample_rate, encoder_noise, vs_noise (the other options keep their defaults).
  BenchOptions options;
  NoiseSpectrum de_noise, vs_noise;   // measured on the unit's quiet segments (informative)
  std::vector<std::pair<std::string, std::string>> sources;  // experiment -> file (informative)

  // InputError (source "twin" unless given): the unit and the options.
  void validate(const std::string& source = "") const;
};

// Copies the twin's chain (the fields listed at Twin::options) into `options`, leaving the
// switches (noise, delay on/off, hysteresis law, ...) as they are.
void apply_chain(const Twin& twin, BenchOptions& options);

std::string twin_toml(const Twin& twin);
// Writes twin_toml atomically; InputError when the file cannot be written.
void write_twin(const std::filesystem::path& path, const Twin& twin);
Twin read_twin(const std::filesystem::path& path);
// The same from TOML text; `source` names it in errors.
Twin parse_twin(const std::string& text, const std::string& source);

}  // namespace piezobench::bench
