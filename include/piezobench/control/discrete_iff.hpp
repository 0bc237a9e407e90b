#pragma once
// The report's IFF controller (eq. 2.4) as it runs on the real-time target: discretized at the
// loop rate by Tustin with pre-warping at the resonance, realized as second-order sections, with
// a gain that can change at run time without a bump and a leak so the integrator cannot run away.
//
// y[k] = g K0(z) Vs[k]. The gain g multiplies the input of the sections (not their output), so a
// gain change moves the output continuously from the next sample on. step() allocates nothing.
#include "piezobench/control/iff.hpp"
#include "piezobench/lti/state_space.hpp"

namespace piezobench::control {

struct DiscreteIffOptions {
  double sample_rate = 10e3;                // Hz
  double prewarp = 2.0 * M_PI * 95.2;       // rad/s, Tustin pre-warping frequency (the resonance)
  // Anti-windup: when the caller reports that the output was limited (step(vs, applied)), the
  // states are pulled back so that the output tracks what was applied.
  double antiwindup_gain = 1.0;             // 0 = off
  void validate() const;                    // InputError naming the field
};

class DiscreteIff {
 public:
  explicit DiscreteIff(const IffControllerParams& params = {}, const DiscreteIffOptions& options = {},
                       double gain = 0.0);

  // One sample: returns g K0 Vs. Allocates nothing.
  double step(double vs) noexcept;
  // Tells the controller what the loop really applied after its limits for the last output, for
  // the anti-windup. Call after step() when the output was clamped.
  void applied(double output) noexcept;
  // New gain from the next sample on, without a bump.
  void set_gain(double gain) noexcept;
  [[nodiscard]] double gain() const noexcept;
  void reset() noexcept;

  // The discrete transfer function at gain 1 (sample time 1/sample_rate), for checks.
  [[nodiscard]] lti::StateSpace model() const;

 private:
  static constexpr int kMaxSections = 4;
  double b_[kMaxSections][3]{};
  double a_[kMaxSections][2]{};
  double w_[kMaxSections][2]{};
  int sections_ = 0;
  double gain_ = 0.0;
  double last_output_ = 0.0;
  DiscreteIffOptions options_;
};

}  // namespace piezobench::control
