#include "nonlinear.hpp"

#include <cmath>

namespace piezobench::bench::detail {

PlayHysteresis PlayHysteresis::bench_default(double scale) {
  std::array<double, kOperators> r{};
  std::array<double, kOperators> w{};
  for (int i = 0; i < kOperators; ++i) {
    r[static_cast<std::size_t>(i)] = 10.0 + 10.0 * i;
    w[static_cast<std::size_t>(i)] = 0.163 * scale;
  }
  return {r, w};
}

PlayHysteresis PlayHysteresis::from(const std::vector<double>& thresholds, const std::vector<double>& weights) {
  std::array<double, kOperators> r{};
  std::array<double, kOperators> w{};
  double last = 1.0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    // Unused operators: weight 0 (their threshold, above the last one, never matters).
    last = i < thresholds.size() ? thresholds[i] : 2.0 * last;
    r[i] = last;
    w[i] = i < weights.size() ? weights[i] : 0.0;
  }
  return {r, w};
}

PlayHysteresis::PlayHysteresis(const std::array<double, kOperators>& thresholds,
                               const std::array<double, kOperators>& weights)
    : thresholds_(Eigen::Map<const Array>(thresholds.data())), weights_(Eigen::Map<const Array>(weights.data())) {}

BoucWenHysteresis BoucWenHysteresis::bench_default(double scale) { return {1.0 * scale, 0.02}; }

BoucWenHysteresis::BoucWenHysteresis(double a, double beta) : a_(a), beta_(beta), h_max_(beta > 0.0 ? a / (2.0 * beta) : 0.0) {}

Creep::Creep(double voltage_per_decade, double load_per_decade, double sample_time) {
  for (int i = 0; i < kStates; ++i) {
    alpha_(i) = -std::expm1(-kDecimation * sample_time / kTimeConstants[static_cast<std::size_t>(i)]);
    voltage_(i) = voltage_per_decade;
    load_(i) = load_per_decade;
  }
}

}  // namespace piezobench::bench::detail
