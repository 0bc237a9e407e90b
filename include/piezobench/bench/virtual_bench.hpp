#pragma once
// The virtual test bench (report section 2, Figure 2.1): one amplified piezoelectric actuator
// between a fixed base and a suspended mass on an air bearing, driven through a 16-bit DAC and a
// 20 V/V amplifier, read by an encoder (d_e) and by the force-sensor stack through a 16-bit ADC
// behind the resistor high-pass (Vs). It behaves like the real bench, instrument limits and
// nonlinearities included: hysteresis and creep of the stacks, quantization, noise, a measurement
// delay and the lightly damped non-minimum-phase zero on u -> Vs that the report observed.
//
// VirtualBench is stepped one sample at a time (10 kHz by default). step() allocates nothing, takes
// no lock and does no I/O: the real-time loop (rt module) runs it in lockstep as its
// hardware-in-the-loop backend, and the experiments (experiments.hpp) run it to write measurement
// files. docs/virtual-bench.md describes the model in full; in short:
//
//  - Linear part, exact: the amplifier's first-order bandwidth, the actuator (2-DoF model or a
//    super element), the suspended (and added) mass, and the force-sensor stack's electrical side
//    are one continuous state space, discretized exactly for the DAC's zero-order hold (matrix
//    exponential, precomputed for each mass configuration), so the massless node's fast pole
//    (-50000 rad/s) costs nothing in accuracy or stability.
//  - Force-sensor stack (2-DoF model): a piezoelectric element with blocked capacitance C_b and
//    coupling alpha = gs C_b, shunted by R: tension T = ke_sc e + ce e' + alpha V and
//    C_b V' = alpha e' - V / R. Above the corner 1/(2 pi R C) the stack is open-circuit (stiffness
//    ke, Table 3.1, and Vs = gs e); at DC it is short-circuited (ke_sc = ke - gs^2 C_b), so the
//    same element gives the 0.4 Hz high-pass on Vs and the stiffness that depends on the
//    electrical boundary. C_b is chosen so that the in-situ capacitance (the LCR reading) is the
//    unit's capacitance_sensor, which puts the high-pass corner at 1/(2 pi R capacitance_sensor).
//  - Non-minimum-phase zero: the sensor read-out shares a return conductor (resistance
//    ground_resistance) with the actuator stacks' drive current C_a dVa/dt, which adds
//    -R_g C_a dVa/dt to the measured Vs. Near the anti-resonance (where the true Vs nearly vanishes)
//    this quadrature term moves the lightly damped zero pair into the right half plane without
//    moving its frequency (0.16 Ohm: damping -0.004 at 41.1 Hz, the report's 0.4 %). The ADC's
//    first-order anti-aliasing filter (1 kHz) matters here: without it the sampled Vs would catch
//    the drive current's spikes at arbitrary phases and alias the DAC's images onto the dip, and
//    the zero seen in the sampled files would not be the model's (with it they agree within
//    0.0005 in damping).
//  - Hysteresis: Prandtl-Ishlinskii play operators on the stack voltage (thresholds 10..80 V), so
//    loops widen relative to their stroke as the amplitude grows and the large-signal stroke
//    exceeds the small-signal gain, as the report found (250 um against 17 um/V x 8.5 V/V). A
//    second law, Bouc-Wen (BenchOptions::hysteresis_law), is there for the tests of the
//    hysteresis identification and compensation (ident/hysteresis.hpp), which must not meet the
//    family they identify; with a quadratic term on the effective voltage ("bouc-wen-asymmetric")
//    its loops are asymmetric about their centre (the modified PI's case).
//  - Creep: three first-order creep states (5, 50, 500 s) on the actuator stacks, driven by the
//    voltage-induced free stroke (creep_coefficient) and by the stacks' elastic strain under load
//    (load_creep_coefficient), so a constant load keeps compressing the APA (Figure 2.4, k1 < k2).
//  - Instruments: DAC 16 bit +-10 V (ZOH), amplifier gain, bandwidth and output clamp; encoder
//    quantization and noise; ADC 16 bit +-10 V behind a first-order anti-aliasing low-pass, with
//    noise; a measurement delay.
//
// Delay: `delay` is the total delay seen in the FRFs at low frequency, the DAC's hold (half a
// sample) included. The bench delays the command by delay - Ts/2 (whole samples through a ring
// buffer, the fraction exactly by splitting the hold interval); 200 us at 10 kHz is 1.5 samples +
// the hold. With delay < Ts/2 only the hold remains.
//
// Signs and units follow DESIGN.md: SI inside, d_e positive when the APA lengthens; more voltage
// shortens the APA (ga < 0), so u -> d_e has a negative static gain.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "piezobench/apa/two_dof.hpp"
#include "piezobench/core/fields.hpp"
#include "piezobench/lti/state_space.hpp"

namespace piezobench::bench {

// Most play operators the bench's Prandtl-Ishlinskii law takes (UnitTruth::hysteresis_thresholds).
inline constexpr std::size_t kMaxPlayOperators = 8;

// The true properties of one virtual actuator: what a perfect characterization would find. The
// campaign's tests compare their results with these (truth.hpp).
struct UnitTruth {
  int id = 1;                               // unit number (1..7 in the report's batch)
  apa::TwoDofParams model;                  // 2-DoF parameters of this unit (Table 3.1 with spread);
                                            // model.m is replaced on the bench by the bench's masses
  double capacitance_sensor = 4.95e-6;      // F, sensor stack in situ (LCR at 1 kHz, small signal)
  double capacitance_actuator = 9.87e-6;    // F, the two actuator stacks in parallel (LCR)
  double stroke_factor = 1.0;               // free stroke relative to a good unit (unit 3: clearly < 1);
                                            // already applied to model.ga by batch_unit
  double flatness_tilt = 0.0;               // rad, tilt of interface 2 relative to interface 1
  double flatness_tilt_direction = 0.0;     // rad, direction of that tilt in the probe plane (x-y)
  double flatness_warp = 0.0;               // m, saddle-shaped warp amplitude of the interfaces
  double hysteresis_scale = 1.0;            // relative width (and large-signal gain) of the hysteresis
  // The Prandtl-Ishlinskii law's play operators when given (a digital twin's identified hysteresis,
  // bench/twin.hpp): thresholds (V, > 0, increasing) and weights (effective V per V, >= 0), at most
  // kMaxPlayOperators of each; they replace the default operators (10, 20, ..., 80 V, each
  // 0.163 x hysteresis_scale), and hysteresis_scale then only scales the Bouc-Wen laws. Empty: the
  // default.
  std::vector<double> hysteresis_thresholds, hysteresis_weights;
  double creep_coefficient = 0.0;           // voltage creep per decade of time, relative to the step
  double load_creep_coefficient = 0.0;      // creep of the stacks' elastic strain under a load,
                                            // per decade of time (relative)
  double mode_y_Hz = 280.0;                 // fixed-free bending modes (hammer test)
  double mode_x_Hz = 412.0;
  double mode_damping = 0.01;
  bool defective = false;
  std::string defect;                       // what is wrong with it ("" for a good unit)

  // InputError (source "unit N") naming the field: the model (TwoDofParams::validate), positive
  // capacitances and stroke factor, non-negative scales and coefficients, modes > 0 Hz, damping in
  // [0, 1), play operators as said above.
  void validate() const;
};

constexpr auto describe(core::Type<UnitTruth>) {
  using S = UnitTruth;
  using namespace core::shown;
  constexpr core::Shown kRadian{"rad", "rad", 1.0};
  return core::fields<S>("UnitTruth", "the true properties of one unit of the virtual batch (SI)",
      core::field("id", &S::id, kNone, "unit number (1..7 in the report's batch)"),
      core::field("model", &S::model, kNone, "2-DoF parameters of this unit (m is replaced on the bench by the bench's masses)"),
      core::field("capacitance_sensor", &S::capacitance_sensor, kFaradAsUf, "sensor stack in situ (LCR at 1 kHz, small signal)"),
      core::field("capacitance_actuator", &S::capacitance_actuator, kFaradAsUf, "the two actuator stacks in parallel (LCR)"),
      core::field("stroke_factor", &S::stroke_factor, kRatio, "free stroke relative to a good unit (already in model.ga)"),
      core::field("flatness_tilt", &S::flatness_tilt, kRadian, "tilt of interface 2 relative to interface 1"),
      core::field("flatness_tilt_direction", &S::flatness_tilt_direction, kRadian, "direction of that tilt in the probe plane (x-y)"),
      core::field("flatness_warp", &S::flatness_warp, kMetreAsUm, "saddle-shaped warp amplitude of the interfaces"),
      core::field("hysteresis_scale", &S::hysteresis_scale, kRatio, "relative width (and large-signal gain) of the hysteresis"),
      core::field("hysteresis_thresholds", &S::hysteresis_thresholds, kVolt, "play operators' thresholds (empty: the default operators)"),
      core::field("hysteresis_weights", &S::hysteresis_weights, kVoltPerVolt, "play operators' weights (empty: the default operators)"),
      core::field("creep_coefficient", &S::creep_coefficient, kRatio, "voltage creep per decade of time, relative to the step"),
      core::field("load_creep_coefficient", &S::load_creep_coefficient, kRatio, "creep of the stacks' strain under a load, per decade of time"),
      core::field("mode_y_Hz", &S::mode_y_Hz, kHertz, "fixed-free bending mode in y (hammer test)"),
      core::field("mode_x_Hz", &S::mode_x_Hz, kHertz, "fixed-free bending mode in x (hammer test)"),
      core::field("mode_damping", &S::mode_damping, kRatio, "damping ratio of those modes"),
      core::field("defective", &S::defective, kNone, "the unit is defective"),
      core::field("defect", &S::defect, kNone, "what is wrong with it (\"\" for a good unit)"));
}

// Unit `id` of the report's batch (1..7) drawn around the report's values from `seed`: stiffness
// and capacitance within about +-2 %, flatness from a random tilt and warp (Table 1.1-like), unit 3
// defective (about half the capacitance, a stroke clearly off). The same (id, seed) gives the same
// unit. InputError (field "unit") for an id outside 1..7.
UnitTruth batch_unit(int id, std::uint64_t seed);

// The law of the stacks' hysteresis on the virtual bench (docs/virtual-bench.md).
enum class HysteresisLaw {
  kPrandtlIshlinskii,  // "prandtl-ishlinskii": 8 play operators, thresholds 10..80 V (the default)
  kBoucWen,            // "bouc-wen": Bouc-Wen, a = 1 x hysteresis_scale, beta = 0.02 /V
  kBoucWenAsymmetric,  // "bouc-wen-asymmetric": the same plus kAsymmetricQuadratic x hysteresis_scale
                       // x Va^2 on the effective voltage: loops asymmetric about their centre
};
inline constexpr double kAsymmetricQuadratic = 1e-3;  // 1/V
inline constexpr const char* kHysteresisLaws = "prandtl-ishlinskii, bouc-wen or bouc-wen-asymmetric";
std::string to_string(HysteresisLaw law);
HysteresisLaw hysteresis_law_from_string(const std::string& name);  // InputError (field "hysteresis_law")

struct BenchOptions {
  double sample_rate = 10e3;                // Hz, the real-time target's rate (at most 1e6)
  // DAC: 16 bit over +-10 V, zero-order hold.
  int dac_bits = 16;
  double dac_range = 10.0;                  // V
  // Amplifier (PD200): Va = gain u through a first-order bandwidth, clamped to [va_min, va_max]
  // (the command gain * u is clamped, so the output never leaves the range).
  double amplifier_gain = 20.0;             // V/V
  double amplifier_bandwidth_Hz = 5000.0;
  double va_min = -20.0;                    // V, APA300ML stack range
  double va_max = 150.0;                    // V
  // Mechanics around the actuator.
  double suspended_mass = 5.7;              // kg, granite and parts on the air bearing
  double added_mass = 6.4;                  // kg, the mass of the static stiffness test (the bench
                                            // precomputes its matrices with and without it)
  double gravity = 9.8;                     // m/s^2
  // Encoder (Renishaw Vionic) and force-sensor read-out.
  double encoder_resolution = 2.5e-9;       // m
  double encoder_noise = 1e-9;              // m rms
  double hpf_resistance = 80.6e3;           // Ohm, across the sensor stack (C from the unit)
  bool hpf_resistor = true;                 // the resistor is in place (report section 2.5); without
                                            // it the stack sees the ADC's input resistance only
  double adc_input_resistance = 10e6;       // Ohm (neglected beside the resistor when it is in place)
  int adc_bits = 16;
  double adc_range = 10.0;                  // V
  double vs_noise = 1e-3;                   // V rms
  double adc_bandwidth_Hz = 1000.0;         // first-order anti-aliasing low-pass on Vs before the ADC
  // Shared return resistance between the actuator drive current and the sensor read-out: the
  // origin of the non-minimum-phase zero (see the file comment). Used when nonminimum_phase_zero.
  double ground_resistance = 0.16;          // Ohm
  // Electrical boundary of the actuator stacks (report section 2.2). false: driven by the amplifier
  // (a voltage source: short circuit); true: disconnected (open circuit, 2-DoF model only): their
  // charge stays, their voltage follows their strain (Va reads it; the DAC command does nothing)
  // and they are stiffer, ka + ga^2 / C_ab with C_ab their blocked capacitance
  // (docs/virtual-bench.md).
  bool actuator_open_circuit = false;
  // Effects that can be switched off (all on by default).
  double delay = 200e-6;                    // s, total measurement delay (hold included); 0 = only the hold
  bool nonminimum_phase_zero = true;        // the lightly damped NMP zero on u -> Vs
  bool hysteresis = true;
  HysteresisLaw hysteresis_law = HysteresisLaw::kPrandtlIshlinskii;
  bool creep = true;
  bool noise = true;                        // measurement noise (quantization stays)
  // A TOML file describing a super element that replaces the 2-DoF model of the actuator when set.
  // Keys (paths relative to the TOML file's folder):
  //   k_file, m_file, nodes_file   the super element (fem::read_super_element); required
  //   coordinates_file             node coordinates (optional)
  //   format                       "auto" (default), "ansys", "calculix", "matrix-market"
  //   fix                          nodes clamped to the fixed base, e.g. [76429]; required
  //   actuator                     "A:B:DIR" force pair of the actuator stacks (+ga Va pushes A and
  //                                B apart); required
  //   sensor                       "A:B:DIR" relative displacement across the sensor stack; required
  //   output                       "NODE:DIR" the moving interface: d_e, where the suspended mass
  //                                sits; required
  //   ga                           N/V (default 23.2, the report's tuned value)
  //   gs                           V/m (default 4.9e6)
  //   modal_damping                damping ratio of every mode (default 0.01)
  //   max_mode_Hz                  modes kept (above: static correction), default 20000
  //   guided                       true (default): the mass node moves along DIR only (air bearing)
  //   stack_modulus_Pa             information: the stacks' modulus the element was built with (> 0)
  // Example for the APA95ML of /work/shared/data/apa95ml-ansys: docs/virtual-bench.md.
  std::optional<std::filesystem::path> superelement;

  // InputError (source "bench options") naming the field.
  void validate() const;
  // Ohm: what discharges the sensor stack, hpf_resistance or (without the resistor) adc_input_resistance.
  [[nodiscard]] double sensor_shunt_resistance() const { return hpf_resistor ? hpf_resistance : adc_input_resistance; }
};

// What the bench's instruments give for one sample.
struct BenchSample {
  double de = 0.0;  // m, encoder (quantized, noisy, delayed)
  double vs = 0.0;  // V, force-sensor stack through the high-pass and the ADC (quantized, noisy, delayed)
  double va = 0.0;  // V, amplifier output at the actuator stacks (after its clamp)
};

// The samples of a run, one array per channel (VirtualBench::run(u)).
struct BenchRun {
  Eigen::VectorXd de;  // m
  Eigen::VectorXd vs;  // V
  Eigen::VectorXd va;  // V
};

constexpr auto describe(core::Type<BenchRun>) {
  using S = BenchRun;
  using namespace core::shown;
  return core::fields<S>("BenchRun", "the measurements of a run of DAC commands on the virtual bench, one per command",
      core::field("de", &S::de, kMetre, "encoder (quantized, noisy, delayed)"),
      core::field("vs", &S::vs, kVolt, "force-sensor stack through the high-pass and the ADC"),
      core::field("va", &S::va, kVolt, "amplifier output at the actuator stacks (after its clamp)"));
}

class VirtualBench {
 public:
  // Validates the options and the unit (InputError; a super-element file that cannot be read or
  // used is an InputError naming it). Draws its noise from `seed`. The bench starts at rest.
  VirtualBench(const UnitTruth& unit, const BenchOptions& options, std::uint64_t seed);
  ~VirtualBench();
  VirtualBench(VirtualBench&&) noexcept;
  VirtualBench& operator=(VirtualBench&&) noexcept;
  VirtualBench(const VirtualBench&) = delete;
  VirtualBench& operator=(const VirtualBench&) = delete;

  // Advances one sample period with the DAC command u (V; quantized to dac_bits and limited to
  // +-dac_range like a real DAC; a NaN command is held at 0 V) and returns the measurements of
  // the new sample (taken at the end of the period, before the next command). Allocates nothing.
  BenchSample step(double u) noexcept;
  // The same as out[k] = step(u[k]) for k = 0 .. min(sizes) - 1, in order, but faster: the bench's
  // state stays in registers between samples. For experiments that know their command in advance.
  void run(std::span<const double> u, std::span<BenchSample> out) noexcept;
  // run(u, out) for every command of u, the samples as one array per channel.
  BenchRun run(std::span<const double> u);

  // Puts a mass on the suspended mass (kg, >= 0; 0 takes it off), effective from the next step:
  // its inertia and (times the load fraction) its weight. 0 and options().added_mass are
  // precomputed; another value is prepared here (this allocates; if that fails the mass is left
  // unchanged, which added_mass() shows). Negative or non-finite values are ignored.
  void set_added_mass(double kg) noexcept;
  // Share of the added mass's weight the bench carries, in [0, 1] (default 1): the operator
  // lowers the mass by hand, so the experiments ramp it. Clamped to [0, 1]; NaN is ignored.
  void set_load_fraction(double fraction) noexcept;
  [[nodiscard]] double added_mass() const;

  // Back to rest (no voltage, no hysteresis or creep memory, no added mass), noise reseeded.
  void reset(std::uint64_t seed);

  // The linear part of the bench from the DAC voltage u to [d_e (m); Vs (V)]: amplifier (gain and
  // bandwidth), actuator (2-DoF model or super element) with the current masses, the
  // non-minimum-phase zero and the high-pass when enabled, the delay as input_delay
  // (effective_delay()). No hysteresis, creep, quantization, noise or clamp. This is the "true
  // plant" the campaign's and the damped-plant study's identifications are checked against.
  [[nodiscard]] lti::StateSpace linear_model() const;

  // Total delay of the measurements at low frequency, s: max(options().delay, Ts / 2).
  [[nodiscard]] double effective_delay() const;
  // "2dof" or "superelement".
  [[nodiscard]] std::string model_name() const;

  [[nodiscard]] double sample_rate() const;
  [[nodiscard]] double time() const;  // s, time of the last sample returned by step()
  [[nodiscard]] const UnitTruth& unit() const;
  [[nodiscard]] const BenchOptions& options() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace piezobench::bench
