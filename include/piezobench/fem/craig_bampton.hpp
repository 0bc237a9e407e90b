#pragma once
// Craig-Bampton reduction of a large sparse FE model to a super element (R. R. Craig and
// M. C. C. Bampton, "Coupling of substructures for dynamic analyses", AIAA J. 6(7), 1968).
//
// The DOF are split into retained interface DOF b and interior DOF i. The reduction basis is
//     [u_b; u_i] = [I 0; Psi Phi] [u_b; q],   Psi = -K_ii^-1 K_ib  (static constraint modes),
// Phi = the N lowest fixed-interface modes K_ii phi = w^2 M_ii phi (mass-normalized), so that
//     K_red = [K_bb + K_ib^T Psi, 0; 0, diag(w^2)],
//     M_red = [M_bb + Psi^T M_ib + M_ib^T Psi + Psi^T M_ii Psi, (M_ib^T + Psi^T M_ii) Phi; sym, I].
// K_ii is factorized once by CHOLMOD (supernodal Cholesky); the modes come from Spectra's
// SymGEigsShiftSolver in shift-invert mode (Lanczos on (K_ii - sigma M_ii)^-1 M_ii), reusing the
// factor when the shift is 0.
//
// Interface points: a plain node keeps all its DOF (3 for solid elements); a CalculiX *RIGID BODY
// (REF NODE + ROT NODE) stands for a whole face and becomes one 6-DOF node of the super element
// numbered as the REF NODE: its x, y, z are the REF NODE's translations and its rx, ry, rz the
// ROT NODE's translations (ccx stores the rigid-body rotations there).
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "piezobench/fem/matrix_io.hpp"
#include "piezobench/fem/superelement.hpp"

namespace piezobench::fem {

struct InterfacePoint {
  long node = -1;      // a node of the model (the REF NODE of a *RIGID BODY)
  long rot_node = -1;  // the ROT NODE of that *RIGID BODY, or -1 for a plain node
  // "NODE" or "REF:ROT"; InputError naming `field` otherwise.
  static InterfacePoint parse(const std::string& text, const std::string& field);
};

struct CraigBamptonOptions {
  int modes = 20;                  // N fixed-interface modes kept (>= 0)
  // Shift sigma of the shift-invert eigensolver, (rad/s)^2. 0 (default) reuses the factor of
  // K_ii; a small negative value helps when K_ii is nearly singular (a barely held interior).
  double shift = 0.0;
  double tolerance = 1e-10;        // relative tolerance of the Ritz values (Spectra)
  int max_iterations = 1000;       // Lanczos restarts (Spectra's maxit)
  int ncv = 0;                     // Lanczos basis size; 0 = max(2 N + 1, N + 20), capped at n_i
  ProgressCallback progress;       // called with (step, fraction) during long steps; may be empty
  // InputError naming the field when a value is out of range.
  void validate() const;
};

struct CraigBamptonResult {
  SuperElement reduced;                    // interface DOF (per point), then N modal DOF
  Eigen::VectorXd fixed_interface_Hz;      // the N fixed-interface modes, ascending
  Index interior_dofs = 0;
  Index interface_dofs = 0;
  Index factor_nonzeros = 0;               // nonzeros of the Cholesky factor of K_ii
  Index eigensolver_iterations = 0;        // Spectra restarts
  Index eigensolver_operations = 0;        // solves with the factor
  double seconds = 0.0;                    // wall time of the reduction
};

constexpr auto describe(core::Type<CraigBamptonResult>) {
  using S = CraigBamptonResult;
  using namespace core::shown;
  return core::fields<S>("CraigBamptonResult", "a Craig-Bampton reduction of a large model to a super element",
      core::field("reduced", &S::reduced, kNone, "the super element: interface DOF (per point), then N modal DOF"),
      core::field("fixed_interface_Hz", &S::fixed_interface_Hz, kHertz, "the N fixed-interface modes, ascending"),
      core::field("interior_dofs", &S::interior_dofs, kNone, "DOF condensed into the modes"),
      core::field("interface_dofs", &S::interface_dofs, kNone, "DOF kept at the interface points"),
      core::field("factor_nonzeros", &S::factor_nonzeros, kNone, "nonzeros of the Cholesky factor of K_ii"),
      core::field("eigensolver_iterations", &S::eigensolver_iterations, kNone, "Lanczos restarts (Spectra)"),
      core::field("eigensolver_operations", &S::eigensolver_operations, kNone, "solves with the factor"),
      core::field("seconds", &S::seconds, kSecond, "wall time of the reduction"));
}

// Throws InputError for interface points that are not in the model (or lack DOF) and for a
// request of more modes than interior DOF; NumericalError when K_ii is not positive definite (an
// unconstrained interior: retain more DOF) or the eigensolver does not converge (retry_may_help).
[[nodiscard]] CraigBamptonResult craig_bampton(const SparseModel& model, const std::vector<InterfacePoint>& interface,
                                               const CraigBamptonOptions& options = {});
// The same for a caller that has no further use for the model's K and M: they are freed as soon
// as their blocks are copied (at 150,000 DOF a third of the peak memory); the rest of the model
// (DOF list, coordinates, source) is left as it was.
[[nodiscard]] CraigBamptonResult craig_bampton(SparseModel&& model, const std::vector<InterfacePoint>& interface,
                                               const CraigBamptonOptions& options = {});

}  // namespace piezobench::fem
