#pragma once
// The added-mass test of an actuator (report section 2.2), from its record as measured: the static
// stiffness k1, k2 with the logarithmic creep model (metrology::static_stiffness) and the Prony
// creep of the same record (fit_creep, as `hysteresis creep`): the weight carried in (N), d_e (m)
// out. The weight is the operator's mass log times gravity, else added_mass over the detected
// [t_on, t_off) times gravity (added_weight_N).
//
// Units: SI (s, m, kg, N, Hz).
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "piezobench/ident/hysteresis.hpp"
#include "piezobench/metrology/stiffness.hpp"

namespace piezobench::ident {

struct AddedMassOptions {
  metrology::StaticStiffnessOptions stiffness;  // added_mass (kg), gravity (m/s^2), reading windows (s)
  std::string source;                           // errors: InputError(source, ...)
};

struct AddedMassAnalysis {
  metrology::StaticStiffnessResult stiffness;  // k1, k2 (N/m), readings, the creep model and its fit
  bool mass_log = false;                       // the weight came from the mass log
  // The Prony creep: gain = instantaneous compliance (m/N, < 0 for a weight that compresses),
  // residual and verdict; nullopt when it failed (see failed).
  std::optional<CreepFit> creep;
  // "creep fit: ...": the Prony fit failed on valid data (NumericalError).
  std::vector<std::string> failed;
};

// The weight carried (N) at every sample: mass_log_kg * gravity_m_s2 when the log is given (not
// empty), else added_mass_kg * gravity_m_s2 over t_on_s <= t < t_off_s and 0 elsewhere.
Eigen::VectorXd added_weight_N(const Eigen::Ref<const Eigen::VectorXd>& t_s, const Eigen::Ref<const Eigen::VectorXd>& mass_log_kg,
                               double t_on_s, double t_off_s, double added_mass_kg, double gravity_m_s2);

// t_s strictly increasing, de_m, mass_log_kg (or empty: no log) of the same length, sampled at
// sample_rate_Hz. InputError and NumericalError as metrology::static_stiffness (the readings are
// the analysis' core); InputError as fit_creep for the creep; its NumericalError is listed in
// `failed` and the creep left out.
AddedMassAnalysis analyze_added_mass(const Eigen::Ref<const Eigen::VectorXd>& t_s, const Eigen::Ref<const Eigen::VectorXd>& de_m,
                                     const Eigen::Ref<const Eigen::VectorXd>& mass_log_kg, double sample_rate_Hz,
                                     const AddedMassOptions& options);

}  // namespace piezobench::ident
