#include "piezobench/core/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"

namespace piezobench::core {

double median(std::vector<double> values) {
  const std::size_t n = values.size();
  if (n == 0) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

namespace {

// The continued fraction of I_x(a, b) / (x^a (1 - x)^b / (a B(a, b))) (DLMF 8.17.22):
// 1 / (1 + d1 / (1 + d2 / (1 + ...))), d_{2m+1} = -(a + m)(a + b + m) x / ((a + 2m)(a + 2m + 1)),
// d_{2m} = m (b - m) x / ((a + 2m - 1)(a + 2m)); converges fast for x < (a + 1) / (a + b + 2).
double beta_continued_fraction(double a, double b, double x) {
  constexpr double tiny = 1e-300, eps = 1e-16;
  // Modified Lentz: f = C D products of the convergents' ratios, zeros replaced by `tiny`.
  double c = 1.0, d = 1.0 - (a + b) * x / (a + 1.0);
  d = 1.0 / (std::abs(d) < tiny ? tiny : d);
  double f = d;
  for (int m = 1; m <= 100000; ++m) {
    const double dm = m * (b - m) * x / ((a + 2.0 * m - 1.0) * (a + 2.0 * m));
    const double dm1 = -(a + m) * (a + b + m) * x / ((a + 2.0 * m) * (a + 2.0 * m + 1.0));
    double delta = 1.0;
    for (const double coefficient : {dm, dm1}) {
      d = 1.0 + coefficient * d;
      d = 1.0 / (std::abs(d) < tiny ? tiny : d);
      c = 1.0 + coefficient / c;
      if (std::abs(c) < tiny) c = tiny;
      delta = c * d;
      f *= delta;
    }
    if (std::abs(delta - 1.0) < eps) return f;
  }
  return f;  // not reached for the arguments the quantiles use (a, b < 1e7)
}

}  // namespace

double incomplete_beta(double a, double b, double x) {
  if (!(a > 0.0 && b > 0.0 && std::isfinite(a) && std::isfinite(b))) {
    throw InputError("incomplete beta", "a, b", "finite numbers > 0", format_number(a) + ", " + format_number(b));
  }
  if (!(x >= 0.0 && x <= 1.0)) throw InputError("incomplete beta", "x", "a number in [0, 1]", format_number(x));
  if (x == 0.0 || x == 1.0) return x;
  const double log_front = std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x);
  if (x < (a + 1.0) / (a + b + 2.0)) return std::exp(log_front) * beta_continued_fraction(a, b, x) / a;
  return 1.0 - std::exp(log_front) * beta_continued_fraction(b, a, 1.0 - x) / b;
}

double student_t_quantile(double p, double dof) {
  if (!(dof > 0.0 && std::isfinite(dof))) throw InputError("student t quantile", "dof", "a finite number > 0", format_number(dof));
  if (!(p > 0.0 && p < 1.0)) throw InputError("student t quantile", "p", "a probability in (0, 1)", format_number(p));
  if (p < 0.5) return -student_t_quantile(1.0 - p, dof);
  if (p == 0.5) return 0.0;
  // P(T > t) = I_{dof / (dof + t^2)}(dof / 2, 1 / 2) / 2, decreasing in t: bracket, then bisect.
  const auto upper_tail = [&](double t) { return 0.5 * incomplete_beta(0.5 * dof, 0.5, dof / (dof + t * t)); };
  const double tail = 1.0 - p;
  double lo = 0.0, hi = 1.0;
  while (upper_tail(hi) > tail) {
    lo = hi;
    hi *= 2.0;
  }
  while (hi - lo > 1e-14 * hi) {
    const double mid = 0.5 * (lo + hi);
    (upper_tail(mid) > tail ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace piezobench::core
