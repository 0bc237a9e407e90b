#pragma once
// What a perfect characterization campaign would find for one virtual unit on the virtual bench:
// the numbers the campaign's tests compare their results with.
#include <nlohmann/json_fwd.hpp>

#include "piezobench/bench/virtual_bench.hpp"

namespace piezobench::bench {

// The truth of `unit` on the bench `options` (its switches count: without creep k1 = k2, without
// the NMP zero the anti-resonance is minimum phase, and so on). Keys (SI unless the name says
// otherwise):
//   id, defective, defect, model ("2dof" or "superelement"), delay_s (effective, hold included)
//   model_2dof        {m, k1, c1, ke, ce, ka, ca, ga, gs}: the unit's 2-DoF parameters (SI; m is
//                     the suspended mass); null for a super element
//   capacitance_uF    {sensor, actuator}: the LCR readings without error
//   hpf_corner_Hz     1 / (2 pi R C_sensor), R what discharges the sensor stack on this bench;
//                     hpf_corner_with_resistor_Hz, hpf_corner_without_resistor_Hz: with
//                     R = hpf_resistance and R = adc_input_resistance
//   resonance_Hz, resonance_damping         lowest lightly damped (< 0.2) pole pair of the linear bench
//   antiresonance_Hz, antiresonance_damping lowest complex zero pair of u -> Vs (damping < 0:
//                     non-minimum phase), zero_is_nonminimum_phase
//   nmp_zero          {frequency_Hz, damping}: the same pair
//   static_gain_um_per_V    u -> d_e on the FRF's stiffness line (sensor stack open-circuited,
//                           i.e. between the high-pass corner and the resonance)
//   dc_gain_um_per_V        u -> d_e at DC (sensor stack short-circuited through R)
//   static_gain_Vs_V_per_V  u -> Vs before the high-pass (the stiffness-line level of Vs)
//   stiffness_N_per_um {k_tot: shell + stacks with the sensor open (what the resonance shows),
//                       static: with the sensor short-circuited through R (a slow load),
//                       resonance: m_sus (2 pi resonance_Hz)^2,
//                       k1, k2: the readings of the `stiffness` experiment defined below,
//                       k_sc: k1 with the stacks short-circuited (the actuators on the amplifier,
//                       the sensor on R: this bench's k1), k_oc: k1 of the same test with every
//                       stack open (actuator_open_circuit, no resistor; null for a super element),
//                       open_circuit: the static stiffness with every stack open (ka + ga^2/C_ab,
//                       ke), null for a super element}
//   stroke_um         max - min of the probe reading in the `stroke` experiment (-20 V -> 150 V)
//   flatness_um       peak-to-valley of the 8 points from their least-squares plane
//   bending_modes_Hz  {y, x}, bending_damping  (hammer test)
//   hysteresis_scale, creep_coefficient, load_creep_coefficient, stroke_factor
//   stiffness_readings the reading windows below (s)
// k1 and k2 come from the noise-free `stiffness` record (mass m_a put on over [3, 3.5] s, taken off
// over [13, 13.5] s): with d_before, d_loaded, d_after the means of d_e over [2.0, 2.9),
// [12.0, 12.9) and [14.0, 15.0) s, k1 = m_a g / (d_before - d_loaded) and
// k2 = m_a g / (d_after - d_loaded). Creep during the loaded 10 s makes k1 < k2 (Table 2.1).
// stroke_um and k1, k2 are measured on noise-free simulations (a few hundred thousand samples);
// the rest is analytic. Throws as VirtualBench's constructor.
nlohmann::json truth_json(const UnitTruth& unit, const BenchOptions& options);

}  // namespace piezobench::bench
