#pragma once
// Root locus of a SISO loop.
//
// Convention (MATLAB's rlocus): negative feedback u = -k y around the open loop L, so the
// closed-loop poles are the roots of 1 + k L(s) = 0, i.e. eig(A - k B (1 + k D)^-1 C).
#include <vector>

#include "piezobench/core/fields.hpp"
#include "piezobench/lti/state_space.hpp"

namespace piezobench::lti {

struct RootLocus {
  std::vector<double> gains;  // dimensionless loop gains k
  // poles[i] are the closed-loop poles at gains[i]. Branches are kept in a consistent order: entry
  // b of poles[i] continues entry b of poles[i - 1] (matched by minimum total displacement).
  std::vector<CVector> poles;
};

constexpr auto describe(core::Type<RootLocus>) {
  using S = RootLocus;
  using namespace core::shown;
  return core::fields<S>("RootLocus", "closed-loop poles of a SISO loop under u = -k y at a list of gains",
      core::field("gains", &S::gains, kRatio, "loop gains k"),
      core::field("poles", &S::poles, kRadPerSecond,
                  "closed-loop poles (z-plane when discrete), a row per gain, a column per branch (Python: gains x branches)"));
}

// Closed-loop poles at one gain. Throws InputError for a non-SISO loop or one with delays (use
// lti::pade first), NumericalError when 1 + k D = 0.
CVector closed_loop_poles(const StateSpace& open_loop, double gain);  // gain k: dimensionless

// Closed-loop poles at the given gains (any order; kept as given), branches matched.
RootLocus rlocus(const StateSpace& open_loop, const std::vector<double>& gains);  // gains k: dimensionless

struct RootLocusOptions {
  double gain_min = 0.0;  // first gain of the automatic grid (>= 0)
  // Last gain; 0 = automatic: grow until every branch is within `settle_fraction` of its
  // open-loop zero or has left for infinity (asymptotes), or `max_points` is reached.
  double gain_max = 0.0;
  // Largest move of any pole between two consecutive gains, as a fraction of the scale of that
  // pole (|p| + the smallest nonzero pole or zero magnitude); steps are bisected until it holds.
  double max_relative_step = 0.02;
  double settle_fraction = 1e-3;
  int max_points = 20000;
  // Bounds on the work (docs/cli.md, resource bounds): a loop of more than max_order states is an
  // InputError; the adaptive grid solves at most max_work / n^3 eigenvalue problems of the loop's
  // order n (rejected steps included) and throws NumericalError (retry may help: a larger budget,
  // or fewer points) when they do not suffice.
  int max_order = 200;
  double max_work = 1e8;  // a count of operations (n^3 per eigenvalue problem)
  void validate() const;  // InputError naming the field
};

// Automatic, adaptive gain grid that follows every branch continuously.
RootLocus rlocus_auto(const StateSpace& open_loop, const RootLocusOptions& options = {});

struct BranchOptimum {
  double gain = 0.0;     // dimensionless, gain of maximum damping on the branch
  double damping = 0.0;  // damping ratio there
  Complex pole;          // the branch's pole there
};

constexpr auto describe(core::Type<BranchOptimum>) {
  using S = BranchOptimum;
  using namespace core::shown;
  return core::fields<S>("BranchOptimum", "the gain of maximum damping on one root-locus branch",
      core::field("gain", &S::gain, kRatio, "loop gain k of maximum damping on the branch"),
      core::field("damping", &S::damping, kRatio, "damping ratio of the branch's pole there"),
      core::field("pole", &S::pole, kRadPerSecond, "the branch's pole there (z-plane when discrete)"));
}
// Follows the branch that starts (k = 0) at the open-loop pole nearest `start_pole` from gain 0 to
// gain_max (0 = automatic: rlocus_auto's grid, ending once this branch has settled at a zero or
// gone towards an asymptote, whatever the other branches do) and returns the gain that maximizes its damping ratio,
// refined by golden-section search to a relative gain tolerance of 1e-6. options.gain_min is
// ignored (the grid starts at 0, where the branch is identified).
BranchOptimum max_damping_on_branch(const StateSpace& open_loop, Complex start_pole,
                                    const RootLocusOptions& options = {});

}  // namespace piezobench::lti
