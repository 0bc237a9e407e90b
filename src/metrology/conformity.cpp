#include "piezobench/metrology/conformity.hpp"

#include <cmath>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"

namespace piezobench::metrology {

std::string to_string(Conformity c) {
  switch (c) {
    case Conformity::kPass: return "pass";
    case Conformity::kMarginal: return "marginal";
    case Conformity::kFail: return "fail";
  }
  return "fail";
}

Conformity conformity_from_string(const std::string& name) {
  for (const Conformity c : {Conformity::kPass, Conformity::kMarginal, Conformity::kFail}) {
    if (to_string(c) == name) return c;
  }
  throw InputError("conformity", "verdict", "pass, marginal or fail", "'" + name + "'");
}

namespace {

double normal_cdf(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

void validate(double value, double u, std::optional<double> min, std::optional<double> max, double k) {
  const char* source = "conformity";
  if (!std::isfinite(value)) throw InputError(source, "value", "a finite number", format_number(value));
  if (!(u >= 0.0 && std::isfinite(u))) throw InputError(source, "expanded uncertainty", "a finite number >= 0", format_number(u));
  if (!(k > 0.0 && std::isfinite(k))) throw InputError(source, "coverage factor", "a finite number > 0", format_number(k));
  if (!min && !max) throw InputError(source, "tolerance", "a lower or an upper limit", "neither");
  if ((min && !std::isfinite(*min)) || (max && !std::isfinite(*max))) throw InputError(source, "tolerance", "finite limits", "a non-finite one");
  if (min && max && *min > *max) {
    throw InputError(source, "tolerance", "min <= max", format_number(*min) + " > " + format_number(*max));
  }
}

}  // namespace

ConformityDecision decide(double value, double expanded_uncertainty, std::optional<double> min, std::optional<double> max,
                          double coverage_factor) {
  validate(value, expanded_uncertainty, min, max, coverage_factor);
  ConformityDecision d;
  d.value = value;
  d.expanded_uncertainty = expanded_uncertainty;
  d.coverage_factor = coverage_factor;
  d.min = min;
  d.max = max;
  d.guard_band = expanded_uncertainty;
  const double U = expanded_uncertainty;
  const bool outside = (min && value < *min - U) || (max && value > *max + U);
  const bool inside = (!min || value >= *min + U) && (!max || value <= *max - U);
  // With U = 0 a value on a limit conforms (the plain comparison: inside wins).
  d.verdict = inside ? Conformity::kPass : (outside ? Conformity::kFail : Conformity::kMarginal);
  if (U > 0.0) {
    const double u = U / coverage_factor;
    const double above_min = min ? normal_cdf((value - *min) / u) : 1.0;  // P(true >= min)
    const double below_max = max ? normal_cdf((*max - value) / u) : 1.0;  // P(true <= max)
    d.probability_of_conformity = std::max(0.0, above_min + below_max - 1.0);
  } else {
    d.probability_of_conformity = (!min || value >= *min) && (!max || value <= *max) ? 1.0 : 0.0;
  }
  d.false_accept_probability = d.verdict == Conformity::kPass ? 1.0 - d.probability_of_conformity : 0.0;
  return d;
}

}  // namespace piezobench::metrology
