#pragma once
// Stroke and hysteresis of an actuator from quasi-static voltage/displacement records (report
// section 1.3: slow ramp of the stack voltage Va from -20 V to 150 V read by a low-bandwidth probe;
// section 2.1: 1 Hz sine around 65 V with amplitudes from 4 V to 80 V, displacement d_e).
//
// Stroke: the range of the displacement, max - min of d_e after a centred moving average of
//   `smoothing_s` (so that probe noise does not widen it), with the voltage range that produced it.
//   The slope of the straight line fitted to d_e(Va) is the mean sensitivity. The loop width of the
//   ramp is the largest distance between the rising and the falling branch at the same voltage
//   (branches compared on a grid of 50 voltages inside the covered range, by linear interpolation).
// Hysteresis per amplitude: the loop width at the offset voltage, i.e. the distance between d_e on
//   the rising and on the falling branch when Va crosses the offset (crossings found with a
//   Schmitt trigger at +-amplitude/2 so that noise cannot make extra crossings; d_e linearly
//   interpolated at the crossing; averaged over the periods after the first `skip_periods`),
//   relative to the peak-to-peak displacement of the loop. Only the part of the record from the
//   first to the last maximum of Va is used (within 2 % of the range), so ramps into and out of the
//   sine (the bench ramps from and to 0 V) are left out: from its first maximum on, a hysteretic
//   stack follows its steady loop. Offset and amplitude are read from Va over that part:
//   (max + min)/2 and (max - min)/2.
// Units: V and m (SI); results in the same units.
#include "piezobench/core/fields.hpp"
#include <Eigen/Dense>
#include <string>

namespace piezobench::metrology {

struct StrokeOptions {
  double smoothing_s = 0.02;  // s, moving-average length applied to d_e before its range is taken
  void validate() const;      // InputError (source "stroke options")
};

struct StrokeResult {
  double stroke = 0.0;       // m, max - min of the smoothed d_e (>= 0)
  double va_min = 0.0;       // V, voltage range covered by the record
  double va_max = 0.0;       // V
  double sensitivity = 0.0;  // m/V, slope of the straight line d_e(Va) (negative: the APA shortens)
  double loop_width = 0.0;   // m, largest distance between rising and falling branches
  double noise = 0.0;        // m rms per sample of d_e (noise_from_second_differences, uncertainty_budget.hpp)
  long smoothing_samples = 1;  // samples of the moving average (a count)
};

// va, de: same length (>= 10 samples), finite; fs > 0 Hz. The voltage must span at least 1 V.
// InputError naming `source` and the field ("Va", "de", "sample rate") otherwise.
StrokeResult analyze_stroke(const Eigen::Ref<const Eigen::VectorXd>& va, const Eigen::Ref<const Eigen::VectorXd>& de,
                            double fs, const StrokeOptions& options = {}, const std::string& source = "");

struct HysteresisOptions {
  int skip_periods = 0;  // periods left out after the first maximum, >= 0
  void validate() const;
};

struct HysteresisResult {
  double offset = 0.0;          // V
  double amplitude = 0.0;       // V
  double width = 0.0;           // m, |d_e rising - d_e falling| at the offset (>= 0)
  double loop_stroke = 0.0;     // m, peak-to-peak d_e over the periods used
  double relative_width = 0.0;  // width / loop_stroke
  int periods = 0;              // the fewer of the rising and the falling crossings used
  Eigen::Index first_sample = 0;  // the part of the record used: from the first maximum of Va ...
  Eigen::Index samples = 0;       // ... for this many samples (to the last maximum)
};

// InputError naming `source` and the field for: lengths that differ, non-finite samples, an
// amplitude below 0.1 V, or fewer than one rising and one falling crossing after skip_periods.
HysteresisResult analyze_hysteresis(const Eigen::Ref<const Eigen::VectorXd>& va,
                                    const Eigen::Ref<const Eigen::VectorXd>& de, const HysteresisOptions& options = {},
                                    const std::string& source = "");

constexpr auto describe(core::Type<StrokeResult>) {
  using S = StrokeResult;
  using namespace core::shown;
  return core::fields<S>("StrokeResult", "stroke and sensitivity of a quasi-static record",
      core::field("stroke", &S::stroke, kMetreAsUm, "max - min of the smoothed d_e (results.json: the unit's stroke_um)").part_only(),
      core::field("va_min", &S::va_min, kVolt, "lowest Va of the record"),
      core::field("va_max", &S::va_max, kVolt, "highest Va of the record"),
      core::field("sensitivity", &S::sensitivity, kMetrePerVoltAsUmPerV, "slope of d_e against Va (negative: the APA shortens)"),
      core::field("loop_width", &S::loop_width, kMetreAsUm, "largest distance between the rising and falling branches"),
      core::field("noise", &S::noise, kMetreAsUm, "noise of d_e per sample (second differences)"),
      core::field("smoothing_samples", &S::smoothing_samples, kNone, "samples of the moving average"));
}

constexpr auto describe(core::Type<HysteresisResult>) {
  using S = HysteresisResult;
  using namespace core::shown;
  return core::fields<S>("HysteresisResult", "one hysteresis loop at an amplitude",
      core::field("offset", &S::offset, kVolt, "offset of the sine on Va"),
      core::field("amplitude", &S::amplitude, kVolt, "amplitude of the sine on Va"),
      core::field("width", &S::width, kMetreAsUm, "|d_e rising - d_e falling| at the offset"),
      core::field("loop_stroke", &S::loop_stroke, kMetreAsUm, "peak-to-peak d_e over the periods used"),
      core::field("relative_width", &S::relative_width, kRatio, "width / loop_stroke"),
      core::field("periods", &S::periods, kNone, "the fewer of the rising and falling crossings used"),
      core::field("first_sample", &S::first_sample, kNone, "first sample analysed (the first maximum of Va)").part_only(),
      core::field("samples", &S::samples, kNone, "samples analysed (to the last maximum)").part_only());
}

}  // namespace piezobench::metrology
