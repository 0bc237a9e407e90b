#include "piezobench/bench/tracking.hpp"

#include <fmt/format.h>

#include <cmath>
#include <span>
#include <string>

#include "piezobench/core/error.hpp"

namespace piezobench::bench {

namespace {

std::span<const double> column(const io::TimeSeries& r, const std::string& name, Eigen::Index begin, Eigen::Index end) {
  const Eigen::Index j = r.index(name);
  return {r.data.col(j).data() + begin, static_cast<std::size_t>(end - begin)};
}

double setting(const io::TimeSeries& r, const std::string& key) {
  const auto it = r.settings.find(key);
  if (it == r.settings.end() || !std::holds_alternative<double>(it->second)) {
    throw InputError(r.source, key, "a number (a tracking record's setting)", "none");
  }
  return std::get<double>(it->second);
}

}  // namespace

TrackingFigures tracking_figures(const io::TimeSeries& r, Eigen::Index begin, Eigen::Index end) {
  if (begin < 0 || end > r.samples() || end - begin < 2) {
    throw InputError(r.source, "samples", fmt::format("a window within 0..{}", r.samples()), fmt::format("{}..{}", begin, end));
  }
  const std::span<const double> c = column(r, "c", begin, end);
  const std::span<const double> de_open = column(r, "de_open", begin, end);
  const std::span<const double> de_ff = column(r, "de_ff", begin, end);
  const ident::LoopMetrics open = ident::loop_metrics(c, de_open);
  const ident::LoopMetrics ff = ident::loop_metrics(c, de_ff);
  TrackingFigures f;
  f.width_open = open.width;
  f.width_ff = ff.width;
  f.stroke_open = open.stroke;
  const double slope = setting(r, "target_slope_m_per_V"), intercept = setting(r, "target_intercept_m");
  double sum_open = 0.0, sum_ff = 0.0;
  for (std::size_t k = 0; k < c.size(); ++k) {
    const double target = slope * c[k] + intercept;
    sum_open += (de_open[k] - target) * (de_open[k] - target);
    sum_ff += (de_ff[k] - target) * (de_ff[k] - target);
  }
  f.rms_open = std::sqrt(sum_open / static_cast<double>(c.size()));
  f.rms_ff = std::sqrt(sum_ff / static_cast<double>(c.size()));
  return f;
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
