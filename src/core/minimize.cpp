#include "piezobench/core/minimize.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"

namespace piezobench::core {

void GoldenSectionOptions::validate() const {
  if (!(std::isfinite(tolerance) && tolerance >= 0.0)) {
    throw InputError("golden-section options", "tolerance", "a finite width >= 0", format_number_exact(tolerance));
  }
  if (max_iterations < 0) throw InputError("golden-section options", "max_iterations", ">= 0", std::to_string(max_iterations));
}

ScalarMinimum golden_section_minimize(const std::function<double(double)>& f, double a, double b,
                                      const GoldenSectionOptions& options) {
  options.validate();
  if (!(std::isfinite(a) && std::isfinite(b) && a < b)) {
    throw InputError("golden-section search", "bracket", "finite a < b",
                     format_number_exact(a) + ", " + format_number_exact(b));
  }
  ScalarMinimum out;
  auto eval = [&](double x) {
    ++out.evaluations;
    const double v = f(x);
    return std::isnan(v) ? std::numeric_limits<double>::infinity() : v;
  };
  const double inv_phi = (std::sqrt(5.0) - 1.0) / 2.0;
  double x1 = b - inv_phi * (b - a);
  double x2 = a + inv_phi * (b - a);
  double f1 = eval(x1);
  double f2 = eval(x2);
  for (int it = 0; it < options.max_iterations && b - a > options.tolerance; ++it) {
    if (f1 <= f2) {
      b = x2;
      x2 = x1;
      f2 = f1;
      x1 = b - inv_phi * (b - a);
      f1 = eval(x1);
    } else {
      a = x1;
      x1 = x2;
      f1 = f2;
      x2 = a + inv_phi * (b - a);
      f2 = eval(x2);
    }
  }
  out.lower = a;
  out.upper = b;
  out.x = f1 <= f2 ? x1 : x2;
  out.value = f1 <= f2 ? f1 : f2;
  return out;
}

}  // namespace piezobench::core
