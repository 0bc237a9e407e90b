#include "piezobench/ident/hysteresis.hpp"

#include <fmt/format.h>

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/nnls.hpp"

namespace piezobench::ident {

namespace {

void require_finite(double v, const std::string& source, const std::string& field) {
  if (!std::isfinite(v)) throw InputError(source, field, "a finite value", format_number_exact(v));
}

void check_record(std::span<const double> x, std::span<const double> y, const std::string& source, const char* xname,
                  const char* yname) {
  if (x.size() != y.size()) {
    throw InputError(source, yname, fmt::format("{} samples (those of {})", x.size(), xname), std::to_string(y.size()));
  }
  if (x.size() < 10) throw InputError(source, xname, "at least 10 samples", std::to_string(x.size()));
  for (std::size_t k = 0; k < x.size(); ++k) {
    if (!std::isfinite(x[k])) throw InputError(source, xname, "finite samples", fmt::format("{} at sample {}", x[k], k));
    if (!std::isfinite(y[k])) throw InputError(source, yname, "finite samples", fmt::format("{} at sample {}", y[k], k));
  }
}

double range(std::span<const double> x) {
  const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
  return *hi - *lo;
}

Eigen::Map<const Eigen::VectorXd> view(std::span<const double> x) {
  return {x.data(), static_cast<Eigen::Index>(x.size())};
}

// Sign-constrained least squares of `target` on `columns` plus a free constant; the first column
// gets the sign of the target's slope against it. Returns the coefficients of s * target (the last
// one the constant) and s.
struct SignedFit {
  Eigen::VectorXd x;
  double sign = 1.0;
};
SignedFit signed_fit(const Eigen::MatrixXd& columns, std::span<const double> target, const std::string& method) {
  const Eigen::Index n = columns.rows(), m = columns.cols();
  const Eigen::VectorXd y = view(target);
  const Eigen::VectorXd x0 = columns.col(0);
  const double xm = x0.mean(), ym = y.mean();
  const double cov = (x0.array() - xm).matrix().dot((y.array() - ym).matrix());
  if (!(std::abs(cov) > 0.0)) throw NumericalError(method, "the output does not follow the input (no slope)", false);
  SignedFit f;
  f.sign = cov > 0.0 ? 1.0 : -1.0;
  Eigen::MatrixXd a(n, m + 1);
  a.leftCols(m) = columns;
  a.col(m).setOnes();
  std::vector<bool> free(static_cast<std::size_t>(m + 1), false);
  free.back() = true;
  // Columns scaled to unit norm (volts, states and the constant are of different sizes).
  Eigen::VectorXd scale(m + 1);
  for (Eigen::Index j = 0; j <= m; ++j) {
    const double c = a.col(j).norm();
    scale(j) = c > 0.0 ? 1.0 / c : 1.0;
    a.col(j) *= scale(j);
  }
  const NnlsResult r = nnls(a, f.sign * y, free);
  if (!r.converged) throw NumericalError(method, "the constrained least-squares problem did not converge", false);
  f.x = r.x.cwiseProduct(scale);
  return f;
}

std::vector<double> default_thresholds(int n, double range_v) {
  std::vector<double> r(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) r[static_cast<std::size_t>(i)] = (i + 0.5) * range_v / n;
  return r;
}

}  // namespace

// ---- PrandtlIshlinskii ----

void PrandtlIshlinskii::validate(const std::string& source) const {
  const std::string s = source.empty() ? "Prandtl-Ishlinskii operator" : source;
  require_finite(linear_weight, s, "linear_weight");
  if (thresholds.size() != weights.size()) {
    throw InputError(s, "weights", fmt::format("{} weights (one per threshold)", thresholds.size()), std::to_string(weights.size()));
  }
  for (std::size_t i = 0; i < thresholds.size(); ++i) {
    require_finite(thresholds[i], s, fmt::format("thresholds[{}]", i));
    require_finite(weights[i], s, fmt::format("weights[{}]", i));
    if (!(thresholds[i] > (i == 0 ? 0.0 : thresholds[i - 1]))) {
      throw InputError(s, fmt::format("thresholds[{}]", i), "thresholds > 0, strictly increasing",
                       format_number_exact(thresholds[i]));
    }
  }
  if (!(linear_weight > 0.0))
    throw InputError(s, "linear_weight", "a weight > 0 (an invertible operator)", format_number_exact(linear_weight));
  const double slope = min_slope();
  if (!(slope > 0.0)) {
    throw InputError(s, "weights", "partial sums w_0 + ... + w_i > 0 (an invertible operator)",
                     fmt::format("a partial sum {}", format_number_exact(slope)));
  }
}

double PrandtlIshlinskii::min_slope() const {
  double sum = linear_weight, lowest = linear_weight;
  for (double w : weights) {
    sum += w;
    lowest = std::min(lowest, sum);
  }
  return lowest;
}

PrandtlIshlinskii inverse(const PrandtlIshlinskii& h) {
  h.validate();
  const std::size_t n = h.thresholds.size();
  PrandtlIshlinskii g;
  g.linear_weight = 1.0 / h.linear_weight;
  g.thresholds.resize(n);
  g.weights.resize(n);
  double before = h.linear_weight;  // w_0 + ... + w_{i-1}
  for (std::size_t i = 0; i < n; ++i) {
    // r'_i = w_0 r_i + sum_{1<=j<=i} w_j (r_i - r_j)
    double r = h.linear_weight * h.thresholds[i];
    for (std::size_t j = 0; j < i; ++j) r += h.weights[j] * (h.thresholds[i] - h.thresholds[j]);
    g.thresholds[i] = r;
    const double after = before + h.weights[i];
    g.weights[i] = -h.weights[i] / (after * before);
    before = after;
  }
  return g;
}

PrandtlIshlinskiiOperator::PrandtlIshlinskiiOperator(PrandtlIshlinskii h) : h_(std::move(h)) {
  h_.validate();
  state_.assign(h_.thresholds.size(), 0.0);
}

void PrandtlIshlinskiiOperator::reset() noexcept { std::fill(state_.begin(), state_.end(), 0.0); }

std::vector<double> evaluate(const PrandtlIshlinskii& h, std::span<const double> v) {
  PrandtlIshlinskiiOperator op(h);
  std::vector<double> y(v.size());
  for (std::size_t k = 0; k < v.size(); ++k) y[k] = op.step(v[k]);
  return y;
}

Eigen::MatrixXd play_outputs(std::span<const double> v, std::span<const double> thresholds) {
  const auto n = static_cast<Eigen::Index>(v.size());
  const auto m = static_cast<Eigen::Index>(thresholds.size());
  Eigen::MatrixXd p(n, m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const double r = thresholds[static_cast<std::size_t>(i)];
    double s = 0.0;
    for (Eigen::Index k = 0; k < n; ++k) {
      const double x = v[static_cast<std::size_t>(k)];
      s = std::min(std::max(s, x - r), x + r);
      p(k, i) = s;
    }
  }
  return p;
}

Eigen::MatrixXd creep_states(std::span<const double> v, std::span<const double> time_constants, double sample_rate) {
  const auto n = static_cast<Eigen::Index>(v.size());
  const auto m = static_cast<Eigen::Index>(time_constants.size());
  Eigen::MatrixXd f(n, m);
  for (Eigen::Index j = 0; j < m; ++j) {
    const double alpha = -std::expm1(-1.0 / (sample_rate * time_constants[static_cast<std::size_t>(j)]));
    double s = 0.0;
    for (Eigen::Index k = 0; k < n; ++k) {
      f(k, j) = s;  // strictly causal: the state before sample k's input
      s += alpha * (v[static_cast<std::size_t>(k)] - s);
    }
  }
  return f;
}

// ---- HysteresisModel ----

void DeadZoneSuperposition::validate(const std::string& source) const {
  const std::string s = source.empty() ? "dead-zone superposition" : source;
  if (x.size() != y.size()) throw InputError(s, "y", fmt::format("{} values (one per knot)", x.size()), std::to_string(y.size()));
  for (std::size_t k = 0; k < x.size(); ++k) {
    require_finite(x[k], s, fmt::format("x[{}]", k));
    require_finite(y[k], s, fmt::format("y[{}]", k));
    if (k > 0 && !(x[k] > x[k - 1]))
      throw InputError(s, fmt::format("x[{}]", k), "knots strictly increasing", format_number_exact(x[k]));
    if (k > 0 && !(y[k] > y[k - 1])) {
      throw InputError(s, fmt::format("y[{}]", k), "values strictly increasing (an invertible map)",
                       format_number_exact(y[k]));
    }
  }
  for (const auto& [name, v] : {std::pair<const char*, double>{"slope_below", slope_below}, {"slope_above", slope_above}}) {
    require_finite(v, s, name);
    if (!(v > 0.0)) throw InputError(s, name, "a slope > 0 (an invertible map)", format_number_exact(v));
  }
}

DeadZoneSuperposition inverse(const DeadZoneSuperposition& s) {
  s.validate();
  return {s.y, s.x, 1.0 / s.slope_below, 1.0 / s.slope_above};
}

void HysteresisModel::validate(const std::string& source) const {
  const std::string s = source.empty() ? "hysteresis model" : source;
  hysteresis.validate(s);
  output.validate(s + ": output");
  if (hysteresis.linear_weight != 1.0)
    throw InputError(s, "linear_weight", "1 (H in effective volts)", format_number_exact(hysteresis.linear_weight));
  if (creep_time_constants.size() != creep_coefficients.size()) {
    throw InputError(s, "creep_coefficients", fmt::format("{} coefficients (one per time constant)", creep_time_constants.size()),
                     std::to_string(creep_coefficients.size()));
  }
  for (std::size_t j = 0; j < creep_time_constants.size(); ++j) {
    const double tau = creep_time_constants[j], c = creep_coefficients[j];
    if (!(std::isfinite(tau) && tau > 0.0))
      throw InputError(s, fmt::format("creep_time_constants[{}]", j), "a time > 0 s", format_number_exact(tau));
    if (!(std::isfinite(c) && c >= 0.0))
      throw InputError(s, fmt::format("creep_coefficients[{}]", j), "a coefficient >= 0", format_number_exact(c));
  }
  require_finite(gain, s, "gain");
  if (gain == 0.0) throw InputError(s, "gain", "a gain != 0 m/V", "0");
  require_finite(offset, s, "offset");
  require_finite(reference_slope, s, "reference_slope");
  if (!(reference_slope > 0.0))
    throw InputError(s, "reference_slope", "a slope > 0", format_number_exact(reference_slope));
  require_finite(reference_intercept, s, "reference_intercept");
  require_finite(input_min, s, "input_min");
  require_finite(input_max, s, "input_max");
}

std::vector<double> HysteresisModel::predict(std::span<const double> v, double sample_rate) const {
  validate();
  std::vector<double> y = evaluate(hysteresis, v);
  if (!creep_time_constants.empty()) {
    const Eigen::MatrixXd f = creep_states(v, creep_time_constants, sample_rate);
    const Eigen::VectorXd c = view(creep_coefficients);
    const Eigen::VectorXd fc = f * c;
    for (std::size_t k = 0; k < y.size(); ++k) y[k] += fc(static_cast<Eigen::Index>(k));
  }
  for (double& x : y) x = offset + gain * output(x);
  return y;
}

// ---- Identification ----

void HysteresisFitOptions::validate() const {
  const std::string s = "hysteresis fit options";
  if (operators < 1 || operators > 200) throw InputError(s, "operators", "an integer in 1..200", std::to_string(operators));
  if (!(std::isfinite(threshold_range) && threshold_range >= 0.0)) {
    throw InputError(s, "threshold_range", "a range >= 0 V (0: half the range of Va)",
                     format_number_exact(threshold_range));
  }
  for (std::size_t j = 0; j < creep_time_constants.size(); ++j) {
    const double tau = creep_time_constants[j];
    if (!(std::isfinite(tau) && tau > 0.0))
      throw InputError(s, fmt::format("creep_time_constants[{}]", j), "a time > 0 s", format_number_exact(tau));
  }
  if (thresholds.size() > 200) throw InputError(s, "thresholds", "at most 200 thresholds", std::to_string(thresholds.size()));
  for (std::size_t i = 0; i < thresholds.size(); ++i) {
    if (!(std::isfinite(thresholds[i]) && thresholds[i] > (i == 0 ? 0.0 : thresholds[i - 1]))) {
      throw InputError(s, fmt::format("thresholds[{}]", i), "thresholds > 0, strictly increasing",
                       format_number_exact(thresholds[i]));
    }
  }
  if (dead_zones < 0 || dead_zones > 50) throw InputError(s, "dead_zones", "an integer in 0..50", std::to_string(dead_zones));
  if (!(std::isfinite(max_relative_residual) && max_relative_residual > 0.0)) {
    throw InputError(s, "max_relative_residual", "a fraction > 0", format_number_exact(max_relative_residual));
  }
}

namespace {

// Kuhnen's modified PI (HysteresisFitOptions::dead_zones > 0): the linear equation-error fit of
// (H, T = S^-1) on the displacement u = sign d_e - centre, then S = t_0 T^-1(z + b).
void fit_modified(std::span<const double> va, std::span<const double> de, double sample_rate, const HysteresisFitOptions& o,
                  const std::vector<double>& r, HysteresisModel& model) {
  const std::string method = "modified Prandtl-Ishlinskii identification";
  const auto rows = static_cast<Eigen::Index>(va.size());
  const int n = static_cast<int>(r.size()), k = o.dead_zones;
  const auto m = static_cast<Eigen::Index>(o.creep_time_constants.size());
  const Eigen::VectorXd v = view(va), d = view(de);
  const double cov = (v.array() - v.mean()).matrix().dot((d.array() - d.mean()).matrix());
  if (!(std::abs(cov) > 0.0)) throw NumericalError(method, "the output does not follow the input (no slope)", false);
  const double sign = cov > 0.0 ? 1.0 : -1.0;
  const Eigen::VectorXd y = sign * d;
  const double centre = 0.5 * (y.maxCoeff() + y.minCoeff()), half = 0.5 * (y.maxCoeff() - y.minCoeff());
  const Eigen::VectorXd u = y.array() - centre;
  // Dead-zone thresholds of T, sorted: -k..-1 below the centre, 0, 1..k above.
  std::vector<double> e;
  for (int j = -k; j <= k; ++j) e.push_back(half * j / (k + 1));
  const auto nz = static_cast<Eigen::Index>(e.size());
  // Va = T(u) - sum w_i P_i - sum c_j F_j - b; unknowns (t, w, c) >= 0, b free.
  Eigen::MatrixXd a(rows, nz + n + m + 1);
  for (Eigen::Index j = 0; j < nz; ++j) {
    const double ej = e[static_cast<std::size_t>(j)];
    for (Eigen::Index i = 0; i < rows; ++i) {
      a(i, j) = ej > 0.0 ? std::max(u(i) - ej, 0.0) : ej < 0.0 ? std::min(u(i) - ej, 0.0) : u(i);
    }
  }
  a.middleCols(nz, n) = -play_outputs(va, r);
  if (m > 0) a.middleCols(nz + n, m) = -creep_states(va, o.creep_time_constants, sample_rate);
  a.col(a.cols() - 1).setConstant(-1.0);
  std::vector<bool> free(static_cast<std::size_t>(a.cols()), false);
  free.back() = true;
  Eigen::VectorXd scale(a.cols());
  for (Eigen::Index j = 0; j < a.cols(); ++j) {
    const double c = a.col(j).norm();
    scale(j) = c > 0.0 ? 1.0 / c : 1.0;
    a.col(j) *= scale(j);
  }
  const NnlsResult res = nnls(a, v, free);
  if (!res.converged) throw NumericalError(method, "the constrained least-squares problem did not converge", false);
  const Eigen::VectorXd x = res.x.cwiseProduct(scale);
  const double t0 = x(k);
  if (!(t0 > 1e-9 * x.head(nz).cwiseAbs().maxCoeff())) {
    throw NumericalError(method, "the central weight of S^-1 came out 0: the map would not be invertible (d_e does not follow Va?)", true);
  }
  model.hysteresis.linear_weight = 1.0;
  model.hysteresis.thresholds = r;
  model.hysteresis.weights.assign(static_cast<std::size_t>(n), 0.0);
  for (int i = 0; i < n; ++i) model.hysteresis.weights[static_cast<std::size_t>(i)] = x(nz + i);
  model.creep_time_constants = o.creep_time_constants;
  model.creep_coefficients.assign(static_cast<std::size_t>(m), 0.0);
  for (Eigen::Index j = 0; j < m; ++j) model.creep_coefficients[static_cast<std::size_t>(j)] = x(nz + n + j);
  const double b = x(x.size() - 1);
  // T at its knots; S(z) = t0 T^-1(z + b): knots T(e_j) - b -> t0 e_j.
  const auto t_of = [&](double uu) {
    double sum = 0.0;
    for (Eigen::Index j = 0; j < nz; ++j) {
      const double ej = e[static_cast<std::size_t>(j)];
      sum += x(j) * (ej > 0.0 ? std::max(uu - ej, 0.0) : ej < 0.0 ? std::min(uu - ej, 0.0) : uu);
    }
    return sum;
  };
  double below = 0.0, above = 0.0;
  for (Eigen::Index j = 0; j < nz; ++j) {
    const double ej = e[static_cast<std::size_t>(j)];
    if (ej <= 0.0) below += x(j);
    if (ej >= 0.0) above += x(j);
  }
  model.output.x.clear();
  model.output.y.clear();
  for (const double ej : e) {
    model.output.x.push_back(t_of(ej) - b);
    model.output.y.push_back(t0 * ej);
  }
  model.output.slope_below = t0 / below;
  model.output.slope_above = t0 / above;
  model.gain = sign / t0;
  model.offset = sign * centre;
}

// The modified PI fit with its reference line, residual (d_e's, output error) and verdict.
HysteresisFit finish_fit(std::span<const double> va, std::span<const double> de, double sample_rate, const HysteresisFitOptions& o,
                         const std::vector<double>& r) {
  HysteresisFit out;
  HysteresisModel& model = out.model;
  fit_modified(va, de, sample_rate, o, r, model);
  model.input_min = *std::min_element(va.begin(), va.end());
  model.input_max = *std::max_element(va.begin(), va.end());
  model.validate("hysteresis fit");
  // Effective voltage S(H + creep) of the record and its best line against Va.
  const std::vector<double> predicted = model.predict(va, sample_rate);
  std::vector<double> eff(predicted.size());
  for (std::size_t i = 0; i < eff.size(); ++i) eff[i] = (predicted[i] - model.offset) / model.gain;
  const LoopMetrics line = loop_metrics(va, eff);
  model.reference_slope = line.slope;
  model.reference_intercept = line.intercept;
  model.validate("hysteresis fit");
  double sum = 0.0;
  for (std::size_t i = 0; i < de.size(); ++i) sum += (predicted[i] - de[i]) * (predicted[i] - de[i]);
  out.samples = va.size();
  out.stroke = range(de);
  out.rms_residual = std::sqrt(sum / static_cast<double>(de.size()));
  out.relative_residual = out.stroke > 0.0 ? out.rms_residual / out.stroke : 0.0;
  if (!(out.relative_residual <= o.max_relative_residual)) {
    out.quality.add_problem(fmt::format("d_e: rms residual {} % of the stroke (limit {} %)",
                                        format_number(100.0 * out.relative_residual, 3),
                                        format_number(100.0 * o.max_relative_residual, 3)));
    out.quality.advise("more operators or dead zones, creep states (a drifting record), or a record starting at rest");
  }
  return out;
}

}  // namespace

HysteresisFit fit_hysteresis(std::span<const double> va, std::span<const double> de, double sample_rate,
                             const HysteresisFitOptions& options) {
  options.validate();
  const std::string source = "hysteresis fit";
  const std::string method = "Prandtl-Ishlinskii identification";
  check_record(va, de, source, "Va", "de");
  if (!(std::isfinite(sample_rate) && sample_rate > 0.0))
    throw InputError(source, "sample_rate", "a rate > 0 Hz", format_number_exact(sample_rate));
  const double va_range = range(va);
  if (!(va_range > 0.0)) throw InputError(source, "Va", "a voltage that moves", "a constant");
  const std::vector<double> r = !options.thresholds.empty()
                                    ? options.thresholds
                                    : default_thresholds(options.operators, options.threshold_range > 0.0 ? options.threshold_range : 0.5 * va_range);
  const auto n = static_cast<Eigen::Index>(r.size());
  const auto m = static_cast<Eigen::Index>(options.creep_time_constants.size());
  const auto rows = static_cast<Eigen::Index>(va.size());

  if (options.dead_zones > 0) return finish_fit(va, de, sample_rate, options, r);
  Eigen::MatrixXd columns(rows, 1 + n + m);
  columns.col(0) = view(va);
  columns.middleCols(1, n) = play_outputs(va, r);
  if (m > 0) columns.rightCols(m) = creep_states(va, options.creep_time_constants, sample_rate);
  const SignedFit f = signed_fit(columns, de, method);
  const double w0 = f.x(0);
  const double scale = f.x.head(1 + n + m).cwiseAbs().maxCoeff();
  if (!(w0 > 1e-9 * scale)) {
    throw NumericalError(method, "the linear weight w_0 came out 0: the operator would not be invertible (d_e does not follow Va?)",
                         true);
  }

  HysteresisFit out;
  HysteresisModel& model = out.model;
  model.hysteresis.linear_weight = 1.0;
  model.hysteresis.thresholds = r;
  model.hysteresis.weights.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) model.hysteresis.weights[static_cast<std::size_t>(i)] = f.x(1 + i) / w0;
  model.creep_time_constants = options.creep_time_constants;
  model.creep_coefficients.resize(static_cast<std::size_t>(m));
  for (Eigen::Index j = 0; j < m; ++j) model.creep_coefficients[static_cast<std::size_t>(j)] = f.x(1 + n + j) / w0;
  model.gain = f.sign * w0;
  model.offset = f.sign * f.x(1 + n + m);
  model.input_min = *std::min_element(va.begin(), va.end());
  model.input_max = *std::max_element(va.begin(), va.end());

  // Effective voltage of the record and its best line against Va: the compensated actuator's line.
  const Eigen::VectorXd effective = columns * (f.x.head(1 + n + m) / w0);
  const std::vector<double> eff(effective.data(), effective.data() + effective.size());
  const LoopMetrics line = loop_metrics(va, eff);
  model.reference_slope = line.slope;
  model.reference_intercept = line.intercept;
  model.validate(source);

  const Eigen::VectorXd residual = (model.offset + model.gain * effective.array()).matrix() - view(de);
  out.samples = va.size();
  out.stroke = range(de);
  out.rms_residual = std::sqrt(residual.squaredNorm() / static_cast<double>(rows));
  out.relative_residual = out.stroke > 0.0 ? out.rms_residual / out.stroke : 0.0;
  if (!(out.relative_residual <= options.max_relative_residual)) {
    out.quality.add_problem(fmt::format("d_e: rms residual {} % of the stroke (limit {} %)",
                                        format_number(100.0 * out.relative_residual, 3),
                                        format_number(100.0 * options.max_relative_residual, 3)));
    out.quality.advise("more operators, creep states (a drifting record), or a record starting at rest; loops asymmetric "
                       "about their centre are beyond a Prandtl-Ishlinskii operator: try the modified one (dead_zones, "
                       "--dead-zones)");
  }
  return out;
}

CreepFit fit_creep(std::span<const double> input, std::span<const double> output, double sample_rate,
                   std::vector<double> time_constants, double max_relative_residual) {
  const std::string source = "creep fit";
  check_record(input, output, source, "input", "output");
  if (!(std::isfinite(sample_rate) && sample_rate > 0.0))
    throw InputError(source, "sample_rate", "a rate > 0 Hz", format_number_exact(sample_rate));
  if (!(range(input) > 0.0)) throw InputError(source, "input", "an input that moves (a step)", "a constant");
  if (!(std::isfinite(max_relative_residual) && max_relative_residual > 0.0)) {
    throw InputError(source, "max_relative_residual", "a fraction > 0", format_number_exact(max_relative_residual));
  }
  const double duration = static_cast<double>(input.size()) / sample_rate;
  if (time_constants.empty()) {
    for (double tau = 1.0; tau <= 0.5 * duration || time_constants.empty(); tau *= 10.0) time_constants.push_back(tau);
  }
  for (std::size_t j = 0; j < time_constants.size(); ++j) {
    if (!(std::isfinite(time_constants[j]) && time_constants[j] > 0.0)) {
      throw InputError(source, fmt::format("time_constants[{}]", j), "a time > 0 s",
                       format_number_exact(time_constants[j]));
    }
  }
  const auto m = static_cast<Eigen::Index>(time_constants.size());
  const auto rows = static_cast<Eigen::Index>(input.size());
  Eigen::MatrixXd columns(rows, 1 + m);
  columns.col(0) = view(input);
  columns.rightCols(m) = creep_states(input, time_constants, sample_rate);
  const std::string method = "creep identification";
  const SignedFit f = signed_fit(columns, output, method);
  const double g = f.x(0);
  if (!(g > 1e-9 * f.x.head(1 + m).cwiseAbs().maxCoeff())) {
    throw NumericalError(method, "the instantaneous gain came out 0 (the output does not follow the input?)", true);
  }
  CreepFit out;
  out.time_constants = time_constants;
  out.gain = f.sign * g;
  out.offset = f.sign * f.x(1 + m);
  for (Eigen::Index j = 0; j < m; ++j) out.coefficients.push_back(f.x(1 + j) / g);
  out.creep_per_decade = std::accumulate(out.coefficients.begin(), out.coefficients.end(), 0.0) / static_cast<double>(m);
  const Eigen::VectorXd model = (f.sign * (columns * f.x.head(1 + m)).array() + out.offset).matrix();
  const Eigen::VectorXd residual = model - view(output);
  out.rms_residual = std::sqrt(residual.squaredNorm() / static_cast<double>(rows));
  const double stroke = range(output);
  out.relative_residual = stroke > 0.0 ? out.rms_residual / stroke : 0.0;
  if (!(out.relative_residual <= max_relative_residual)) {
    out.quality.add_problem(fmt::format("output: rms residual {} % of the range (limit {} %)",
                                        format_number(100.0 * out.relative_residual, 3),
                                        format_number(100.0 * max_relative_residual, 3)));
    out.quality.advise("other time constants (a decade apart, within the record), or a record with one clean step");
  }
  return out;
}

LoopMetrics loop_metrics(std::span<const double> command, std::span<const double> output) {
  const std::string source = "loop metrics";
  if (command.size() != output.size()) {
    throw InputError(source, "output", fmt::format("{} samples (those of the command)", command.size()), std::to_string(output.size()));
  }
  if (command.size() < 2) throw InputError(source, "command", "at least 2 samples", std::to_string(command.size()));
  const Eigen::VectorXd c = view(command), y = view(output);
  const double cm = c.mean(), ym = y.mean();
  const Eigen::ArrayXd dc = c.array() - cm;
  const double scc = dc.square().sum();
  if (!(scc > 0.0)) throw InputError(source, "command", "a command that moves", "a constant");
  LoopMetrics m;
  m.slope = (dc * (y.array() - ym)).sum() / scc;
  m.intercept = ym - m.slope * cm;
  const Eigen::ArrayXd dev = y.array() - (m.slope * c.array() + m.intercept);
  m.stroke = y.maxCoeff() - y.minCoeff();
  m.width = m.stroke > 0.0 ? (dev.maxCoeff() - dev.minCoeff()) / m.stroke : 0.0;
  m.rms_deviation = std::sqrt(dev.square().mean());
  const double mid = 0.5 * (c.maxCoeff() + c.minCoeff()), half = 0.5 * (c.maxCoeff() - c.minCoeff());
  Eigen::MatrixXd basis(c.size(), 4);
  basis.col(0).setOnes();
  basis.col(1) = (c.array() - mid) / half;
  basis.col(2) = basis.col(1).array().square();
  basis.col(3) = basis.col(2).array() * basis.col(1).array();
  const Eigen::VectorXd cubic = basis.colPivHouseholderQr().solve((y.array() - ym).matrix());
  m.asymmetry = m.stroke > 0.0 ? std::abs(cubic(2)) / m.stroke : 0.0;
  return m;
}

}  // namespace piezobench::ident
