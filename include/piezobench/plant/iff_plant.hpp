#pragma once
// The report's model of the plant the IFF controller sees (eq. 2.3, section 2.6): from the DAC
// voltage u (V) to the force-sensor voltage Vs (V). Below both its users: ident fits it to a
// measured FRF (ident/plant_fit.hpp), control closes the loop around it (control/iff.hpp).
#include "piezobench/core/units.hpp"
#include "piezobench/lti/state_space.hpp"
#include "piezobench/lti/transfer_function.hpp"

namespace piezobench::plant {

// G(s) = g0 (1 + 2 xz s/wz + s^2/wz^2) / (1 + 2 xp s/wp + s^2/wp^2) * s / (w_hpf + s) * exp(-s delay)
// from u (V) to Vs (V). Defaults: the report's manual fit (section 2.6). xz < 0 is a
// non-minimum-phase zero pair (mirrored into the right half plane), which the report's data show.
struct IffPlantParams {
  double g0 = 0.64;                    // V/V
  double wz = kTwoPi * 42.7;           // rad/s, anti-resonance
  double xz = 0.004;                   // damping ratio of the zero (< 0: non-minimum phase)
  double wp = kTwoPi * 95.2;           // rad/s, resonance
  double xp = 0.02;                    // damping ratio of the pole
  double w_hpf = kTwoPi * 0.4;         // rad/s, high-pass corner of the resistor across the sensor stack
  double delay = 0.0;                  // s (the report adds 200 us to match the phase)
  void validate() const;               // InputError naming the field
};
// G(s) as a transfer function with its delay; validates `params` first.
lti::TransferFunction iff_plant(const IffPlantParams& params = {});
// G(j omega) of the same formula (omega in rad/s), without validation (for fits' inner loops).
lti::Complex iff_plant_response(const IffPlantParams& params, double omega);
// omega: rad/s.
lti::CVector iff_plant_response(const IffPlantParams& params, const lti::Vector& omega);

}  // namespace piezobench::plant
