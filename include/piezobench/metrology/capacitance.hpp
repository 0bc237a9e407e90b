#pragma once
// Capacitance checks of the piezoelectric stacks (report section 1.2: LCR meter at 1 kHz, the
// sensor stack and the two actuator stacks measured separately; APA 3 reads half the expected
// value), against a specification range and against the rest of the batch.
//
// Batch outliers use the robust ("modified") z-score of B. Iglewicz and D. C. Hoaglin, "How to
// detect and handle outliers", ASQC 1993: z_i = 0.6745 (x_i - median) / MAD, MAD = median |x_i -
// median|; a value is an outlier when |z_i| > threshold (3.5, their recommendation) AND it is
// farther than min_relative_deviation from the median (so that a batch whose units agree to 0.1 %
// does not flag a unit 1 % off). The median and MAD are not moved by the outliers themselves,
// which is why they are used rather than the mean and standard deviation (with 7 units, one unit at
// half the value pulls the mean by 7 % and inflates the standard deviation enough to hide itself).
#include <string>
#include <vector>

#include "piezobench/core/fields.hpp"

namespace piezobench::metrology {

// A closed interval [min, max]; either end may be infinite.
struct Range {
  double min = 0.0;
  double max = 0.0;                                                             // same unit as min
  [[nodiscard]] bool contains(double v) const { return v >= min && v <= max; }  // v: same unit as the range
  // InputError (source, field) unless min <= max and neither is NaN.
  void validate(const std::string& source, const std::string& field) const;
};

struct CapacitanceSpec {
  Range sensor{4.0e-6, 6.0e-6};     // F, the sensor stack
  Range actuator{8.0e-6, 12.0e-6};  // F, the two actuator stacks in parallel
  void validate(const std::string& source = "capacitance spec") const;
};

struct CapacitanceCheck {
  double sensor = 0.0;    // F
  double actuator = 0.0;  // F
  bool sensor_in_spec = false;
  bool actuator_in_spec = false;
  std::vector<std::string> reasons;  // one sentence per failed check, values in uF
  [[nodiscard]] bool ok() const { return sensor_in_spec && actuator_in_spec; }
};

// InputError (source, field "sensor" / "actuator") for a non-finite or non-positive value.
CapacitanceCheck check_capacitance(double sensor_F, double actuator_F, const CapacitanceSpec& spec,
                                   const std::string& source = "");

struct OutlierOptions {
  double threshold = 3.5;                // dimensionless, |modified z| above this ...
  double min_relative_deviation = 0.05;  // ... and |x - median| > this * |median|
  void validate() const;                 // InputError (source "outlier options")
};

struct OutlierAnalysis {
  double median = 0.0;               // same unit as the values
  double mad = 0.0;                  // median absolute deviation (same unit as the values)
  std::vector<double> robust_z;      // 0.6745 (x - median) / MAD (+-inf when MAD = 0 and x != median)
  std::vector<bool> outlier;
};

// Fewer than 3 values: no verdict (every outlier flag false, robust_z 0). InputError (source,
// field) for a non-finite value (its index named).
// values: the caller's unit.
OutlierAnalysis robust_outliers(const std::vector<double>& values, const OutlierOptions& options = {},
                                const std::string& source = "", const std::string& field = "values");

constexpr auto describe(core::Type<OutlierOptions>) {
  using S = OutlierOptions;
  using namespace core::shown;
  return core::fields<S>("OutlierOptions", "the batch's outlier rule",
      core::field("threshold", &S::threshold, kRatio, "|modified z| above this ...").key("robust_z_threshold"),
      core::field("min_relative_deviation", &S::min_relative_deviation, kRatio, "... and |x - median| > this * |median|"));
}

}  // namespace piezobench::metrology
