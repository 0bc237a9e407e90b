#pragma once
// The virtual test bench (report section 2, Figure 2.1): one amplified piezoelectric actuator
// between a fixed base and a suspended mass on an air bearing, driven through a 16-bit DAC and a
// 20 V/V amplifier, read by an encoder (d_e) and by the force-sensor stack through a 16-bit ADC
// behind the resistor high-pass (Vs). It behaves like the real bench, instrument limits and
// nonlinearities included: hysteresis and creep of the stacks, quantization, noise, a measurement
// delay and the lightly damped non-minimum-phase zero on u -> Vs that the report observed.
//
// VirtualBench is stepped one sample at a time (10 kHz by default; internal sub-steps where the
// accuracy needs them). step() allocates nothing, takes no lock and does no I/O: the real-time
// loop (rt module) runs it in lockstep as its hardware-in-the-loop backend, and the experiments
// (experiments.hpp) run it to write measurement files.
//
// Signs and units follow DESIGN.md: SI inside, d_e positive when the APA lengthens; more voltage
// shortens the APA (ga < 0), so u -> d_e has a negative static gain.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "piezobench/apa/two_dof.hpp"
#include "piezobench/lti/state_space.hpp"

namespace piezobench::bench {

// The true properties of one virtual actuator: what a perfect characterization would find. The
// campaign's tests compare their results with these.
struct UnitTruth {
  int id = 1;                               // unit number (1..7 in the report's batch)
  apa::TwoDofParams model;                  // 2-DoF parameters of this unit (Table 3.1 with spread)
  double capacitance_sensor = 4.95e-6;      // F, sensor stack (small signal, LCR at 1 kHz)
  double capacitance_actuator = 9.87e-6;    // F, the two actuator stacks in parallel
  double stroke_factor = 1.0;               // free stroke relative to a good unit (unit 3: clearly < 1)
  double flatness_tilt = 0.0;               // rad, tilt between the two interfaces
  double flatness_warp = 0.0;               // m, out-of-plane warp amplitude of the interfaces
  double hysteresis_scale = 1.0;            // relative width of the hysteresis loops
  double creep_coefficient = 0.0;           // creep per decade of time, relative to the step
  double mode_y_Hz = 280.0;                 // fixed-free bending modes (hammer test)
  double mode_x_Hz = 412.0;
  double mode_damping = 0.01;
  bool defective = false;
  std::string defect;                       // what is wrong with it ("" for a good unit)
};

// Unit `id` of the report's batch (1..7) drawn around the report's values from `seed`: stiffness
// and capacitance within about +-2 %, flatness from a random tilt and warp (Table 1.1-like), unit 3
// defective (about half the capacitance, a stroke clearly off). The same (id, seed) gives the same
// unit. InputError (field "unit") for an id outside 1..7.
UnitTruth batch_unit(int id, std::uint64_t seed);

struct BenchOptions {
  double sample_rate = 10e3;                // Hz, the real-time target's rate
  // DAC: 16 bit over +-10 V, zero-order hold.
  int dac_bits = 16;
  double dac_range = 10.0;                  // V
  // Amplifier (PD200): Va = gain u through a first-order bandwidth, clamped to [va_min, va_max].
  double amplifier_gain = 20.0;             // V/V
  double amplifier_bandwidth_Hz = 5000.0;
  double va_min = -20.0;                    // V, APA300ML stack range
  double va_max = 150.0;
  // Mechanics around the actuator.
  double suspended_mass = 5.7;              // kg, granite and parts on the air bearing
  double gravity = 9.8;                     // m/s^2
  // Encoder (Renishaw Vionic) and force-sensor read-out.
  double encoder_resolution = 2.5e-9;       // m
  double encoder_noise = 1e-9;              // m rms
  double hpf_resistance = 80.6e3;           // Ohm, across the sensor stack (C from the unit)
  int adc_bits = 16;
  double adc_range = 10.0;                  // V
  double vs_noise = 1e-3;                   // V rms
  // Effects that can be switched off (all on by default).
  double delay = 200e-6;                    // s, total measurement delay; 0 = none
  bool nonminimum_phase_zero = true;        // the lightly damped NMP zero on u -> Vs
  bool hysteresis = true;
  bool creep = true;
  bool noise = true;
  // A super element (folder or files readable by fem::read_super_element) replaces the 2-DoF
  // model of the actuator when set.
  std::optional<std::filesystem::path> superelement;

  // InputError (source "bench options") naming the field.
  void validate() const;
};

// What the bench's instruments give for one sample.
struct BenchSample {
  double de = 0.0;  // m, encoder (quantized, noisy, delayed)
  double vs = 0.0;  // V, force-sensor stack through the high-pass and the ADC (quantized, noisy, delayed)
  double va = 0.0;  // V, amplifier output at the actuator stacks (after its clamp)
};

class VirtualBench {
 public:
  // Validates the options and the unit (InputError). Draws its noise from `seed`.
  VirtualBench(const UnitTruth& unit, const BenchOptions& options, std::uint64_t seed);
  ~VirtualBench();
  VirtualBench(VirtualBench&&) noexcept;
  VirtualBench& operator=(VirtualBench&&) noexcept;
  VirtualBench(const VirtualBench&) = delete;
  VirtualBench& operator=(const VirtualBench&) = delete;

  // Advances one sample period with the DAC command u (V; quantized to dac_bits and limited to
  // +-dac_range like a real DAC; a NaN command is held at 0 V) and returns the measurements of
  // the new sample. Allocates nothing.
  BenchSample step(double u) noexcept;

  // Puts a mass on the suspended mass (kg, >= 0; 0 takes it off), effective from the next step.
  void set_added_mass(double kg) noexcept;

  // Back to rest (no voltage, no hysteresis or creep memory), with the noise reseeded.
  void reset(std::uint64_t seed);

  // The linear part of the bench from the DAC voltage u to [d_e (m); Vs (V)]: amplifier (gain and
  // bandwidth), actuator (2-DoF model or super element) with the current masses, the
  // non-minimum-phase zero and the high-pass when enabled, the delay as input_delay. No
  // hysteresis, creep, quantization, noise or clamp. This is the "true plant" the campaign's and
  // the damped-plant study's identifications are checked against.
  [[nodiscard]] lti::StateSpace linear_model() const;

  [[nodiscard]] double sample_rate() const;
  [[nodiscard]] double time() const;  // s, time of the last sample returned by step()
  [[nodiscard]] const UnitTruth& unit() const;
  [[nodiscard]] const BenchOptions& options() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace piezobench::bench
