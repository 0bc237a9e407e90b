#pragma once
// Discretization (c2d) and time responses.
#include <string>

#include "piezobench/core/fields.hpp"
#include "piezobench/lti/state_space.hpp"
#include "piezobench/lti/transfer_function.hpp"

namespace piezobench::lti {

enum class DiscretizationMethod { kZoh, kTustin };
std::string to_string(DiscretizationMethod method);             // "zoh", "tustin"
DiscretizationMethod discretization_method_from_string(const std::string& name);  // InputError if unknown

struct DiscretizeOptions {
  DiscretizationMethod method = DiscretizationMethod::kZoh;
  // Tustin only: the frequency (rad/s) where the discrete response matches the continuous one
  // exactly; 0 = no pre-warping. Must lie below the Nyquist frequency pi / Ts.
  double prewarp_frequency = 0.0;
  // Throws InputError naming the field.
  // sample_time: s.
  void validate(double sample_time) const;
};

// Matrix exponential by scaling and squaring with a [13/13] Pade approximant (Higham, "The scaling
// and squaring method for the matrix exponential revisited", SIAM J. Matrix Anal. Appl. 26(4), 2005).
Matrix expm(const Matrix& a);

// Continuous -> discrete with sample time Ts (s).
//  ZOH: [Ad Bd; 0 I] = expm([A B; 0 0] Ts), C and D unchanged (exact for piecewise-constant inputs).
//  Tustin: s = (2/Ts) (z - 1)/(z + 1), or with pre-warping at w: s = w / tan(w Ts / 2) (z - 1)/(z + 1).
// Delays are kept in seconds. Throws InputError for a discrete input or Ts <= 0; NumericalError when
// Tustin meets a pole at s = 2/Ts.
// sample_time: s.
StateSpace c2d(const StateSpace& sys, double sample_time, const DiscretizeOptions& options = {});
// sample_time: s.
TransferFunction c2d(const TransferFunction& tf, double sample_time, const DiscretizeOptions& options = {});

struct TimeResponse {
  Vector t;  // s (sample k at k * Ts)
  Matrix y;  // samples x outputs
  Matrix x;  // samples x states
};

constexpr auto describe(core::Type<TimeResponse>) {
  using S = TimeResponse;
  using namespace core::shown;
  return core::fields<S>("TimeResponse", "the samples of a discrete system's response (lsim, step, impulse)",
      core::field("t", &S::t, kSecond, "time of each sample, k Ts"),
      core::field("y", &S::y, kNone, "outputs, samples x outputs (the system's output units)"),
      core::field("x", &S::x, kNone, "states, samples x states"));
}

// Response of a discrete system to the input samples u (samples x inputs) from state x0 (empty =
// zero). Delays must be whole multiples of the sample time (InputError otherwise) and shift the
// signals by that many samples.
TimeResponse lsim(const StateSpace& discrete_sys, const Matrix& u, const Vector& x0 = Vector());
// Unit-step and unit-impulse responses (impulse: for continuous systems a pulse of height 1 / Ts
// held over the first sample (area 1), so that the samples approximate the continuous impulse
// response; for discrete systems the unit sample). Continuous systems are first discretized with
// ZOH at `sample_time` (exact at the samples for a step); for discrete systems `sample_time` must
// be 0 or the system's own (InputError otherwise). One column of y per output, input `input`.
TimeResponse step(const StateSpace& sys, double sample_time, Index samples, Index input = 0);
// sample_time: s.
TimeResponse impulse(const StateSpace& sys, double sample_time, Index samples, Index input = 0);

}  // namespace piezobench::lti
