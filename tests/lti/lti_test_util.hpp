#pragma once
// Small builders of complex vectors shared by the lti tests.
#include <cmath>
#include <initializer_list>

#include "piezobench/lti/state_space.hpp"

namespace piezobench::test {

using lti::Complex;
using lti::CVector;
using lti::Index;

// s = -zeta w +- j w sqrt(1 - zeta^2), negative imaginary part first (the documented order).
inline CVector pair(double w, double zeta) {
  CVector p(2);
  const double wd = w * std::sqrt(1.0 - zeta * zeta);
  p << Complex(-zeta * w, -wd), Complex(-zeta * w, wd);
  return p;
}

inline CVector cvec(std::initializer_list<Complex> v) {
  CVector out(static_cast<Index>(v.size()));
  Index k = 0;
  for (const Complex& x : v) out(k++) = x;
  return out;
}

inline CVector real_values(std::initializer_list<double> v) {
  CVector out(static_cast<Index>(v.size()));
  Index k = 0;
  for (const double x : v) out(k++) = Complex(x, 0.0);
  return out;
}

// The parts one after the other.
inline CVector concat(std::initializer_list<CVector> parts) {
  Index n = 0;
  for (const auto& p : parts) n += p.size();
  CVector out(n);
  Index k = 0;
  for (const auto& p : parts) {
    out.segment(k, p.size()) = p;
    k += p.size();
  }
  return out;
}

}  // namespace piezobench::test
