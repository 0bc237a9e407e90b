#include "piezobench/ident/hysteresis_model_choice.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <utility>

#include "piezobench/core/error.hpp"

namespace piezobench::ident {

HysteresisModelChoice identify_hysteresis_model(std::span<const double> v, std::span<const double> d, double sample_rate_Hz,
                                                const HysteresisModelChoiceOptions& o) {
  const auto first = static_cast<std::size_t>(o.steady_first_sample);
  const std::size_t n = o.steady_samples > 0 ? static_cast<std::size_t>(o.steady_samples) : v.size() - std::min(first, v.size());
  if (o.steady_first_sample < 0 || o.steady_samples < 0 || first + n > v.size() || v.size() != d.size()) {
    throw InputError("hysteresis model", "steady_samples",
                     fmt::format("a steady loop inside the record of {} samples (Va and d_e alike)", v.size()),
                     fmt::format("samples [{}, {}) of Va {} and d_e {}", o.steady_first_sample, first + n, v.size(), d.size()));
  }
  const auto steady = [&](std::span<const double> x) { return x.subspan(first, n); };
  HysteresisModelChoice out;
  const LoopMetrics record = loop_metrics(steady(v), steady(d));
  out.width = record.width;
  out.asymmetry = record.asymmetry;
  out.fit = fit_hysteresis(v, d, sample_rate_Hz);
  if (out.asymmetry > o.asymmetry_limit) {
    HysteresisFitOptions modified_options;
    modified_options.dead_zones = o.dead_zones;
    try {
      HysteresisFit modified = fit_hysteresis(v, d, sample_rate_Hz, modified_options);
      const bool better = modified.quality.poor() != out.fit.quality.poor() ? out.fit.quality.poor()
                                                                            : modified.relative_residual < out.fit.relative_residual;
      if (better) std::swap(modified, out.fit);
      out.alternative = std::move(modified);
    } catch (const NumericalError& e) {
      out.alternative_error = e.what();  // the plain PI stays
    }
  }
  out.predicted_m = out.fit.model.predict(v, sample_rate_Hz);
  out.model_width = loop_metrics(steady(v), steady(out.predicted_m)).width;
  return out;
}

}  // namespace piezobench::ident
