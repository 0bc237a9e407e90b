#pragma once
// The one scalar minimizer of piezobench: golden-section search (J. Kiefer, "Sequential minimax
// search for a maximum", Proc. AMS 4, 1953) on a bracket, used by the high-pass corner fit
// (ident/features.hpp) and the gain of maximum damping on a root-locus branch (lti/rlocus.hpp, and
// through it control::iff_root_locus and the campaign's IFF optimum).
// Units: the caller's (the parameters, residuals and tolerances are in the units of the caller's problem).
#include <functional>

namespace piezobench::core {

struct GoldenSectionOptions {
  double tolerance = 1e-12;  // stop when the bracket is at most this wide (in x)
  int max_iterations = 300;  // at most this many narrowing steps
  void validate() const;     // InputError (source "golden-section options") naming the field
};

struct ScalarMinimum {
  double x = 0.0;       // the better of the two interior points of the last bracket
  double value = 0.0;   // f(x)
  double lower = 0.0;   // the last bracket [lower, upper]
  double upper = 0.0;
  int evaluations = 0;
};

// Minimum of f, assumed unimodal on [a, b] (a < b, else InputError field "bracket"). f is evaluated
// only inside the bracket; a NaN value counts as +infinity.
ScalarMinimum golden_section_minimize(const std::function<double(double)>& f, double a, double b,
                                      const GoldenSectionOptions& options = {});

}  // namespace piezobench::core
