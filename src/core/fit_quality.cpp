#include "piezobench/core/fit_quality.hpp"

#include <cmath>
#include <cstdio>

#include "piezobench/core/error.hpp"

namespace piezobench::core {

std::string to_string(FitVerdict v) { return v == FitVerdict::kGood ? "good" : "poor"; }

FitVerdict fit_verdict_from_string(const std::string& s) {
  if (s == "good") return FitVerdict::kGood;
  if (s == "poor") return FitVerdict::kPoor;
  throw InputError("", "quality", "good or poor", "'" + s + "'");
}

void FitQuality::add_problem(const std::string& problem, bool physical) {
  verdict = FitVerdict::kPoor;
  if (!physical) impossible = true;
  problems.push_back(problem);
}

void FitQuality::check_error(const std::string& what, double relative_error) {
  if (std::isfinite(relative_error) && relative_error <= kPoorRelativeError) return;
  char text[160];
  std::snprintf(text, sizeof text, "%s: relative rms error %.3g above %.2g", what.c_str(), relative_error, kPoorRelativeError);
  add_problem(text);
}

void FitQuality::advise(const std::string& what_to_try) {
  if (poor() && advice.empty()) advice = what_to_try;
}

std::string FitQuality::summary() const {
  if (!poor()) return "good";
  std::string s = "poor:";
  for (std::size_t i = 0; i < problems.size(); ++i) s += (i == 0 ? " " : "; ") + problems[i];
  if (!advice.empty()) s += ". Try: " + advice;
  return s;
}

}  // namespace piezobench::core
