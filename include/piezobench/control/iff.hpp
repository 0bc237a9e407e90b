#pragma once
// Integral Force Feedback (IFF): the report's plant model (eq. 2.3) and controller (eq. 2.4), and
// the root locus of the loop of the report's Figure 2.9.
//
// Loop convention (Figure 2.9): the DAC voltage is u = u' + g K0(s) Vs, with Vs = G(s) u the
// force-sensor voltage, K0 the controller at g = 1 and u' the new ("damped plant") input. The
// closed-loop characteristic equation is 1 - g K0(s) G(s) = 0, i.e. the negative-feedback root
// locus (lti/rlocus.hpp) of the open loop L = -K0 G; with the report's K0 (negative gain), damping
// grows with g > 0.
#include <optional>
#include <vector>

#include "piezobench/lti/rlocus.hpp"
#include "piezobench/lti/state_space.hpp"
#include "piezobench/lti/transfer_function.hpp"
#include "piezobench/core/fields.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/plant/iff_plant.hpp"

namespace piezobench::control {

// The plant of eq. 2.3 lives below control and ident (plant/iff_plant.hpp); the loop's functions
// take it under these names.
using plant::IffPlantParams;
using plant::iff_plant;
using plant::iff_plant_response;

// K0(s) = gain * s/(s + w_hpf) * 1/(s + w_lpf) * 1/(s + w_robust): eq. 2.4 at g = 1 (gain = -10).
struct IffControllerParams {
  double gain = -10.0;                 // 1/s^2 scaling of the report's controller
  double w_hpf = kTwoPi * 2.0;         // rad/s, high-pass that limits the low-frequency gain
  double w_lpf = kTwoPi * 20.0;        // rad/s, integral action above it
  double w_robust = kTwoPi * 2000.0;      // rad/s, roll-off for robustness to high-frequency modes
  void validate() const;
};
lti::Zpk iff_controller(const IffControllerParams& params = {});

// results.json's keys are the campaign file's (iff_controller = { gain, hpf_Hz, lpf_Hz, robust_Hz }).
constexpr auto describe(core::Type<IffControllerParams>) {
  using S = IffControllerParams;
  using namespace core::shown;
  return core::fields<S>("IffControllerParams", "the report's IFF controller K(s) = g s/(s + w_hpf) 1/(s + w_lpf) 1/(s + w_robust) (eq. 2.4)",
      core::field("gain", &S::gain, kNone, "g, 1/s^2 scaling"),
      core::field("w_hpf", &S::w_hpf, kRadPerSecondAsHz, "high-pass that limits the low-frequency gain").key("hpf_Hz"),
      core::field("w_lpf", &S::w_lpf, kRadPerSecondAsHz, "integral action above it").key("lpf_Hz"),
      core::field("w_robust", &S::w_robust, kRadPerSecondAsHz, "roll-off for robustness to high-frequency modes").key("robust_Hz"));
}

struct IffLoopOptions {
  // Pade order used for a delay of the plant or controller (root loci need finite states).
  int pade_order = 6;
  // Frequency (rad/s) of the resonance whose branch is optimized; empty = the plant's complex pole
  // with the smallest damping ratio.
  std::optional<double> resonance = std::nullopt;
  lti::RootLocusOptions locus;
  void validate() const;
};

// L = -K0 G as a SISO state space, delays replaced by Pade approximants of options.pade_order.
lti::StateSpace iff_open_loop(const lti::StateSpace& plant, const lti::StateSpace& controller,
                              const IffLoopOptions& options = {});

struct IffRootLocus {
  lti::RootLocus locus;            // closed-loop poles at each gain g
  lti::Complex resonance_pole;     // open-loop pole the optimized branch starts from
  lti::BranchOptimum optimum;      // gain of maximum damping on that branch
  // Index (in each poles vector of `locus`) of the optimized branch.
  lti::Index resonance_branch = 0;
};

constexpr auto describe(core::Type<IffRootLocus>) {
  using S = IffRootLocus;
  using namespace core::shown;
  return core::fields<S>("IffRootLocus", "root locus of the IFF loop 1 - g K0 G = 0 and the damping optimum on its resonance branch",
      core::field("locus", &S::locus, kNone, "closed-loop poles at each gain g"),
      core::field("resonance_pole", &S::resonance_pole, kRadPerSecond, "open-loop pole the optimized branch starts from"),
      core::field("optimum", &S::optimum, kNone, "gain of maximum damping on that branch"),
      core::field("resonance_branch", &S::resonance_branch, kNone, "column of the optimized branch in locus.poles"));
}

// Root locus at the given gains (automatic grid when `gains` is empty) and the optimum on the
// resonance branch. Throws InputError for non-SISO plant/controller or a plant with no complex pole.
IffRootLocus iff_root_locus(const lti::StateSpace& plant, const lti::StateSpace& controller,
                            const std::vector<double>& gains, const IffLoopOptions& options = {});

}  // namespace piezobench::control
