#include "piezobench/control/iff.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/lti/analysis.hpp"
#include "piezobench/lti/conversions.hpp"
#include "piezobench/lti/delay.hpp"
#include "piezobench/lti/interconnect.hpp"

namespace piezobench::control {
namespace {

void require_positive(double value, const char* field) {
  if (!(std::isfinite(value) && value > 0.0)) {
    throw InputError("", field, "a finite positive number", format_number_exact(value));
  }
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

void IffControllerParams::validate() const {
  if (!std::isfinite(gain) || gain == 0.0)
    throw InputError("", "gain", "a finite non-zero gain", format_number_exact(gain));
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
    throw InputError("", "controller", "the plant's sample time " + format_number(plant.sample_time, 10) + " s",
                     format_number(controller.sample_time, 10) + " s");
  }
  const lti::StateSpace g = plant.has_delay() ? lti::pade(plant, options.pade_order) : plant;
  const lti::StateSpace k = controller.has_delay() ? lti::pade(controller, options.pade_order) : controller;
  return lti::scale(lti::series(g, k), -1.0);
}

IffRootLocus iff_root_locus(const lti::StateSpace& plant, const lti::StateSpace& controller,
                            const std::vector<double>& gains, const IffLoopOptions& options) {
  const lti::StateSpace loop = iff_open_loop(plant, controller, options);
  for (const double g : gains) {
    if (!std::isfinite(g) || g < 0.0) throw InputError("", "gains", "finite gains >= 0", format_number_exact(g));
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
