#include "piezobench/bench/virtual_bench.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <numbers>
#include <vector>

#include "nonlinear.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/units.hpp"
#include "plant.hpp"
#include "random.hpp"
#include "superelement_plant.hpp"

namespace piezobench::bench {

using detail::ContinuousPlant;

namespace {

constexpr const char* kOptionsSource = "bench options";

void require(bool ok, const std::string& source, const std::string& field, const std::string& expected, double found) {
  if (!ok) throw InputError(source, field, expected, format_number_exact(found));
}

// The 2-DoF bench in the fixed-size form its inner loop uses: six states (Va, x, x', xn, V, Vs at
// the ADC), the columns of Phi and Gamma as 6-vectors, so that x[k+1] = sum_j phi_j x_j +
// sum_j gamma_j in_j runs in SIMD registers (3 packets per column) with few loads: the step is bound
// by loads, not by arithmetic.
using Vec6 = Eigen::Matrix<double, 6, 1>;
struct TwoDofCore {
  std::array<Vec6, 6> phi{};
  std::array<Vec6, 4> gamma{};
  double ka = 0.0;  // N/m, for the creep drive ka xn
};

struct Config {
  double added_mass = 0.0;  // kg
  ContinuousPlant plant;
  TwoDofCore two;
  detail::ModalPlant modal;
};

constexpr std::size_t kMaxConfigs = 4;

}  // namespace

std::string to_string(HysteresisLaw law) {
  switch (law) {
    case HysteresisLaw::kBoucWen: return "bouc-wen";
    case HysteresisLaw::kBoucWenAsymmetric: return "bouc-wen-asymmetric";
    case HysteresisLaw::kPrandtlIshlinskii: break;
  }
  return "prandtl-ishlinskii";
}

HysteresisLaw hysteresis_law_from_string(const std::string& name) {
  if (name == "prandtl-ishlinskii") return HysteresisLaw::kPrandtlIshlinskii;
  if (name == "bouc-wen") return HysteresisLaw::kBoucWen;
  if (name == "bouc-wen-asymmetric") return HysteresisLaw::kBoucWenAsymmetric;
  throw InputError("", "hysteresis_law", kHysteresisLaws, "'" + name + "'");
}

void UnitTruth::validate() const {
  const std::string source = fmt::format("unit {}", id);
  model.validate(source);
  require(std::isfinite(capacitance_sensor) && capacitance_sensor > 0.0, source, "capacitance_sensor", "a capacitance > 0 F",
          capacitance_sensor);
  require(std::isfinite(capacitance_actuator) && capacitance_actuator > 0.0, source, "capacitance_actuator",
          "a capacitance > 0 F", capacitance_actuator);
  require(std::isfinite(stroke_factor) && stroke_factor > 0.0, source, "stroke_factor", "a factor > 0", stroke_factor);
  require(std::isfinite(flatness_tilt), source, "flatness_tilt", "a finite angle (rad)", flatness_tilt);
  require(std::isfinite(flatness_tilt_direction), source, "flatness_tilt_direction", "a finite angle (rad)",
          flatness_tilt_direction);
  require(std::isfinite(flatness_warp), source, "flatness_warp", "a finite warp (m)", flatness_warp);
  require(std::isfinite(hysteresis_scale) && hysteresis_scale >= 0.0, source, "hysteresis_scale", "a scale >= 0",
          hysteresis_scale);
  require(std::isfinite(creep_coefficient) && creep_coefficient >= 0.0 && creep_coefficient < 1.0, source,
          "creep_coefficient", "a creep per decade in [0, 1)", creep_coefficient);
  require(std::isfinite(load_creep_coefficient) && load_creep_coefficient >= 0.0 && load_creep_coefficient < 1.0, source,
          "load_creep_coefficient", "a creep per decade in [0, 1)", load_creep_coefficient);
  if (hysteresis_thresholds.size() != hysteresis_weights.size() || hysteresis_thresholds.size() > kMaxPlayOperators) {
    throw InputError(source, "hysteresis_weights", fmt::format("as many weights as thresholds, at most {}", kMaxPlayOperators),
                     fmt::format("{} thresholds and {} weights", hysteresis_thresholds.size(), hysteresis_weights.size()));
  }
  for (std::size_t i = 0; i < hysteresis_thresholds.size(); ++i) {
    const double r = hysteresis_thresholds[i];
    const double previous = i == 0 ? 0.0 : hysteresis_thresholds[i - 1];
    require(std::isfinite(r) && r > previous, source, fmt::format("hysteresis_thresholds[{}]", i),
            "a threshold > 0 V and above the previous one", r);
    require(std::isfinite(hysteresis_weights[i]) && hysteresis_weights[i] >= 0.0, source, fmt::format("hysteresis_weights[{}]", i),
            "a weight >= 0", hysteresis_weights[i]);
  }
  require(std::isfinite(mode_y_Hz) && mode_y_Hz > 0.0, source, "mode_y_Hz", "a frequency > 0 Hz", mode_y_Hz);
  require(std::isfinite(mode_x_Hz) && mode_x_Hz > 0.0, source, "mode_x_Hz", "a frequency > 0 Hz", mode_x_Hz);
  require(std::isfinite(mode_damping) && mode_damping >= 0.0 && mode_damping < 1.0, source, "mode_damping",
          "a damping ratio in [0, 1)", mode_damping);
}

void BenchOptions::validate() const {
  const std::string s = kOptionsSource;
  // At most 1 MHz, the real-time loop's limit (rt::kMaxSampleRate): the delay line holds up to 1 s
  // of samples (a twin with sample_rate_Hz = 1e12 asked for 8 TB; fuzz/regression/twin_toml).
  require(std::isfinite(sample_rate) && sample_rate > 0.0 && sample_rate <= 1e6, s, "sample_rate", "a rate in (0, 1e6] Hz", sample_rate);
  require(dac_bits >= 2 && dac_bits <= 32, s, "dac_bits", "2 to 32 bits", dac_bits);
  require(std::isfinite(dac_range) && dac_range > 0.0, s, "dac_range", "a range > 0 V", dac_range);
  require(std::isfinite(amplifier_gain) && amplifier_gain > 0.0, s, "amplifier_gain", "a gain > 0 V/V", amplifier_gain);
  require(std::isfinite(amplifier_bandwidth_Hz) && amplifier_bandwidth_Hz > 0.0, s, "amplifier_bandwidth_Hz",
          "a bandwidth > 0 Hz", amplifier_bandwidth_Hz);
  require(std::isfinite(va_min) && va_min <= 0.0, s, "va_min", "a lower voltage limit <= 0 V (the bench rests at 0 V)",
          va_min);
  require(std::isfinite(va_max) && va_max > 0.0 && va_max > va_min, s, "va_max",
          "an upper voltage limit > 0 V and > va_min", va_max);
  require(std::isfinite(suspended_mass) && suspended_mass > 0.0, s, "suspended_mass", "a mass > 0 kg", suspended_mass);
  require(std::isfinite(added_mass) && added_mass >= 0.0, s, "added_mass", "a mass >= 0 kg", added_mass);
  require(std::isfinite(gravity) && gravity >= 0.0, s, "gravity", "an acceleration >= 0 m/s^2", gravity);
  require(std::isfinite(encoder_resolution) && encoder_resolution >= 0.0, s, "encoder_resolution",
          "a resolution >= 0 m (0: none)", encoder_resolution);
  require(std::isfinite(encoder_noise) && encoder_noise >= 0.0, s, "encoder_noise", "a noise >= 0 m rms", encoder_noise);
  require(std::isfinite(hpf_resistance) && hpf_resistance > 0.0, s, "hpf_resistance", "a resistance > 0 Ohm",
          hpf_resistance);
  require(std::isfinite(adc_input_resistance) && adc_input_resistance > 0.0, s, "adc_input_resistance",
          "a resistance > 0 Ohm", adc_input_resistance);
  require(adc_bits >= 2 && adc_bits <= 32, s, "adc_bits", "2 to 32 bits", adc_bits);
  require(std::isfinite(adc_range) && adc_range > 0.0, s, "adc_range", "a range > 0 V", adc_range);
  require(std::isfinite(vs_noise) && vs_noise >= 0.0, s, "vs_noise", "a noise >= 0 V rms", vs_noise);
  require(std::isfinite(adc_bandwidth_Hz) && adc_bandwidth_Hz > 0.0, s, "adc_bandwidth_Hz", "a bandwidth > 0 Hz",
          adc_bandwidth_Hz);
  require(std::isfinite(ground_resistance) && ground_resistance >= 0.0, s, "ground_resistance", "a resistance >= 0 Ohm",
          ground_resistance);
  require(std::isfinite(delay) && delay >= 0.0 && delay <= 1.0, s, "delay", "a delay in [0, 1] s", delay);
  if (superelement && superelement->empty()) throw InputError(s, "superelement", "a TOML file", "an empty path");
  if (superelement && actuator_open_circuit) {
    throw InputError(s, "actuator_open_circuit", "stacks driven by the amplifier with a super element (its coupling is not modelled)",
                     "open-circuit stacks");
  }
}

struct VirtualBench::State {
  UnitTruth unit;
  BenchOptions options;
  std::shared_ptr<const detail::SuperElementMechanics> mechanics;  // super-element bench only
  apa::TwoDofParams params;                                        // 2-DoF bench: the unit's, m = suspended mass
  detail::Electrics electrics;
  double ts = 0.0;
  std::size_t whole_delay = 0;  // samples in the ring buffer
  double fraction = 0.0;  // fraction of a sample, in the discretization
  // Instruments.
  double dac_lsb = 0.0, dac_inv = 0.0, dac_code_min = 0.0, dac_code_max = 0.0;
  double adc_lsb = 0.0, adc_inv = 0.0, adc_code_min = 0.0, adc_code_max = 0.0;
  double enc_res = 0.0, enc_inv = 0.0;  // resolution and 1 / resolution (0: no quantization)
  double enc_noise = 0.0, vs_noise = 0.0;
  double ga = 0.0;       // N/V, the actuator sensitivity in use
  bool use_hysteresis = false, use_creep = false;
  // Mass configurations.
  std::vector<Config> configs;
  std::size_t config = 0;
  double load_fraction = 1.0;
  double weight = 0.0;  // N, force of the added mass on the moving mass (negative: down)
  // Signals.
  std::vector<double> ring;  // power-of-two size
  std::size_t ring_mask = 0;
  std::vector<double> z, z_next;  // super-element bench: modal state
  // What changes from one sample to the next, apart from the buffers: run() keeps a local copy in
  // registers while it loops.
  struct Dyn {
    Vec6 x = Vec6::Zero();  // 2-DoF bench state (Va, x, x', xn, V, Vs at the ADC)
    std::size_t ring_pos = 0;
    double out_va = 0.0, out_load = 0.0;  // Va and ka xn at the last sample
    detail::Hysteresis hysteresis;
    detail::Creep creep;
    detail::Xoshiro256 rng;
    std::uint64_t steps = 0;
  };
  Dyn d;

  [[nodiscard]] bool superelement() const { return mechanics != nullptr; }

  Config make_config(double added) const {
    Config c;
    c.added_mass = added;
    const double moving = options.suspended_mass + added;
    if (superelement()) {
      c.plant = detail::superelement_plant(*mechanics, moving, unit.stroke_factor, electrics);
      c.modal = detail::discretize_modal(c.plant, ts, fraction);
      return c;
    }
    apa::TwoDofParams p = params;
    p.m = moving;
    c.plant = detail::two_dof_plant(p, electrics);
    const detail::DiscretePlant dp = detail::discretize(c.plant, ts, fraction);
    static_assert(sizeof(TwoDofCore::phi) / sizeof(Vec6) == 6);
    assert(dp.Phi.rows() == 6);
    for (int j = 0; j < 6; ++j) c.two.phi[static_cast<std::size_t>(j)] = dp.Phi.col(j);
    for (int j = 0; j < 4; ++j) c.two.gamma[static_cast<std::size_t>(j)] = dp.Gamma.col(j);
    // Open-circuit stacks hold their charge, which all but stops their creep under load (charge
    // drive is the classic cure for piezo creep): no load-creep drive then.
    c.two.ka = electrics.actuator_open_circuit ? 0.0 : p.ka;
    return c;
  }

  void rest(std::uint64_t seed) {
    std::fill(ring.begin(), ring.end(), 0.0);
    d.ring_pos = 0;
    d.x.setZero();
    std::fill(z.begin(), z.end(), 0.0);
    std::fill(z_next.begin(), z_next.end(), 0.0);
    d.out_va = d.out_load = 0.0;
    d.hysteresis.reset();
    d.creep.reset();
    config = 0;
    load_fraction = 1.0;
    weight = 0.0;
    d.rng.reseed(seed);
    d.steps = 0;
  }

  // --- The inner loop (VirtualBench::step and run). Everything that changes is in `d`, so that run()
  // can pass a local copy the compiler keeps in registers. ---

  // DAC (a NaN is held at 0 V, the rest limited and quantized), amplifier command clamped to the
  // stack range, delay line: the commands held over the first (early) and the second (late) part
  // of the coming period.
  [[gnu::always_inline]] void command(Dyn& dy, double u, double& early, double& late) noexcept {
    if (!(u == u)) u = 0.0;
    const double uq = quantize(u, dac_lsb, dac_inv, dac_code_min, dac_code_max);
    double vt = options.amplifier_gain * uq;
    vt = vt < options.va_min ? options.va_min : vt;
    vt = vt > options.va_max ? options.va_max : vt;
    dy.ring_pos = (dy.ring_pos + 1) & ring_mask;
    ring[dy.ring_pos] = vt;
    late = ring[(dy.ring_pos - whole_delay) & ring_mask];
    early = ring[(dy.ring_pos - whole_delay - 1) & ring_mask];
  }

  // Hysteresis and creep from the state at the start of the period (held over it): the extra
  // actuator force, N.
  [[gnu::always_inline]] double nonlinear_force(Dyn& dy) const noexcept {
    const double va = dy.out_va;
    const double dh = use_hysteresis ? dy.hysteresis.update(va) : 0.0;
    double force = ga * dh;
    if (use_creep) {
      force += dy.creep.force();
      dy.creep.update(ga * (va + dh), dy.out_load);
    }
    return force;
  }

  // The instruments: noise, then quantization.
  [[gnu::always_inline]] BenchSample measure(Dyn& dy, double de, double vs) const noexcept {
    BenchSample out;
    double n_de = 0.0, n_vs = 0.0;
    dy.rng.normal_pair(n_de, n_vs);
    de += enc_noise * n_de;
    // Beyond 2^51 counts (5.6e6 m at 2.5 nm) the rounding would not hold: the reading saturates there.
    double counts = de * enc_inv;
    counts = counts < -0x1p51 ? -0x1p51 : counts;
    counts = counts > 0x1p51 ? 0x1p51 : counts;
    out.de = enc_inv > 0.0 ? round_nearest(counts) * enc_res : de;
    vs += vs_noise * n_vs;
    out.vs = quantize(vs, adc_lsb, adc_inv, adc_code_min, adc_code_max);
    out.va = dy.out_va;
    ++dy.steps;
    return out;
  }

  [[gnu::always_inline]] BenchSample step_two_dof(Dyn& dy, double u) noexcept {
    double early = 0.0, late = 0.0;
    command(dy, u, early, late);
    const double force = nonlinear_force(dy);
    const double mass_force = weight * load_fraction;
    const TwoDofCore& k = configs[config].two;
    const Vec6 x0 = dy.x;
    // Summed as a tree: each step waits for the previous state, so latency counts too.
    const Vec6 inputs = (k.gamma[0] * early + k.gamma[1] * late) + (k.gamma[2] * force + k.gamma[3] * mass_force);
    dy.x = ((k.phi[0] * x0(0) + k.phi[1] * x0(1)) + (k.phi[2] * x0(2) + k.phi[3] * x0(3))) +
           ((k.phi[4] * x0(4) + k.phi[5] * x0(5)) + inputs);
    dy.out_va = dy.x(0);
    dy.out_load = k.ka * dy.x(3);
    return measure(dy, dy.x(1), dy.x(5));
  }

  BenchSample step_modal(Dyn& dy, double u) noexcept {
    double early = 0.0, late = 0.0;
    command(dy, u, early, late);
    const double force = nonlinear_force(dy);
    const double mass_force = weight * load_fraction;
    const detail::ModalPlant& m = configs[config].modal;
    const double in[4] = {early, late, force, mass_force};
    const auto n = static_cast<int>(z.size());
    const double* g = m.Gamma.data();  // column-major n x 4
    const double* zc = z.data();
    double* zn = z_next.data();
    for (int i = 0; i < m.real_blocks; ++i) zn[i] = m.a[static_cast<std::size_t>(i)] * zc[i];
    for (int j = 0; j < m.complex_blocks; ++j) {
      const int i = m.real_blocks + 2 * j;
      const double a = m.a[static_cast<std::size_t>(m.real_blocks + j)];
      const double b = m.b[static_cast<std::size_t>(m.real_blocks + j)];
      zn[i] = a * zc[i] + b * zc[i + 1];
      zn[i + 1] = -b * zc[i] + a * zc[i + 1];
    }
    for (int col = 0; col < 4; ++col) {
      const double v = in[col];
      const double* gc = g + static_cast<std::ptrdiff_t>(col) * n;
      for (int i = 0; i < n; ++i) zn[i] += gc[i] * v;
    }
    std::swap(z, z_next);
    double y[3] = {0.0, 0.0, 0.0};
    const double* cm = m.C.data();  // column-major 4 x n
    const double* zz = z.data();
    for (int i = 0; i < n; ++i) {
      const double* ci = cm + static_cast<std::ptrdiff_t>(4) * i;
      y[0] += ci[detail::kOutVa] * zz[i];
      y[1] += ci[detail::kOutDe] * zz[i];
      y[2] += ci[detail::kOutVs] * zz[i];
    }
    const double* dm = m.D.data();  // column-major 4 x 3
    const double held[3] = {late, force, mass_force};
    for (int col = 0; col < 3; ++col) {
      y[0] += dm[4 * col + detail::kOutVa] * held[col];
      y[1] += dm[4 * col + detail::kOutDe] * held[col];
      y[2] += dm[4 * col + detail::kOutVs] * held[col];
    }
    dy.out_va = y[0];
    dy.out_load = 0.0;
    return measure(dy, y[1], y[2]);
  }

  // Round to nearest with a fixed number of operations (no division, no library call).
  static double round_nearest(double v) noexcept {
    constexpr double kMagic = 6755399441055744.0;  // 1.5 * 2^52: valid for |v| < 2^51
    return (v + kMagic) - kMagic;
  }
  static double quantize(double v, double lsb, double inv_lsb, double code_min, double code_max) noexcept {
    double code = round_nearest(v * inv_lsb);
    code = code < code_min ? code_min : code;
    code = code > code_max ? code_max : code;
    return code * lsb;
  }
};

VirtualBench::VirtualBench(const UnitTruth& unit, const BenchOptions& options, std::uint64_t seed)
    : state_(std::make_unique<State>()) {
  unit.validate();
  options.validate();
  State& s = *state_;
  s.unit = unit;
  s.options = options;
  s.ts = 1.0 / options.sample_rate;
  const double line = std::max(options.delay - 0.5 * s.ts, 0.0) / s.ts;
  const double whole = std::floor(line + 1e-9);
  s.whole_delay = static_cast<std::size_t>(whole);
  s.fraction = line - whole;
  if (s.fraction < 1e-9) s.fraction = 0.0;
  std::size_t size = 2;
  while (size < s.whole_delay + 2) size *= 2;
  s.ring.assign(size, 0.0);
  s.ring_mask = size - 1;

  s.dac_lsb = 2.0 * options.dac_range / std::ldexp(1.0, options.dac_bits);
  s.dac_inv = 1.0 / s.dac_lsb;
  s.dac_code_max = std::ldexp(1.0, options.dac_bits - 1) - 1.0;
  s.dac_code_min = -std::ldexp(1.0, options.dac_bits - 1);
  s.adc_lsb = 2.0 * options.adc_range / std::ldexp(1.0, options.adc_bits);
  s.adc_inv = 1.0 / s.adc_lsb;
  s.adc_code_max = std::ldexp(1.0, options.adc_bits - 1) - 1.0;
  s.adc_code_min = -std::ldexp(1.0, options.adc_bits - 1);
  s.enc_res = options.encoder_resolution;
  s.enc_inv = options.encoder_resolution > 0.0 ? 1.0 / options.encoder_resolution : 0.0;
  s.enc_noise = options.noise ? options.encoder_noise : 0.0;
  s.vs_noise = options.noise ? options.vs_noise : 0.0;

  s.electrics.amplifier_bandwidth = kTwoPi * options.amplifier_bandwidth_Hz;
  s.electrics.hpf_resistance = options.sensor_shunt_resistance();
  s.electrics.actuator_open_circuit = options.actuator_open_circuit;
  s.electrics.capacitance_sensor = unit.capacitance_sensor;
  s.electrics.capacitance_actuator = unit.capacitance_actuator;
  s.electrics.ground_resistance = options.nonminimum_phase_zero ? options.ground_resistance : 0.0;
  s.electrics.adc_bandwidth = kTwoPi * options.adc_bandwidth_Hz;

  s.params = unit.model;
  s.params.m = options.suspended_mass;
  if (options.superelement) {
    s.mechanics = std::make_shared<const detail::SuperElementMechanics>(detail::load_superelement(*options.superelement));
    s.ga = s.mechanics->spec.ga * unit.stroke_factor;
  } else {
    s.ga = s.params.ga;
  }
  const bool own_operators = !unit.hysteresis_thresholds.empty() && options.hysteresis_law == HysteresisLaw::kPrandtlIshlinskii;
  s.use_hysteresis = options.hysteresis && (own_operators ? true : unit.hysteresis_scale > 0.0);
  s.use_creep = options.creep && (unit.creep_coefficient > 0.0 || unit.load_creep_coefficient > 0.0);
  switch (options.hysteresis_law) {
    case HysteresisLaw::kBoucWen: s.d.hysteresis = detail::BoucWenHysteresis::bench_default(unit.hysteresis_scale); break;
    case HysteresisLaw::kBoucWenAsymmetric:
      s.d.hysteresis = detail::Hysteresis(detail::BoucWenHysteresis::bench_default(unit.hysteresis_scale), kAsymmetricQuadratic * unit.hysteresis_scale);
      break;
    case HysteresisLaw::kPrandtlIshlinskii:
      s.d.hysteresis = own_operators ? detail::PlayHysteresis::from(unit.hysteresis_thresholds, unit.hysteresis_weights)
                                     : detail::PlayHysteresis::bench_default(unit.hysteresis_scale);
      break;
  }
  // The super element has no stack extension to drive the load creep: voltage creep only there.
  s.d.creep = detail::Creep(unit.creep_coefficient, s.superelement() ? 0.0 : unit.load_creep_coefficient, s.ts);

  s.configs.reserve(kMaxConfigs);
  s.configs.push_back(s.make_config(0.0));
  if (options.added_mass > 0.0) s.configs.push_back(s.make_config(options.added_mass));
  if (s.superelement()) {
    const auto n = static_cast<std::size_t>(s.configs.front().plant.states());
    s.z.assign(n, 0.0);
    s.z_next.assign(n, 0.0);
  }
  s.rest(seed);
}

VirtualBench::~VirtualBench() = default;
VirtualBench::VirtualBench(VirtualBench&&) noexcept = default;
VirtualBench& VirtualBench::operator=(VirtualBench&&) noexcept = default;

BenchSample VirtualBench::step(double u) noexcept {
  State& s = *state_;
  return s.mechanics == nullptr ? s.step_two_dof(s.d, u) : s.step_modal(s.d, u);
}

void VirtualBench::run(std::span<const double> u, std::span<BenchSample> out) noexcept {
  State& s = *state_;
  const std::size_t n = std::min(u.size(), out.size());
  if (s.mechanics != nullptr) {
    for (std::size_t k = 0; k < n; ++k) out[k] = s.step_modal(s.d, u[k]);
    return;
  }
  State::Dyn local = s.d;  // a copy whose address does not escape: it can live in registers
  for (std::size_t k = 0; k < n; ++k) out[k] = s.step_two_dof(local, u[k]);
  s.d = local;
}

BenchRun VirtualBench::run(std::span<const double> u) {
  std::vector<BenchSample> out(u.size());
  run(u, out);
  const auto n = static_cast<Eigen::Index>(u.size());
  BenchRun r{Eigen::VectorXd(n), Eigen::VectorXd(n), Eigen::VectorXd(n)};
  for (Eigen::Index k = 0; k < n; ++k) {
    const BenchSample& b = out[static_cast<std::size_t>(k)];
    r.de(k) = b.de;
    r.vs(k) = b.vs;
    r.va(k) = b.va;
  }
  return r;
}

void VirtualBench::set_added_mass(double kg) noexcept {
  State& s = *state_;
  if (!(std::isfinite(kg) && kg >= 0.0)) return;
  for (std::size_t i = 0; i < s.configs.size(); ++i) {
    if (std::abs(s.configs[i].added_mass - kg) <= 1e-12 * std::max(1.0, kg)) {
      s.config = i;
      s.weight = -kg * s.options.gravity;
      return;
    }
  }
  try {
    Config c = s.make_config(kg);
    // Keep 0 and options.added_mass (the first two); reuse a free slot or a third one not in use.
    std::size_t slot = s.configs.size();
    if (slot >= kMaxConfigs) slot = s.config == kMaxConfigs - 1 ? kMaxConfigs - 2 : kMaxConfigs - 1;
    if (slot == s.configs.size()) {
      s.configs.push_back(std::move(c));
    } else {
      s.configs[slot] = std::move(c);
    }
    s.config = slot;
    s.weight = -kg * s.options.gravity;
  } catch (...) {
    // Left unchanged: added_mass() still reports the mass in use.
  }
}

void VirtualBench::set_load_fraction(double fraction) noexcept {
  if (!(fraction == fraction)) return;
  state_->load_fraction = std::clamp(fraction, 0.0, 1.0);
}

double VirtualBench::added_mass() const { return state_->configs[state_->config].added_mass; }

void VirtualBench::reset(std::uint64_t seed) { state_->rest(seed); }

lti::StateSpace VirtualBench::linear_model() const {
  const State& s = *state_;
  const ContinuousPlant& p = s.configs[s.config].plant;
  const lti::Index n = p.states();
  lti::Matrix c(2, n), d(2, 1);
  c.row(0) = p.C.row(detail::kOutDe);
  c.row(1) = p.C.row(detail::kOutVs);
  d(0, 0) = p.D(detail::kOutDe, detail::kInVa) * s.options.amplifier_gain;
  d(1, 0) = p.D(detail::kOutVs, detail::kInVa) * s.options.amplifier_gain;
  lti::StateSpace sys(p.A, p.B.col(detail::kInVa) * s.options.amplifier_gain, c, d);
  sys.input_delay = lti::Vector::Constant(1, effective_delay());
  return sys;
}

double VirtualBench::effective_delay() const { return std::max(state_->options.delay, 0.5 * state_->ts); }
std::string VirtualBench::model_name() const { return state_->superelement() ? "superelement" : "2dof"; }
double VirtualBench::sample_rate() const { return state_->options.sample_rate; }
double VirtualBench::time() const { return static_cast<double>(state_->d.steps) * state_->ts; }
const UnitTruth& VirtualBench::unit() const { return state_->unit; }
const BenchOptions& VirtualBench::options() const { return state_->options; }

}  // namespace piezobench::bench
