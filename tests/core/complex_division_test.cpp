#include "piezobench/core/complex_division.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace piezobench::core {
namespace {

using C = std::complex<double>;

// The same bits in both parts (NaN: both NaN, whatever the payload).
::testing::AssertionResult same_bits(C got, C want) {
  const auto eq = [](double g, double w) {
    return (std::isnan(g) && std::isnan(w)) || std::bit_cast<std::uint64_t>(g) == std::bit_cast<std::uint64_t>(w);
  };
  if (eq(got.real(), want.real()) && eq(got.imag(), want.imag())) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "got (" << got.real() << ", " << got.imag() << "), the library gives (" << want.real()
                                       << ", " << want.imag() << ")";
}

// A random double: sign, exponent 2^-e_range..2^e_range, and zero one time in eight.
double random_part(std::mt19937_64& rng, int e_range) {
  std::uniform_int_distribution<int> zero(0, 7), sign(0, 1), e(-e_range, e_range);
  std::uniform_real_distribution<double> m(1.0, 2.0);
  if (zero(rng) == 0) return sign(rng) ? -0.0 : 0.0;
  return (sign(rng) ? -1.0 : 1.0) * std::ldexp(m(rng), e(rng));
}

TEST(ComplexDivision, GivesTheLibrarysBitsAcrossTheSafeRangeAndBeyond) {
  std::mt19937_64 rng(34);
  // 2^-60..2^60: the models' values; 2^-260..2^260: parts outside [2^-200, 2^200] go to the library.
  for (const int e_range : {60, 199, 260}) {
    for (int i = 0; i < 200000; ++i) {
      const C x(random_part(rng, e_range), random_part(rng, e_range));
      const C y(random_part(rng, e_range), random_part(rng, e_range));
      ASSERT_TRUE(same_bits(divide(x, y), x / y)) << "(" << x << ") / (" << y << ")";
    }
  }
}

TEST(ComplexDivision, HandsZeroNonFiniteAndExtremeOperandsToTheLibrary) {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  const double tiny = 1e-310, huge = 1e308, min = std::numeric_limits<double>::min();
  const std::vector<double> parts = {0.0, -0.0, 1.0, -3.5, 0x1p-200, 0x1p200, 0x1p-201, 0x1p201, tiny, huge, min, inf, -inf, nan};
  for (const double a : parts) {
    for (const double b : parts) {
      for (const double c : parts) {
        for (const double d : parts) {
          const C x(a, b), y(c, d);
          EXPECT_TRUE(same_bits(divide(x, y), x / y)) << "(" << x << ") / (" << y << ")";
        }
      }
    }
  }
}

TEST(ComplexDivision, DelayPhasorIsTheLibrarysExponential) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> w(0.0, 1e6), tau(-1e-3, 1e-3);
  for (int i = 0; i < 100000; ++i) {
    const double omega = w(rng), delay = i % 10 == 0 ? 0.0 : tau(rng);
    ASSERT_TRUE(same_bits(delay_phasor(omega, delay), std::exp(-C(0.0, omega) * delay))) << omega << " " << delay;
  }
  EXPECT_TRUE(same_bits(delay_phasor(0.0, 0.0), std::exp(-C(0.0, 0.0) * 0.0)));
  EXPECT_TRUE(same_bits(delay_phasor(1e-310, 1.0), std::exp(-C(0.0, 1e-310) * 1.0)));
  // e^(-j pi/2): (cos, sin) of -pi/2 as the library rounds them.
  EXPECT_NEAR(delay_phasor(std::acos(-1.0) / 2.0, 1.0).imag(), -1.0, 1e-15);
}

}  // namespace
}  // namespace piezobench::core
