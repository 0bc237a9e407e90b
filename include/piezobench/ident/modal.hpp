#pragma once
// Modal frequencies and damping from (hammer-test) FRFs, report section 1.4.
//
//  - Peak picking: local maxima of |H| with a minimum prominence; frequency from a parabola through
//    the three samples around the maximum, damping from the half-power bandwidth,
//    zeta = (w2 - w1) / (2 wn) (accurate for light damping and well separated modes).
//  - LSCF: the least-squares complex-frequency-domain estimator with a common denominator
//    (P. Guillaume, P. Verboven, S. Vanlanduit, H. Van der Auweraer, B. Peeters, "A poly-reference
//    implementation of the least-squares complex frequency-domain estimator", IMAC XXI, 2003;
//    B. Peeters et al., "The PolyMAX frequency-domain method", Shock and Vibration 11, 2004, here
//    with a single reference): z-domain polynomial basis Omega_k = exp(j omega_k Ts),
//    Ts = pi / omega_max, real coefficients, reduced normal equations, highest denominator
//    coefficient fixed to 1; physical poles lambda = ln(z) / Ts. Run over a range of model orders,
//    a pole is stable when the previous order has one within frequency_tolerance in frequency and
//    damping_tolerance in damping (the stabilization diagram); a mode is reported when it stays
//    stable over min_stable_orders consecutive orders.
#include <string>
#include <vector>

#include "piezobench/core/fit_quality.hpp"

#include "piezobench/ident/vector_fitting.hpp"

namespace piezobench::ident {

struct Mode {
  Complex pole;                    // rad/s, Im > 0 (peak picking: -zeta wn + j wn sqrt(1 - zeta^2))
  double natural_frequency = 0.0;  // rad/s
  double damping = 0.0;
  Index stable_orders = 0;         // LSCF: length of the chain of stable poles; peak picking: 0
  [[nodiscard]] double frequency_Hz() const;
};

struct PeakPickingOptions {
  double min_omega = 0.0;       // rad/s; band searched (0 = from the first point)
  double max_omega = 0.0;       // rad/s; 0 = up to the last point
  double min_prominence = 2.0;  // ratio, peak / the higher of the minima separating it from higher peaks
  Index max_modes = 0;          // keep the most prominent ones; 0 = all
  void validate() const;        // throws InputError (source "peak picking options")
};

// Peaks of the sum of |H|^2 over outputs (h: points x outputs), by increasing frequency. Peaks whose
// half-power points are not both inside the data are skipped.
// omega: rad/s.
std::vector<Mode> peak_picking(const Vector& omega, const CMatrix& h, const PeakPickingOptions& options = {});

struct LscfOptions {
  double min_omega = 0.0;              // rad/s, band used (0 = from the first point)
  double max_omega = 0.0;              // rad/s, 0 = up to the last point
  Index min_order = 2;                 // denominator orders swept (number of z-domain poles)
  Index max_order = 40;
  double frequency_tolerance = 0.01;   // stabilization: relative frequency change between orders
  double damping_tolerance = 0.05;     // stabilization: relative damping change between orders
  Index min_stable_orders = 5;         // consecutive stable orders for a mode to be reported
  double max_damping = 0.2;            // physical poles: 0 < zeta < max_damping
  void validate() const;               // throws InputError (source "lscf options")
};

struct StabilizationPole {
  Index order = 0;
  Complex pole;                    // rad/s
  double natural_frequency = 0.0;  // rad/s
  double damping = 0.0;
  bool stable = false;             // matched a pole of the previous order within both tolerances
};

struct LscfResult {
  std::vector<Mode> modes;                     // by increasing frequency
  std::vector<StabilizationPole> diagram;      // every physical pole of every order
  core::FitQuality quality;                    // poor: no stable mode, or a mode outside the band
};

// h: points x outputs (common denominator over outputs). Throws InputError for bad data or too few
// points for max_order (need at least max_order + 1 points in the band).
// omega: rad/s.
LscfResult lscf(const Vector& omega, const CMatrix& h, const LscfOptions& options = {});

constexpr auto describe(core::Type<Mode>) {
  using S = Mode;
  using namespace core::shown;
  return core::fields<S>("Mode", "a mode found by peak picking or LSCF",
      core::field("pole", &S::pole, kRadPerSecond, "Im > 0 (peak picking: -zeta wn + j wn sqrt(1 - zeta^2))"),
      core::field("natural_frequency", &S::natural_frequency, kRadPerSecondAsHz, "wn"),
      core::field("damping", &S::damping, kRatio, "zeta"),
      core::field("stable_orders", &S::stable_orders, kNone, "LSCF: length of the chain of stable poles; peak picking: 0"));
}

constexpr auto describe(core::Type<StabilizationPole>) {
  using S = StabilizationPole;
  using namespace core::shown;
  return core::fields<S>("StabilizationPole", "a physical pole of one order of the LSCF's stabilization diagram",
      core::field("order", &S::order, kNone, "denominator order"),
      core::field("pole", &S::pole, kRadPerSecond, "Im > 0"),
      core::field("natural_frequency", &S::natural_frequency, kRadPerSecondAsHz, "|pole|"),
      core::field("damping", &S::damping, kRatio, "zeta"),
      core::field("stable", &S::stable, kNone, "matched a pole of the previous order within both tolerances"));
}

constexpr auto describe(core::Type<LscfResult>) {
  using S = LscfResult;
  using namespace core::shown;
  return core::fields<S>("LscfResult", "the modes and the stabilization diagram of an LSCF run",
      core::field("modes", &S::modes, kNone, "by increasing frequency"),
      core::field("diagram", &S::diagram, kNone, "every physical pole of every order"),
      core::field("quality", &S::quality, kNone, "the verdict (poor: no stable mode, or a mode outside the band)").key("."));
}

}  // namespace piezobench::ident
