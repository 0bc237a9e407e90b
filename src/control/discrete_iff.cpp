#include "piezobench/control/discrete_iff.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/lti/interconnect.hpp"

namespace piezobench::control {
namespace {

}  // namespace

void DiscreteIffOptions::validate() const {
  if (!(std::isfinite(sample_rate) && sample_rate > 0.0)) {
    throw InputError("", "sample_rate", "a finite positive rate in Hz", format_number(sample_rate));
  }
  const double nyquist = std::numbers::pi * sample_rate;
  if (!(std::isfinite(prewarp) && prewarp >= 0.0 && prewarp < nyquist)) {
    throw InputError("", "prewarp", "0 or a frequency in (0, " + format_number(nyquist) + ") rad/s", format_number(prewarp));
  }
  if (!(std::isfinite(antiwindup_gain) && antiwindup_gain >= 0.0 && antiwindup_gain <= 1.0)) {
    throw InputError("", "antiwindup_gain", "a number in [0, 1]", format_number(antiwindup_gain));
  }
}

DiscreteIff::DiscreteIff(const IffControllerParams& params, const DiscreteIffOptions& options, double gain)
    : params_(params), options_(options) {
  params.validate();
  options.validate();
  if (!std::isfinite(gain)) throw InputError("", "gain", "a finite gain", format_number(gain));
  gain_ = gain;
  const double ts = 1.0 / options.sample_rate;
  const double w = options.prewarp;
  // s = c (z - 1)/(z + 1). A factor (s + p) becomes ((c + p) + (p - c) z^-1) / (1 + z^-1).
  const double c = w > 0.0 ? w / std::tan(w * ts / 2.0) : 2.0 / ts;
  const double ph = params.w_hpf, pr = params.w_robust, pl = params.w_lpf;
  const double alpha_h = (ph - c) / (c + ph), alpha_r = (pr - c) / (c + pr), alpha_l = (pl - c) / (c + pl);
  // Section 1: K s / ((s + w_hpf)(s + w_robust)) = K c (1 - z^-2) / ((c + ph)(c + pr)(1 + ah z^-1)(1 + ar z^-1)).
  const double g1 = params.gain * c / ((c + ph) * (c + pr));
  b_[0][0] = g1;
  b_[0][1] = 0.0;
  b_[0][2] = -g1;
  a_[0][0] = alpha_h + alpha_r;
  a_[0][1] = alpha_h * alpha_r;
  // Section 2: 1 / (s + w_lpf) = (1 + z^-1) / ((c + pl)(1 + al z^-1)).
  const double g2 = 1.0 / (c + pl);
  b_[1][0] = g2;
  b_[1][1] = g2;
  b_[1][2] = 0.0;
  a_[1][0] = alpha_l;
  a_[1][1] = 0.0;
  sections_ = 2;
}

double DiscreteIff::step(double vs) noexcept {
  if (!std::isfinite(vs)) {
    reset();
    ++nonfinite_;
    return 0.0;
  }
  double x = gain_ * vs;
  for (int i = 0; i < sections_; ++i) {
    const double y = b_[i][0] * x + w_[i][0];
    w_[i][0] = b_[i][1] * x - a_[i][0] * y + w_[i][1];
    w_[i][1] = b_[i][2] * x - a_[i][1] * y;
    x = y;
  }
  if (!std::isfinite(x) || !std::isfinite(w_[sections_ - 1][0]) || !std::isfinite(w_[0][0])) {
    reset();
    ++nonfinite_;
    return 0.0;
  }
  last_output_ = x;
  return x;
}

void DiscreteIff::applied(double output) noexcept {
  if (!std::isfinite(output) || sections_ == 0) return;
  // The last update of the last section used y = last_output_; redo its feedback part with
  // y + kappa (applied - y), i.e. subtract a * kappa * e from its states.
  const double e = options_.antiwindup_gain * (output - last_output_);
  const int i = sections_ - 1;
  w_[i][0] -= a_[i][0] * e;
  w_[i][1] -= a_[i][1] * e;
  last_output_ += e;
}

bool DiscreteIff::set_gain(double gain) noexcept {
  if (!std::isfinite(gain)) return false;
  gain_ = gain;
  return true;
}

double DiscreteIff::gain() const noexcept { return gain_; }

void DiscreteIff::reset() noexcept {
  for (auto& w : w_) w[0] = w[1] = 0.0;
  last_output_ = 0.0;
}

lti::StateSpace DiscreteIff::model() const {
  const double ts = 1.0 / options_.sample_rate;
  lti::StateSpace result;
  for (int i = 0; i < sections_; ++i) {
    // Direct form II transposed of (b0 + b1 z^-1 + b2 z^-2) / (1 + a1 z^-1 + a2 z^-2): the states
    // are w0, w1 exactly as in step(), so the model's state trajectory is the controller's.
    //   y = w0 + b0 u;  w0' = w1 + (b1 - a1 b0) u - a1 w0;  w1' = (b2 - a2 b0) u - a2 w0.
    // A first-order section (a2 = b2 = 0) keeps only w0 (w1 stays 0).
    const double b0 = b_[i][0], b1 = b_[i][1], b2 = b_[i][2], a1 = a_[i][0], a2 = a_[i][1];
    const bool first_order = a2 == 0.0 && b2 == 0.0;
    const lti::Index n = first_order ? 1 : 2;
    lti::Matrix a(n, n), b(n, 1), c(1, n), d(1, 1);
    if (first_order) {
      a << -a1;
      b << b1 - a1 * b0;
      c << 1.0;
    } else {
      a << -a1, 1.0, -a2, 0.0;
      b << b1 - a1 * b0, b2 - a2 * b0;
      c << 1.0, 0.0;
    }
    d << b0;
    lti::StateSpace section(a, b, c, d, ts);
    result = i == 0 ? section : lti::series(result, section);
  }
  return result;
}

}  // namespace piezobench::control
