#pragma once
// The two degrees-of-freedom model of an amplified piezoelectric actuator (report section 3,
// Figures 3.2 and 3.3, Table 3.1; after Souleille et al., "A concept of active mount for space
// applications", CEAS Space Journal 10, 2018), and the test bench around it (report section 2).
//
// Model (all SI, displacements positive up, i.e. lengthening the APA):
//
//            mass m  (displacement x = d_e)
//       ______|_____________________
//      |                            |
//    shell                     sensor stack  ke, ce      extension e = x - xn, Vs = gs e
//   k1, c1                          |
//      |                       node (massless, displacement xn)
//      |                            |
//      |                     actuator stacks ka, ca, force f = ga Va pushing the node up
//   ___|____________________________|___  base (fixed)
//
// With Z1 = k1 + c1 s, Ze = ke + ce s, Za = ka + ca s (dynamic stiffnesses) the equations are
//   mass:  m x'' = -k1 x - c1 x' - T,          T = ke (x - xn) + ce (x' - xn')   (sensor force)
//   node:  0 = f - ka xn - ca xn' + T           (no mass, so the forces on it balance)
// The node equation is first order in xn: with dampers in both stacks the node has its own
// relaxation, xn' = (ke x + ce x' - (ka + ke) xn + f) / (ca + ce), hence three states
// [x, x', xn] (not four). In the Laplace domain
//   [m s^2 + Z1 + Ze   -Ze     ] [x ]   [0]
//   [-Ze               Ze + Za ] [xn] = [f],
//   x / f = Ze / P(s),   e / f = -(m s^2 + Z1) / P(s),   P(s) = (m s^2 + Z1)(Ze + Za) + Ze Za.
// Consequences (Table 3.1 values, amplifier gain 20 V/V, input u):
//   static u -> d_e = G ga ke/(ke + ka) / k_tot = -16.81 um/V,  k_tot = k1 + ke ka/(ke + ka)
//   static u -> Vs  = -G gs ga k1 / ((ke + ka) k_tot) = +0.588 V/V
//   zeros of u -> Vs: m s^2 + c1 s + k1 = 0, i.e. sqrt(k1/m) = 41.09 Hz (the mass on the shell alone
//   while the sensor stack does not stretch); resonance close to sqrt(k_tot/m) = 95.37 Hz; one real
//   pole near -(ka + ke)/(ca + ce) (the node relaxation, -50000 rad/s).
// The sign convention is the report's: ga < 0, so more voltage lowers the APA (negative static
// gain u -> d_e) while Vs rises.
// docs/models.md holds the derivation in full.
#include <map>
#include <string>
#include <vector>

#include "piezobench/core/fields.hpp"
#include "piezobench/lti/state_space.hpp"

namespace piezobench::apa {

// The 9 parameters of Table 3.1 (defaults), SI units.
struct TwoDofParams {
  double m = 5.7;      // kg, mass carried by the APA
  double k1 = 0.38e6;  // N/m, shell stiffness
  double c1 = 5.0;     // N s/m, shell damping
  double ke = 5.0e6;   // N/m, sensor stack stiffness
  double ce = 100.0;   // N s/m, sensor stack damping
  double ka = 2.5e6;   // N/m, actuator stacks stiffness (the two in series)
  double ca = 50.0;    // N s/m, actuator stacks damping
  double ga = -2.58;   // N/V, actuator sensitivity f = ga Va (nonzero; negative in the report)
  double gs = 0.46e6;  // V/m, sensor sensitivity Vs = gs e (nonzero)

  // The names of the parameters, in the order above ("m", "k1", ..., "gs").
  static const std::vector<std::string>& names();
  // Value of a named parameter; InputError (field "parameter") for an unknown name.
  [[nodiscard]] double get(const std::string& name) const;
  // Sets a named parameter; InputError naming `source` and the key for an unknown name.
  // value: SI, the parameter's unit.
  void set(const std::string& name, double value, const std::string& source = "");

  // Throws InputError (source "2-DoF parameters" unless given) naming the field: m, k1, ke, ka > 0;
  // c1, ce, ca >= 0 with ca + ce > 0 (the massless node needs a damper to have finite dynamics);
  // ga, gs finite and nonzero; everything finite.
  void validate(const std::string& source = "") const;

  // k_tot = k1 + ke ka / (ke + ka), N/m (static stiffness seen by the mass).
  [[nodiscard]] double total_stiffness() const;
};

// Parameters from name -> value pairs (e.g. a TOML table): keys missing from `values` keep the
// defaults of `base`; an unknown key is an InputError naming `source` and the key. The result is
// validated.
TwoDofParams two_dof_params_from_map(const std::map<std::string, double>& values, const std::string& source,
                                     const TwoDofParams& base = {});

// The bench around the actuator (report section 2): amplifier, suspended and added masses, the
// resistor across the sensor stack, a pure delay.
struct TwoDofBench {
  double amplifier_gain = 20.0;  // V/V, Va = G u (PD200); nonzero
  double suspended_mass = 0.0;   // kg; > 0 replaces params.m (the suspended granite and parts), 0 = params.m
  double added_mass = 0.0;       // kg, >= 0, added on top (e.g. 6.4 kg in the static stiffness test)
  // High-pass made by a resistor R across the sensor stack of capacitance C: Vs is seen through
  // s / (s + 1/(R C)). Both 0 = none (default); both > 0 otherwise (report: R = 80.6 kOhm, C ~ 5 uF).
  double hpf_resistance = 0.0;   // Ohm
  double hpf_capacitance = 0.0;  // F
  double delay = 0.0;            // s, >= 0, pure delay on the input u (DAC, computation)

  [[nodiscard]] bool has_hpf() const { return hpf_resistance > 0.0 || hpf_capacitance > 0.0; }
  // 1/(R C), rad/s; 0 without a high-pass.
  [[nodiscard]] double hpf_corner() const;
  // Mass moving with the APA's top: (suspended_mass or params.m) + added_mass, kg.
  [[nodiscard]] double moving_mass(const TwoDofParams& p) const;
  // InputError (source "bench" unless given) naming the field.
  void validate(const std::string& source = "") const;
};

// Output order of both state spaces below.
inline constexpr lti::Index kOutputDe = 0;  // d_e, m
inline constexpr lti::Index kOutputVs = 1;  // Vs, V

// The actuator alone: input Va (V, at the actuator stacks), outputs [d_e (m); Vs (V)], states
// [x (m), x' (m/s), xn (m)]. Validates p.
lti::StateSpace two_dof_actuator(const TwoDofParams& p);

// The actuator on the bench: input u (V, at the DAC), outputs [d_e (m); Vs (V)] with the
// amplifier gain, the moving mass of `bench`, the high-pass on Vs (one more state, last) and the
// delay (as StateSpace::input_delay, exact in frequency responses). Validates both.
lti::StateSpace two_dof_bench(const TwoDofParams& p, const TwoDofBench& bench);

// Closed-form frequency response of two_dof_bench at s = j omega (rad/s): the two outputs per
// frequency, omega.size() x 2 (column kOutputDe, kOutputVs). Cheap; used by the tuning.
lti::CMatrix two_dof_response(const TwoDofParams& p, const TwoDofBench& bench, const lti::Vector& omega);

// What `piezobench model 2dof` reports about a model on the bench.
struct TwoDofCharacteristics {
  lti::CVector poles;               // rad/s, lti::poles order
  lti::CVector zeros_vs;            // rad/s, transmission zeros of u -> Vs
  double static_gain_de = 0.0;      // m/V, u -> d_e at s = 0
  double static_gain_vs = 0.0;      // V/V, u -> Vs at s = 0 (0 with the high-pass)
  double static_gain_vs_actuator = 0.0;  // V/V, u -> Vs at s = 0 without the high-pass
  double resonance = 0.0;           // rad/s, natural frequency of the least damped complex pole pair
  double resonance_damping = 0.0;
  double antiresonance = 0.0;       // rad/s, natural frequency of the least damped complex zero pair of u -> Vs
  double antiresonance_damping = 0.0;
};
TwoDofCharacteristics characterize(const TwoDofParams& p, const TwoDofBench& bench);

// `model 2dof --json`'s keys (poles and zeros in rad/s, the rest in their shown units).
constexpr auto describe(core::Type<TwoDofCharacteristics>) {
  using S = TwoDofCharacteristics;
  using namespace core::shown;
  return core::fields<S>("TwoDofCharacteristics", "poles, zeros, static gains and resonances of a 2-DoF model on the bench",
      core::field("poles", &S::poles, kRadPerSecond, "poles of the model on the bench").key("poles"),
      core::field("zeros_vs", &S::zeros_vs, kRadPerSecond, "transmission zeros of u -> Vs").key("zeros_Vs"),
      core::field("static_gain_de", &S::static_gain_de, kMetrePerVoltAsUmPerV, "u -> d_e at s = 0"),
      core::field("static_gain_vs", &S::static_gain_vs, kVoltPerVolt, "u -> Vs at s = 0 (0 with the high-pass)").key("static_gain_Vs_V_per_V"),
      core::field("static_gain_vs_actuator", &S::static_gain_vs_actuator, kVoltPerVolt, "u -> Vs at s = 0 without the high-pass")
          .key("static_gain_Vs_before_hpf_V_per_V"),
      core::field("resonance", &S::resonance, kRadPerSecondAsHz, "natural frequency of the least damped pole pair"),
      core::field("resonance_damping", &S::resonance_damping, kRatio, "its damping ratio"),
      core::field("antiresonance", &S::antiresonance, kRadPerSecondAsHz, "natural frequency of the least damped zero pair of u -> Vs"),
      core::field("antiresonance_damping", &S::antiresonance_damping, kRatio, "its damping ratio"));
}

constexpr auto describe(core::Type<TwoDofParams>) {
  using S = TwoDofParams;
  using namespace core::shown;
  return core::fields<S>("TwoDofParams", "the 9 parameters of the 2-DoF model (Table 3.1)",
      core::field("m", &S::m, kKilogram, "mass carried by the APA").in_report(),
      core::field("k1", &S::k1, kNewtonPerMetreAsNPerUm, "shell stiffness").in_report(),
      core::field("c1", &S::c1, kNewtonSecondPerMetre, "shell damping").in_report(),
      core::field("ke", &S::ke, kNewtonPerMetreAsNPerUm, "sensor stack stiffness").in_report(),
      core::field("ce", &S::ce, kNewtonSecondPerMetre, "sensor stack damping").in_report(),
      core::field("ka", &S::ka, kNewtonPerMetreAsNPerUm, "actuator stacks stiffness (the two in series)").in_report(),
      core::field("ca", &S::ca, kNewtonSecondPerMetre, "actuator stacks damping").in_report(),
      core::field("ga", &S::ga, kNewtonPerVolt, "actuator sensitivity f = ga Va").in_report(),
      core::field("gs", &S::gs, kVoltPerMetreAsVPerUm, "sensor sensitivity Vs = gs e").in_report());
}

constexpr auto describe(core::Type<TwoDofBench>) {
  using S = TwoDofBench;
  using namespace core::shown;
  return core::fields<S>("TwoDofBench", "the bench around the actuator: amplifier, masses, resistor, delay",
      core::field("amplifier_gain", &S::amplifier_gain, kVoltPerVolt, "Va = G u"),
      core::field("suspended_mass", &S::suspended_mass, kKilogram, "> 0 replaces the model's m"),
      core::field("added_mass", &S::added_mass, kKilogram, "added on top"),
      core::field("hpf_resistance", &S::hpf_resistance, kOhm, "resistor across the sensor stack (0: none)"),
      core::field("hpf_capacitance", &S::hpf_capacitance, kFaradAsUf, "capacitance of the sensor stack"),
      core::field("delay", &S::delay, kSecond, "pure delay on the input u"));
}

}  // namespace piezobench::apa
