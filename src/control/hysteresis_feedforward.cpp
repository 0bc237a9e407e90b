#include "piezobench/control/hysteresis_feedforward.hpp"

#include <cmath>
#include <string>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"

namespace piezobench::control {

HysteresisFeedforward::HysteresisFeedforward(const ident::HysteresisModel& model, double sample_rate)
    : model_(model), inverse_((model.validate(), ident::inverse(model.hysteresis))), output_inverse_(ident::inverse(model.output)) {
  if (!(std::isfinite(sample_rate) && sample_rate > 0.0)) {
    throw InputError("hysteresis feedforward", "sample_rate", "a rate > 0 Hz", format_number_exact(sample_rate));
  }
  for (double tau : model_.creep_time_constants) alpha_.push_back(-std::expm1(-1.0 / (sample_rate * tau)));
  creep_.assign(alpha_.size(), 0.0);
}

void HysteresisFeedforward::reset() noexcept {
  inverse_.reset();
  std::fill(creep_.begin(), creep_.end(), 0.0);
  last_ = 0.0;
}

double HysteresisFeedforward::at_rest(double c) const {
  ident::PrandtlIshlinskiiOperator fresh(inverse_.model());
  return fresh.step(output_inverse_(model_.reference_slope * c + model_.reference_intercept));
}

std::vector<double> apply_feedforward(const ident::HysteresisModel& model, double sample_rate, const std::vector<double>& command) {
  HysteresisFeedforward ff(model, sample_rate);
  std::vector<double> out(command.size());
  for (std::size_t k = 0; k < command.size(); ++k) out[k] = ff.step(command[k]);
  return out;
}

}  // namespace piezobench::control
