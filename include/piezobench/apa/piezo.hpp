#pragma once
// Actuator and sensor sensitivities of a piezoelectric stack from its material constants
// (report section 4, eq. 4.1, Table 4.1):
//   ka = cE A / L                  (N/m, stack stiffness at constant field)
//   ga = d33 n ka                  (N/V, blocked force per volt: F_a = ga V_a)        eq. 4.1b
//   gs = d33 / (eps_T sD n)        (V/m, open-circuit voltage per metre of extension) eq. 4.1a
// Sources: A. Preumont, "Vibration Control of Active Structures", 4th ed., p. 123 (sensor);
// Fleming and Leang, "Design, Modeling and Control of Nanopositioning Systems" (actuator).
// Defaults are Table 4.1 (THP5H-like soft PZT): ga = 26.11 N/V, gs = 5.06e6 V/m, ka = 2.4e8 N/m.
#include <string>

#include "piezobench/core/fields.hpp"

namespace piezobench::apa {

struct PiezoConstants {
  double d33 = 680e-12;   // m/V, piezoelectric charge constant
  double eps_t = 4.0e-8;  // F/m, permittivity at constant stress
  double s_d = 21e-12;    // m^2/N, elastic compliance at constant electric displacement
  double c_e = 48e9;      // N/m^2, Young's modulus at constant field
  double length = 20e-3;  // m, stack length
  double area = 1e-4;     // m^2, stack cross-section
  double layers = 160;    // count, number of layers n in the stack: an integer >= 1

  // InputError (source "piezo constants" unless given) naming the field: every constant positive
  // and finite, layers an integer >= 1.
  void validate(const std::string& source = "") const;
};

struct PiezoSensitivities {
  double ka = 0.0;  // N/m
  double ga = 0.0;  // N/V
  double gs = 0.0;  // V/m
};

// Shown in SI (`model piezo --json`'s keys ka_N_per_m, ga_N_per_V, gs_V_per_m).
constexpr auto describe(core::Type<PiezoSensitivities>) {
  using S = PiezoSensitivities;
  return core::fields<S>("PiezoSensitivities", "eq. 4.1's sensitivities of a stack from its material constants",
      core::field("ka", &S::ka, core::Shown{"N/m", "N/m", 1.0}, "cE A / L: stack stiffness at constant field"),
      core::field("ga", &S::ga, core::shown::kNewtonPerVolt, "d33 n ka: blocked force per volt (eq. 4.1b)"),
      core::field("gs", &S::gs, core::Shown{"V/m", "V/m", 1.0}, "d33 / (eps_T sD n): open-circuit volts per metre of extension (eq. 4.1a)"));
}

// Eq. 4.1 (validates the constants).
PiezoSensitivities piezo_sensitivities(const PiezoConstants& c);

}  // namespace piezobench::apa
