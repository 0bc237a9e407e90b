#pragma once
// The quality verdict every fit returns (vector fitting, second-order, IFF plant, 2-DoF tuning,
// LSCF): "good" or "poor", from the fit's error per output and the physical sign of its parameters.
// A poor fit is still a result (the numbers and their errors are shown), but the command says so on
// stderr with what to try, writes "quality": "poor" in JSON and exits with kPoorFitExitCode. A
// parameter that cannot be physical (a negative stiffness, mass or damping, an unstable pole where
// none can be) makes the fit `impossible`: its parameters are not printed as a result.
#include "piezobench/core/fields.hpp"
#include <string>
#include <vector>

namespace piezobench::core {

enum class FitVerdict { kGood, kPoor };
std::string to_string(FitVerdict v);                      // "good", "poor"
FitVerdict fit_verdict_from_string(const std::string& s);  // InputError field "quality"

// Relative rms error (rms |model / data - 1|, or rms |model - data| / rms |data|) above which a fit
// is poor: 20 % is several times the error of a Welch estimate with a coherence of 0.9 and tens of
// averages, and far below the error of a fit that misses a resonance.
inline constexpr double kPoorRelativeError = 0.2;

// The exit code of a command whose fit is poor (docs/cli.md; 2, 3, 4 are core/error.hpp's ExitCode,
// 5 a failed acceptance check with --strict).
inline constexpr int kPoorFitExitCode = 6;

struct FitQuality {
  FitVerdict verdict = FitVerdict::kGood;
  bool impossible = false;            // a parameter has an impossible value: do not print them
  std::vector<std::string> problems;  // each names the output or parameter and its number
  std::string advice;                 // what to try (empty when good)

  [[nodiscard]] bool poor() const { return verdict == FitVerdict::kPoor; }
  // Marks the fit poor for `problem`; `physical` = false for an impossible parameter.
  void add_problem(const std::string& problem, bool physical = true);
  // Marks the fit poor when `relative_error` exceeds kPoorRelativeError (or is not finite).
  void check_error(const std::string& what, double relative_error);
  // Sets the advice when the fit is poor and none is set yet.
  void advise(const std::string& what_to_try);
  // "good" or "poor: PROBLEM; PROBLEM. Try: ADVICE".
  [[nodiscard]] std::string summary() const;
};

// In results.json a fit's quality is merged into the fit (its field is declared with key "."):
// "quality": "good" or "poor", "quality_problems", "quality_advice", "quality_impossible".
constexpr auto describe(Type<FitQuality>) {
  using S = FitQuality;
  return fields<S>("FitQuality", "a fit's verdict and what makes it poor",
      field("verdict", &S::verdict, shown::kNone, "good or poor").key("quality"),
      field("impossible", &S::impossible, shown::kNone, "a parameter has an impossible value").key("quality_impossible"),
      field("problems", &S::problems, shown::kNone, "each names the output or parameter and its number").key("quality_problems"),
      field("advice", &S::advice, shown::kNone, "what to try (empty when good)").key("quality_advice"));
}

}  // namespace piezobench::core
