#pragma once
// The campaign file (TOML; docs/campaign.md has a complete example): which units were measured,
// which files hold each experiment and under which channel names, the specifications a unit must
// meet, the bench constants, and the analysis settings.
//
// Paths in the file are relative to the campaign file's folder (absolute paths are taken as they
// are). The campaign only names files to READ: every output goes to the --out folder under fixed
// names, so nothing a campaign says can make piezobench write elsewhere.
//
// Every problem is an InputError naming the campaign file and the key (e.g. "units[2].stroke"):
// TOML syntax (with the line), unknown keys (at every level), wrong types, values out of range, a
// unit listed twice, a missing measurement file, an unknown channel role. Channel names are checked
// against the files when they are read (campaign/pipeline.hpp).
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "piezobench/control/iff.hpp"
#include "piezobench/dsp/window.hpp"
#include "piezobench/fem/superelement_setup.hpp"
#include "piezobench/metrology/uncertainty_budget.hpp"
#include "piezobench/metrology/capacitance.hpp"
#include "piezobench/metrology/flatness.hpp"

namespace piezobench::campaign {

// The experiments a unit can have (keys of a [[units]] entry).
// kStiffnessOpen: the stiffness test with every stack open (actuators disconnected from the
// amplifier, no resistor on the sensor: k_oc, report section 2.2); kFrfNoResistor: u -> Vs without
// the resistor across the sensor stack (report section 2.5, Figure 2.7); kTracking: the tracking
// experiment's record (`measure tracking`, bench/tracking.hpp: d_e against the command without and
// with the inverse hysteresis feedforward).
enum class Experiment { kFlatness, kCapacitance, kStroke, kHysteresis, kStiffness, kStiffnessOpen, kFrf, kFrfNoResistor, kIff, kHammer,
                        kTracking };
// "flatness", "capacitance", "stroke", "hysteresis", "stiffness", "stiffness_open_circuit", "frf",
// "frf_without_resistor", "iff", "hammer", "tracking".
std::string to_string(Experiment e);
Experiment experiment_from_string(const std::string& name, const std::string& source = "");  // InputError
const std::vector<Experiment>& all_experiments();

// Channel roles each experiment reads, required ones first; the defaults are the virtual bench's
// channel names (bench/experiments.hpp), which are also the role names:
//   flatness x, y, z [interface]; capacitance C_sensor, C_actuator; stroke Va, de;
//   hysteresis Va, de; stiffness and stiffness_open_circuit de [added_mass]; frf u, de, Vs;
//   frf_without_resistor u, Vs; iff u_prime, de; hammer F, v; tracking c, de_open, de_ff (and the
//   record's settings: bench/tracking.hpp's tracking_layout).
// Optional roles are used when their channel is in the file (or when mapped explicitly, in which
// case the channel must be there).
const std::vector<std::string>& required_roles(Experiment e);
const std::vector<std::string>& optional_roles(Experiment e);

// One measurement file.
struct FileSpec {
  std::filesystem::path path;                   // resolved (absolute or relative to the working dir)
  std::string given;                            // the path as written in the campaign
  std::string key;                              // where it is set, e.g. "units[2].iff[1]"
  std::map<std::string, std::string> channels;  // role -> channel name in the file (all roles)
  std::vector<std::string> explicit_roles;      // roles mapped by the campaign (must exist)
  double sample_rate = 0.0;                     // Hz; 0 = from the file (t or fs)
  double gain = 0.0;                            // iff: controller gain g (0 = from the file's settings)
  std::map<std::string, std::string> units;     // role -> unit of a channel whose file gives none
};

struct UnitSpec {
  int id = 0;
  std::string name;     // "APA 1" unless given
  std::string key;      // "units[0]"
  std::optional<std::string> serial;  // the unit's serial number, when known (checked against the records')
  std::optional<FileSpec> flatness, capacitance, stroke, stiffness, stiffness_open, frf, frf_no_resistor, hammer, tracking;
  std::vector<FileSpec> hysteresis, iff;
  // LCR readings typed into the campaign instead of a file (F): capacitance_uF = {sensor, actuator}.
  std::optional<double> capacitance_sensor, capacitance_actuator;
  [[nodiscard]] bool has(Experiment e) const;
};

// [specs]: what a unit must meet. An absent limit is not checked.
struct Specs {
  std::optional<double> flatness_max;                       // m (flatness_um)
  metrology::FlatnessMethod flatness_method = metrology::FlatnessMethod::kLeastSquares;
  std::optional<metrology::Range> capacitance_sensor;       // F (capacitance_sensor_uF = [min, max])
  std::optional<metrology::Range> capacitance_actuator;     // F
  std::optional<double> stroke_min;                         // m (stroke_min_um)
  std::optional<metrology::Range> stiffness;                // N/m, for k1, k2 and the resonance (N/um in the file)
  metrology::OutlierOptions outliers;                       // outlier_threshold, outlier_min_relative_deviation
  bool reject_outliers = true;                              // a batch outlier (capacitance, stroke) is rejected
};

// [bench]: constants of the bench and the instruments.
struct BenchConstants {
  double amplifier_gain = 20.0;     // V/V (amplifier_gain)
  double suspended_mass = 5.7;      // kg (suspended_mass_kg)
  double added_mass = 6.4;          // kg (added_mass_kg), static stiffness test
  double gravity = 9.8;             // m/s^2 (gravity_m_per_s2)
  // Ohm (hpf_resistance_ohm), across the sensor stack; nullopt (not given, or 0): no resistor, so no
  // high-pass is computed from R C_sensor (the report's bench has 80.6 kOhm).
  std::optional<double> hpf_resistance;
  double probe_accuracy = 0.5e-6;   // m (probe_accuracy_um), flatness probe
  // The inputs' standard uncertainties of the acceptance checks' budgets (docs/uncertainty.md, section
  // 7): added_mass_uncertainty_kg, gravity_uncertainty_m_per_s2, suspended_mass_uncertainty_kg,
  // encoder_resolution_um, capacitance_uncertainty_relative, displacement_scale_uncertainty_relative.
  metrology::StaticTestUncertainties uncertainty;
  // Provenance (docs/campaign.md): the bench the records come from (`name`: a record whose
  // settings.bench names another is refused; "" = not checked) and when they were taken
  // (`recorded_from`, `recorded_until`: TOML dates or date-times; a record whose recorded_at is
  // outside, or unreadable, is refused). Seconds since the epoch, UTC; a date counts whole, an
  // offset-less date-time as UTC; nullopt = open.
  std::string name;
  std::optional<long long> recorded_from_s, recorded_until_s;
};

// [analysis]: how the data are processed.
struct AnalysisSettings {
  dsp::WindowType window = dsp::WindowType::kHannPeriodic;
  long nfft = 0;                 // samples; 0 = automatic (4 s segments, at least 4 averages)
  double overlap = 0.5;
  // Band of the FRF features, the tuning and the IFF plant fit. Below ~10 Hz the stacks' creep and
  // hysteresis raise the small-signal gain of noise-excited FRFs by 10-30 % (virtual bench), so the
  // stiffness line is read between 20 Hz and the resonance.
  double fmin_Hz = 20.0;
  double fmax_Hz = 500.0;        // above, the force sensor's anti-aliasing filter and the node relaxation, which eq. 2.3 lacks
  double hpf_fmax_Hz = 5.0;      // band below which the high-pass corner is fitted
  double damped_fmin_Hz = 5.0;   // band of the damped-plant second-order fits
  double damped_fmax_Hz = 400.0;
  double hammer_fmin_Hz = 100.0; // band searched for flexible modes
  double hammer_fmax_Hz = 1000.0;
  long fit_order = 6;            // vector-fitting order of the FRF features
  // The plant fits and the 2-DoF tuning compare their models with the FRF through the Welch window's
  // resolution kernel (dsp/resolution_kernel.hpp); false: the models' own responses.
  bool window_resolution = true;
  int iff_unit = 0;              // unit whose IFF data make the batch's `iff` result (0 = first with IFF data)
  control::IffControllerParams controller;  // eq. 2.4 (iff_controller = {gain, hpf_Hz, lpf_Hz, robust_Hz})
  int threads = 0;               // units analysed in parallel; 0 = all cores
};

// [superelement] (optional): a super element put on the bench (report section 4): bottom clamped
// (fix), the suspended mass on the moving interface (output), guided; the actuator pair and the
// sensor stack (sensor); ga and gs tuned against each unit's measured FRFs (superelement_fit.hpp).
// Keys: format, k_file, m_file, nodes_file, coordinates_file, fix, actuator, output, sensor, masses
// (added to the suspended mass), damping (modal:ZETA).
struct CampaignSuperElement {
  fem::SuperElementSetup setup;  // forces [actuator], outputs [output, sensor]; source = the campaign
  std::string given;             // the K file as written in the campaign
  double modal_damping = 0.02;
  // Pa (stack_modulus_Pa): the stacks' effective modulus the element was built with (default: Table
  // 4.1's c^E). Eq. 4.1 is evaluated with it: ga = d33 n E A / L, and gs times E / c^E (the ceramic's
  // share of the stack's strain when glue and electrodes soften it; docs/apa300ml.md).
  double stack_modulus = 48e9;
};

struct Campaign {
  std::filesystem::path file;      // the campaign file
  std::filesystem::path folder;    // its folder (base of relative paths)
  std::string title;
  BenchConstants bench;
  Specs specs;
  AnalysisSettings analysis;
  std::map<std::string, std::string> channels;  // [channels]: role -> default channel name
  std::vector<UnitSpec> units;                  // in file order
  std::optional<CampaignSuperElement> superelement;
};

// Reads and validates a campaign; every measurement file must exist (InputError naming the key).
Campaign read_campaign(const std::filesystem::path& file);
// Same from TOML text; `file` names it in messages and gives the folder of relative paths.
// check_files = false skips the existence checks (for tests of the syntax).
Campaign parse_campaign(const std::string& text, const std::filesystem::path& file, bool check_files = true);

}  // namespace piezobench::campaign
