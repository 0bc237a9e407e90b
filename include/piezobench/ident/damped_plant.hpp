#pragma once
// One damped plant u' -> d_e of the IFF experiment (report section 2.6), from its FRF as measured:
// the loop does not change d_e's read-out delay, so the open-loop fit's delay is removed first
// (H e^{j w delay_s}); then over [fmin_Hz, fmax_Hz]
//
//   dominant       the damped pole: the dominant pair of a vector fit of fit_order poles
//                  (dominant_pole.hpp, the method of `iff study`), its natural frequency searched
//                  in the band
//   second_order   the report's second-order fit (fit_delayed_second_order, delay fixed at 0) of
//                  the same lines, for comparison only: it misplaces the pole by up to 50 % once the
//                  controller's poles have moved into the band
#include <optional>
#include <string>
#include <vector>

#include "piezobench/dsp/frf.hpp"
#include "piezobench/ident/dominant_pole.hpp"
#include "piezobench/ident/plant_fit.hpp"

namespace piezobench::ident {

struct DampedPlantOptions {
  std::string output = "de";  // the FRF's output d_e
  double fmin_Hz = 0.0;       // Hz, band of both fits (the 0 Hz line left out)
  double fmax_Hz = 0.0;       // Hz, > fmin_Hz
  double delay_s = 0.0;       // s, >= 0: removed before the fits
  long fit_order = 6;         // poles of the vector fit
  // Errors: InputError(source, field, ...); the fits' messages name "source: field".
  std::string source, field;
};

struct DampedPlantAnalysis {
  std::optional<DominantPole> dominant;             // nullopt: the vector fit failed (see failed)
  long dominant_fit_order = 0;                      // poles of that vector fit
  std::optional<DelayedSecondOrderFit> second_order;  // nullopt: it failed (second_order_error)
  std::string second_order_error;                   // the comparison fit's NumericalError, else ""
  double delay_removed_s = 0.0;                     // s
  double fmin_Hz = 0.0, fmax_Hz = 0.0;              // Hz, the band
  long lines = 0;                                   // lines in the band
  // "dominant pole: ...": the vector fit failed on valid data (NumericalError).
  std::vector<std::string> failed;
};

// `frf` as measured (Hz). InputError: the output is not in the FRF, an invalid FRF, a band that is
// not 0 <= fmin_Hz < fmax_Hz, a negative or non-finite delay, data the fits refuse. A vector fit
// that fails numerically is listed in `failed`; the second-order fit's failure in
// second_order_error.
DampedPlantAnalysis analyze_damped_plant(const dsp::Frf& frf, const DampedPlantOptions& options);

}  // namespace piezobench::ident
