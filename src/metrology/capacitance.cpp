#include "piezobench/metrology/capacitance.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "check.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/statistics.hpp"

namespace piezobench::metrology {

void Range::validate(const std::string& source, const std::string& field) const {
  if (std::isnan(min) || std::isnan(max) || min > max) {
    throw InputError(source, field, "a range [min, max] with min <= max", fmt::format("[{}, {}]", format_number(min), format_number(max)));
  }
}

void CapacitanceSpec::validate(const std::string& source) const {
  sensor.validate(source, "sensor");
  actuator.validate(source, "actuator");
}

CapacitanceCheck check_capacitance(double sensor_F, double actuator_F, const CapacitanceSpec& spec,
                                   const std::string& source) {
  spec.validate();
  detail::require_finite_positive(sensor_F, source, "sensor", "F");
  detail::require_finite_positive(actuator_F, source, "actuator", "F");
  CapacitanceCheck c;
  c.sensor = sensor_F;
  c.actuator = actuator_F;
  c.sensor_in_spec = spec.sensor.contains(sensor_F);
  c.actuator_in_spec = spec.actuator.contains(actuator_F);
  auto reason = [](const char* what, double v, const Range& r) {
    return fmt::format("capacitance of the {} {:.3g} uF outside the specification [{:.3g}, {:.3g}] uF", what, v * 1e6,
                       r.min * 1e6, r.max * 1e6);
  };
  if (!c.sensor_in_spec) c.reasons.push_back(reason("sensor stack", sensor_F, spec.sensor));
  if (!c.actuator_in_spec) c.reasons.push_back(reason("actuator stacks", actuator_F, spec.actuator));
  return c;
}

void OutlierOptions::validate() const {
  if (!(std::isfinite(threshold) && threshold > 0.0)) {
    throw InputError("outlier options", "threshold", "a finite value > 0", format_number(threshold));
  }
  if (!(std::isfinite(min_relative_deviation) && min_relative_deviation >= 0.0)) {
    throw InputError("outlier options", "min_relative_deviation", "a finite value >= 0", format_number(min_relative_deviation));
  }
}

using core::median;

OutlierAnalysis robust_outliers(const std::vector<double>& values, const OutlierOptions& options,
                                const std::string& source, const std::string& field) {
  options.validate();
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      throw InputError(source, field, "finite values", fmt::format("{} at index {}", values[i], i));
    }
  }
  OutlierAnalysis a;
  a.robust_z.assign(values.size(), 0.0);
  a.outlier.assign(values.size(), false);
  if (values.empty()) return a;
  a.median = median(values);
  std::vector<double> dev(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) dev[i] = std::abs(values[i] - a.median);
  a.mad = median(dev);
  if (values.size() < 3) return a;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double d = values[i] - a.median;
    if (a.mad > 0.0) {
      a.robust_z[i] = 0.6745 * d / a.mad;
    } else {
      a.robust_z[i] = d == 0.0 ? 0.0 : std::copysign(std::numeric_limits<double>::infinity(), d);
    }
    a.outlier[i] = std::abs(a.robust_z[i]) > options.threshold &&
                   std::abs(d) > options.min_relative_deviation * std::abs(a.median);
  }
  return a;
}

}  // namespace piezobench::metrology
