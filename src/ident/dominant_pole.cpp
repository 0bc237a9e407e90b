#include "piezobench/ident/dominant_pole.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::ident {

void DominantPoleOptions::validate() const {
  fit.validate();
  const bool automatic = omega_min == 0.0 && omega_max == 0.0;
  if (!automatic && !(std::isfinite(omega_min) && std::isfinite(omega_max) && omega_min >= 0.0 && omega_max > omega_min)) {
    throw InputError("dominant pole options", "omega_max", "a band 0 <= omega_min < omega_max (rad/s), or both 0",
                     fmt::format("[{}, {}]", format_number_exact(omega_min), format_number_exact(omega_max)));
  }
}

double DominantPole::frequency_Hz() const { return natural_frequency / kTwoPi; }

DominantPole dominant_pole(const Vector& omega, const CVector& h, const DominantPoleOptions& options) {
  options.validate();
  DominantPole d;
  d.fit = vector_fit(omega, CMatrix(h), options.fit);
  const double lo = options.omega_max > 0.0 ? options.omega_min : omega.minCoeff();
  const double hi = options.omega_max > 0.0 ? options.omega_max : omega.maxCoeff();
  double best = -1.0;
  for (Index k = 0; k < d.fit.poles.size(); ++k) {
    const Complex p = d.fit.poles(k);
    const double w = std::abs(p);
    if (p.imag() <= 0.0 || w < lo || w > hi) continue;
    // The pair's contribution r/(s - p) + conj(r)/(s - conj(p)) at its largest on the data's
    // frequencies (the header says why not |r| / |Re p|).
    double peak = 0.0;
    for (Index i = 0; i < omega.size(); ++i) {
      const Complex s(0.0, omega(i));
      double sum = 0.0;
      for (Index o = 0; o < d.fit.residues.rows(); ++o) {
        const Complex r = d.fit.residues(o, k);
        sum += std::abs(r / (s - p) + std::conj(r) / (s - std::conj(p)));
      }
      peak = std::max(peak, sum);
    }
    if (peak > best) {
      best = peak;
      d.pole = p;
    }
  }
  if (best < 0.0) {
    throw NumericalError(
        "dominant pole",
        fmt::format("the order-{} vector fit has no complex pole with a natural frequency in [{}, {}] Hz",
                    options.fit.order, format_number(lo / kTwoPi, 4), format_number(hi / kTwoPi, 4)),
        true);
  }
  d.peak = best;
  d.natural_frequency = std::abs(d.pole);
  d.damping = -d.pole.real() / d.natural_frequency;
  return d;
}

}  // namespace piezobench::ident
