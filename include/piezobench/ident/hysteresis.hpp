#pragma once
// Hysteresis and creep of a piezoelectric actuator from a record of its stack voltage Va and its
// displacement d_e: a Prandtl-Ishlinskii (PI) operator with a Prony-series creep, identified by
// sign-constrained linear least squares (core/nnls.hpp), and its exact inverse.
//
// The PI operator (M. Brokate and J. Sprekels, "Hysteresis and Phase Transitions", Springer 1996;
// K. Kuhnen, "Modeling, identification and compensation of complex hysteretic nonlinearities: a
// modified Prandtl-Ishlinskii approach", Eur. J. Control 9(4), 2003):
//     H[v](t) = w_0 v(t) + sum_{i=1..n} w_i P_{r_i}[v](t),
//     P_r[v](t) = min(max(P_r[v](t-), v(t) - r), v(t) + r),  0 < r_1 < ... < r_n,
// every play operator starting at 0 with the actuator at rest. It is strictly increasing (and so
// invertible) when w_0 > 0 and every partial sum w_0 + w_1 + ... + w_i > 0 (w_i >= 0 suffices).
// Its inverse is again a PI operator (Kuhnen 2003, eq. 10): thresholds r'_i = sum_{j<=i} w_j (r_i - r_j),
// weights w'_0 = 1 / w_0 and w'_i = -w_i / ((w_0 + ... + w_i)(w_0 + ... + w_{i-1})), starting at 0
// too, so H^-1[H[v]] = v exactly, sample by sample (the play operators are rate-independent and a
// sampled signal is the piecewise linear one through its samples).
//
// The actuator model (units: V in, m out):
//     d_e = offset + gain (H[Va] + sum_j c_j F_j[Va]),   w_0 = 1 (H in "effective volts"),
// F_j the first-order creep states of time constants tau_j (F_j[k+1] = F_j[k] + (1 - exp(-T/tau_j))
// (Va[k] - F_j[k]), from 0: strictly causal, so a feedforward can cancel them exactly). The
// identification solves one linear least-squares problem in (w_0, w_i, c_j, offset) with
// w_0, w_i, c_j >= 0 (an increasing, invertible operator and a creep that grows) after taking the
// sign of the displacement's slope (the APA shortens with voltage: gain < 0).
//
// Loops asymmetric about their centre (which a PI operator cannot draw) show as a residual that
// stays large as operators are added: the fit reports it and its verdict says so.
#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "piezobench/core/fields.hpp"
#include "piezobench/core/fit_quality.hpp"

namespace piezobench::ident {

// H[v] = linear_weight v + sum_i weights[i] P_{thresholds[i]}[v].
struct PrandtlIshlinskii {
  double linear_weight = 1.0;     // w_0 (output unit per input unit)
  std::vector<double> thresholds; // r_i, strictly increasing, > 0 (input unit)
  std::vector<double> weights;    // w_i (output unit per input unit), same size
  // InputError (source `source`, default "Prandtl-Ishlinskii operator") naming the field: finite
  // values, equal sizes, thresholds > 0 and strictly increasing, an invertible operator (w_0 > 0,
  // partial sums > 0).
  void validate(const std::string& source = "") const;
  // Smallest partial sum w_0 + ... + w_i (the smallest slope of any branch); > 0: invertible.
  [[nodiscard]] double min_slope() const;
};

// The exact inverse (see the file comment). Validates (InputError).
PrandtlIshlinskii inverse(const PrandtlIshlinskii& h);

// A PI operator running sample by sample: step(v) advances every play operator to v and returns
// H[v]. No allocation after construction.
class PrandtlIshlinskiiOperator {
 public:
  PrandtlIshlinskiiOperator() = default;
  explicit PrandtlIshlinskiiOperator(PrandtlIshlinskii h);  // validates; at rest
  double step(double v) noexcept {                          // v: input unit; returns the output unit
    double y = h_.linear_weight * v;                        // output unit
    const std::size_t n = state_.size();
    for (std::size_t i = 0; i < n; ++i) {
      const double r = h_.thresholds[i];  // input unit
      double p = state_[i];
      p = p < v - r ? v - r : p;
      p = p > v + r ? v + r : p;
      state_[i] = p;
      y += h_.weights[i] * p;
    }
    return y;
  }
  void reset() noexcept;
  [[nodiscard]] const PrandtlIshlinskii& model() const noexcept { return h_; }
  [[nodiscard]] const std::vector<double>& state() const noexcept { return state_; }

 private:
  PrandtlIshlinskii h_;
  std::vector<double> state_;  // input unit: the play operators' outputs
};

// H[v] for a whole record, from rest.
std::vector<double> evaluate(const PrandtlIshlinskii& h, std::span<const double> v);
// The play operators' outputs P_{r_i}[v] from rest: v.size() x thresholds.size().
Eigen::MatrixXd play_outputs(std::span<const double> v, std::span<const double> thresholds);
// The creep states F_j[v] (see the file comment) from rest: v.size() x time_constants.size().
// sample_rate: Hz.
Eigen::MatrixXd creep_states(std::span<const double> v, std::span<const double> time_constants, double sample_rate);

// The static output nonlinearity of Kuhnen's modified PI operator (Kuhnen 2003, section 3): a
// superposition of one-sided dead-zone operators, S(z) = sum_j s_j D_{d_j}(z) with
// D_d(z) = max(z - d, 0) (d > 0), z (d = 0), min(z - d, 0) (d < 0), which draws loops asymmetric
// about their centre (S[H[v]]: the ascending and descending branches bent differently). A
// superposition of dead zones is a continuous piecewise-linear function; it is stored as its knots
// (x_k, y_k) and end slopes, and is invertible when every piece rises. Its inverse is again one
// (knots swapped, slopes inverted): exact, analytic. Empty knots: the identity.
struct DeadZoneSuperposition {
  std::vector<double> x;      // knots (input unit), strictly increasing
  std::vector<double> y;      // S(x_k) (output unit), strictly increasing
  double slope_below = 1.0;   // output unit per input unit, slope left of x.front(), > 0
  double slope_above = 1.0;   // output unit per input unit, slope right of x.back(), > 0
  [[nodiscard]] bool identity() const noexcept { return x.empty(); }
  // InputError (source `source`, default "dead-zone superposition") naming the field.
  void validate(const std::string& source = "") const;
  // S(z); no allocation (a linear search over the knots).
  [[nodiscard]] double operator()(double z) const noexcept {
    const std::size_t n = x.size();
    if (n == 0) return z;
    if (z <= x[0]) return y[0] + slope_below * (z - x[0]);
    if (z >= x[n - 1]) return y[n - 1] + slope_above * (z - x[n - 1]);
    std::size_t k = 1;
    while (x[k] < z) ++k;
    return y[k - 1] + (y[k] - y[k - 1]) * (z - x[k - 1]) / (x[k] - x[k - 1]);
  }
};
// The exact inverse (validates: InputError).
DeadZoneSuperposition inverse(const DeadZoneSuperposition& s);

// An identified actuator: d_e = offset + gain S(H[Va] + sum_j c_j F_j[Va]) (S the identity for the
// plain PI model, a dead-zone superposition for Kuhnen's modified PI).
struct HysteresisModel {
  PrandtlIshlinskii hysteresis;                 // V -> effective V, linear_weight 1
  DeadZoneSuperposition output;                 // effective V -> effective V (empty: identity)
  std::vector<double> creep_time_constants;     // tau_j, s
  std::vector<double> creep_coefficients;       // c_j (relative to the effective voltage), >= 0
  double gain = 0.0;                            // m per effective V (< 0 for the APA: it shortens)
  double offset = 0.0;                          // m, d_e at rest
  // The line the compensated actuator follows: effective voltage = reference_slope c +
  // reference_intercept for a linear command c (V), the best straight line of the identification
  // record's effective voltage against Va. With the inverse feedforward, d_e = offset + gain
  // (reference_slope c + reference_intercept): the stroke the record had, without its loop.
  double reference_slope = 1.0;
  double reference_intercept = 0.0;             // V
  double input_min = 0.0, input_max = 0.0;      // V, range of Va in the identification record
  // InputError (source `source`, default "hysteresis model") naming the field.
  void validate(const std::string& source = "") const;
  // d_e (m) for the stack voltage v (V) sampled at sample_rate (Hz; used by the creep), from rest.
  [[nodiscard]] std::vector<double> predict(std::span<const double> v, double sample_rate) const;
};

struct HysteresisFitOptions {
  int operators = 10;                         // play operators n, 1..200
  double threshold_range = 0.0;               // V, R: thresholds (i - 1/2) R / n, i = 1..n; 0 = half
                                              // the range of Va (a larger threshold never turns)
  std::vector<double> creep_time_constants;   // s, > 0; empty: no creep states
  // V: the thresholds themselves (> 0, strictly increasing, at most 200); when given they replace
  // `operators` and `threshold_range` (e.g. a twin's i A / 8 grid for the virtual bench's 8 operators).
  std::vector<double> thresholds;
  // Kuhnen's modified PI (asymmetric loops): > 0 identifies S too, with this many dead zones on
  // each side of the displacement's centre (thresholds (j/(k+1)) of its half range, weights >= 0:
  // S saturates towards both ends). The fit is then Kuhnen's linear one in (H, S^-1): Va = S^-1[d]
  // - sum w_i P_i[Va] - creep - b by sign-constrained least squares; its residual is d_e's. 0 (default):
  // the plain PI model. 0..50.
  int dead_zones = 0;
  double max_relative_residual = 0.02;        // the verdict: rms residual / stroke above it is poor
  void validate() const;                      // InputError (source "hysteresis fit options")
};

struct HysteresisFit {
  HysteresisModel model;
  double rms_residual = 0.0;        // m, rms of d_e - model
  double relative_residual = 0.0;   // rms_residual / (max d_e - min d_e)
  double stroke = 0.0;              // m, max d_e - min d_e
  std::size_t samples = 0;
  core::FitQuality quality;         // poor when relative_residual > max_relative_residual
};

// Identifies the model from Va (V) and d_e (m) sampled at sample_rate (Hz), the record starting at
// rest (Va = 0 and no history: the play operators' initial state). InputError for mismatched or
// too short (< 10 samples) records, non-finite samples, or a Va that does not move; NumericalError
// when the least-squares problem gives no invertible operator (d_e does not follow Va).
HysteresisFit fit_hysteresis(std::span<const double> va, std::span<const double> de, double sample_rate,
                             const HysteresisFitOptions& options = {});

// Creep of a step record (the stiffness test: the added weight in, d_e out; or a voltage step):
//     y = offset + gain (x + sum_j c_j F_j[x]),  c_j >= 0,
// with the creep states of HysteresisModel. creep_per_decade is the mean of c_j when the time
// constants are a decade apart (a Prony series of equal coefficients one decade apart grows by
// about that coefficient per decade of time between the first and the last time constant).
struct CreepFit {
  std::vector<double> time_constants;  // s
  std::vector<double> coefficients;    // relative, c_j
  double gain = 0.0;                   // output per input unit (instantaneous)
  double offset = 0.0;                 // output unit
  double creep_per_decade = 0.0;       // mean c_j (relative)
  double rms_residual = 0.0;           // output unit
  double relative_residual = 0.0;      // rms / (max y - min y)
  core::FitQuality quality;            // poor when relative_residual > max_relative_residual
};
// time_constants empty: 1, 10, 100 s up to half the record's duration (at least one). InputError
// as fit_hysteresis; NumericalError when the output does not follow the input.
// sample_rate: Hz.
CreepFit fit_creep(std::span<const double> input, std::span<const double> output, double sample_rate,
                   std::vector<double> time_constants = {}, double max_relative_residual = 0.05);

// How straight a response is against its command: the best straight line (least squares) of
// `output` against `command`, the hysteresis width (peak-to-peak deviation of the output from that
// line over the stroke: for a loop symmetric about the line, its full width at the centre) and the
// rms deviation. `reference` (optional): rms of output - (reference_slope command + reference_intercept).
struct LoopMetrics {
  // slope: output unit per command unit; intercept: output unit.
  double slope = 0.0, intercept = 0.0;  // output = slope command + intercept (best line)
  double stroke = 0.0;                  // output unit, max - min of the output
  double width = 0.0;                   // ratio, (max - min of output - line) / stroke
  double rms_deviation = 0.0;           // rms of output - line (output unit)
  // |a2| / stroke, a2 the x^2 coefficient of the least-squares cubic of the output in
  // x = (command - its mid-range) / its half-range: 0 for a loop point-symmetric about its centre
  // (what a PI operator draws for a symmetric command, over whole periods), the height of the
  // loop's bend otherwise (Kuhnen's modified PI's case).
  double asymmetry = 0.0;
};
// InputError for mismatched sizes, fewer than 2 samples, or a command that does not move.
LoopMetrics loop_metrics(std::span<const double> command, std::span<const double> output);

constexpr auto describe(core::Type<PrandtlIshlinskii>) {
  using S = PrandtlIshlinskii;
  using namespace core::shown;
  return core::fields<S>("PrandtlIshlinskii", "a Prandtl-Ishlinskii operator",
      core::field("linear_weight", &S::linear_weight, kNone, "w_0, output unit per input unit"),
      core::field("thresholds", &S::thresholds, kNone, "r_i, input unit, strictly increasing"),
      core::field("weights", &S::weights, kNone, "w_i, output unit per input unit"));
}

constexpr auto describe(core::Type<DeadZoneSuperposition>) {
  using S = DeadZoneSuperposition;
  using namespace core::shown;
  return core::fields<S>("DeadZoneSuperposition", "the output map of Kuhnen's modified PI (empty knots: the identity)",
      core::field("x", &S::x, kNone, "knots, input unit"),
      core::field("y", &S::y, kNone, "S(x_k), output unit"),
      core::field("slope_below", &S::slope_below, kRatio, "slope left of the first knot"),
      core::field("slope_above", &S::slope_above, kRatio, "slope right of the last knot"));
}

constexpr auto describe(core::Type<HysteresisModel>) {
  using S = HysteresisModel;
  using namespace core::shown;
  return core::fields<S>("HysteresisModel", "d_e = offset + gain S(H[Va] + sum_j c_j F_j[Va])",
      core::field("hysteresis", &S::hysteresis, kNone, "the PI operator, V -> effective V"),
      core::field("output", &S::output, kNone, "the dead-zone output map (identity for the plain PI)"),
      core::field("creep_time_constants", &S::creep_time_constants, kSecond, "tau_j"),
      core::field("creep_coefficients", &S::creep_coefficients, kRatio, "c_j, relative to the effective voltage"),
      core::field("gain", &S::gain, kMetrePerVoltAsUmPerV, "m per effective V (< 0: the APA shortens)"),
      core::field("offset", &S::offset, kMetreAsUm, "d_e at rest"),
      core::field("reference_slope", &S::reference_slope, kRatio, "effective voltage per command volt of the compensated line"),
      core::field("reference_intercept", &S::reference_intercept, kVolt, "effective voltage at zero command"),
      core::field("input_min", &S::input_min, kVolt, "lowest Va of the identification record"),
      core::field("input_max", &S::input_max, kVolt, "highest Va of the identification record"));
}

constexpr auto describe(core::Type<HysteresisFit>) {
  using S = HysteresisFit;
  using namespace core::shown;
  return core::fields<S>("HysteresisFit", "a hysteresis model with how well it fits its record",
      core::field("model", &S::model, kNone, "the identified model"),
      core::field("rms_residual", &S::rms_residual, kMetreAsUm, "rms of d_e - model"),
      core::field("relative_residual", &S::relative_residual, kRatio, "rms_residual / stroke"),
      core::field("stroke", &S::stroke, kMetreAsUm, "max d_e - min d_e"),
      core::field("samples", &S::samples, kNone, "samples fitted"),
      core::field("quality", &S::quality, kNone, "the verdict").key("."));
}

constexpr auto describe(core::Type<CreepFit>) {
  using S = CreepFit;
  using namespace core::shown;
  return core::fields<S>("CreepFit", "a Prony-series creep y = offset + gain (x + sum_j c_j F_j[x])",
      core::field("time_constants", &S::time_constants, kSecond, "tau_j").in_report(),
      core::field("coefficients", &S::coefficients, kRatio, "c_j").in_report(),
      core::field("gain", &S::gain, kNone, "instantaneous gain, output per input unit"),
      core::field("offset", &S::offset, kNone, "output unit"),
      core::field("creep_per_decade", &S::creep_per_decade, kRatio, "mean c_j: relative creep per decade of time").in_report(),
      core::field("rms_residual", &S::rms_residual, kNone, "output unit"),
      core::field("relative_residual", &S::relative_residual, kRatio, "rms / (max y - min y)").in_report(),
      core::field("quality", &S::quality, kNone, "the verdict").key("."));
}

constexpr auto describe(core::Type<LoopMetrics>) {
  using S = LoopMetrics;
  using namespace core::shown;
  return core::fields<S>("LoopMetrics", "how straight a response is against its command (best line, hysteresis width)",
      core::field("slope", &S::slope, kNone, "of the best line, output unit per command unit"),
      core::field("intercept", &S::intercept, kNone, "of the best line, output unit"),
      core::field("stroke", &S::stroke, kNone, "max - min of the output, output unit"),
      core::field("width", &S::width, kRatio, "peak-to-peak deviation of the output from the line / stroke"),
      core::field("rms_deviation", &S::rms_deviation, kNone, "rms of output - line, output unit"),
      core::field("asymmetry", &S::asymmetry, kRatio, "|x^2 coefficient of the cubic fit| / stroke (0: point-symmetric loop)"));
}

}  // namespace piezobench::ident
