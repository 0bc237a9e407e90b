#pragma once
// The linear part of the virtual bench: continuous models (2-DoF actuator or super element with the
// amplifier, the masses and the force-sensor stack's electrical side) and their exact
// discretizations for a zero-order-held input with a fractional input delay.
//
// Every continuous model here has the same inputs and outputs:
//   inputs  kInVa     amplifier command G u after the clamp (V)
//           kInForce  extra actuator force (N) in the direction of ga Va (hysteresis and creep)
//           kInMass   external force on the moving mass (N, positive up: the added weight is < 0)
//   outputs kOutVa    amplifier output Va (V)
//           kOutDe    d_e (m)
//           kOutVs    sensor voltage as read (V): high-pass, the parasitic term of the
//                     non-minimum-phase zero when enabled, then the ADC's anti-aliasing low-pass
//                     (so no feedthrough: D has no kOutVs entry)
//           kOutLoad  ka xn (N): the actuator stacks' extension times their stiffness (creep
//                     drive; 0 for a super element)
#include <Eigen/Dense>
#include <array>
#include <string>
#include <vector>

#include "piezobench/apa/two_dof.hpp"
#include "piezobench/lti/state_space.hpp"

namespace piezobench::bench::detail {

inline constexpr int kInVa = 0, kInForce = 1, kInMass = 2, kInputs = 3;
inline constexpr int kOutVa = 0, kOutDe = 1, kOutVs = 2, kOutLoad = 3, kOutputs = 4;

struct ContinuousPlant {
  lti::Matrix A, B, C, D;  // n x n, n x 3, 4 x n, 4 x 3
  [[nodiscard]] Eigen::Index states() const { return A.rows(); }
};

// What the electrical side and the amplifier add to any actuator model.
struct Electrics {
  double amplifier_bandwidth = 0.0;   // rad/s
  double hpf_resistance = 0.0;        // Ohm
  double capacitance_sensor = 0.0;    // F, in situ (LCR)
  double capacitance_actuator = 0.0;  // F
  double ground_resistance = 0.0;     // Ohm; 0 = no parasitic term (minimum-phase zero)
  double adc_bandwidth = 0.0;         // rad/s, first-order anti-aliasing low-pass on Vs (> 0)
  // The actuator stacks disconnected from the amplifier (open circuit, 2-DoF model only): their
  // charge C_ab Va + ga xn stays 0, so the state Va is their voltage -ga xn / C_ab (no drive
  // current, hence no parasitic term) and they are stiffer, ka + ga^2 / C_ab (report section 2.2).
  bool actuator_open_circuit = false;
};
// Ohm: the stacks' insulation, the only discharge path of open-circuit stacks.
inline constexpr double kStackInsulationResistance = 1e9;

// Diagonal scales d (powers of two) such that diag(d)^-1 m diag(d) has rows and columns of similar
// norms (Parlett-Reinsch balancing). For exponentials and discretizations of badly scaled models.
lti::Vector balancing_scales(const lti::Matrix& m);

// Blocked capacitance of the 2-DoF model's sensor stack whose in-situ (quasi-static, APA free)
// capacitance is `in_situ`: C_b = C K / (K + gs^2 C), K = ke + ka k1 / (ka + k1) (see
// docs/virtual-bench.md). The high-pass pole of the bench is then at -1 / (R in_situ) up to the
// (corner / resonance)^2 ~ 1e-5 coupling with the mechanics.
double blocked_capacitance(const apa::TwoDofParams& p, double in_situ);
// The same for the actuator stacks (coupling ga, in-situ capacitance `in_situ`):
// C_ab = in_situ - ga^2 / (ka + ke k1 / (ke + k1)). InputError when it is not positive.
double actuator_blocked_capacitance(const apa::TwoDofParams& p, double in_situ);

// The 2-DoF bench (states Va, x, x', xn, V, Vs after the anti-aliasing filter). `p.m` is the moving mass. InputError when the
// sensor stack's short-circuit stiffness ke - gs^2 C_b is not positive.
ContinuousPlant two_dof_plant(const apa::TwoDofParams& p, const Electrics& e);

// Exact discretization with sample time ts of a plant whose kInVa input is delayed by
// (whole + fraction) ts (0 <= fraction < 1; the whole part is the caller's ring buffer):
//   x[k+1] = Phi x[k] + G_early va[k - whole - 1] + G_late va[k - whole] + G_force f[k] + G_mass m[k]
// (columns of Gamma in this order: kEarly, kLate, kForce, kMass).
inline constexpr int kEarly = 0, kLate = 1, kForce = 2, kMass = 3, kDiscreteInputs = 4;
struct DiscretePlant {
  lti::Matrix Phi;    // n x n
  lti::Matrix Gamma;  // n x 4
};
DiscretePlant discretize(const ContinuousPlant& plant, double ts, double fraction);

// The same in real modal coordinates z = S^-1 x: Phi is block diagonal (1x1 blocks for real
// eigenvalues first, then 2x2 rotation blocks [a b; -b a] for complex pairs), computed in closed
// form per block. For super elements, whose stepping cost must stay linear in the number of states.
// NumericalError when A is not diagonalizable to working precision.
struct ModalPlant {
  int real_blocks = 0;             // z[0 .. real_blocks) are 1x1 blocks
  int complex_blocks = 0;          // then pairs (z[j], z[j+1])
  std::vector<double> a, b;        // per block: real: a = exp(lambda ts); complex: exp(sigma ts) (cos, sin)(omega ts)
  lti::Matrix Gamma;               // n x 4 (as DiscretePlant, in modal coordinates)
  lti::Matrix C;                   // 4 x n, outputs from z
  lti::Matrix D;                   // 4 x 3, feedthrough (as ContinuousPlant::D)
};
ModalPlant discretize_modal(const ContinuousPlant& plant, double ts, double fraction);

}  // namespace piezobench::bench::detail
