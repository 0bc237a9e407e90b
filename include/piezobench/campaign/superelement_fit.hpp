#pragma once
// Report section 4: a super element on the test bench, its actuator and sensor sensitivities tuned
// against a unit's measured FRFs, and checked against eq. 4.1.
//
// The bench: the setup's fixed nodes clamped, `moving_mass` on the moving interface (the setup's
// first output, an absolute displacement), that node guided along its direction (the air bearing),
// modal damping; input the actuator force pair (the setup's first force), outputs [d_e, the sensor
// stack's extension] (the setup's two outputs). With F_a = ga V_a, V_a = amplifier_gain u and
// V_s = gs e_s:
//   u -> d_e = amplifier_gain ga H_de(f),   u -> V_s = amplifier_gain ga gs H_s(f).
// ga is the median of |measured u -> d_e| / |amplifier_gain H_de| over the tuning band (below the
// resonances, where neither the damping nor the moving mass's dynamics matter much), gs the
// median of |measured u -> V_s| / |amplifier_gain ga H_s| there, away (15 %) from the model's
// anti-resonance, where the ratio measures the zeros' positions, not gs; each takes the sign that makes
// the phases agree in the band. The measurement chain (the sensor's high-pass, the ADC's
// low-pass, the delays) is not in the model: the band stays well above the high-pass corner.
#include <Eigen/Dense>

#include "piezobench/dsp/frf.hpp"
#include "piezobench/fem/structural_model.hpp"
#include "piezobench/fem/superelement.hpp"
#include "piezobench/fem/superelement_setup.hpp"

namespace piezobench::campaign {

struct SuperElementFitOptions {
  double moving_mass = 5.7;      // kg, on the moving interface
  double amplifier_gain = 20.0;  // V/V
  double modal_damping = 0.02;   // every mode of the bench model
  double band_min_Hz = 5.0;      // tuning band: from here ...
  double band_fraction = 0.5;    // ... to this fraction of the lower of the two resonances
  double error_max_Hz = 300.0;   // the errors are judged from band_min_Hz to here (issue 31: 20-300 Hz)
  // InputError (source "superelement fit") for values out of range.
  void validate() const;
};

struct SuperElementFit {
  double ga = 0.0;                 // N/V
  double gs = 0.0;                 // V/m
  double band_lo_Hz = 0.0, band_hi_Hz = 0.0;
  double resonance_Hz = 0.0;       // first peak of the model's u -> d_e
  double antiresonance_Hz = 0.0;   // dip of the model's u -> V_s below the resonance (0: none)
  double de_error_dB = 0.0;        // median |20 log10 model/measured| of u -> d_e, band_lo .. error_max_Hz
  double vs_error_dB = 0.0;        // same for u -> V_s
  // The tuned model at the measured frequencies: input "u", outputs "de" (u -> d_e, m/V) and "Vs"
  // (u -> V_s, V/V), no coherence.
  dsp::Frf model;
};

// The bench model (see above). InputError when the setup has no force or fewer than two outputs,
// or its first output is not an absolute translation.
[[nodiscard]] fem::StructuralModel superelement_bench_model(const fem::SuperElement& se, const fem::SuperElementSetup& setup,
                                                            const SuperElementFitOptions& options);

// Tunes ga and gs against `measured` (u -> outputs "de" and "Vs"). InputError for a measured FRF
// without those outputs or with no frequency in the tuning band; NumericalError when the model
// response cannot be computed.
[[nodiscard]] SuperElementFit fit_superelement(const fem::SuperElement& se, const fem::SuperElementSetup& setup,
                                               const dsp::Frf& measured, const SuperElementFitOptions& options = {});

}  // namespace piezobench::campaign
