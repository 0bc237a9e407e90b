#pragma once
// The dominant resonance of a measured frequency response (report section 2.6: the pole of each
// damped plant u' -> d_e under Integral Force Feedback).
//
// Method: a vector fit of `fit.order` poles over the data, then, of its complex pairs whose natural
// frequency lies in [omega_min, omega_max], the one whose contribution r/(s - p) + conj(r)/(s -
// conj(p)) is the largest on the data's frequencies (summed over outputs): the resonance dominates
// the response, while a pair the fit adds for a small feature or for noise contributes much less.
// (Not |r| / |Re p|, the pair's peak on a continuous axis: unbounded for a pair the fit puts on the
// imaginary axis with a tiny residue between two lines, and large for a damping near 1, where the
// pair has no peak; both happened on the demo's damped plants, depending on the noise.) Unlike
// the report's second-order fit, this stays on the closed loop's pole once the controller's own
// poles have moved into the band (large gains), where a second-order model misplaces it by 10 to
// 50 %.
#include "piezobench/core/fields.hpp"
#include "piezobench/ident/vector_fitting.hpp"

namespace piezobench::ident {

struct DominantPoleOptions {
  VectorFittingOptions fit = [] {
    VectorFittingOptions o;
    o.order = 6;
    o.fail_if_not_converged = false;  // noisy data: the residual settles; the pole is what counts
    return o;
  }();
  double omega_min = 0.0;  // rad/s, band of natural frequencies searched (0 / 0: the data's band)
  double omega_max = 0.0;  // rad/s
  void validate() const;   // InputError (source "dominant pole options"): 0 <= omega_min < omega_max or both 0
};

struct DominantPole {
  Complex pole;                    // rad/s, Im > 0
  double natural_frequency = 0.0;  // |pole|, rad/s
  double damping = 0.0;            // -Re pole / |pole|
  double peak = 0.0;               // its largest contribution on the data's frequencies, data units
  VectorFittingResult fit;         // the model it comes from (its relative_rms_error is the fit's error)
  [[nodiscard]] double frequency_Hz() const;
};

// omega, h as for vector_fit (one output). InputError as vector_fit; NumericalError when the fit
// fails or has no complex pair in the band.
// omega: rad/s.
DominantPole dominant_pole(const Vector& omega, const CVector& h, const DominantPoleOptions& options = {});

constexpr auto describe(core::Type<DominantPole>) {
  using S = DominantPole;
  using namespace core::shown;
  return core::fields<S>("DominantPole", "the dominant pole pair of a vector fit",
      core::field("pole", &S::pole, kRadPerSecond, "Im > 0"),
      core::field("natural_frequency", &S::natural_frequency, kRadPerSecondAsHz, "|pole|"),
      core::field("damping", &S::damping, kRatio, "-Re pole / |pole|"),
      core::field("peak", &S::peak, kNone, "its largest contribution on the data's frequencies, data units"),
      core::field("fit", &S::fit, kNone, "the vector fit it comes from"));
}

}  // namespace piezobench::ident
