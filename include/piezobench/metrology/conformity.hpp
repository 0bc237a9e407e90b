#pragma once
// Decisions of conformity with a measurement's uncertainty (ISO 14253-1:2017, "Decision rules for
// verifying conformity or nonconformity with specifications"; JCGM 106:2012, "The role of
// measurement uncertainty in conformity assessment").
//
// A measured value y with expanded uncertainty U (coverage factor k, normally 2) against a
// tolerance [min, max] (either side may be open):
//   pass      y inside the acceptance zone [min + U, max - U]: conformity is proved (the guard band
//             w = U, ISO 14253-1's default rule);
//   fail      y outside the rejection zone, below min - U or above max + U: nonconformity is proved;
//   marginal  otherwise: a limit lies within y +- U, and neither can be proved.
// With the measurand's knowledge Gaussian, mean y and standard deviation u = U / k (JCGM 106
// section 7.3), the probability of conformity is p_c = Phi((max - y) / u) - Phi((min - y) / u); the
// probability that a unit passed this way does not conform (the specific risk of a false accept) is
// 1 - p_c, at most 1 - Phi(k) = 2.3 % for k = 2 at the edge of the acceptance zone of a one-sided
// tolerance. U = 0 reduces the rule to the plain comparison (no marginal band).
// Units: the caller's (value, U and limits in one unit).
#include <optional>
#include <string>

#include "piezobench/core/fields.hpp"

namespace piezobench::metrology {

enum class Conformity { kPass = 0, kMarginal = 1, kFail = 2 };
std::string to_string(Conformity c);  // "pass", "marginal", "fail"
Conformity conformity_from_string(const std::string& name);  // InputError (source "conformity") for anything else

struct ConformityDecision {
  Conformity verdict = Conformity::kPass;
  double value = 0.0;                   // the caller's unit
  double expanded_uncertainty = 0.0;    // U, the caller's unit (>= 0)
  double coverage_factor = 2.0;         // k (ratio), U = k u
  std::optional<double> min, max;       // the tolerance, the caller's unit (absent: open)
  double guard_band = 0.0;              // w = U: the acceptance zone is the tolerance narrowed by w on each limit
  double probability_of_conformity = 1.0;  // p_c (ratio), Gaussian with u = U / k
  double false_accept_probability = 0.0;   // 1 - p_c when the verdict is pass, else 0 (ratio)
};

constexpr auto describe(core::Type<ConformityDecision>) {
  using S = ConformityDecision;
  using namespace core::shown;
  return core::fields<S>("ConformityDecision", "a value with its uncertainty against a tolerance (ISO 14253-1)",
      core::field("verdict", &S::verdict, kNone, "pass, marginal or fail"),
      core::field("value", &S::value, kNone, "the measured value, the check's unit"),
      core::field("expanded_uncertainty", &S::expanded_uncertainty, kNone, "U = k u, the check's unit"),
      core::field("coverage_factor", &S::coverage_factor, kRatio, "k"),
      core::field("min", &S::min, kNone, "lower limit, the check's unit (None: open)"),
      core::field("max", &S::max, kNone, "upper limit, the check's unit (None: open)"),
      core::field("guard_band", &S::guard_band, kNone, "w = U, the check's unit"),
      core::field("probability_of_conformity", &S::probability_of_conformity, kRatio, "p_c, Gaussian with u = U / k"),
      core::field("false_accept_probability", &S::false_accept_probability, kRatio, "1 - p_c of a pass, else 0"));
}

// The decision above. InputError (source "conformity") for a non-finite value, U < 0 or not finite,
// k <= 0, no limit at all, or min > max.
[[nodiscard]] ConformityDecision decide(double value, double expanded_uncertainty, std::optional<double> min,
                                        std::optional<double> max, double coverage_factor = 2.0);

}  // namespace piezobench::metrology
