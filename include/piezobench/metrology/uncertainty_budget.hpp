#pragma once
// Uncertainty budgets of the static tests by the GUM's first-order law of propagation (JCGM
// 100:2008, "Evaluation of measurement data - Guide to the expression of uncertainty in
// measurement", section 5.1.2): for y = f(x_1, ..., x_N) with uncorrelated inputs,
//
//   u_c(y)^2 = sum_i (c_i u(x_i))^2,   c_i = df/dx_i,   U = k u_c(y)   (k = 2: about 95 %)
//
// Each budget lists its components (the input's standard uncertainty, its sensitivity, its
// contribution |c_i| u(x_i)), so a report can say which input dominates.
//
//  stiffness k = m g / d       (report eq. 2.1), d the deflection between two readings:
//                              u(m), u(g) declared; u(d)^2 = 2 (q^2 / 12 + s^2 / n) + (e d)^2, q the
//                              encoder's resolution, s the reading's noise (the creep fit's rms
//                              residual), n the samples averaged per reading (white noise assumed),
//                              e the displacement sensor's relative scale uncertainty.
//  stroke = max - min of d_e   u^2 = 2 (q^2 / 12 + s^2 / n) + (e stroke)^2, each extreme a moving average of n
//                              noisy, quantized samples (the stroke analysis' smoothing), s the
//                              noise per sample (noise_from_second_differences of the record).
//  stiffness k = m w^2         (report eq. 2.2): u(m) declared, u(w) the resonance's standard error.
//  capacitance                 u = the LCR meter's relative standard uncertainty x C (declared)
//                              combined with the readings' standard error of the mean.
//  flatness = max - min of the deviations from the plane: u^2 = 2 a^2, a the probe's standard
//                              uncertainty per point (declared probe_accuracy).
// Units: SI (kg, m/s^2, m, F, N/m); the components keep their inputs' units.
#include <span>
#include <string>
#include <vector>

#include "piezobench/core/fields.hpp"

namespace piezobench::metrology {

struct BudgetComponent {
  std::string name;                   // "added mass"
  std::string unit;                   // the input's SI unit, "kg"
  double standard_uncertainty = 0.0;  // u(x_i), the input's unit
  double sensitivity = 0.0;           // c_i = dy/dx_i, y's unit per the input's
  double contribution = 0.0;          // |c_i| u(x_i), y's unit
};

struct UncertaintyBudget {
  std::string unit;                    // y's SI unit
  std::vector<BudgetComponent> components;
  double combined = 0.0;               // u_c(y), y's unit
  double coverage_factor = 2.0;        // k (ratio)
  double expanded = 0.0;               // U = k u_c, y's unit
};

constexpr auto describe(core::Type<BudgetComponent>) {
  using S = BudgetComponent;
  using namespace core::shown;
  return core::fields<S>("BudgetComponent", "one input of an uncertainty budget (GUM 5.1.2)",
      core::field("name", &S::name, kNone, "the input"),
      core::field("unit", &S::unit, kNone, "the input's SI unit"),
      core::field("standard_uncertainty", &S::standard_uncertainty, kNone, "u(x_i), SI"),
      core::field("sensitivity", &S::sensitivity, kNone, "c_i = dy/dx_i, SI"),
      core::field("contribution", &S::contribution, kNone, "|c_i| u(x_i), y's SI unit"));
}

constexpr auto describe(core::Type<UncertaintyBudget>) {
  using S = UncertaintyBudget;
  using namespace core::shown;
  return core::fields<S>("UncertaintyBudget", "a GUM first-order uncertainty budget",
      core::field("unit", &S::unit, kNone, "y's SI unit"),
      core::field("components", &S::components, kNone, "the inputs, each with its contribution"),
      core::field("combined", &S::combined, kNone, "u_c(y), SI"),
      core::field("coverage_factor", &S::coverage_factor, kRatio, "k"),
      core::field("expanded", &S::expanded, kNone, "U = k u_c, SI"));
}

// u_c and U of the components (contribution = |sensitivity| standard_uncertainty filled in).
// InputError (source "uncertainty budget") for a negative or non-finite uncertainty or sensitivity,
// or k <= 0.
[[nodiscard]] UncertaintyBudget combine(std::string unit, std::vector<BudgetComponent> components, double coverage_factor = 2.0);

// The readings' share of the static tests' uncertainty, declared per campaign (docs/uncertainty.md,
// section 7, gives the defaults and where they come from).
struct StaticTestUncertainties {
  double added_mass_kg = 0.005;            // u(m_a): a 6.4 kg mass on a scale of 10 g resolution
  double gravity_m_per_s2 = 0.02;          // u(g): 9.8 used for g between 9.78 and 9.83
  double encoder_resolution_m = 2.5e-9;    // q of d_e (the report's encoder: 2.5 nm)
  double capacitance_relative = 0.005;     // u(C) / C of the LCR meter (ratio)
  double suspended_mass_kg = 0.02;         // u(m) of the suspended mass (resonance stiffness)
  double displacement_scale_relative = 0.001;  // u of the displacement sensor's scale factor (ratio)
};

// k = m g / d from the test's deflection d (m, > 0), its readings' noise s (m rms) and the samples
// n averaged per reading (>= 1).
[[nodiscard]] UncertaintyBudget stiffness_budget(double added_mass_kg, double gravity_m_per_s2, double deflection_m,
                                                 double reading_noise_m, double samples_per_reading,
                                                 const StaticTestUncertainties& inputs);
// k = m w^2 (report eq. 2.2) from the suspended mass (kg), the resonance w (rad/s) and its standard
// error (rad/s, from the FRF fit).
[[nodiscard]] UncertaintyBudget resonance_stiffness_budget(double suspended_mass_kg, double resonance_rad_s,
                                                           double resonance_standard_error_rad_s, const StaticTestUncertainties& inputs);
// stroke (m) with the noise s (m rms per sample) of d_e and the n samples (a count) its moving average spans.
[[nodiscard]] UncertaintyBudget stroke_budget(double stroke_m, double noise_m, double averaged_samples, const StaticTestUncertainties& inputs);
// The white noise's standard deviation of a record that is smooth at the sample rate (a ramp, a
// slow sine): rms of the second differences / sqrt(6) (a straight line has none; white noise of
// sigma gives second differences of variance 6 sigma^2). x and the result in the caller's unit;
// 0 for fewer than 3 samples.
[[nodiscard]] double noise_from_second_differences(std::span<const double> x);
// capacitance C (F) from `readings` readings with standard deviation `scatter_F` (0 and 1 for a typed value).
[[nodiscard]] UncertaintyBudget capacitance_budget(double capacitance_F, double scatter_F, double readings,
                                                   const StaticTestUncertainties& inputs);
// flatness from points each known to `probe_accuracy_m` (standard uncertainty, m).
[[nodiscard]] UncertaintyBudget flatness_budget(double probe_accuracy_m);

}  // namespace piezobench::metrology
