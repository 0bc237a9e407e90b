#include "piezobench/metrology/uncertainty_budget.hpp"

#include <cmath>
#include <utility>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"

namespace piezobench::metrology {

UncertaintyBudget combine(std::string unit, std::vector<BudgetComponent> components, double coverage_factor) {
  const char* source = "uncertainty budget";
  if (!(coverage_factor > 0.0 && std::isfinite(coverage_factor))) {
    throw InputError(source, "coverage factor", "a finite number > 0", format_number(coverage_factor));
  }
  UncertaintyBudget b;
  b.unit = std::move(unit);
  b.coverage_factor = coverage_factor;
  double sum = 0.0;
  for (BudgetComponent& c : components) {
    if (!(c.standard_uncertainty >= 0.0 && std::isfinite(c.standard_uncertainty))) {
      throw InputError(source, c.name, "a standard uncertainty >= 0", format_number(c.standard_uncertainty));
    }
    if (!std::isfinite(c.sensitivity)) throw InputError(source, c.name, "a finite sensitivity", format_number(c.sensitivity));
    c.contribution = std::abs(c.sensitivity) * c.standard_uncertainty;
    sum += c.contribution * c.contribution;
  }
  b.components = std::move(components);
  b.combined = std::sqrt(sum);
  b.expanded = coverage_factor * b.combined;
  return b;
}

namespace {

void require_positive(const char* what, double v) {
  if (!(v > 0.0 && std::isfinite(v))) throw InputError("uncertainty budget", what, "a finite number > 0", format_number(v));
}

// The uncertainty of one reading: its quantization (uniform over q) and its noise averaged over n samples.
double reading_uncertainty(double resolution, double noise, double samples) {
  return std::sqrt(resolution * resolution / 12.0 + noise * noise / samples);
}

}  // namespace

UncertaintyBudget stiffness_budget(double added_mass_kg, double gravity_m_per_s2, double deflection_m, double reading_noise_m,
                                   double samples_per_reading, const StaticTestUncertainties& in) {
  require_positive("added mass", added_mass_kg);
  require_positive("gravity", gravity_m_per_s2);
  require_positive("deflection", deflection_m);
  if (!(samples_per_reading >= 1.0)) throw InputError("uncertainty budget", "samples per reading", "at least 1", format_number(samples_per_reading));
  const double k = added_mass_kg * gravity_m_per_s2 / deflection_m;
  const double u_d = std::sqrt(2.0) * reading_uncertainty(in.encoder_resolution_m, reading_noise_m, samples_per_reading);
  return combine("N/m", {{"added mass", "kg", in.added_mass_kg, k / added_mass_kg, 0.0},
                         {"gravity", "m/s^2", in.gravity_m_per_s2, k / gravity_m_per_s2, 0.0},
                         {"deflection (two readings: resolution and noise)", "m", u_d, -k / deflection_m, 0.0},
                         {"deflection (the sensor's scale)", "m", in.displacement_scale_relative * deflection_m, -k / deflection_m, 0.0}});
}

UncertaintyBudget resonance_stiffness_budget(double suspended_mass_kg, double resonance_rad_s, double resonance_standard_error_rad_s,
                                             const StaticTestUncertainties& in) {
  require_positive("suspended mass", suspended_mass_kg);
  require_positive("resonance", resonance_rad_s);
  const double k = suspended_mass_kg * resonance_rad_s * resonance_rad_s;
  return combine("N/m", {{"suspended mass", "kg", in.suspended_mass_kg, k / suspended_mass_kg, 0.0},
                         {"resonance (the FRF fit's standard error)", "rad/s", resonance_standard_error_rad_s, 2.0 * k / resonance_rad_s, 0.0}});
}

UncertaintyBudget stroke_budget(double stroke_m, double noise_m, double averaged_samples, const StaticTestUncertainties& in) {
  if (!(averaged_samples >= 1.0)) throw InputError("uncertainty budget", "samples averaged", "at least 1", format_number(averaged_samples));
  const double u_extreme = reading_uncertainty(in.encoder_resolution_m, noise_m, averaged_samples);
  return combine("m", {{"maximum of d_e (resolution and noise)", "m", u_extreme, 1.0, 0.0},
                       {"minimum of d_e (resolution and noise)", "m", u_extreme, -1.0, 0.0},
                       {"the sensor's scale", "m", in.displacement_scale_relative * std::abs(stroke_m), 1.0, 0.0}});
}

UncertaintyBudget capacitance_budget(double capacitance_F, double scatter_F, double readings, const StaticTestUncertainties& in) {
  require_positive("capacitance", capacitance_F);
  if (!(readings >= 1.0)) throw InputError("uncertainty budget", "readings", "at least 1", format_number(readings));
  return combine("F", {{"LCR meter (relative accuracy x C)", "F", in.capacitance_relative * capacitance_F, 1.0, 0.0},
                       {"scatter of the readings (standard error of their mean)", "F", scatter_F / std::sqrt(readings), 1.0, 0.0}});
}

UncertaintyBudget flatness_budget(double probe_accuracy_m) {
  return combine("m", {{"highest point (probe accuracy)", "m", probe_accuracy_m, 1.0, 0.0},
                       {"lowest point (probe accuracy)", "m", probe_accuracy_m, -1.0, 0.0}});
}

double noise_from_second_differences(std::span<const double> x) {
  if (x.size() < 3) return 0.0;
  double sum = 0.0;
  for (std::size_t i = 2; i < x.size(); ++i) {
    const double d2 = x[i] - 2.0 * x[i - 1] + x[i - 2];
    sum += d2 * d2;
  }
  return std::sqrt(sum / static_cast<double>(x.size() - 2) / 6.0);
}

}  // namespace piezobench::metrology
