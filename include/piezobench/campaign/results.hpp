#pragma once
// The typed results of a campaign: one struct per analysis of a unit (unit_analysis.hpp fills
// them), the batch (pipeline.hpp) and the whole campaign. Numbers are SI unless the field name
// says otherwise (`_Hz`, `_deg`); the serializers (results_json.hpp: results.json, results.mat,
// the CLI's --json; report_document.hpp: the report) turn them into the documents' units and keys.
//
// An analysis that was not run (experiment not measured, or failed on valid data) is a nullopt;
// its failure is one line of UnitAnalysis::failed.
#include <Eigen/Core>
#include <array>
#include <complex>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "piezobench/apa/tuning.hpp"
#include "piezobench/apa/two_dof.hpp"
#include "piezobench/bench/tracking.hpp"
#include "piezobench/core/fields.hpp"
#include "piezobench/campaign/campaign_file.hpp"
#include "piezobench/dsp/frf.hpp"
#include "piezobench/ident/actuator_frf.hpp"
#include "piezobench/ident/plant_fit.hpp"
#include "piezobench/ident/dominant_pole.hpp"
#include "piezobench/ident/features.hpp"
#include "piezobench/ident/hysteresis.hpp"
#include "piezobench/metrology/uncertainty_budget.hpp"
#include "piezobench/metrology/conformity.hpp"
#include "piezobench/metrology/capacitance.hpp"
#include "piezobench/metrology/flatness.hpp"
#include "piezobench/metrology/stiffness.hpp"
#include "piezobench/metrology/stroke.hpp"

namespace piezobench::campaign {

// Where an analysis' data came from.
struct RecordProvenance {
  std::string file;                                          // as given in the campaign
  std::string key;                                           // campaign key, e.g. "units[0].frf"
  std::vector<std::pair<std::string, std::string>> channels; // role -> channel name in the file (roles present)
  long samples = 0;
  double sample_rate_Hz = 0.0;
  std::string input;                 // FRF: the input role ("" for other records)
  std::vector<std::string> outputs;  // FRF: the output roles
};

constexpr auto describe(core::Type<RecordProvenance>) {
  using S = RecordProvenance;
  using namespace core::shown;
  return core::fields<S>("RecordProvenance", "where an analysis' data came from",
      core::field("file", &S::file, kNone, "as given in the campaign"),
      core::field("key", &S::key, kNone, "campaign key, e.g. \"units[0].frf\""),
      core::field("channels", &S::channels, kNone, "(role, channel name in the file) of the roles present"),
      core::field("samples", &S::samples, kNone, "samples in the record"),
      core::field("sample_rate_Hz", &S::sample_rate_Hz, kHertz, "of the record"),
      core::field("input", &S::input, kNone, "FRF: the input role (\"\" for other records)"),
      core::field("outputs", &S::outputs, kNone, "FRF: the output roles"));
}

// A curve of the report (thinned or log-spaced samples).
struct Curve {
  std::vector<double> x, y;  // in the units the curve's field names (e.g. x Va [V], y d_e [m])
};

constexpr auto describe(core::Type<Curve>) {
  using S = Curve;
  using namespace core::shown;
  return core::fields<S>("Curve", "a curve of the report (thinned or log-spaced samples)",
      core::field("x", &S::x, kNone, "abscissae, in the unit the curve's field names"),
      core::field("y", &S::y, kNone, "ordinates, in the unit the curve's field names"));
}

struct FlatnessAnalysis {
  metrology::FlatnessMethod method = metrology::FlatnessMethod::kLeastSquares;  // the spec's
  double flatness = 0.0;                     // m, by `method`
  double least_squares = 0.0;                // m
  std::optional<double> minimum_zone;        // m (at most 100 points)
  long points = 0;
  struct Interface {
    double id = 0.0;            // dimensionless label, value of the interface channel
    double least_squares = 0.0; // m
  };
  std::vector<Interface> per_interface;      // interfaces with 3 non-collinear points or more
  double probe_accuracy = 0.0;               // m, [bench]
  RecordProvenance provenance;
  std::vector<double> deviation;             // m, of every point (thinned), for the report
  Curve probe_xy;                            // x, y of the same points [m] (the report's figure)
};

constexpr auto describe(core::Type<FlatnessAnalysis::Interface>) {
  using S = FlatnessAnalysis::Interface;
  using namespace core::shown;
  return core::fields<S>("FlatnessInterface", "the flatness of one interface",
      core::field("id", &S::id, kNone, "value of the interface channel").key("interface"),
      core::field("least_squares", &S::least_squares, kMetreAsUm, "least-squares flatness of its points"));
}

constexpr auto describe(core::Type<FlatnessAnalysis>) {
  using S = FlatnessAnalysis;
  using namespace core::shown;
  return core::fields<S>("FlatnessAnalysis", "flatness of the interfaces from the probe points (report 1.2)",
      core::field("method", &S::method, kNone, "the spec's method"),
      core::field("points", &S::points, kNone, "probe points").in_report(),
      core::field("flatness", &S::flatness, kMetreAsUm, "by `method` (results.json: the unit's flatness_um)").part_only().in_report(),
      core::field("least_squares", &S::least_squares, kMetreAsUm, "peak-to-valley distance from the least-squares plane").in_report(),
      core::field("minimum_zone", &S::minimum_zone, kMetreAsUm, "minimum-zone flatness (at most 100 points)").in_report(),
      core::field("per_interface", &S::per_interface, kNone, "interfaces with 3 non-collinear points or more"),
      core::field("probe_accuracy", &S::probe_accuracy, kMetreAsUm, "[bench] probe accuracy").in_report(),
      core::field("provenance", &S::provenance, kNone, "the record"),
      core::field("deviation", &S::deviation, kMetre, "of every point from the plane (thinned)").part_only(),
      core::field("probe_xy", &S::probe_xy, kNone, "x, y of the same points [m]").part_only());
}

struct CapacitanceAnalysis {
  double sensor = 0.0;    // F, mean of the readings
  double actuator = 0.0;  // F
  std::optional<RecordProvenance> provenance;  // nullopt: typed into the campaign under `key`
  std::string key;                             // "units[i].capacitance_uF" when typed
  double sensor_scatter = 0.0;    // F, standard deviation of the readings (0: typed)
  double actuator_scatter = 0.0;  // F
  long readings = 1;              // readings averaged (a count; 1: typed)
};

constexpr auto describe(core::Type<CapacitanceAnalysis>) {
  using S = CapacitanceAnalysis;
  using namespace core::shown;
  return core::fields<S>("CapacitanceAnalysis", "capacitances of the stacks",
      core::field("sensor", &S::sensor, kFaradAsUf, "sensor stack, mean of the readings"),
      core::field("actuator", &S::actuator, kFaradAsUf, "actuator stacks"),
      core::field("provenance", &S::provenance, kNone, "the record (None: typed into the campaign under `key`)"),
      core::field("key", &S::key, kNone, "\"units[i].capacitance_uF\" when typed"),
      core::field("sensor_scatter", &S::sensor_scatter, kFaradAsUf, "standard deviation of the sensor's readings").part_only(),
      core::field("actuator_scatter", &S::actuator_scatter, kFaradAsUf, "standard deviation of the actuator's readings").part_only(),
      core::field("readings", &S::readings, kNone, "readings averaged (1: typed)").part_only());
}

struct StrokeAnalysis {
  metrology::StrokeResult result;
  RecordProvenance provenance;
  Curve de_vs_va;  // x Va [V], y d_e [m] (thinned)
};

constexpr auto describe(core::Type<StrokeAnalysis>) {
  using S = StrokeAnalysis;
  using namespace core::shown;
  return core::fields<S>("StrokeAnalysis", "the stroke record (report 1.3)",
      core::field("result", &S::result, kNone, "stroke, voltage range, sensitivity, loop width").key("."),
      core::field("provenance", &S::provenance, kNone, "the record"),
      core::field("de_vs_va", &S::de_vs_va, kNone, "x Va [V], y d_e [m] (thinned)").part_only());
}

struct HysteresisLoop {
  metrology::HysteresisResult result;
  RecordProvenance provenance;
  Curve loop;  // x Va [V], y d_e [m], the part of the record analysed (thinned)
};

constexpr auto describe(core::Type<HysteresisLoop>) {
  using S = HysteresisLoop;
  using namespace core::shown;
  return core::fields<S>("HysteresisLoop", "one hysteresis record at an amplitude (report 2.1)",
      core::field("result", &S::result, kNone, "the loop's figures").key("."),
      core::field("provenance", &S::provenance, kNone, "the record"),
      core::field("loop", &S::loop, kNone, "x Va [V], y d_e [m] (thinned)").part_only());
}

// The asymmetry of the steady loop (ident::LoopMetrics::asymmetry) above which the campaign fits
// Kuhnen's modified PI besides the plain one: 1 % of the stroke (at 80 V the bench's symmetric laws
// give 0.02-0.03 %, its asymmetric Bouc-Wen law 2.2 %).
inline constexpr double kHysteresisAsymmetryLimit = 0.01;
// The dead zones per side of the modified PI the campaign fits (ident::HysteresisFitOptions).
inline constexpr int kCampaignDeadZones = 4;

// The hysteresis model identified from the unit's largest-amplitude hysteresis record
// (ident::fit_hysteresis, docs/hysteresis.md): what `hysteresis fit` (with `--dead-zones 4` for the
// modified PI) gives for that file.
struct HysteresisModelFit {
  // The chosen model's fit: the plain PI, or Kuhnen's modified PI (fit.model.output not the
  // identity) when the loop is asymmetric and the modified fit is better: a good verdict where the
  // plain one is poor, or the same verdict and a smaller residual.
  ident::HysteresisFit fit;
  std::optional<ident::HysteresisFit> alternative;  // the candidate not chosen (only when both were fitted)
  std::string alternative_error;  // why the modified PI, asked for, could not be fitted (NumericalError); else empty
  double asymmetry = 0.0;      // of the record's steady loop (ident::LoopMetrics::asymmetry)
  double amplitude = 0.0;      // V, of the record it comes from
  double width = 0.0;          // hysteresis width of that record's steady loop (ident::loop_metrics:
                               // peak-to-peak deviation from the best line / stroke, over the samples
                               // its HysteresisLoop analysed: the ramps from and back to rest left out)
  double model_width = 0.0;    // the same figure for the model's prediction of the record
  RecordProvenance provenance;
  Curve loop;                  // x Va [V], y d_e [m]: the record's loop (thinned)
  Curve model_loop;            // x Va [V], y d_e [m]: the model's prediction of it (thinned)
};

constexpr auto describe(core::Type<HysteresisModelFit>) {
  using S = HysteresisModelFit;
  using namespace core::shown;
  return core::fields<S>("HysteresisModelFit", "the hysteresis model identified from the largest loop",
      core::field("fit", &S::fit, kNone, "the chosen model's fit (plain or modified PI)"),
      core::field("alternative", &S::alternative, kNone, "the candidate not chosen (when both were fitted)"),
      core::field("alternative_error", &S::alternative_error, kNone, "why the modified PI could not be fitted"),
      core::field("asymmetry", &S::asymmetry, kRatio, "of the record's steady loop").key("loop_asymmetry"),
      core::field("amplitude", &S::amplitude, kVolt, "of the record it comes from"),
      core::field("width", &S::width, kRatio, "hysteresis width of the record's steady loop / stroke").key("hysteresis_width"),
      core::field("model_width", &S::model_width, kRatio, "the same for the model's prediction").key("model_hysteresis_width"),
      core::field("provenance", &S::provenance, kNone, "the record"),
      core::field("loop", &S::loop, kNone, "x Va [V], y d_e [m]: the record's loop (thinned)").part_only(),
      core::field("model_loop", &S::model_loop, kNone, "x Va [V], y d_e [m]: the model's prediction (thinned)").part_only());
}

// The tracking experiment's record (`measure tracking`; the demo runs it on one unit with that
// unit's hysteresis_model as the feedforward): d_e against the command without and with the
// inverse hysteresis feedforward, the figures recomputed from the record's samples
// (bench::tracking_layout, bench::tracking_figures: width = peak-to-peak deviation from the best
// line / stroke; rms error against the record's target line).
struct TrackingAnalysis {
  bench::TrackingFigures sine, triangle;
  double amplitude = 0.0;        // V
  std::string feedforward;       // the record's: "identified" (from its open run) or "given"
  double clamped_samples = 0.0;  // of the compensated command, at the stack range
  RecordProvenance provenance;
  // x c [V], y d_e [m] over each waveform's window (thinned): without and with the feedforward.
  Curve sine_open, sine_ff, triangle_open, triangle_ff;
};

constexpr auto describe(core::Type<TrackingAnalysis>) {
  using S = TrackingAnalysis;
  using namespace core::shown;
  return core::fields<S>("TrackingAnalysis", "the tracking record without and with the inverse hysteresis feedforward",
      core::field("sine", &S::sine, kNone, "the 1 Hz sine"),
      core::field("triangle", &S::triangle, kNone, "the triangle"),
      core::field("amplitude", &S::amplitude, kVolt, "of the command"),
      core::field("feedforward", &S::feedforward, kNone, "\"identified\" (from its open run) or \"given\""),
      core::field("clamped_samples", &S::clamped_samples, kNone, "of the compensated command, at the stack range"),
      core::field("provenance", &S::provenance, kNone, "the record"),
      core::field("sine_open", &S::sine_open, kNone, "x c [V], y d_e [m] without the feedforward").part_only(),
      core::field("sine_ff", &S::sine_ff, kNone, "x c [V], y d_e [m] with it").part_only(),
      core::field("triangle_open", &S::triangle_open, kNone, "x c [V], y d_e [m] without").part_only(),
      core::field("triangle_ff", &S::triangle_ff, kNone, "x c [V], y d_e [m] with").part_only());
}

struct StiffnessAnalysis {
  metrology::StaticStiffnessResult result;  // its `fit` is emptied: see `de` and `fit`
  metrology::StaticStiffnessOptions options;
  bool mass_log = false;  // the record had an added_mass channel
  RecordProvenance provenance;
  Curve de;   // x t [s], y d_e [m] (thinned)
  Curve fit;  // x t [s], y creep model [m] (thinned)
  // The Prony-series creep of the record (ident::fit_creep, docs/hysteresis.md): the weight carried
  // (N: the mass log, or added_mass over [t_on, t_off), times gravity) in, d_e (m) out; its gain is
  // the instantaneous compliance (m/N, < 0), its residual and verdict say how well it fits.
  std::optional<ident::CreepFit> creep;
};

constexpr auto describe(core::Type<StiffnessAnalysis>) {
  using S = StiffnessAnalysis;
  using namespace core::shown;
  return core::fields<S>("StiffnessAnalysis", "a static stiffness record (report 2.2)",
      core::field("result", &S::result, kNone, "the readings, k1, k2, creep").key("."),
      core::field("options", &S::options, kNone, "how it was read").key("."),
      core::field("mass_log", &S::mass_log, kNone, "the record had an added_mass channel"),
      core::field("provenance", &S::provenance, kNone, "the record"),
      core::field("de", &S::de, kNone, "x t [s], y d_e [m] (thinned)").part_only(),
      core::field("fit", &S::fit, kNone, "x t [s], y creep model [m] (thinned)").part_only(),
      core::field("creep", &S::creep, kNone, "Prony-series creep, weight (N) in, d_e (m) out (results.json: creep_prony)").part_only());
}

// The FRF analysis' parts and cross-check limits (ident/actuator_frf.hpp, where they are declared).
using ident::HighPassCorner;
using ident::kFeatureCrossCheckTolerance;
using ident::kHighPassCrossCheckRatio;
using ident::NmpEvidence;
using ident::VectorFitSummary;

// The FRFs u -> [d_e, Vs] of a unit's record and what is read from them (ident::analyze_actuator_frf).
struct FrfAnalysis : ident::ActuatorFrfAnalysis {
  RecordProvenance provenance;
  dsp::Frf frf;                       // u -> [de, Vs] (outputs named "de", "Vs")
  std::optional<double> k_resonance;  // N/m, m_sus w_r^2 (metrology::stiffness_from_resonance)
};

// The record's provenance, FRF and stiffness from the resonance, then ident::ActuatorFrfAnalysis's
// own declaration.
constexpr auto describe(core::Type<FrfAnalysis>) {
  using S = FrfAnalysis;
  using namespace core::shown;
  return std::apply(
      [](const auto&... analysis) {
        return core::fields<S>(
            "FrfAnalysis", "the FRFs u -> [d_e, Vs] and what is read from them (report 2.3-2.5)",
            core::field("provenance", &S::provenance, kNone, "the record"),
            core::field("frf", &S::frf, kNone, "u -> [de, Vs]").part_only(),
            core::field("k_resonance", &S::k_resonance, kNewtonPerMetreAsNPerUm, "m_sus w_r^2 (results.json: the unit's stiffness_N_per_um.resonance)").part_only(),
            analysis...);
      },
      core::kFields<ident::ActuatorFrfAnalysis>.fields);
}

// The tuned 2-DoF model (report section 3) with the fitted measurement chain.
struct Model2DofFit {
  apa::TwoDofTuning tuning;
  apa::TwoDofBench bench;  // the chain the model was tuned with (delay, high-pass)
  double fmin_Hz = 0.0, fmax_Hz = 0.0;
};

constexpr auto describe(core::Type<Model2DofFit>) {
  using S = Model2DofFit;
  using namespace core::shown;
  return core::fields<S>("Model2DofFit", "the tuned 2-DoF model (report 3) with the fitted measurement chain",
      core::field("tuning", &S::tuning, kNone, "the tuning"),
      core::field("bench", &S::bench, kNone, "the chain the model was tuned with (delay, high-pass)"),
      core::field("fmin_Hz", &S::fmin_Hz, kHertz, "band of the tuning, low end"),
      core::field("fmax_Hz", &S::fmax_Hz, kHertz, "band of the tuning, high end"));
}

// u -> Vs at low frequency with or without the resistor across the sensor stack (report section
// 2.5, Figure 2.7): Welch with segments of half the record, a first-order high-pass fitted below
// hpf_fmax_Hz. A corner below a third of the lowest line is not observable in the record.
struct LowFrequencyVs {
  RecordProvenance provenance;
  dsp::Frf frf;                         // u -> Vs
  double lowest_line_Hz = 0.0;
  double fmax_Hz = 0.0;                 // band [lowest_line_Hz, fmax_Hz]
  std::optional<double> fitted_corner_Hz;
  double relative_rms_error = 0.0;
  long points = 0;
  bool observable = false;              // fitted corner >= lowest line / 3
};

constexpr auto describe(core::Type<LowFrequencyVs>) {
  using S = LowFrequencyVs;
  using namespace core::shown;
  return core::fields<S>("LowFrequencyVs", "u -> Vs at low frequency, a first-order high-pass fitted (report 2.5)",
      core::field("provenance", &S::provenance, kNone, "the record"),
      core::field("frf", &S::frf, kNone, "u -> Vs").part_only(),
      core::field("lowest_line_Hz", &S::lowest_line_Hz, kHertz, "the FRF's lowest line"),
      core::field("fmax_Hz", &S::fmax_Hz, kHertz, "band [lowest_line_Hz, fmax_Hz]").part_only(),
      core::field("fitted_corner_Hz", &S::fitted_corner_Hz, kHertz, "the fitted corner"),
      core::field("relative_rms_error", &S::relative_rms_error, kRatio, "of the first-order fit"),
      core::field("points", &S::points, kNone, "lines fitted"),
      core::field("observable", &S::observable, kNone, "fitted corner >= lowest line / 3"));
}

struct ResistorComparison {
  std::optional<LowFrequencyVs> with_resistor;  // from the FRF record (when measured)
  LowFrequencyVs without_resistor;
};

constexpr auto describe(core::Type<ResistorComparison>) {
  using S = ResistorComparison;
  using namespace core::shown;
  return core::fields<S>("ResistorComparison", "u -> Vs at low frequency with and without the resistor",
      core::field("with_resistor", &S::with_resistor, kNone, "from the FRF record (when measured)"),
      core::field("without_resistor", &S::without_resistor, kNone, "from the record without the resistor"));
}

// One damped plant u' -> d_e of the IFF experiment.
struct DampedPlant {
  double gain = 0.0;             // V/V, controller gain g
  std::string file;              // as given in the campaign
  RecordProvenance provenance;
  dsp::Frf frf;                  // u' -> d_e
  // The damped pole: the dominant pair of a vector fit in the damped-plant band, d_e's delay
  // removed (ident/dominant_pole.hpp, as `iff study`); nullopt when it failed.
  std::optional<ident::DominantPole> identified;
  long identified_order = 0;     // of the vector fit
  double fmin_Hz = 0.0, fmax_Hz = 0.0;  // the damped-plant band
  // The report's second-order fit of the same data, for comparison (nullopt when it failed).
  std::optional<ident::DelayedSecondOrderFit> second_order;
  double delay_removed = 0.0;    // s
};

constexpr auto describe(core::Type<DampedPlant>) {
  using S = DampedPlant;
  using namespace core::shown;
  return core::fields<S>("DampedPlant", "one damped plant u' -> d_e of the IFF experiment (report 2.6)",
      core::field("gain", &S::gain, kNone, "controller gain g"),
      core::field("file", &S::file, kNone, "as given in the campaign").part_only(),
      core::field("provenance", &S::provenance, kNone, "the record"),
      core::field("frf", &S::frf, kNone, "u' -> d_e").part_only(),
      core::field("identified", &S::identified, kNone, "the damped pole (vector fit, d_e's delay removed)").key("fit"),
      core::field("identified_order", &S::identified_order, kNone, "order of that vector fit").part_only(),
      core::field("fmin_Hz", &S::fmin_Hz, kHertz, "the damped-plant band, low end").part_only(),
      core::field("fmax_Hz", &S::fmax_Hz, kHertz, "the damped-plant band, high end").part_only(),
      core::field("second_order", &S::second_order, kNone, "the report's second-order fit of the same data").key("second_order_fit"),
      core::field("delay_removed", &S::delay_removed, kSecond, "d_e's delay removed before the fit"));
}

struct FlexibleModes {
  RecordProvenance provenance;
  dsp::FrfProvenance welch;
  struct Mode {
    double frequency_Hz = 0.0;
    double damping = 0.0;
    long stable_orders = 0;  // LSCF only
  };
  std::vector<Mode> peak_picking, lscf;
  dsp::Frf frf;  // F -> v
};

constexpr auto describe(core::Type<FlexibleModes::Mode>) {
  using S = FlexibleModes::Mode;
  using namespace core::shown;
  return core::fields<S>("FlexibleMode", "one flexible mode",
      core::field("frequency_Hz", &S::frequency_Hz, kHertz, "natural frequency"),
      core::field("damping", &S::damping, kRatio, "damping ratio"),
      core::field("stable_orders", &S::stable_orders, kNone, "LSCF: orders it is stable over"));
}

constexpr auto describe(core::Type<FlexibleModes>) {
  using S = FlexibleModes;
  using namespace core::shown;
  return core::fields<S>("FlexibleModes", "flexible modes from the hammer test (report 2.7)",
      core::field("provenance", &S::provenance, kNone, "the record"),
      core::field("welch", &S::welch, kNone, "the Welch estimate's settings"),
      core::field("peak_picking", &S::peak_picking, kNone, "modes by peak picking"),
      core::field("lscf", &S::lscf, kNone, "modes by LSCF"),
      core::field("frf", &S::frf, kNone, "F -> v").part_only());
}

// Why a unit could not be analysed: one of its files is missing, unreadable or holds data no
// analysis can use (a channel missing, NaN, a dead sensor's constant signal, ...). The unit's other
// results are then left out, so the batch is the batch without it (pipeline.hpp).
struct NotAnalysed {
  std::string file;    // as given in the campaign ("" when the failure is not a file's)
  std::string key;     // campaign key of the file entry, e.g. "units[1].frf"
  std::string reason;  // the InputError's message
};

constexpr auto describe(core::Type<NotAnalysed>) {
  using S = NotAnalysed;
  using namespace core::shown;
  return core::fields<S>("NotAnalysed", "why a unit could not be analysed",
      core::field("file", &S::file, kNone, "as given in the campaign (\"\" when not a file's)"),
      core::field("key", &S::key, kNone, "campaign key of the file entry"),
      core::field("reason", &S::reason, kNone, "the InputError's message"));
}

// One acceptance check of a unit (pipeline.hpp): the value with its expanded uncertainty against the
// specification's limits, decided by metrology::decide (ISO 14253-1: pass, marginal, fail).
struct AcceptanceCheck {
  std::string quantity;                    // "stroke", "stiffness k1", "capacitance of the sensor stack", ...
  std::string unit;                        // of the decision's value, U and limits: "um", "uF", "N/um"
  metrology::ConformityDecision decision;  // in `unit`
  metrology::UncertaintyBudget budget;     // SI (its own `unit`)
  std::string reason;                      // the sentence of a marginal or failed check, "" on pass
};

constexpr auto describe(core::Type<AcceptanceCheck>) {
  using S = AcceptanceCheck;
  using namespace core::shown;
  return core::fields<S>("AcceptanceCheck", "a value +- U against its limits (ISO 14253-1)",
      core::field("quantity", &S::quantity, kNone, "what is checked"),
      core::field("unit", &S::unit, kNone, "of the decision's value, U and limits"),
      core::field("decision", &S::decision, kNone, "verdict, U, guard band, probability of conformity").key("."),
      core::field("budget", &S::budget, kNone, "the GUM budget behind U (SI)"),
      core::field("reason", &S::reason, kNone, "why a check is marginal or fails"));
}

struct UnitAnalysis {
  int id = 0;
  std::string name;
  std::optional<NotAnalysed> not_analysed;  // set: nothing else of the unit is filled in
  std::optional<FlatnessAnalysis> flatness_analysis;
  std::optional<CapacitanceAnalysis> capacitance_analysis;
  std::optional<StrokeAnalysis> stroke_analysis;
  std::vector<HysteresisLoop> hysteresis;  // by amplitude
  std::optional<HysteresisModelFit> hysteresis_model;  // from the largest amplitude
  std::optional<TrackingAnalysis> tracking;
  std::optional<StiffnessAnalysis> stiffness_analysis;       // stacks on the amplifier and the resistor
  std::optional<StiffnessAnalysis> stiffness_open_analysis;  // every stack open (k_oc)
  std::optional<FrfAnalysis> frf_analysis;
  std::optional<ResistorComparison> resistor;
  std::optional<Model2DofFit> model_2dof;
  std::vector<DampedPlant> damped;         // by gain, with or without an identified pole
  std::optional<FlexibleModes> flexible_modes;
  std::vector<std::string> not_measured;     // experiments the campaign does not list
  std::vector<std::string> failed;           // "frf: vector fitting failed: ..." (NumericalError)
  std::vector<std::string> warnings;         // cross-checks that disagree (kHighPassCrossCheckRatio, ...)
  // The acceptance (pipeline.hpp): accepted only when every check passes; marginal when none fails
  // but one is marginal (`run --strict` fails on it too); reasons of both.
  bool accepted = false;
  bool marginal = false;
  std::vector<std::string> reasons;
  std::vector<AcceptanceCheck> checks;
};

// The numbers the batch analyses and the acceptance read, each from the analysis that holds it
// (SI; nullopt or nullptr: that analysis was not run or did not give it). UnitAnalysis's
// declaration lists them as derived fields, so the documents show them as the unit's.
inline std::optional<double> flatness_of(const UnitAnalysis& u) {  // m, by the spec's method
  return u.flatness_analysis ? std::optional(u.flatness_analysis->flatness) : std::nullopt;
}
inline std::optional<double> capacitance_sensor_of(const UnitAnalysis& u) {  // F
  return u.capacitance_analysis ? std::optional(u.capacitance_analysis->sensor) : std::nullopt;
}
inline std::optional<double> capacitance_actuator_of(const UnitAnalysis& u) {  // F
  return u.capacitance_analysis ? std::optional(u.capacitance_analysis->actuator) : std::nullopt;
}
inline std::optional<double> stroke_of(const UnitAnalysis& u) {  // m
  return u.stroke_analysis ? std::optional(u.stroke_analysis->result.stroke) : std::nullopt;
}
inline std::optional<double> k1_of(const UnitAnalysis& u) {  // N/m (k_sc = k1)
  return u.stiffness_analysis ? std::optional(u.stiffness_analysis->result.k1) : std::nullopt;
}
inline std::optional<double> k2_of(const UnitAnalysis& u) {  // N/m
  return u.stiffness_analysis ? std::optional(u.stiffness_analysis->result.k2) : std::nullopt;
}
inline std::optional<double> k_oc_of(const UnitAnalysis& u) {  // N/m, k1 of the test with every stack open
  return u.stiffness_open_analysis ? std::optional(u.stiffness_open_analysis->result.k1) : std::nullopt;
}
inline std::optional<double> k_resonance_of(const UnitAnalysis& u) {  // N/m, m_sus w_r^2
  return u.frf_analysis ? u.frf_analysis->k_resonance : std::nullopt;
}
inline std::optional<double> resonance_Hz_of(const UnitAnalysis& u) {  // Hz
  return u.frf_analysis ? u.frf_analysis->resonance_Hz : std::nullopt;
}
inline std::optional<double> antiresonance_Hz_of(const UnitAnalysis& u) {  // Hz
  return u.frf_analysis ? u.frf_analysis->antiresonance_Hz : std::nullopt;
}
inline std::optional<double> static_gain_of(const UnitAnalysis& u) {  // m/V
  return u.frf_analysis ? u.frf_analysis->static_gain : std::nullopt;
}
inline std::optional<double> sensitivity_of(const UnitAnalysis& u) {  // m/V
  return u.stroke_analysis ? std::optional(u.stroke_analysis->result.sensitivity) : std::nullopt;
}
inline std::optional<double> resonance_damping_of(const UnitAnalysis& u) {  // 1
  return u.frf_analysis ? u.frf_analysis->resonance_damping : std::nullopt;
}
inline std::optional<double> hpf_corner_Hz_of(const UnitAnalysis& u) {  // Hz
  return u.frf_analysis ? u.frf_analysis->hpf.corner_Hz : std::nullopt;
}
inline std::optional<double> hpf_corner_without_resistor_Hz_of(const UnitAnalysis& u) {  // Hz
  return u.resistor ? u.resistor->without_resistor.fitted_corner_Hz : std::nullopt;
}
inline std::optional<double> first_mode_Hz_of(const UnitAnalysis& u) {  // Hz, LSCF's first mode, else peak picking's
  if (!u.flexible_modes) return std::nullopt;
  const auto& modes = u.flexible_modes->lscf.empty() ? u.flexible_modes->peak_picking : u.flexible_modes->lscf;
  return modes.empty() ? std::nullopt : std::optional(modes.front().frequency_Hz);
}
inline std::optional<double> tracking_width_ff_of(const UnitAnalysis& u) {  // 1
  return u.tracking ? std::optional(u.tracking->sine.width_ff) : std::nullopt;
}
inline std::optional<double> tracking_rms_reduction_of(const UnitAnalysis& u) {  // 1
  return u.tracking ? std::optional(u.tracking->sine.rms_reduction()) : std::nullopt;
}
inline const dsp::Frf* frf_of(const UnitAnalysis& u) {  // u -> [de, Vs]
  return u.frf_analysis ? &u.frf_analysis->frf : nullptr;
}
inline const ident::IffPlantFit* iff_plant_of(const UnitAnalysis& u) {  // u -> Vs, eq. 2.3 with delay
  return u.frf_analysis && u.frf_analysis->iff_plant ? &*u.frf_analysis->iff_plant : nullptr;
}
inline const ident::DelayedSecondOrderFit* de_plant_of(const UnitAnalysis& u) {  // u -> d_e, mass-spring-damper with delay
  return u.frf_analysis && u.frf_analysis->de_plant ? &*u.frf_analysis->de_plant : nullptr;
}

constexpr auto describe(core::Type<UnitAnalysis>) {
  using S = UnitAnalysis;
  using namespace core::shown;
  return core::fields<S>("UnitAnalysis", "one unit's analyses and acceptance",
      core::field("id", &S::id, kNone, "unit id"),
      core::field("name", &S::name, kNone, "unit name"),
      core::field("not_analysed", &S::not_analysed, kNone, "set: nothing else of the unit is filled in"),
      core::field("flatness_analysis", &S::flatness_analysis, kNone, "flatness of the interfaces").key("flatness"),
      core::field("capacitance_analysis", &S::capacitance_analysis, kNone, "capacitances of the stacks (results.json: capacitance_provenance)").part_only(),
      core::field("stroke_analysis", &S::stroke_analysis, kNone, "the stroke record").key("stroke"),
      core::field("hysteresis", &S::hysteresis, kNone, "hysteresis loops, by amplitude"),
      core::field("hysteresis_model", &S::hysteresis_model, kNone, "the model of the largest loop").part_only(),
      core::field("tracking", &S::tracking, kNone, "the tracking record"),
      core::field("stiffness_analysis", &S::stiffness_analysis, kNone, "stacks on the amplifier and the resistor").key("stiffness_static"),
      core::field("stiffness_open_analysis", &S::stiffness_open_analysis, kNone, "every stack open (k_oc)").key("stiffness_open_circuit"),
      core::field("frf_analysis", &S::frf_analysis, kNone, "the FRFs and their features").key("frf"),
      core::field("resistor", &S::resistor, kNone, "u -> Vs with and without the resistor (results.json: hpf_resistor)").part_only(),
      core::field("model_2dof", &S::model_2dof, kNone, "the tuned 2-DoF model (results.json: model_2dof, model_2dof_fit)").part_only(),
      core::field("damped", &S::damped, kNone, "damped plants, by gain (results.json: iff_damped_plants)").part_only(),
      core::field("flexible_modes", &S::flexible_modes, kNone, "flexible modes"),
      core::derived("flatness", &flatness_of, kMetreAsUm, "flatness of the interfaces by the spec's method"),
      core::derived("capacitance_sensor", &capacitance_sensor_of, kFaradAsUf, "capacitance of the sensor stack").key("capacitance_uF.sensor"),
      core::derived("capacitance_actuator", &capacitance_actuator_of, kFaradAsUf, "capacitance of the actuator stacks").key("capacitance_uF.actuator"),
      core::derived("stroke", &stroke_of, kMetreAsUm, "stroke, max - min of d_e over the stack range"),
      core::derived("k1", &k1_of, kNewtonPerMetreAsNPerUm, "static stiffness, mass put on (= k_sc)").key("stiffness_N_per_um.k1"),
      core::derived("k2", &k2_of, kNewtonPerMetreAsNPerUm, "static stiffness, mass taken off").key("stiffness_N_per_um.k2"),
      core::derived("k_resonance", &k_resonance_of, kNewtonPerMetreAsNPerUm, "stiffness from the resonance, m_sus w^2").key("stiffness_N_per_um.resonance"),
      core::derived("k_oc", &k_oc_of, kNewtonPerMetreAsNPerUm, "static stiffness with every stack open").key("stiffness_N_per_um.k_oc"),
      core::derived("resonance_Hz", &resonance_Hz_of, kHertz, "resonance of u -> d_e").part_only(),
      core::derived("antiresonance_Hz", &antiresonance_Hz_of, kHertz, "anti-resonance of u -> Vs").part_only(),
      core::derived("static_gain", &static_gain_of, kMetrePerVoltAsUmPerV, "static gain u -> d_e").part_only(),
      core::derived("sensitivity", &sensitivity_of, kMetrePerVoltAsUmPerV, "slope of d_e against Va").part_only(),
      core::derived("resonance_damping", &resonance_damping_of, kRatio, "damping ratio of the resonance").part_only(),
      core::derived("hpf_corner_Hz", &hpf_corner_Hz_of, kHertz, "high-pass corner of the force sensor"),
      core::derived("hpf_corner_without_resistor_Hz", &hpf_corner_without_resistor_Hz_of, kHertz, "fitted corner without the resistor").part_only(),
      core::derived("first_mode_Hz", &first_mode_Hz_of, kHertz, "first flexible mode (LSCF, else peak picking)").part_only(),
      core::derived("tracking_width_ff", &tracking_width_ff_of, kRatio, "hysteresis width of the 1 Hz sine with the feedforward").part_only(),
      core::derived("tracking_rms_reduction", &tracking_rms_reduction_of, kRatio, "rms tracking error without / with the feedforward (sine)").part_only(),
      core::derived("frf", &frf_of, kNone, "u -> [de, Vs]").part_only(),
      core::derived("iff_plant", &iff_plant_of, kNone, "u -> Vs, eq. 2.3 with delay").part_only(),
      core::derived("de_plant", &de_plant_of, kNone, "u -> d_e, mass-spring-damper with delay").part_only(),
      core::field("not_measured", &S::not_measured, kNone, "experiments the campaign does not list"),
      core::field("failed", &S::failed, kNone, "one line per analysis that failed"),
      core::field("warnings", &S::warnings, kNone, "cross-checks that disagree"),
      core::field("accepted", &S::accepted, kNone, "the acceptance: every check passes"),
      core::field("marginal", &S::marginal, kNone, "no check fails, one is marginal (a limit within value +- U)"),
      core::field("reasons", &S::reasons, kNone, "why it is rejected or marginal"),
      core::field("checks", &S::checks, kNone, "each acceptance check with its uncertainty and verdict"));
}

// ------------------------------------------------------------------------------------ batch

struct QuantitySpread {
  std::string quantity;  // results key, e.g. "capacitance_sensor_uF" (values in that unit)
  std::string label;     // for people, e.g. "capacitance of the sensor stack"
  std::string unit;      // of the values, e.g. "uF"
  long units = 0;
  double min = 0.0, max = 0.0, median = 0.0, relative_spread = 0.0, mad = 0.0;  // in `unit` (relative_spread: ratio)
};

struct BatchOutlier {
  int unit = 0;
  std::string quantity;  // as in QuantitySpread
  double value = 0.0, median = 0.0, robust_z = 0.0;  // same unit as the quantity's values (robust_z: dimensionless)
};

// Unit-to-unit similarity of the FRFs: rms distance in dB from the batch median magnitude.
struct FrfSimilarity {
  struct Unit {
    int unit = 0;
    double de_rms_dB = 0.0, vs_rms_dB = 0.0;  // NaN when no point compares
  };
  double fmin_Hz = 0.0, fmax_Hz = 0.0;
  std::vector<Unit> units;
  double max_rms_dB = 0.0;
};

struct BatchAnalysis {
  std::vector<BatchOutlier> outliers;
  std::vector<QuantitySpread> spread;
  std::optional<FrfSimilarity> similarity;  // two units with an FRF or more
  metrology::OutlierOptions rule;
  bool rejects = false;  // outliers in capacitance or stroke reject a unit
};

constexpr auto describe(core::Type<QuantitySpread>) {
  using S = QuantitySpread;
  using namespace core::shown;
  return core::fields<S>("QuantitySpread", "one quantity over the batch (values in its results.json unit)",
      core::field("quantity", &S::quantity, kNone, "results key, e.g. capacitance_sensor_uF"),
      core::field("label", &S::label, kNone, "for people"),
      core::field("unit", &S::unit, kNone, "of the values"),
      core::field("units", &S::units, kNone, "units measured"),
      core::field("min", &S::min, kNone, "in the quantity's unit"),
      core::field("max", &S::max, kNone, "in the quantity's unit"),
      core::field("median", &S::median, kNone, "in the quantity's unit"),
      core::field("relative_spread", &S::relative_spread, kRatio, "(max - min) / |median|"),
      core::field("mad", &S::mad, kNone, "median absolute deviation, in the quantity's unit"));
}

constexpr auto describe(core::Type<BatchOutlier>) {
  using S = BatchOutlier;
  using namespace core::shown;
  return core::fields<S>("BatchOutlier", "a unit whose quantity is an outlier of the batch",
      core::field("unit", &S::unit, kNone, "unit id"),
      core::field("quantity", &S::quantity, kNone, "as in QuantitySpread"),
      core::field("value", &S::value, kNone, "in the quantity's unit"),
      core::field("median", &S::median, kNone, "of the batch"),
      core::field("robust_z", &S::robust_z, kRatio, "modified z-score"));
}

constexpr auto describe(core::Type<FrfSimilarity::Unit>) {
  using S = FrfSimilarity::Unit;
  using namespace core::shown;
  return core::fields<S>("FrfSimilarityUnit", "one unit's rms distance from the batch median |H|",
      core::field("unit", &S::unit, kNone, "unit id"),
      core::field("de_rms_dB", &S::de_rms_dB, kDecibel, "u -> d_e (NaN when no point compares)"),
      core::field("vs_rms_dB", &S::vs_rms_dB, kDecibel, "u -> Vs").key("Vs_rms_dB"));
}

constexpr auto describe(core::Type<FrfSimilarity>) {
  using S = FrfSimilarity;
  using namespace core::shown;
  return core::fields<S>("FrfSimilarity", "unit-to-unit similarity of the FRFs",
      core::field("fmin_Hz", &S::fmin_Hz, kHertz, "band compared, low end").part_only(),
      core::field("fmax_Hz", &S::fmax_Hz, kHertz, "band compared, high end").part_only(),
      core::field("units", &S::units, kNone, "per unit"),
      core::field("max_rms_dB", &S::max_rms_dB, kDecibel, "the largest"));
}

constexpr auto describe(core::Type<BatchAnalysis>) {
  using S = BatchAnalysis;
  using namespace core::shown;
  return core::fields<S>("BatchAnalysis", "the batch: spreads, outliers and FRF similarity",
      core::field("outliers", &S::outliers, kNone, "units whose quantity is an outlier"),
      core::field("spread", &S::spread, kNone, "each quantity over the batch (results.json: an object by quantity)").part_only(),
      core::field("similarity", &S::similarity, kNone, "of the FRFs (two units with an FRF or more)"),
      core::field("rule", &S::rule, kNone, "the outlier rule").key("outlier_rule"),
      core::field("rejects", &S::rejects, kNone, "outliers in capacitance or stroke reject a unit").key("outlier_rule.rejects"));
}

// The IFF study: root locus of the fitted plant with the report's controller against the poles of
// the measured damped plants.
struct IffStudy {
  control::IffControllerParams controller;
  std::optional<int> unit;                 // the unit whose plant is used
  std::optional<ident::IffPlantFit> plant;
  std::vector<double> gains;                                    // V/V, of the damped plants with an identified pole
  std::vector<std::complex<double>> damped_poles, model_poles;  // rad/s
  std::vector<double> relative_pole_distance;
  double max_relative_pole_distance = 0.0;
  double pole_distance_tolerance = 0.0;  // relative, above it: `warning`
  std::optional<std::string> warning;
  std::optional<double> optimal_gain, max_damping;  // optimal_gain: V/V (IFF gain g); max_damping: ratio
  std::complex<double> optimal_pole;       // rad/s
  std::string note;                        // why there is no study
  std::optional<std::string> failed;       // a NumericalError of the study
  // The root locus for the plot (report Figure 2.10b), inside 3 wp of the origin, upper half plane.
  struct Branch {
    Curve re_im;               // x Re, y Im [rad/s]
    std::vector<double> gains;  // V/V, at each point
    bool resonance_branch = false;
  };
  std::vector<Branch> branches;
  Curve open_loop_poles, open_loop_zeros;  // x Re, y Im [rad/s]
};

constexpr auto describe(core::Type<IffStudy::Branch>) {
  using S = IffStudy::Branch;
  using namespace core::shown;
  return core::fields<S>("IffLocusBranch", "one branch of the IFF root locus, for the plot",
      core::field("re_im", &S::re_im, kNone, "x Re, y Im [rad/s]"),
      core::field("gains", &S::gains, kNone, "the controller gain at each point"),
      core::field("resonance_branch", &S::resonance_branch, kNone, "the branch from the resonance pole"));
}

constexpr auto describe(core::Type<IffStudy>) {
  using S = IffStudy;
  using namespace core::shown;
  return core::fields<S>("IffStudy", "the IFF root locus of the fitted plant against the measured damped plants (report 2.6)",
      core::field("controller", &S::controller, kNone, "the report's controller, eq. 2.4"),
      core::field("unit", &S::unit, kNone, "the unit whose plant is used"),
      core::field("plant", &S::plant, kNone, "that unit's IFF plant fit"),
      core::field("gains", &S::gains, kNone, "of the damped plants with an identified pole"),
      core::field("damped_poles", &S::damped_poles, kRadPerSecond, "identified on the damped plants").key("damped_poles"),
      core::field("model_poles", &S::model_poles, kRadPerSecond, "the root locus at the same gains").key("model_poles"),
      core::field("relative_pole_distance", &S::relative_pole_distance, kRatio, "|model - damped| / |model| per gain"),
      core::field("max_relative_pole_distance", &S::max_relative_pole_distance, kRatio, "the largest"),
      core::field("pole_distance_tolerance", &S::pole_distance_tolerance, kRatio, "above it: warning"),
      core::field("warning", &S::warning, kNone, "the model misses the damped poles"),
      core::field("optimal_gain", &S::optimal_gain, kNone, "the gain of maximum damping of the resonance branch"),
      core::field("max_damping", &S::max_damping, kRatio, "that damping"),
      core::field("optimal_pole", &S::optimal_pole, kRadPerSecond, "the pole there").key("optimal_pole"),
      core::field("note", &S::note, kNone, "why there is no study"),
      core::field("failed", &S::failed, kNone, "a NumericalError of the study"),
      core::field("branches", &S::branches, kNone, "the root locus for the plot (Figure 2.10b)").part_only(),
      core::field("open_loop_poles", &S::open_loop_poles, kNone, "x Re, y Im [rad/s]").part_only(),
      core::field("open_loop_zeros", &S::open_loop_zeros, kNone, "x Re, y Im [rad/s]").part_only());
}

// Report section 4: the super element on the bench, ga and gs tuned against one unit's measured
// FRFs (superelement_fit.hpp).
struct SuperElementUnitFit {
  int unit = 0;
  std::string name;
  double ga = 0.0;                   // N/V (signed: the sign that makes the phases agree)
  double gs = 0.0;                   // V/m
  double ga_relative_to_eq41 = 0.0;  // |ga| / eq. 4.1's - 1
  double gs_relative_to_eq41 = 0.0;
  std::array<double, 2> band_Hz{};   // the tuning band
  double resonance_Hz = 0.0;                  // of the tuned model's u -> d_e
  std::optional<double> antiresonance_Hz;     // of the tuned model's u -> V_s (below the resonance)
  std::optional<double> measured_resonance_Hz, measured_antiresonance_Hz;  // the unit's (FrfAnalysis)
  double de_error_dB = 0.0, vs_error_dB = 0.0;  // median |model/measured| in dB (superelement_fit.hpp)
};

constexpr auto describe(core::Type<SuperElementUnitFit>) {
  using S = SuperElementUnitFit;
  using namespace core::shown;
  return core::fields<S>("SuperElementUnitFit", "the super element's ga and gs tuned against one unit's FRFs (report 4)",
      core::field("unit", &S::unit, kNone, "unit id"),
      core::field("name", &S::name, kNone, "unit name").in_report(),
      core::field("ga", &S::ga, kNewtonPerVolt, "signed: the sign that makes the phases agree").in_report(),
      core::field("ga_relative_to_eq41", &S::ga_relative_to_eq41, kRatio, "|ga| / eq. 4.1's - 1").in_report(),
      core::field("gs", &S::gs, kVoltPerMetreAsVPerUm, "signed, as ga").in_report(),
      core::field("gs_relative_to_eq41", &S::gs_relative_to_eq41, kRatio, "|gs| / eq. 4.1's - 1").in_report(),
      core::field("band_Hz", &S::band_Hz, kHertz, "the tuning band"),
      core::field("resonance_Hz", &S::resonance_Hz, kHertz, "of the tuned model's u -> d_e").in_report(),
      core::field("measured_resonance_Hz", &S::measured_resonance_Hz, kHertz, "the unit's").in_report(),
      core::field("antiresonance_Hz", &S::antiresonance_Hz, kHertz, "of the tuned model's u -> V_s (below the resonance)").in_report(),
      core::field("measured_antiresonance_Hz", &S::measured_antiresonance_Hz, kHertz, "the unit's").in_report(),
      core::field("de_error_dB", &S::de_error_dB, kDecibel, "median |model / measured| of u -> d_e").in_report(),
      core::field("vs_error_dB", &S::vs_error_dB, kDecibel, "the same of u -> V_s").in_report());
}

// The super element's comparison with the measurements: every unit with an FRF tuned, medians,
// eq. 4.1's sensitivities for the bench's piezo constants, and the tuned model of the first such
// unit for Figure 4.2.
struct SuperElementComparison {
  std::string source;        // as given in the campaign
  long dofs = 0;
  std::vector<double> modes_Hz;  // the first ten of the bench model
  double moving_mass = 0.0;      // kg, on the moving interface
  double eq41_ga = 0.0;          // N/V, eq. 4.1 with Table 4.1's constants and the stacks' modulus
  double eq41_gs = 0.0;          // V/m
  double stack_modulus = 48e9;   // Pa, the stacks' effective modulus eq. 4.1 is evaluated with
  std::vector<SuperElementUnitFit> units;
  std::optional<double> ga, gs;  // N/V, V/m: medians of |ga|, |gs| over the units
  std::optional<double> resonance_Hz;           // the first unit's tuned model
  std::optional<double> measured_resonance_Hz;  // median of the units'
  std::vector<std::string> warnings;
  // Figure 4.2: the first tuned unit's model at its measured frequencies (SuperElementFit::model:
  // outputs "de", m/V, and "Vs", V/V).
  struct Response {
    int unit = 0;
    std::string name;
    dsp::Frf model;
  };
  std::optional<Response> figure;
  std::optional<std::string> failed;
};

constexpr auto describe(core::Type<SuperElementComparison::Response>) {
  using S = SuperElementComparison::Response;
  using namespace core::shown;
  return core::fields<S>("SuperElementResponse", "the first tuned unit's model at its measured frequencies (Figure 4.2)",
      core::field("unit", &S::unit, kNone, "unit id"),
      core::field("name", &S::name, kNone, "unit name"),
      core::field("model", &S::model, kNone, "outputs de (m/V) and Vs (V/V)"));
}

constexpr auto describe(core::Type<SuperElementComparison>) {
  using S = SuperElementComparison;
  using namespace core::shown;
  return core::fields<S>("SuperElementComparison", "the super element on the bench against the measured FRFs (report 4)",
      core::field("source", &S::source, kNone, "as given in the campaign"),
      core::field("dofs", &S::dofs, kNone, "degrees of freedom of the reduced model"),
      core::field("modes_Hz", &S::modes_Hz, kHertz, "the first ten of the bench model"),
      core::field("moving_mass", &S::moving_mass, kKilogram, "on the moving interface"),
      core::field("eq41_ga", &S::eq41_ga, kNewtonPerVolt, "eq. 4.1 with Table 4.1's constants").key("eq41.ga_N_per_V"),
      core::field("eq41_gs", &S::eq41_gs, kVoltPerMetreAsVPerUm, "eq. 4.1 with Table 4.1's constants").key("eq41.gs_V_per_um"),
      core::field("stack_modulus", &S::stack_modulus, kPascal, "the stacks' effective modulus eq. 4.1 is evaluated with").key("eq41.stack_modulus_Pa"),
      core::field("units", &S::units, kNone, "every unit with an FRF, tuned"),
      core::field("ga", &S::ga, kNewtonPerVolt, "median |ga| over the units"),
      core::field("gs", &S::gs, kVoltPerMetreAsVPerUm, "median |gs| over the units"),
      core::field("resonance_Hz", &S::resonance_Hz, kHertz, "the first unit's tuned model"),
      core::field("measured_resonance_Hz", &S::measured_resonance_Hz, kHertz, "median of the units'"),
      core::field("warnings", &S::warnings, kNone, "disagreements with the measurements"),
      core::field("figure", &S::figure, kNone, "Figure 4.2's model").part_only(),
      core::field("failed", &S::failed, kNone, "a NumericalError of the comparison"));
}

struct CampaignResult {
  Campaign campaign;  // as read
  std::vector<UnitAnalysis> units;
  BatchAnalysis batch;
  IffStudy iff;
  std::optional<SuperElementComparison> superelement;  // when the campaign gives one
  int accepted = 0;
  int marginal = 0;      // analysed, no check failed, one marginal (neither accepted nor rejected)
  int rejected = 0;      // analysed and rejected
  int not_analysed = 0;  // units with UnitAnalysis::not_analysed (neither accepted nor rejected)
};

inline int unit_count_of(const CampaignResult& r) { return static_cast<int>(r.units.size()); }

// What campaign.run returns in Python (the campaign as read is its input, not declared). results.json
// holds the counts under "summary" from this declaration; it writes the parts its own way
// (results_json.cpp: "units", "batch", "iff", "superelement"), so they are kept out of results_object.
constexpr auto describe(core::Type<CampaignResult>) {
  using S = CampaignResult;
  using namespace core::shown;
  return core::fields<S>("CampaignResult", "the results of a campaign: every unit, the batch, the IFF study",
      core::field("units", &S::units, kNone, "every unit's analysis, in the campaign's order").part_only(),
      core::field("batch", &S::batch, kNone, "the batch's spreads, outliers and FRF similarity").part_only(),
      core::field("iff", &S::iff, kNone, "the IFF study").part_only(),
      core::field("superelement", &S::superelement, kNone, "the super element on the bench (when the campaign gives one)").part_only(),
      core::derived("unit_count", &unit_count_of, kNone, "units of the campaign").key("summary.units"),
      core::field("accepted", &S::accepted, kNone, "units accepted").key("summary.accepted"),
      core::field("marginal", &S::marginal, kNone, "units with a marginal check and no failed one").key("summary.marginal"),
      core::field("rejected", &S::rejected, kNone, "units analysed and rejected").key("summary.rejected"),
      core::field("not_analysed", &S::not_analysed, kNone, "units whose data could not be analysed").key("summary.not_analysed"));
}

}  // namespace piezobench::campaign
