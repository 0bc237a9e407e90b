#pragma once
// The tracking experiment (`measure tracking`, `simulate tracking`): how straight the stroke is
// against the command, without and with the inverse hysteresis feedforward
// (control/hysteresis_feedforward.hpp), on any bench (a BenchRunner).
//
// The command c (V at the stacks): a 1 s raised-cosine ramp from 0 V to the offset
// (va_min + va_max) / 2, `periods` periods of a 1 Hz sine of the amplitude, the same number of
// periods of a 1 Hz triangle of the same amplitude, and a 1 s ramp back to 0 V. It runs twice:
//  1. open: Va = c (no compensation);
//  2. compensated: the same command through the runner's LIVE feedforward stage
//     (BenchRunner::open_loop_feedforward: on a real-time backend the loop's own stage,
//     rt::LoopOptions::feedforward, before its clamp and slew limit), the model being the one given
//     or else the one identified from run 1 (ident::fit_hysteresis on its Va, de). It is blended in
//     and out over the two ramps (the stage's weight: the run starts and ends at 0 V); the samples
//     clamped to [va_min, va_max] are counted.
// For each waveform (the last `periods` - 1 periods of it) and run: the hysteresis width (peak-to-peak
// deviation of d_e from its best straight line against c, over the stroke; ident::loop_metrics)
// and the rms tracking error against the target d_ref = offset + gain (reference_slope c +
// reference_intercept), the straight line the model's compensated actuator follows (the same
// target for both runs: without compensation it is about the open loop's own best line, so the
// open run's error is its loop's deviation).
//
// Record channels: t, c (V), Va_open, de_open, Va_ff, de_ff (V, m), sample rate the bench's.
// Settings (besides the common ones): amplitude_V, offset_V, frequency_Hz (1), periods,
// feedforward ("identified" or "given"), fit_relative_residual (identified only), clamped_samples,
// target_slope_m_per_V, target_intercept_m (d_ref),
// and for w in {sine, triangle}: width_open_w, width_ff_w (fractions), rms_open_w_m, rms_ff_w_m,
// stroke_open_w_m.
#include <span>
#include <string>

#include "piezobench/core/fields.hpp"
#include "piezobench/ident/hysteresis.hpp"
#include "piezobench/io/timeseries.hpp"

namespace piezobench::bench {

struct TrackingFigures {
  double width_open = 0.0, width_ff = 0.0;  // ratio, hysteresis width / stroke
  double rms_open = 0.0, rms_ff = 0.0;      // m, rms tracking error
  double stroke_open = 0.0;                 // m
  [[nodiscard]] double width_reduction() const { return width_ff > 0.0 ? width_open / width_ff : 0.0; }
  [[nodiscard]] double rms_reduction() const { return rms_ff > 0.0 ? rms_open / rms_ff : 0.0; }
};

struct TrackingSummary {
  TrackingFigures sine, triangle;
  bool identified = true;            // the model came from the open run
  double fit_relative_residual = 0.0;
  double clamped_samples = 0.0;
};

// The figures of a tracking record (its settings). InputError (source: the record's) when it is
// not one.
TrackingSummary tracking_summary(const io::TimeSeries& record);

// Where a tracking record's figures are read and against which line: the samples [begin, end) of
// each waveform (its last `periods` - 1 periods) and the target d_ref = target_slope c +
// target_intercept.
struct TrackingLayout {
  Eigen::Index sine_begin = 0, sine_end = 0, triangle_begin = 0, triangle_end = 0;
  double target_slope = 0.0;      // m/V
  double target_intercept = 0.0;  // m
  double amplitude = 0.0;         // V
};
// From the record's sample rate and settings ramp_s, periods, frequency_Hz, amplitude_V,
// target_slope_m_per_V, target_intercept_m. InputError (source: the record's) naming a missing
// setting or windows beyond the record.
TrackingLayout tracking_layout(const io::TimeSeries& record);

// The figures of one waveform from the command c (V) and the displacements without and with the
// feedforward (m), sample by sample, against the target line. InputError for mismatched sizes or
// fewer than 2 samples.
TrackingFigures tracking_figures(std::span<const double> c, std::span<const double> de_open, std::span<const double> de_ff,
                                 double target_slope, double target_intercept);

constexpr auto describe(core::Type<TrackingFigures>) {
  using S = TrackingFigures;
  using namespace core::shown;
  return core::fields<S>("TrackingFigures", "one waveform tracked without and with the inverse hysteresis feedforward",
      core::field("width_open", &S::width_open, kRatio, "hysteresis width / stroke without the feedforward"),
      core::field("width_ff", &S::width_ff, kRatio, "the same with it"),
      core::field("rms_open", &S::rms_open, kMetreAsUm, "rms tracking error without"),
      core::field("rms_ff", &S::rms_ff, kMetreAsUm, "rms tracking error with"),
      core::field("stroke_open", &S::stroke_open, kMetreAsUm, "stroke without"));
}

constexpr auto describe(core::Type<TrackingSummary>) {
  using S = TrackingSummary;
  using namespace core::shown;
  return core::fields<S>("TrackingSummary", "the figures of a tracking record (`measure tracking`, `simulate tracking`)",
      core::field("sine", &S::sine, kNone, "the 1 Hz sine"),
      core::field("triangle", &S::triangle, kNone, "the 1 Hz triangle"),
      core::field("identified", &S::identified, kNone, "the feedforward's model came from the open run"),
      core::field("fit_relative_residual", &S::fit_relative_residual, kRatio, "the identified model's residual / stroke (identified only)"),
      core::field("clamped_samples", &S::clamped_samples, kNone, "compensated samples clamped to [va_min, va_max]"));
}

}  // namespace piezobench::bench
