#pragma once
// Inverse feedforward of an identified hysteresis and creep model (ident/hysteresis.hpp): the
// stage in front of the amplifier that makes the stroke proportional to the command.
//
// For a command c (V at the stacks, "linear volts") it applies the stack voltage
//     Va = H^-1[ S^-1(reference_slope c + reference_intercept) - sum_j c_j F_j ],
// H^-1 the exact inverse of the model's Prandtl-Ishlinskii operator (a PI operator again), S^-1 that
// of its output dead-zone superposition (the modified PI; identity otherwise) and F_j
// the model's creep states driven by the Va it has applied (strictly causal, so the creep is
// cancelled exactly for the model). If the model were the actuator, d_e = offset + gain
// (reference_slope c + reference_intercept): a straight line through the identification record's
// loop. The stage does not limit anything: in the real-time loop it sits before the safety clamp
// and slew limit (rt/loop.hpp), which still bound what reaches the amplifier. When the clamp
// changes what is applied, the inverse's play operators keep following the unclamped Va (the
// command asked for more than the actuator can give; the memory is wiped by the next excursion
// larger than the thresholds).
//
// step() allocates nothing, takes no lock, and does no I/O.
#include <cmath>
#include <vector>

#include "piezobench/ident/hysteresis.hpp"

namespace piezobench::control {

class HysteresisFeedforward {
 public:
  // Validates the model (InputError) and the sample rate (> 0 Hz, for the creep states). At rest.
  // sample_rate: Hz.
  HysteresisFeedforward(const ident::HysteresisModel& model, double sample_rate);

  // The stack voltage (V) for the command c (V). A non-finite c gives the last output.
  double step(double c) noexcept {
    if (!std::isfinite(c)) return last_;
    double z = output_inverse_(model_.reference_slope * c + model_.reference_intercept);
    const std::size_t m = creep_.size();
    for (std::size_t j = 0; j < m; ++j) z -= model_.creep_coefficients[j] * creep_[j];
    const double v = inverse_.step(z);
    for (std::size_t j = 0; j < m; ++j) creep_[j] += alpha_[j] * (v - creep_[j]);
    last_ = v;
    return v;
  }
  // The stage blended in with the weight w in [0, 1]: c + w (step(c) - c) (V). The stage steps on c
  // whatever w is, so its memory follows the whole command (rt::LoopOptions::feedforward_weight).
  double step(double c, double w) noexcept { return c + w * (step(c) - c); }
  // Back to rest (the model's initial state).
  void reset() noexcept;
  [[nodiscard]] const ident::HysteresisModel& model() const noexcept { return model_; }
  // The stack voltage the command c asks for at rest, without history (the start of a run).
  // c: V at the stacks; returns V at the stacks.
  [[nodiscard]] double at_rest(double c) const;

 private:
  ident::HysteresisModel model_;
  ident::PrandtlIshlinskiiOperator inverse_;
  ident::DeadZoneSuperposition output_inverse_;  // S^-1 (identity for the plain PI model)
  std::vector<double> alpha_, creep_;            // alpha_: dimensionless, per sample; creep_: V at the stacks
  double last_ = 0.0;                            // V at the stacks
};

// The feedforward applied to a whole command (V at the stacks) from rest: what the stage gives.
// sample_rate: Hz.
std::vector<double> apply_feedforward(const ident::HysteresisModel& model, double sample_rate, const std::vector<double>& command);

}  // namespace piezobench::control
