#include "piezobench/control/iff.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "piezobench/core/error.hpp"
#include "piezobench/lti/analysis.hpp"
#include "piezobench/lti/conversions.hpp"
#include "piezobench/lti/delay.hpp"
#include "piezobench/lti/interconnect.hpp"

namespace piezobench::control {
namespace {

void require_positive(double value, const char* field) {
  if (!(std::isfinite(value) && value > 0.0)) {
    throw InputError("", field, "a finite positive number", std::to_string(value));
  }
}

void require_nonnegative(double value, const char* field) {
  if (!(std::isfinite(value) && value >= 0.0)) {
    throw InputError("", field, "a finite number >= 0", std::to_string(value));
  }
}

// Second-order factor 1 + 2 x s/w + s^2/w^2 in descending powers.
lti::Vector normalized_quadratic(double w, double x) {
  return (lti::Vector(3) << 1.0 / (w * w), 2.0 * x / w, 1.0).finished();
}

lti::Vector convolve(const lti::Vector& a, const lti::Vector& b) {
  lti::Vector c = lti::Vector::Zero(a.size() + b.size() - 1);
  for (lti::Index i = 0; i < a.size(); ++i) c.segment(i, b.size()) += a(i) * b;
  return c;
}

void require_siso(const lti::StateSpace& sys, const char* what) {
  if (sys.inputs() != 1 || sys.outputs() != 1) {
    throw InputError("", what, "a single-input single-output system",
                     std::to_string(sys.outputs()) + " outputs x " + std::to_string(sys.inputs()) + " inputs");
  }
}

// The plant's complex pole (Im > 0) with the smallest damping ratio, or the one nearest j*w.
lti::Complex resonance_pole(const lti::StateSpace& plant, const std::optional<double>& w) {
  const lti::CVector p = lti::poles(plant);
  lti::Complex best(std::numeric_limits<double>::quiet_NaN(), 0.0);
  double best_score = std::numeric_limits<double>::infinity();
  for (lti::Index i = 0; i < p.size(); ++i) {
    if (p(i).imag() <= 0.0) continue;
    const double score = w ? std::abs(std::abs(p(i)) - *w) : lti::pole_info(p(i)).damping;
    if (score < best_score) {
      best_score = score;
      best = p(i);
    }
  }
  if (std::isnan(best.real())) {
    throw InputError("", "plant", "a plant with a lightly damped (complex) pole to damp", "only real poles");
  }
  return best;
}

lti::Index nearest(const lti::CVector& v, lti::Complex target) {
  lti::Index best = 0;
  for (lti::Index i = 1; i < v.size(); ++i) {
    if (std::abs(v(i) - target) < std::abs(v(best) - target)) best = i;
  }
  return best;
}

}  // namespace

void IffPlantParams::validate() const {
  if (!std::isfinite(g0) || g0 == 0.0) throw InputError("", "g0", "a finite non-zero gain", std::to_string(g0));
  require_positive(wz, "wz");
  if (!std::isfinite(xz)) throw InputError("", "xz", "a finite damping ratio (< 0: non-minimum-phase zero)", std::to_string(xz));
  require_positive(wp, "wp");
  require_nonnegative(xp, "xp");
  require_positive(w_hpf, "w_hpf");
  require_nonnegative(delay, "delay");
}

lti::TransferFunction iff_plant(const IffPlantParams& params) {
  params.validate();
  const lti::Vector hpf_num = (lti::Vector(2) << 1.0, 0.0).finished();
  const lti::Vector hpf_den = (lti::Vector(2) << 1.0, params.w_hpf).finished();
  const lti::Vector num = params.g0 * convolve(normalized_quadratic(params.wz, params.xz), hpf_num);
  const lti::Vector den = convolve(normalized_quadratic(params.wp, params.xp), hpf_den);
  return lti::TransferFunction(num, den, 0.0, params.delay);
}

lti::Complex iff_plant_response(const IffPlantParams& p, double omega) {
  const lti::Complex s(0.0, omega);
  const lti::Complex num = 1.0 + 2.0 * p.xz * s / p.wz + s * s / (p.wz * p.wz);
  const lti::Complex den = 1.0 + 2.0 * p.xp * s / p.wp + s * s / (p.wp * p.wp);
  return p.g0 * num / den * s / (p.w_hpf + s) * std::exp(-s * p.delay);
}

lti::CVector iff_plant_response(const IffPlantParams& params, const lti::Vector& omega) {
  lti::CVector h(omega.size());
  for (lti::Index k = 0; k < omega.size(); ++k) h(k) = iff_plant_response(params, omega(k));
  return h;
}

void IffControllerParams::validate() const {
  if (!std::isfinite(gain) || gain == 0.0) throw InputError("", "gain", "a finite non-zero gain", std::to_string(gain));
  require_positive(w_hpf, "w_hpf");
  require_positive(w_lpf, "w_lpf");
  require_positive(w_robust, "w_robust");
}

lti::Zpk iff_controller(const IffControllerParams& params) {
  params.validate();
  lti::CVector z(1);
  z << 0.0;
  lti::CVector p(3);
  p << -params.w_hpf, -params.w_lpf, -params.w_robust;
  return lti::Zpk(z, p, params.gain);
}

void IffLoopOptions::validate() const {
  if (pade_order < 1 || pade_order > 20) {
    throw InputError("", "pade_order", "an integer in 1..20", std::to_string(pade_order));
  }
  if (resonance) require_positive(*resonance, "resonance");
  locus.validate();
}

lti::StateSpace iff_open_loop(const lti::StateSpace& plant, const lti::StateSpace& controller,
                              const IffLoopOptions& options) {
  options.validate();
  require_siso(plant, "plant");
  require_siso(controller, "controller");
  if (plant.is_discrete() != controller.is_discrete() || plant.sample_time != controller.sample_time) {
    throw InputError("", "controller", "the plant's sample time " + std::to_string(plant.sample_time) + " s",
                     std::to_string(controller.sample_time) + " s");
  }
  const lti::StateSpace g = plant.has_delay() ? lti::pade(plant, options.pade_order) : plant;
  const lti::StateSpace k = controller.has_delay() ? lti::pade(controller, options.pade_order) : controller;
  return lti::scale(lti::series(g, k), -1.0);
}

IffRootLocus iff_root_locus(const lti::StateSpace& plant, const lti::StateSpace& controller,
                            const std::vector<double>& gains, const IffLoopOptions& options) {
  const lti::StateSpace loop = iff_open_loop(plant, controller, options);
  for (const double g : gains) {
    if (!std::isfinite(g) || g < 0.0) throw InputError("", "gains", "finite gains >= 0", std::to_string(g));
  }
  IffRootLocus result;
  const lti::StateSpace plant_states = plant.has_delay() ? lti::pade(plant, options.pade_order) : plant;
  result.resonance_pole = resonance_pole(plant_states, options.resonance);

  lti::RootLocusOptions locus_options = options.locus;
  locus_options.gain_min = 0.0;
  if (!gains.empty()) {
    const double g_max = *std::max_element(gains.begin(), gains.end());
    if (g_max > 0.0) locus_options.gain_max = g_max;
  }
  result.optimum = lti::max_damping_on_branch(loop, result.resonance_pole, options.locus);

  // Follow every branch on a dense grid that also holds the requested gains and g = 0, so that the
  // branch order of every requested gain is that of continuous tracking from the open-loop poles.
  const lti::RootLocus dense = lti::rlocus_auto(loop, locus_options);
  std::vector<double> merged = dense.gains;
  merged.insert(merged.end(), gains.begin(), gains.end());
  merged.push_back(0.0);
  std::sort(merged.begin(), merged.end());
  merged.erase(std::unique(merged.begin(), merged.end()), merged.end());
  const lti::RootLocus tracked = lti::rlocus(loop, merged);
  result.resonance_branch = nearest(tracked.poles.front(), result.resonance_pole);

  result.locus.gains = gains.empty() ? dense.gains : gains;
  for (const double g : result.locus.gains) {
    const auto it = std::lower_bound(merged.begin(), merged.end(), g);
    result.locus.poles.push_back(tracked.poles[static_cast<std::size_t>(it - merged.begin())]);
  }
  return result;
}

}  // namespace piezobench::control
