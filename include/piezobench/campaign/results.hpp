#pragma once
// The typed results of a campaign: one struct per analysis of a unit (unit_analysis.hpp fills
// them), the batch (pipeline.hpp) and the whole campaign. Numbers are SI unless the field name
// says otherwise (`_Hz`, `_deg`); the serializers (results_json.hpp: results.json, results.mat,
// the CLI's --json; report_document.hpp: the report) turn them into the documents' units and keys.
//
// An analysis that was not run (experiment not measured, or failed on valid data) is a nullopt;
// its failure is one line of UnitAnalysis::failed.
#include <Eigen/Core>
#include <complex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "piezobench/apa/tuning.hpp"
#include "piezobench/apa/two_dof.hpp"
#include "piezobench/bench/tracking.hpp"
#include "piezobench/campaign/campaign_file.hpp"
#include "piezobench/ident/plant_fit.hpp"
#include "piezobench/dsp/frf.hpp"
#include "piezobench/ident/dominant_pole.hpp"
#include "piezobench/ident/features.hpp"
#include "piezobench/ident/hysteresis.hpp"
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

// A curve of the report (thinned or log-spaced samples).
struct Curve {
  std::vector<double> x, y;
};

struct FlatnessAnalysis {
  metrology::FlatnessMethod method = metrology::FlatnessMethod::kLeastSquares;  // the spec's
  double flatness = 0.0;                     // m, by `method`
  double least_squares = 0.0;                // m
  std::optional<double> minimum_zone;        // m (at most 100 points)
  long points = 0;
  struct Interface {
    double id = 0.0;            // value of the interface channel
    double least_squares = 0.0; // m
  };
  std::vector<Interface> per_interface;      // interfaces with 3 non-collinear points or more
  double probe_accuracy = 0.0;               // m, [bench]
  RecordProvenance provenance;
  std::vector<double> deviation;             // m, of every point (thinned), for the report
  Curve probe_xy;                            // x, y of the same points [m] (the report's figure)
};

struct CapacitanceAnalysis {
  double sensor = 0.0;    // F, mean of the readings
  double actuator = 0.0;  // F
  std::optional<RecordProvenance> provenance;  // nullopt: typed into the campaign under `key`
  std::string key;                             // "units[i].capacitance_uF" when typed
};

struct StrokeAnalysis {
  metrology::StrokeResult result;
  RecordProvenance provenance;
  Curve de_vs_va;  // x Va [V], y d_e [m] (thinned)
};

struct HysteresisLoop {
  metrology::HysteresisResult result;
  RecordProvenance provenance;
  Curve loop;  // x Va [V], y d_e [m], the part of the record analysed (thinned)
};

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

// A vector fit's summary (ident/vector_fitting.hpp).
struct VectorFitSummary {
  long order = 0;
  double relative_rms_error = 0.0;
  bool converged = false;
};

// Evidence of a non-minimum-phase zero pair in u -> Vs.
struct NmpEvidence {
  struct Zero {
    ident::PhaseVerdict phase_verdict = ident::PhaseVerdict::kUndetermined;
    double phase_change_deg = 0.0;
    std::complex<double> fitted_zero;  // rad/s
    bool fitted_zero_nonminimum_phase = false;
  };
  std::optional<Zero> zero;              // the vector fit's zero nearest the dip
  std::optional<double> iff_plant_fit_xz;
  std::optional<double> iff_plant_fit_xz_standard_error;  // the verdict's 95 % interval is xz +- 1.96 of it
  std::string verdict_from;              // "phase", "iff-plant-fit", "fitted-zero" or "none"
  std::string verdict_reason;            // why (ident::ZeroPhaseVerdict::reason)
};

// The resistor high-pass of the force sensor's read-out.
struct HighPassCorner {
  std::optional<double> first_order_fit_Hz;  // first-order fit below hpf_fmax_Hz
  long first_order_fit_points = 0;
  std::optional<double> r_c_Hz;              // 1 / (2 pi R C_sensor) when C_sensor is measured
  std::optional<double> iff_plant_fit_Hz;    // eq. 2.3 fitted down to the lowest frequency
  std::optional<std::string> iff_plant_fit_error;  // the cross-check's failure (with r_c_Hz)
  std::string method;                        // how corner_Hz was chosen, or why there is none
  double observable_above_Hz = 0.0;          // a third of the FRF's lowest line: a fitted corner below is not observable
  // The unit's corner: r_c (a resistor in [bench] and C_sensor measured), else the IFF fit's, else
  // the first-order fit's when observable; nullopt otherwise (no resistor: no high-pass to report).
  std::optional<double> corner_Hz;
};

// Cross-checks of a unit's FRF features (UnitAnalysis::warnings when they disagree): the high-pass
// corner's (1/(2 pi R C), the IFF plant fit, the first-order fit) by more than this ratio (the
// free IFF plant fit of an 8 s record lands up to a factor 1.6 below 1/(2 pi R C); a bench
// without the resistor read with the default 80.6 kOhm is a factor 50 to 100 off) ...
inline constexpr double kHighPassCrossCheckRatio = 2.0;
// ... and the resonance, anti-resonance and static gain of the fits against the vector fit's by
// more than this relative difference (the demo's anti-resonances differ by up to 7 %: the vector
// fit spreads the narrow notch over its poles).
inline constexpr double kFeatureCrossCheckTolerance = 0.10;

// The FRFs u -> [d_e, Vs] and what is read from them.
struct FrfAnalysis {
  RecordProvenance provenance;
  dsp::FrfProvenance welch;
  std::optional<VectorFitSummary> fit_de, fit_vs;
  std::optional<double> static_gain_vector_fit;  // m/V, vector fit of u -> d_e
  std::optional<double> static_gain;             // m/V, the unit's (second-order fit, else vector fit)
  std::string static_gain_source;                // "" when there is none
  std::optional<double> static_gain_vs;          // V/V, vector fit of u -> Vs
  std::optional<ident::DelayedSecondOrderFit> de_plant;  // u -> d_e, mass-spring-damper with delay
  std::optional<ident::IffPlantFit> iff_plant;          // u -> Vs, eq. 2.3 with delay
  double iff_plant_fmin_Hz = 0.0, iff_plant_fmax_Hz = 0.0;  // its band
  bool iff_plant_w_hpf_measured = false;         // w_hpf from R C_sensor (else fitted)
  NmpEvidence nmp;
  HighPassCorner hpf;
  std::optional<double> resonance_vector_fit_Hz, resonance_vector_fit_damping;
  std::optional<double> antiresonance_vector_fit_Hz, antiresonance_vector_fit_damping;
  std::optional<double> resonance_Hz, resonance_damping;
  std::optional<double> antiresonance_Hz, antiresonance_damping;  // damping < 0: non-minimum-phase
  std::optional<bool> zero_is_nonminimum_phase;
  std::optional<double> shell_stiffness;         // N/m, m_sus w_z^2
};

// The tuned 2-DoF model (report section 3) with the fitted measurement chain.
struct Model2DofFit {
  apa::TwoDofTuning tuning;
  apa::TwoDofBench bench;  // the chain the model was tuned with (delay, high-pass)
  double fmin_Hz = 0.0, fmax_Hz = 0.0;
};

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

struct ResistorComparison {
  std::optional<LowFrequencyVs> with_resistor;  // from the FRF record (when measured)
  LowFrequencyVs without_resistor;
};

// One damped plant u' -> d_e of the IFF experiment.
struct DampedPlant {
  double gain = 0.0;             // controller gain g
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

// Why a unit could not be analysed: one of its files is missing, unreadable or holds data no
// analysis can use (a channel missing, NaN, a dead sensor's constant signal, ...). The unit's other
// results are then left out, so the batch is the batch without it (pipeline.hpp).
struct NotAnalysed {
  std::string file;    // as given in the campaign ("" when the failure is not a file's)
  std::string key;     // campaign key of the file entry, e.g. "units[1].frf"
  std::string reason;  // the InputError's message
};

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
  // The numbers the batch analyses and the acceptance need (SI; nullopt = not available).
  std::optional<double> flatness;            // m, by the spec's method
  std::optional<double> capacitance_sensor;  // F
  std::optional<double> capacitance_actuator;
  std::optional<double> stroke;              // m
  std::optional<double> k1, k2, k_resonance; // N/m (k_sc = k1)
  std::optional<double> k_oc;                // N/m, k1 of the test with every stack open
  std::optional<double> resonance_Hz, antiresonance_Hz, static_gain;  // Hz, Hz, m/V
  std::optional<dsp::Frf> frf;               // u -> [de, Vs] (outputs named "de", "Vs")
  std::optional<ident::IffPlantFit> iff_plant;      // u -> Vs, eq. 2.3 with delay
  std::optional<ident::DelayedSecondOrderFit> de_plant;  // u -> d_e, mass-spring-damper with delay
  std::vector<std::string> not_measured;     // experiments the campaign does not list
  std::vector<std::string> failed;           // "frf: vector fitting failed: ..." (NumericalError)
  std::vector<std::string> warnings;         // cross-checks that disagree (kHighPassCrossCheckRatio, ...)
  // The acceptance (pipeline.hpp).
  bool accepted = false;
  std::vector<std::string> reasons;
};

// ------------------------------------------------------------------------------------ batch

struct QuantitySpread {
  std::string quantity;  // results key, e.g. "capacitance_sensor_uF" (values in that unit)
  std::string label;     // for people, e.g. "capacitance of the sensor stack"
  std::string unit;      // of the values, e.g. "uF"
  long units = 0;
  double min = 0.0, max = 0.0, median = 0.0, relative_spread = 0.0, mad = 0.0;
};

struct BatchOutlier {
  int unit = 0;
  std::string quantity;  // as in QuantitySpread
  double value = 0.0, median = 0.0, robust_z = 0.0;
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

// The IFF study: root locus of the fitted plant with the report's controller against the poles of
// the measured damped plants.
struct IffStudy {
  control::IffControllerParams controller;
  std::optional<int> unit;                 // the unit whose plant is used
  std::optional<ident::IffPlantFit> plant;
  std::vector<double> gains;               // of the damped plants with an identified pole
  std::vector<std::complex<double>> damped_poles, model_poles;  // rad/s
  std::vector<double> relative_pole_distance;
  double max_relative_pole_distance = 0.0;
  double pole_distance_tolerance = 0.0;    // above it: `warning`
  std::optional<std::string> warning;
  std::optional<double> optimal_gain, max_damping;
  std::complex<double> optimal_pole;       // rad/s
  std::string note;                        // why there is no study
  std::optional<std::string> failed;       // a NumericalError of the study
  // The root locus for the plot (report Figure 2.10b), inside 3 wp of the origin, upper half plane.
  struct Branch {
    Curve re_im;               // x Re, y Im [rad/s]
    std::vector<double> gains; // at each point
    bool resonance_branch = false;
  };
  std::vector<Branch> branches;
  Curve open_loop_poles, open_loop_zeros;  // x Re, y Im [rad/s]
};

// Report section 4: the super element on the bench, ga and gs tuned against one unit's measured
// FRFs (superelement_fit.hpp).
struct SuperElementUnitFit {
  int unit = 0;
  std::string name;
  double ga = 0.0;                   // N/V (signed: the sign that makes the phases agree)
  double gs = 0.0;                   // V/m
  double ga_relative_to_eq41 = 0.0;  // |ga| / eq. 4.1's - 1
  double gs_relative_to_eq41 = 0.0;
  double band_lo_Hz = 0.0, band_hi_Hz = 0.0;  // the tuning band
  double resonance_Hz = 0.0;                  // of the tuned model's u -> d_e
  std::optional<double> antiresonance_Hz;     // of the tuned model's u -> V_s (below the resonance)
  std::optional<double> measured_resonance_Hz, measured_antiresonance_Hz;  // the unit's (FrfAnalysis)
  double de_error_dB = 0.0, vs_error_dB = 0.0;  // median |model/measured| in dB (superelement_fit.hpp)
};

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

struct CampaignResult {
  Campaign campaign;  // as read
  std::vector<UnitAnalysis> units;
  BatchAnalysis batch;
  IffStudy iff;
  std::optional<SuperElementComparison> superelement;  // when the campaign gives one
  int accepted = 0;
  int rejected = 0;      // analysed and rejected
  int not_analysed = 0;  // units with UnitAnalysis::not_analysed (neither accepted nor rejected)
};

}  // namespace piezobench::campaign
