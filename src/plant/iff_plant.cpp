#include "piezobench/plant/iff_plant.hpp"

#include <cmath>
#include <string>

#include "piezobench/core/complex_division.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"

namespace piezobench::plant {
namespace {

void require_positive(double value, const char* field) {
  if (!(std::isfinite(value) && value > 0.0))
    throw InputError("", field, "a finite positive number", format_number_exact(value));
}

void require_nonnegative(double value, const char* field) {
  if (!(std::isfinite(value) && value >= 0.0))
    throw InputError("", field, "a finite number >= 0", format_number_exact(value));
}

// Second-order factor 1 + 2 x s/w + s^2/w^2 in descending powers.
lti::Vector normalized_quadratic(double w, double x) {
  return (lti::Vector(3) << 1.0 / (w * w), 2.0 * x / w, 1.0).finished();
}

lti::Vector convolve(const lti::Vector& a, const lti::Vector& b) {
  lti::Vector c = lti::Vector::Zero(a.size() + b.size() - 1);
  for (lti::Index i = 0; i < a.size(); ++i) c.segment(i, b.size()) += a(i) * b;
  return c;
}

}  // namespace

void IffPlantParams::validate() const {
  if (!std::isfinite(g0) || g0 == 0.0) throw InputError("", "g0", "a finite non-zero gain", format_number_exact(g0));
  require_positive(wz, "wz");
  if (!std::isfinite(xz))
    throw InputError("", "xz", "a finite damping ratio (< 0: non-minimum-phase zero)", format_number_exact(xz));
  require_positive(wp, "wp");
  require_nonnegative(xp, "xp");
  require_positive(w_hpf, "w_hpf");
  require_nonnegative(delay, "delay");
}

lti::TransferFunction iff_plant(const IffPlantParams& params) {
  params.validate();
  const lti::Vector hpf_num = (lti::Vector(2) << 1.0, 0.0).finished();
  const lti::Vector hpf_den = (lti::Vector(2) << 1.0, params.w_hpf).finished();
  const lti::Vector num = params.g0 * convolve(normalized_quadratic(params.wz, params.xz), hpf_num);
  const lti::Vector den = convolve(normalized_quadratic(params.wp, params.xp), hpf_den);
  return lti::TransferFunction(num, den, 0.0, params.delay);
}

lti::Complex iff_plant_response(const IffPlantParams& p, double omega) {
  const lti::Complex s(0.0, omega);
  const lti::Complex num = 1.0 + 2.0 * p.xz * s / p.wz + s * s / (p.wz * p.wz);
  const lti::Complex den = 1.0 + 2.0 * p.xp * s / p.wp + s * s / (p.wp * p.wp);
  // p.g0 * num / den * s / (p.w_hpf + s) * std::exp(-s * p.delay), the same bits without the library calls.
  return core::divide(core::divide(p.g0 * num, den) * s, p.w_hpf + s) * core::delay_phasor(omega, p.delay);
}

lti::CVector iff_plant_response(const IffPlantParams& params, const lti::Vector& omega) {
  lti::CVector h(omega.size());
  for (lti::Index k = 0; k < omega.size(); ++k) h(k) = iff_plant_response(params, omega(k));
  return h;
}

}  // namespace piezobench::plant
