#pragma once
// The report's IFF controller (eq. 2.4) as it runs on the real-time target: discretized at the
// loop rate by Tustin with pre-warping at the resonance, realized as second-order sections, with
// a gain that can change at run time without a bump and an anti-windup so the integral action
// cannot run away while the output is limited.
//
// y[k] = g K0(z) Vs[k]. The gain g multiplies the input of the sections (not their output), so a
// gain change moves the output continuously from the next sample on. step() allocates nothing.
//
// Realization: K0(s) = K s / ((s + w_hpf)(s + w_robust)) * 1 / (s + w_lpf) is mapped with
// s = c (z - 1)/(z + 1), c = w / tan(w Ts / 2) (w = prewarp; c = 2 / Ts when prewarp == 0), into
//   section 1 (biquad): the high-pass and the robustness roll-off, zeros at z = 1 and z = -1, and K;
//   section 2 (first order): the low-pass that gives the integral action, zero at z = -1.
// Both are direct form II transposed. The integral-action section is last so that the anti-windup
// (applied()) acts on it directly. The high-pass at w_hpf already bounds the low-frequency gain
// (no pure integrator: a constant input decays to a zero output), which is the report's "leak".
#include <cstdint>

#include "piezobench/control/iff.hpp"
#include "piezobench/lti/state_space.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::control {

struct DiscreteIffOptions {
  double sample_rate = 10e3;                // Hz
  double prewarp = kTwoPi * 95.2;           // rad/s, Tustin pre-warping frequency (the resonance); 0 = none
  // Anti-windup: when the caller reports that the output was limited (applied()), the state of the
  // integral-action section is recomputed as if its output had been gain * applied + (1 - gain) *
  // computed, so with 1 the output tracks what was applied. In [0, 1]; 0 = off.
  double antiwindup_gain = 1.0;             // ratio
  void validate() const;                    // InputError naming the field
};

class DiscreteIff {
 public:
  // Throws InputError (params, options, or a non-finite gain).
  explicit DiscreteIff(const IffControllerParams& params = {}, const DiscreteIffOptions& options = {},
                       double gain = 0.0);  // gain g: V/V

  // One sample: returns g K0 Vs. Allocates nothing.
  // A non-finite input (NaN, inf) is never let into the states: the controller resets (zero
  // states) and returns 0, and nonfinite_inputs() counts it. The same happens if the output itself
  // overflows to a non-finite value. The caller (rt::Loop) reports it and enters its safe state.
  // vs: V (sensor stack); returns V at the DAC.
  double step(double vs) noexcept;
  // Tells the controller what the loop really applied after its limits for the last output, for
  // the anti-windup. Call after step() when the output was clamped; a call with the value step()
  // returned changes nothing. Non-finite values are ignored.
  // output: V at the DAC, as step() returns it.
  void applied(double output) noexcept;
  // New gain from the next sample on, without a bump. A non-finite gain is rejected (returns false,
  // gain unchanged).
  bool set_gain(double gain) noexcept;
  [[nodiscard]] double gain() const noexcept;
  // Zero states (the controller at rest); the gain is kept.
  void reset() noexcept;
  // Number of non-finite inputs or outputs seen by step() since construction.
  [[nodiscard]] std::uint64_t nonfinite_inputs() const noexcept { return nonfinite_; }
  [[nodiscard]] const DiscreteIffOptions& options() const noexcept { return options_; }
  [[nodiscard]] const IffControllerParams& params() const noexcept { return params_; }

  // The discrete transfer function at gain 1 (sample time 1/sample_rate), for checks: the cascade of
  // the sections, input Vs, output y.
  [[nodiscard]] lti::StateSpace model() const;

 private:
  static constexpr int kMaxSections = 4;
  double b_[kMaxSections][3]{};
  double a_[kMaxSections][2]{};
  double w_[kMaxSections][2]{};
  int sections_ = 0;
  double gain_ = 0.0;         // V/V
  double last_output_ = 0.0;  // V, output of the last section (= of the controller) at the last step
  std::uint64_t nonfinite_ = 0;
  IffControllerParams params_;
  DiscreteIffOptions options_;
};

}  // namespace piezobench::control
