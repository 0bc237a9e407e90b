#pragma once
// Poles, transmission zeros, static gain, natural frequency and damping.
#include <vector>

#include "piezobench/core/fields.hpp"
#include "piezobench/lti/state_space.hpp"
#include "piezobench/lti/transfer_function.hpp"

namespace piezobench::lti {

// Eigenvalues of A, computed on the balanced matrix; sorted by increasing magnitude, then by real
// part, then by imaginary part (conjugate pairs adjacent, negative imaginary part first).
CVector poles(const StateSpace& sys);

// Transmission (invariant) zeros: the finite generalized eigenvalues of the system pencil
//   [A - sI  B; C  D].
// The pencil is first reduced to one with no infinite eigenvalues (Emami-Naeini & Van Dooren,
// "Computation of zeros of linear multivariable systems", Automatica 18(4), 1982), on the
// system and then on its dual, with rank decisions on SVDs of the scaled system; the zeros are then
// the eigenvalues of the regular remaining pencil (QZ). Works for MIMO systems of full normal rank
// (square or not). Same sort order as poles().
// Rank decisions: the system is first balanced (powers of two), frequency-scaled so that ||A|| ~ 1
// and its input columns / output rows normalized (none of which moves a zero); a singular value
// counts as nonzero above 10 eps max(n+p, n+m) ||[A B; C D]||_F of that scaled system.
// As with any backward-stable method (SLICOT AB08ND, MATLAB tzero), a zero at infinity that is not
// structural in the given basis (e.g. CB = 0 only up to round-off) can come out as a large finite
// zero, far beyond the largest pole.
CVector zeros(const StateSpace& sys);

// H(0) (continuous) or H(1) (discrete); an entry is +-infinity where a pole at the origin (at z = 1)
// is not cancelled in that channel. Delays do not change it.
Matrix dc_gain(const StateSpace& sys);

struct PoleInfo {
  Complex pole;              // as given (rad/s or z-plane)
  double natural_frequency;  // rad/s, |s| of the continuous-equivalent pole
  double damping;            // -cos(arg(s)) = -Re(s)/|s|: 1 for a stable real pole, -1 for s = 0
};
// Natural frequency and damping of one pole. Discrete poles are mapped to s = log(z) / Ts first
// (as MATLAB's damp). A pole at s = 0 has natural_frequency 0 and damping -1, as MATLAB's damp.
// sample_time: s, 0 = continuous.
PoleInfo pole_info(Complex pole, double sample_time = 0.0);
// pole_info for every pole of the system, in poles() order.
std::vector<PoleInfo> damp(const StateSpace& sys);

// damp() as three columns (MATLAB's [wn, zeta, p] = damp(sys)), in poles() order.
struct Damping {
  CVector poles;             // rad/s or z-plane, as poles()
  Vector natural_frequency;  // rad/s
  Vector damping;            // damping ratio
};
Damping damp_columns(const StateSpace& sys);

constexpr auto describe(core::Type<Damping>) {
  using S = Damping;
  using namespace core::shown;
  return core::fields<S>("Damping", "every pole of a system with its natural frequency and damping ratio (MATLAB's damp)",
      core::field("poles", &S::poles, kRadPerSecond, "the poles as poles() gives them (z-plane when discrete)"),
      core::field("natural_frequency", &S::natural_frequency, kRadPerSecond, "|s| of each pole's continuous equivalent"),
      core::field("damping", &S::damping, kRatio, "-Re(s) / |s| of each (-1 for s = 0)"));
}

}  // namespace piezobench::lti
