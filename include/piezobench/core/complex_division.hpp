#pragma once
// Complex division and delay phasors in the models' inner loops (the plant fits' and the 2-DoF
// tuning's residuals), rounded exactly as the C++ library rounds them but without its calls.
//
// std::complex<double> / std::complex<double> calls the compiler's run-time routine (GCC: libgcc's
// __divdc3), which scales the operands by powers of two when they are near the ends of the double
// range, divides by Smith's algorithm and recovers infinities from NaN results. For operands whose
// non-zero parts lie in [2^-200, 2^200] the scalings are exact and no intermediate under- or
// overflows, so Smith's algorithm alone gives the same bits; divide() does that inline and hands
// every other operand (zero divisor, huge, tiny, non-finite) to the library. The demo spent 10 % of
// its CPU in the routine (docs/performance.md, "The demo"). The build compiles without FMA
// contraction (no -march), so the products and sums round as the library's do;
// tests/core/complex_division_test.cpp compares the bits.
//
// std::exp(std::complex<double>(-0.0, y)) (a delay's e^(-s tau) at s = j omega) is cexp, which for
// a zero real part returns exactly (cos y, sin y) after a rounding-mode switch; delay_phasor computes
// those two values directly.
//
// Units: the caller's (the quotient's unit is x's over y's; delay_phasor takes omega in rad/s and
// delay in s, or any pair whose product is in rad).
#include <cmath>
#include <complex>

namespace piezobench::core {

namespace detail {
// |x| is 0 or in [2^-200, 2^200]: Smith's algorithm on such parts is exact to the library's bits.
inline bool smith_safe(double x) {
  const double a = std::fabs(x);
  return a == 0.0 || (a >= 0x1p-200 && a <= 0x1p200);
}
}  // namespace detail

// x / y, bit for bit the library's quotient.
inline std::complex<double> divide(std::complex<double> x, std::complex<double> y) {
  const double a = x.real(), b = x.imag(), c = y.real(), d = y.imag();
  const double fc = std::fabs(c), fd = std::fabs(d);
  const double big = fc < fd ? fd : fc;
  if (!(big >= 0x1p-200 && big <= 0x1p200) || !detail::smith_safe(a) || !detail::smith_safe(b) || !detail::smith_safe(c) ||
      !detail::smith_safe(d)) {
    return x / y;
  }
  if (fc < fd) {
    const double ratio = c / d;
    const double denom = (c * ratio) + d;
    if (ratio != 0.0) return {((a * ratio) + b) / denom, ((b * ratio) - a) / denom};
    return {((c * (a / d)) + b) / denom, ((c * (b / d)) - a) / denom};
  }
  const double ratio = d / c;
  const double denom = (d * ratio) + c;
  if (ratio != 0.0) return {((b * ratio) + a) / denom, (b - (a * ratio)) / denom};
  return {(a + (d * (b / c))) / denom, (b - (d * (a / c))) / denom};
}

// e^(-j omega delay) (omega in rad/s, delay in s) = std::exp(-std::complex<double>(0, omega) * delay), the same bits.
inline std::complex<double> delay_phasor(double omega, double delay) {
  const double y = -omega * delay;
  return {std::cos(y), std::sin(y)};
}

}  // namespace piezobench::core
