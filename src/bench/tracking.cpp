#include "piezobench/bench/tracking.hpp"

#include <fmt/format.h>

#include <cmath>
#include <span>
#include <string>

#include "piezobench/core/error.hpp"

namespace piezobench::bench {

namespace {

double setting(const io::TimeSeries& r, const std::string& key) {
  const auto it = r.settings.find(key);
  if (it == r.settings.end() || !std::holds_alternative<double>(it->second)) {
    throw InputError(r.source, key, "a number (a tracking record's setting)", "none");
  }
  return std::get<double>(it->second);
}

}  // namespace

TrackingFigures tracking_figures(std::span<const double> c, std::span<const double> de_open, std::span<const double> de_ff,
                                 double target_slope, double target_intercept) {
  if (de_open.size() != c.size() || de_ff.size() != c.size() || c.size() < 2) {
    throw InputError("tracking figures", "samples", fmt::format("c, de_open and de_ff of one size >= 2 (c: {})", c.size()),
                     fmt::format("de_open {}, de_ff {}", de_open.size(), de_ff.size()));
  }
  const ident::LoopMetrics open = ident::loop_metrics(c, de_open);
  const ident::LoopMetrics ff = ident::loop_metrics(c, de_ff);
  TrackingFigures f;
  f.width_open = open.width;
  f.width_ff = ff.width;
  f.stroke_open = open.stroke;
  double sum_open = 0.0, sum_ff = 0.0;
  for (std::size_t k = 0; k < c.size(); ++k) {
    const double target = target_slope * c[k] + target_intercept;
    sum_open += (de_open[k] - target) * (de_open[k] - target);
    sum_ff += (de_ff[k] - target) * (de_ff[k] - target);
  }
  f.rms_open = std::sqrt(sum_open / static_cast<double>(c.size()));
  f.rms_ff = std::sqrt(sum_ff / static_cast<double>(c.size()));
  return f;
}

TrackingLayout tracking_layout(const io::TimeSeries& r) {
  TrackingLayout l;
  const double fs = r.sample_rate, ramp = setting(r, "ramp_s"), periods = setting(r, "periods"), frequency = setting(r, "frequency_Hz");
  if (!(periods >= 2.0 && periods == std::floor(periods))) throw InputError(r.source, "periods", "a whole number >= 2", fmt::format("{}", periods));
  if (!(frequency > 0.0 && ramp >= 0.0)) throw InputError(r.source, "frequency_Hz", "> 0 (with ramp_s >= 0)", fmt::format("{} (ramp_s {})", frequency, ramp));
  const auto n_ramp = static_cast<Eigen::Index>(std::llround(ramp * fs));
  const auto n_wave = static_cast<Eigen::Index>(std::llround(periods / frequency * fs));
  const Eigen::Index per = n_wave / static_cast<Eigen::Index>(periods);
  l.sine_begin = n_ramp + per;
  l.sine_end = n_ramp + n_wave;
  l.triangle_begin = n_ramp + n_wave + per;
  l.triangle_end = n_ramp + 2 * n_wave;
  if (l.triangle_end > r.samples()) {
    throw InputError(r.source, "samples", fmt::format("at least {} (ramp_s, periods, frequency_Hz of a tracking record)", l.triangle_end),
                     std::to_string(r.samples()));
  }
  l.target_slope = setting(r, "target_slope_m_per_V");
  l.target_intercept = setting(r, "target_intercept_m");
  l.amplitude = setting(r, "amplitude_V");
  return l;
}

TrackingSummary tracking_summary(const io::TimeSeries& r) {
  const auto exp = r.settings.find("experiment");
  if (exp == r.settings.end() || !std::holds_alternative<std::string>(exp->second) || std::get<std::string>(exp->second) != "tracking") {
    throw InputError(r.source, "experiment", "a tracking record", "another record");
  }
  TrackingSummary s;
  for (const auto& [name, f] : {std::pair<const char*, TrackingFigures*>{"sine", &s.sine}, {"triangle", &s.triangle}}) {
    const std::string w(name);
    f->width_open = setting(r, "width_open_" + w);
    f->width_ff = setting(r, "width_ff_" + w);
    f->rms_open = setting(r, "rms_open_" + w + "_m");
    f->rms_ff = setting(r, "rms_ff_" + w + "_m");
    f->stroke_open = setting(r, "stroke_open_" + w + "_m");
  }
  const auto ff = r.settings.find("feedforward");
  s.identified = ff != r.settings.end() && std::holds_alternative<std::string>(ff->second) && std::get<std::string>(ff->second) == "identified";
  if (s.identified) s.fit_relative_residual = setting(r, "fit_relative_residual");
  s.clamped_samples = setting(r, "clamped_samples");
  return s;
}

}  // namespace piezobench::bench
