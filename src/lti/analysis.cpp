#include "piezobench/lti/analysis.hpp"

#include <cmath>
#include <limits>

#include "balance.hpp"
#include "check.hpp"
#include "spectral.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/lti/conversions.hpp"

namespace piezobench::lti {

CVector poles(const StateSpace& sys) {
  sys.validate();
  return detail::balanced_eigenvalues(sys.A);
}

CVector zeros(const StateSpace& sys) {
  sys.validate();
  CVector z = detail::system_zeros(sys.A, sys.B, sys.C, sys.D).zeros;
  detail::sort_roots(z);
  return z;
}

Matrix dc_gain(const StateSpace& sys) {
  sys.validate();
  const Index p = sys.outputs();
  const Index m = sys.inputs();
  const Index n = sys.states();
  const Complex origin = sys.is_discrete() ? Complex(1.0, 0.0) : Complex(0.0, 0.0);
  if (n == 0) return sys.D;
  const CVector pl = poles(sys);
  // A pole "at the origin" (at z = 1): within this distance. Eigenvalues of a double (triple)
  // integrator scatter by eps^(1/2) (eps^(1/3)) times ||A||, so the tolerance is relative to the
  // scale of A (continuous) or to 1 (discrete, where |z| ~ 1), and generous.
  double scale = 1.0;
  if (!sys.is_discrete()) {
    const Vector d = detail::balancing_scales(sys.A);
    scale = std::max((d.cwiseInverse().asDiagonal() * sys.A * d.asDiagonal()).lpNorm<Eigen::Infinity>(), 1e-300);
  }
  const double origin_tol = 1e-6 * scale;
  bool pole_at_origin = false;
  for (Index i = 0; i < pl.size(); ++i) pole_at_origin = pole_at_origin || std::abs(pl(i) - origin) <= origin_tol;
  if (!pole_at_origin) {
    // No integrator: H(0) = D + C (0 I - A)^-1 B directly, the most accurate form.
    return detail::evaluate_dense(sys.A, sys.B, sys.C, sys.D, origin).real();
  }
  // With an integrator, each channel's zpk form tells whether it is cancelled there (a decoupling
  // or transmission zero at the origin) instead of dividing by a round-off-sized number.
  Matrix g(p, m);
  StateSpace channel_sys = sys;
  channel_sys.input_delay.resize(0);
  channel_sys.output_delay.resize(0);
  for (Index i = 0; i < p; ++i) {
    for (Index j = 0; j < m; ++j) {
      const Zpk z = to_zpk(channel_sys, i, j);
      if (z.gain == 0.0) {
        g(i, j) = 0.0;
        continue;
      }
      Index excess = 0;  // poles minus zeros at the origin
      Complex k(z.gain, 0.0);
      // Interleave zero and pole factors to keep the running product in range.
      const Index np = z.poles.size();
      const Index nz = z.zeros.size();
      for (Index t = 0; t < std::max(np, nz); ++t) {
        if (t < nz) {
          if (std::abs(z.zeros(t) - origin) <= origin_tol) {
            --excess;
          } else {
            k *= origin - z.zeros(t);
          }
        }
        if (t < np) {
          if (std::abs(z.poles(t) - origin) <= origin_tol) {
            ++excess;
          } else {
            k /= origin - z.poles(t);
          }
        }
      }
      if (excess > 0) {
        g(i, j) = k.real() >= 0.0 ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
      } else if (excess < 0) {
        g(i, j) = 0.0;
      } else {
        g(i, j) = k.real();
      }
    }
  }
  return g;
}

PoleInfo pole_info(Complex pole, double sample_time) {
  detail::require_sample_time(sample_time, "pole_info");
  PoleInfo info{pole, 0.0, 0.0};
  Complex s = pole;
  if (sample_time > 0.0) {
    if (pole == Complex(0.0, 0.0)) {
      // z = 0 is s = -infinity: infinitely fast and fully damped (MATLAB's damp).
      info.natural_frequency = std::numeric_limits<double>::infinity();
      info.damping = 1.0;
      return info;
    }
    s = std::log(pole) / sample_time;
  }
  const double wn = std::abs(s);
  info.natural_frequency = wn;
  info.damping = wn == 0.0 ? -1.0 : -s.real() / wn;
  return info;
}

std::vector<PoleInfo> damp(const StateSpace& sys) {
  const CVector pl = poles(sys);
  std::vector<PoleInfo> out;
  out.reserve(static_cast<std::size_t>(pl.size()));
  for (Index i = 0; i < pl.size(); ++i) out.push_back(pole_info(pl(i), sys.sample_time));
  return out;
}

Damping damp_columns(const StateSpace& sys) {
  const std::vector<PoleInfo> info = damp(sys);
  const auto n = static_cast<Index>(info.size());
  Damping out{CVector(n), Vector(n), Vector(n)};
  for (Index i = 0; i < n; ++i) {
    const PoleInfo& p = info[static_cast<std::size_t>(i)];
    out.poles(i) = p.pole;
    out.natural_frequency(i) = p.natural_frequency;
    out.damping(i) = p.damping;
  }
  return out;
}

}  // namespace piezobench::lti
