// batch_unit: the report's seven APA300ML drawn around Tables 1.1, 1.2 and 3.1.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "flatness.hpp"
#include "random.hpp"
#include "piezobench/bench/virtual_bench.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::bench {

namespace {

// Report Table 1.1 (flatness, um) and Table 1.2 (capacitance, uF), units 1..7.
constexpr std::array<double, 7> kFlatnessUm = {8.9, 3.1, 9.1, 3.0, 1.9, 7.1, 18.7};
constexpr std::array<double, 7> kSensorUf = {5.10, 4.99, 1.72, 4.94, 4.90, 4.99, 4.85};
constexpr std::array<double, 7> kActuatorUf = {10.03, 9.85, 5.18, 9.82, 9.66, 9.91, 9.85};

// Creep of the batch (see docs/virtual-bench.md for how they were chosen: Table 2.1's k1, k2).
constexpr double kVoltageCreep = 0.012;  // per decade
constexpr double kLoadCreep = 0.28;     // per decade

}  // namespace

UnitTruth batch_unit(int id, std::uint64_t seed) {
  if (id < 1 || id > 7) throw InputError("", "unit", "a unit of the batch, 1 to 7", std::to_string(id));
  detail::Xoshiro256 rng(detail::derive_seed(seed, static_cast<std::uint64_t>(id)));
  const auto xi = [&rng] { return std::clamp(rng.normal(), -2.5, 2.5); };
  const auto k = static_cast<std::size_t>(id - 1);

  UnitTruth u;
  u.id = id;
  // Stiffness about +-2 %: the shell and the stacks vary independently, the three stacks together.
  const double stacks = 1.0 + 0.012 * xi();
  u.model.k1 *= 1.0 + 0.01 * xi();
  u.model.ka *= stacks;
  u.model.ke *= stacks;
  u.model.c1 *= 1.0 + 0.05 * xi();
  const double stack_damping = 1.0 + 0.05 * xi();
  u.model.ca *= stack_damping;
  u.model.ce *= stack_damping;
  u.model.ga *= 1.0 + 0.01 * xi();
  u.model.gs *= 1.0 + 0.01 * xi();
  // Capacitance: the report's readings with a little spread of their own.
  u.capacitance_sensor = kSensorUf[k] * 1e-6 * (1.0 + 0.003 * xi());
  u.capacitance_actuator = kActuatorUf[k] * 1e-6 * (1.0 + 0.003 * xi());
  u.hysteresis_scale = 1.0 + 0.05 * xi();
  u.creep_coefficient = kVoltageCreep * (1.0 + 0.1 * xi());
  u.load_creep_coefficient = kLoadCreep * (1.0 + 0.05 * xi());
  u.mode_y_Hz = 280.0 * (1.0 + 0.01 * xi());
  u.mode_x_Hz = 412.0 * (1.0 + 0.01 * xi());
  u.mode_damping = 0.01 * (1.0 + 0.1 * xi());
  u.stroke_factor = 1.0 + 0.01 * xi();
  if (id == 3) {
    u.defective = true;
    u.stroke_factor = 0.6 * (1.0 + 0.01 * xi());
    u.defect = "about half the stack capacitance and a reduced stroke (report section 1.3: returned to the maker)";
  }
  u.model.ga *= u.stroke_factor;

  // Flatness: a random tilt of interface 2 and a warp whose peak-to-valley from the least-squares
  // plane is the unit's Table 1.1 value (with a 3 % spread).
  const double target = kFlatnessUm[k] * 1e-6 * (1.0 + 0.03 * xi());
  u.flatness_tilt_direction = kTwoPi * rng.uniform();
  const double share = 0.3 + 0.6 * rng.uniform();
  const double sign = rng.uniform() < 0.5 ? -1.0 : 1.0;
  const Eigen::Matrix<double, 8, 3> layout = detail::probe_layout();
  const auto flatness = [&layout](const UnitTruth& unit) {
    return detail::plane_flatness(layout.col(0), layout.col(1), detail::probe_heights(unit));
  };
  UnitTruth tilt_only = u;
  tilt_only.flatness_tilt = 1e-4;
  tilt_only.flatness_warp = 0.0;
  UnitTruth warp_only = u;
  warp_only.flatness_tilt = 0.0;
  warp_only.flatness_warp = 1e-6;
  u.flatness_tilt = 1e-4 * share * target / flatness(tilt_only);
  u.flatness_warp = sign * 1e-6 * (1.0 - share) * target / flatness(warp_only);
  const double scale = target / flatness(u);
  u.flatness_tilt = std::atan(std::tan(u.flatness_tilt) * scale);
  u.flatness_warp *= scale;
  return u;
}

}  // namespace piezobench::bench
