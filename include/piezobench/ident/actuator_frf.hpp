#pragma once
// The analysis of an actuator's measured FRFs u -> [d_e, Vs] (report sections 2.3 to 2.5): what the
// campaign reads from them, from the FRF as measured (dsp::Frf, Hz) to the typed analysis.
//
//   static gain, resonance  u -> d_e as a mass-spring-damper with its own delay
//                           (fit_delayed_second_order), else the vector fit's (frf_features)
//   anti-resonance          u -> Vs as the IFF plant (eq. 2.3 with delay, fit_iff_plant), whose
//                           zero pair is exactly the model's; the vector fit's zero nearest the dip
//                           below the resonance is the cross-check
//   non-minimum phase       zero_phase_verdict: the 95 % interval of xz in the IFF plant fit, else
//                           the phase of the data across the dip, else the fitted zero
//   high-pass corner        1/(2 pi R C_sensor) when both are known; else the IFF plant fit's, else a
//                           first-order fit below hpf_fmax_Hz, each only when observable (at least a
//                           third of the FRF's lowest line)
//   shell stiffness         m_sus w_z^2
//
// The vector fits and the plant fits are kept side by side; the reported feature and its
// cross-check more than kFeatureCrossCheckTolerance apart (kHighPassCrossCheckRatio for the corner)
// is a warning naming both.
#include <complex>
#include <optional>
#include <string>
#include <vector>

#include "piezobench/core/fields.hpp"
#include "piezobench/dsp/frf.hpp"
#include "piezobench/ident/features.hpp"
#include "piezobench/ident/plant_fit.hpp"

namespace piezobench::ident {

// A vector fit's summary (ident/vector_fitting.hpp).
struct VectorFitSummary {
  long order = 0;
  double relative_rms_error = 0.0;
  bool converged = false;
  // Of its covariance (ident/vector_fit_uncertainty.hpp), when it has one: the conditioning of its
  // Jacobian and the pairs of its real parameters ("p3.re", "r1.3.im", ...) correlated above 0.95.
  std::optional<double> condition_number;  // dimensionless
  std::vector<std::string> high_correlations;
};

constexpr auto describe(core::Type<VectorFitSummary>) {
  using S = VectorFitSummary;
  using namespace core::shown;
  return core::fields<S>("VectorFitSummary", "a vector fit's summary",
      core::field("order", &S::order, kNone, "poles"),
      core::field("relative_rms_error", &S::relative_rms_error, kRatio, "rms |fit - data| / rms |data|"),
      core::field("converged", &S::converged, kNone, "the poles settled"),
      core::field("condition_number", &S::condition_number, kRatio, "of the fit's Jacobian with unit-norm columns (with standard errors)"),
      core::field("high_correlations", &S::high_correlations, kNone, "\"a/b 0.973\": its parameters correlated above 0.95"));
}

// Evidence of a non-minimum-phase zero pair in u -> Vs.
struct NmpEvidence {
  struct Zero {
    PhaseVerdict phase_verdict = PhaseVerdict::kUndetermined;
    double phase_change_deg = 0.0;
    std::complex<double> fitted_zero;  // rad/s
    bool fitted_zero_nonminimum_phase = false;
  };
  std::optional<Zero> zero;              // the vector fit's zero nearest the dip
  std::optional<double> iff_plant_fit_xz;
  std::optional<double> iff_plant_fit_xz_standard_error;  // the verdict's 95 % interval is xz +- 1.96 of it
  std::string verdict_from;              // "phase", "iff-plant-fit", "fitted-zero" or "none"
  std::string verdict_reason;            // why (ZeroPhaseVerdict::reason)
};

constexpr auto describe(core::Type<NmpEvidence::Zero>) {
  using S = NmpEvidence::Zero;
  using namespace core::shown;
  return core::fields<S>("NmpZero", "the vector fit's zero of u -> Vs nearest the dip, with the phase verdict",
      core::field("phase_verdict", &S::phase_verdict, kNone, "from the measured phase change"),
      core::field("phase_change_deg", &S::phase_change_deg, kDegree, "across the dip"),
      core::field("fitted_zero", &S::fitted_zero, kRadPerSecond, "the vector fit's zero").key("fitted_zero"),
      core::field("fitted_zero_nonminimum_phase", &S::fitted_zero_nonminimum_phase, kNone, "Re > 0"));
}

constexpr auto describe(core::Type<NmpEvidence>) {
  using S = NmpEvidence;
  using namespace core::shown;
  return core::fields<S>("NmpEvidence", "evidence of a non-minimum-phase zero pair in u -> Vs (report 2.3)",
      core::field("zero", &S::zero, kNone, "the vector fit's zero nearest the dip").key("."),
      core::field("iff_plant_fit_xz", &S::iff_plant_fit_xz, kRatio, "xz of the IFF plant fit (< 0: non-minimum phase)"),
      core::field("iff_plant_fit_xz_standard_error", &S::iff_plant_fit_xz_standard_error, kRatio, "its standard error"),
      core::field("verdict_from", &S::verdict_from, kNone, "\"phase\", \"iff-plant-fit\", \"fitted-zero\" or \"none\""),
      core::field("verdict_reason", &S::verdict_reason, kNone, "why"));
}

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

constexpr auto describe(core::Type<HighPassCorner>) {
  using S = HighPassCorner;
  using namespace core::shown;
  return core::fields<S>("HighPassCorner", "the resistor high-pass of the force sensor's read-out",
      core::field("first_order_fit_Hz", &S::first_order_fit_Hz, kHertz, "first-order fit below hpf_fmax_Hz"),
      core::field("first_order_fit_points", &S::first_order_fit_points, kNone, "its points"),
      core::field("r_c_Hz", &S::r_c_Hz, kHertz, "1 / (2 pi R C_sensor) when C_sensor is measured").key("R_C_Hz"),
      core::field("iff_plant_fit_Hz", &S::iff_plant_fit_Hz, kHertz, "eq. 2.3 fitted down to the lowest frequency"),
      core::field("iff_plant_fit_error", &S::iff_plant_fit_error, kNone, "the cross-check's failure"),
      core::field("method", &S::method, kNone, "how corner_Hz was chosen, or why there is none"),
      core::field("observable_above_Hz", &S::observable_above_Hz, kHertz, "a third of the FRF's lowest line"),
      core::field("corner_Hz", &S::corner_Hz, kHertz, "the unit's corner (results.json: the unit's hpf_corner_Hz)").part_only());
}

// Cross-checks of the FRF features (ActuatorFrfResult::warnings when they disagree): the high-pass
// corner's (1/(2 pi R C), the IFF plant fit, the first-order fit) by more than this ratio (the
// free IFF plant fit of an 8 s record lands up to a factor 1.6 below 1/(2 pi R C); a bench
// without the resistor read with the default 80.6 kOhm is a factor 50 to 100 off) ...
inline constexpr double kHighPassCrossCheckRatio = 2.0;
// ... and the resonance, anti-resonance and static gain of the fits against the vector fit's by
// more than this relative difference (the demo's anti-resonances differ by up to 7 %: the vector
// fit spreads the narrow notch over its poles).
inline constexpr double kFeatureCrossCheckTolerance = 0.10;

// What is read from the FRFs u -> [d_e, Vs] (SI unless the name says _Hz).
struct ActuatorFrfAnalysis {
  dsp::FrfProvenance welch;
  std::optional<VectorFitSummary> fit_de, fit_vs;
  std::optional<double> static_gain_vector_fit;  // m/V, vector fit of u -> d_e
  // Its standard error (ident::response_covariance at s = 0): the model's DC gain only (none for the
  // data's plateau, FrfFeatures::static_gain_source).
  std::optional<double> static_gain_vector_fit_standard_error;  // m/V
  std::optional<double> static_gain;             // m/V, the unit's (second-order fit, else vector fit)
  std::string static_gain_source;                // "" when there is none
  std::optional<double> static_gain_vs;          // V/V, vector fit of u -> Vs
  std::optional<DelayedSecondOrderFit> de_plant;  // u -> d_e, mass-spring-damper with delay
  std::optional<IffPlantFit> iff_plant;          // u -> Vs, eq. 2.3 with delay
  double iff_plant_fmin_Hz = 0.0, iff_plant_fmax_Hz = 0.0;  // its band
  bool iff_plant_w_hpf_measured = false;         // w_hpf from R C_sensor (else fitted)
  NmpEvidence nmp;
  HighPassCorner hpf;
  std::optional<double> resonance_vector_fit_Hz, resonance_vector_fit_damping;
  std::optional<double> antiresonance_vector_fit_Hz, antiresonance_vector_fit_damping;
  // Their standard errors (ident::vector_fit_uncertainty from the FRF's std_H, else the noise
  // estimated from the residuals; the zero's by ident::zero_uncertainty); none when the fit's
  // covariance is singular (a pole with a vanishing residue, as a noise-free FRF gives).
  std::optional<double> resonance_vector_fit_standard_error_Hz, resonance_vector_fit_damping_standard_error;
  std::optional<double> antiresonance_vector_fit_standard_error_Hz, antiresonance_vector_fit_damping_standard_error;
  std::optional<double> resonance_Hz, resonance_damping;
  std::optional<double> antiresonance_Hz, antiresonance_damping;  // damping < 0: non-minimum-phase
  std::optional<bool> zero_is_nonminimum_phase;
  std::optional<double> shell_stiffness;         // N/m, m_sus w_z^2
};

// The fields after the record's provenance (campaign::FrfAnalysis adds it in front).
constexpr auto describe(core::Type<ActuatorFrfAnalysis>) {
  using S = ActuatorFrfAnalysis;
  using namespace core::shown;
  return core::fields<S>("ActuatorFrfAnalysis", "what is read from the FRFs u -> [d_e, Vs] (report 2.3-2.5)",
      core::field("welch", &S::welch, kNone, "the Welch estimate's settings"),
      core::field("fit_de", &S::fit_de, kNone, "vector fit of u -> d_e"),
      core::field("fit_vs", &S::fit_vs, kNone, "vector fit of u -> Vs").key("fit_Vs"),
      core::field("static_gain_vector_fit", &S::static_gain_vector_fit, kMetrePerVoltAsUmPerV, "vector fit of u -> d_e"),
      core::field("static_gain_vector_fit_standard_error", &S::static_gain_vector_fit_standard_error, kMetrePerVoltAsUmPerV,
                  "its standard error (the model's DC gain; none for the data's plateau)"),
      core::field("static_gain", &S::static_gain, kMetrePerVoltAsUmPerV, "the unit's (second-order fit, else vector fit)").in_report(),
      core::field("static_gain_source", &S::static_gain_source, kNone, "which fit gave static_gain"),
      core::field("static_gain_vs", &S::static_gain_vs, kVoltPerVolt, "vector fit of u -> Vs").key("static_gain_Vs_V_per_V"),
      core::field("de_plant", &S::de_plant, kNone, "u -> d_e, mass-spring-damper with delay (results.json: de_plant_fit)").part_only(),
      core::field("iff_plant", &S::iff_plant, kNone, "u -> Vs, eq. 2.3 with delay (results.json: iff_plant_fit)").part_only(),
      core::field("iff_plant_fmin_Hz", &S::iff_plant_fmin_Hz, kHertz, "band of the IFF plant fit, low end").part_only(),
      core::field("iff_plant_fmax_Hz", &S::iff_plant_fmax_Hz, kHertz, "band of the IFF plant fit, high end").part_only(),
      core::field("iff_plant_w_hpf_measured", &S::iff_plant_w_hpf_measured, kNone, "w_hpf from R C_sensor (else fitted)").part_only(),
      core::field("nmp", &S::nmp, kNone, "evidence of a non-minimum-phase zero pair").key("nmp_evidence"),
      core::field("hpf", &S::hpf, kNone, "the high-pass corner (results.json: the unit's hpf)").part_only(),
      core::field("resonance_vector_fit_Hz", &S::resonance_vector_fit_Hz, kHertz, "resonance of the vector fit"),
      core::field("resonance_vector_fit_damping", &S::resonance_vector_fit_damping, kRatio, "its damping"),
      core::field("antiresonance_vector_fit_Hz", &S::antiresonance_vector_fit_Hz, kHertz, "anti-resonance of the vector fit"),
      core::field("antiresonance_vector_fit_damping", &S::antiresonance_vector_fit_damping, kRatio, "its damping"),
      core::field("resonance_vector_fit_standard_error_Hz", &S::resonance_vector_fit_standard_error_Hz, kHertz,
                  "standard error of resonance_vector_fit_Hz"),
      core::field("resonance_vector_fit_damping_standard_error", &S::resonance_vector_fit_damping_standard_error, kRatio,
                  "standard error of its damping"),
      core::field("antiresonance_vector_fit_standard_error_Hz", &S::antiresonance_vector_fit_standard_error_Hz, kHertz,
                  "standard error of antiresonance_vector_fit_Hz"),
      core::field("antiresonance_vector_fit_damping_standard_error", &S::antiresonance_vector_fit_damping_standard_error, kRatio,
                  "standard error of its damping"),
      core::field("resonance_Hz", &S::resonance_Hz, kHertz, "resonance of u -> d_e").in_report(),
      core::field("resonance_damping", &S::resonance_damping, kRatio, "its damping ratio").in_report(),
      core::field("antiresonance_Hz", &S::antiresonance_Hz, kHertz, "anti-resonance of u -> Vs").in_report(),
      core::field("antiresonance_damping", &S::antiresonance_damping, kRatio, "its damping (< 0: non-minimum phase)").in_report(),
      core::field("zero_is_nonminimum_phase", &S::zero_is_nonminimum_phase, kNone, "the verdict on the zero pair"),
      core::field("shell_stiffness", &S::shell_stiffness, kNewtonPerMetreAsNPerUm, "m_sus w_z^2").in_report());
}

struct ActuatorFrfOptions {
  std::string de_output = "de";    // the FRF's output d_e (m/V)
  std::string vs_output = "Vs";    // its output Vs (V/V)
  double fmin_Hz = 20.0;           // band of the vector fits and the d_e plant fit
  double fmax_Hz = 500.0;          // band of every fit
  double hpf_fmax_Hz = 5.0;        // the first-order high-pass is fitted below this
  long fit_order = 6;              // poles of the vector fits (FrfFeatureOptions::fit.order)
  double min_coherence = 0.5;      // of the points the plant fits and the high-pass fit use
  // The resistor across the sensor stack (Ohm, [bench] hpf_resistance_ohm; nullopt: none on the
  // bench) and the sensor stack's measured capacitance (F; nullopt: not measured). Both known: the
  // corner is 1/(2 pi R C) and the IFF plant fit takes it as fixed.
  std::optional<double> hpf_resistance_ohm;
  std::optional<double> sensor_capacitance_F;
  double suspended_mass_kg = 0.0;  // m_sus of shell_stiffness
  // The plant fits see their models through the FRF's Welch resolution kernel when its provenance
  // gives it (dsp::resolution_kernel; IffPlantFitOptions::resolution); false: the models' own responses.
  bool window_resolution = true;
  // Errors: InputError(source, field, ...); the fits' messages name "source: field".
  std::string source, field;
};

struct ActuatorFrfResult {
  ActuatorFrfAnalysis analysis;
  // The resonance in rad/s (analysis.resonance_Hz = it / 2 pi), for quantities of w^2 such as the
  // stiffness from the resonance; nullopt with resonance_Hz.
  std::optional<double> resonance_rad_s;
  // "frf u -> d_e features: ...", "IFF plant fit: ...": a fit that failed on valid data
  // (NumericalError); its part of the analysis is left out.
  std::vector<std::string> failed;
  // Cross-checks that disagree (kHighPassCrossCheckRatio, kFeatureCrossCheckTolerance).
  std::vector<std::string> warnings;
};

// `frf` as measured: input u, outputs options.de_output and options.vs_output (H1, with coherence
// when known), Hz. InputError: an output missing, fewer than 20 lines in [fmin_Hz, fmax_Hz], data
// the fits refuse. A fit that fails numerically is listed in `failed` and left out.
ActuatorFrfResult analyze_actuator_frf(const dsp::Frf& frf, const ActuatorFrfOptions& options);

}  // namespace piezobench::ident
