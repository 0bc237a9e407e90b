#pragma once
// Model updating of a super element on the bench (issue 31): scales of named stiffness parts of
// the element (the shell's modulus, the stacks' effective modulus) adjusted so that the bench
// model's resonance and anti-resonance are the measured ones.
//
// The parts: the stacks are beams between interface nodes (fem/beam.hpp), so the element's K is
// K_shell + sum K_beam, and a Craig-Bampton reduction of alpha K_shell is alpha times the
// reduction of K_shell (same constraint modes, same fixed-interface shapes, eigenvalues times
// alpha): scaling a part by a modulus factor is exactly re-making the element with that modulus,
// without a new mesh. M is unchanged.
//   parameter "shell":       K - sum of the stacks' beams        (the shell's Young's modulus)
//   parameter "stacks":      every stack's beam                  (the stacks' effective modulus)
//   parameter "stack:A:B":   the beam between nodes A and B       (one stack, e.g. the sensor)
//
// The features: on superelement_fit.hpp's bench (fixed nodes, the moving mass on the output node,
// guided), undamped: the resonance f_r (first mode) and the anti-resonance f_a (the zero of
// actuator force -> sensor extension below f_r). Per unit, y = [ln f_r, ln f_a]; the target is
// the units' mean. Unknowns: theta = ln(scale). Gauss-Newton on y(theta) - target with central
// differences; J = d ln(feature) / d ln(scale) (the dimensionless sensitivity matrix).
//
// What the data determine: the singular values of J at the starting point. A parameter set whose
// J has a singular value below `rank_tolerance` times the largest is refused (InputError naming
// the parameter with the largest share of the null direction): two features cannot determine a
// third modulus, and a parameter that moves no feature is not "fitted" to its starting value.
//
// Standard errors: the scatter of the units' features (sample covariance S of y over n units,
// the mean's covariance S / n) propagated through the solution's linearization,
// cov(theta) = G (S / n) G^T with G = (J^T J)^-1 J^T; correlation from cov(theta). With one unit
// there is no scatter: no standard errors (nullopt) and a warning.
//
// Mode pairing: the bench measures one axial mode (d_e, V_s), no mode shapes; the resonance is
// paired with the computed mode of largest participation in u -> d_e (not simply the first), so a
// lower mode that the output does not see cannot be mistaken for it.
#include <Eigen/Dense>
#include <optional>
#include <string>
#include <vector>

#include "piezobench/campaign/superelement_fit.hpp"
#include "piezobench/fem/beam.hpp"
#include "piezobench/fem/superelement.hpp"
#include "piezobench/fem/superelement_setup.hpp"

namespace piezobench::campaign {

// One stack of the element as it was built: a beam between two nodes with its section.
struct StackBeam {
  long node_a = -1, node_b = -1;
  fem::BeamSection section;
  // "A:B:E,nu,rho,AREA" (node numbers, SI section); InputError naming `field` otherwise.
  static StackBeam parse(const std::string& text, const std::string& field);
};

// Measured features of one unit.
struct UpdateTarget {
  std::string unit;               // name, for messages
  double resonance_Hz = 0.0;      // peak of u -> d_e
  double antiresonance_Hz = 0.0;  // zero of u -> V_s
};

struct SuperElementUpdateOptions {
  SuperElementFitOptions bench;                          // moving mass (modal damping unused)
  std::vector<std::string> parameters{"shell", "stacks"};
  std::vector<StackBeam> stacks;                         // the element's stacks (needed by every parameter)
  double shell_modulus_Pa = 0.0;                         // the shell's modulus at scale 1 (0: unknown)
  double rank_tolerance = 0.05;                          // relative singular value of J below which a direction is undetermined
  int max_iterations = 30;
  // InputError (source "superelement update") for values out of range, unknown parameter names,
  // a parameter named twice, no stacks.
  void validate() const;
};

struct UpdatedParameter {
  std::string name;                       // "shell", "stacks", "stack:A:B"
  double scale = 1.0;                     // factor on the part's stiffness (= on its modulus)
  std::optional<double> modulus_Pa;       // scale x the modulus at scale 1, when known
  std::optional<double> standard_error;   // dimensionless, of scale (absolute)
};

struct SuperElementUpdate {
  std::vector<UpdatedParameter> parameters;
  Eigen::MatrixXd correlation;             // p x p (empty without standard errors)
  Eigen::MatrixXd sensitivity;             // 2 x p, d ln feature / d ln scale at the solution (rows f_r, f_a)
  Eigen::VectorXd singular_values;         // dimensionless, of the sensitivity at the starting point, descending
  int rank = 0;
  double condition = 0.0;                                           // ratio, largest / smallest singular value
  double target_resonance_Hz = 0.0, target_antiresonance_Hz = 0.0;  // geometric means of the units
  double initial_resonance_Hz = 0.0, initial_antiresonance_Hz = 0.0;
  double resonance_Hz = 0.0, antiresonance_Hz = 0.0;                 // updated model
  int units = 0;
  int iterations = 0;
  std::vector<std::string> warnings;
  fem::SuperElement element;               // the updated element (K scaled by parts, M as given)
};

// The bench model's undamped resonance and anti-resonance (see above); NumericalError when the
// model has no mode seen by the output or no anti-resonance below it.
struct BenchFeatures {
  double resonance_Hz = 0.0, antiresonance_Hz = 0.0;
};
[[nodiscard]] BenchFeatures bench_features(const fem::SuperElement& se, const fem::SuperElementSetup& setup,
                                           const SuperElementFitOptions& options);

// Updates `se` (put on the bench by `setup`) against the units' features. InputError for no
// target, a target that is not positive and finite or with f_a >= f_r, a stack whose nodes the
// element lacks, or parameters the features do not determine (above); NumericalError when the
// iteration does not converge.
[[nodiscard]] SuperElementUpdate update_superelement(const fem::SuperElement& se, const fem::SuperElementSetup& setup,
                                                     const std::vector<UpdateTarget>& targets,
                                                     const SuperElementUpdateOptions& options);

}  // namespace piezobench::campaign
