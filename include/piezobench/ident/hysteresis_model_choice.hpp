#pragma once
// The hysteresis model of an actuator from one record that starts at rest (report section 2.1,
// docs/hysteresis.md): the plain Prandtl-Ishlinskii model (fit_hysteresis) and, when the record's
// steady loop is asymmetric (LoopMetrics::asymmetry above asymmetry_limit), Kuhnen's modified PI
// too (dead_zones per side); the better one is kept: a good verdict where the other's is poor, else
// the smaller relative residual. The loop's figures (width, asymmetry) are those of the steady
// loop, samples [steady_first_sample, steady_first_sample + steady_samples): the ramp from rest and
// back would add the virgin curve. The fits take the whole record (they need its start at rest).
//
// Units: Va in V, d_e in m, sample rate in Hz.
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "piezobench/ident/hysteresis.hpp"

namespace piezobench::ident {

struct HysteresisModelChoiceOptions {
  long steady_first_sample = 0;  // the steady loop's first sample
  long steady_samples = 0;       // its samples; 0: to the end of the record
  double asymmetry_limit = 0.01;  // relative to the stroke: above it the modified PI is fitted too
  int dead_zones = 4;            // per side, of the modified PI (HysteresisFitOptions::dead_zones)
};

struct HysteresisModelChoice {
  HysteresisFit fit;                          // the chosen model's fit (plain or modified PI)
  std::optional<HysteresisFit> alternative;   // the candidate not chosen (only when both were fitted)
  std::string alternative_error;              // the modified PI's NumericalError when it failed, else ""
  double asymmetry = 0.0;                     // ratio: of the record's steady loop, relative to its stroke
  double width = 0.0;                         // ratio: hysteresis width of the steady loop / its stroke
  double model_width = 0.0;                   // ratio: the same for the chosen model's prediction
  std::vector<double> predicted_m;            // m, the chosen model's d_e at every sample of the record
};

// va_V, de_m: the record from rest, sampled at sample_rate_Hz. InputError as fit_hysteresis and
// loop_metrics, or a steady window outside the record; NumericalError when the plain PI cannot be
// fitted (the modified PI's failure is alternative_error).
HysteresisModelChoice identify_hysteresis_model(std::span<const double> va_V, std::span<const double> de_m, double sample_rate_Hz,
                                                const HysteresisModelChoiceOptions& options = {});

}  // namespace piezobench::ident
