#include "piezobench/core/format.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <limits>

namespace piezobench {
namespace {

TEST(FormatNumber, SixSignificantDigitsByDefaultAsPrintfG) {
  EXPECT_EQ(format_number(95.36912), "95.3691");
  EXPECT_EQ(format_number(1.8e6), "1.8e+06");
  EXPECT_EQ(format_number(-0.000123456789), "-0.000123457");
  EXPECT_EQ(format_number(0.0), "0");
}

TEST(FormatNumber, TenDigitsTellNeighboursApartAndSeventeenRoundTrip) {
  EXPECT_EQ(format_number(1e-4, 10), "0.0001");
  EXPECT_EQ(format_number(1.0000000001e-4, 10), "0.0001");      // differs in the 11th digit
  EXPECT_EQ(format_number(1.000000001e-4, 10), "0.0001000000001");
  const double x = 0.1 + 0.2;
  EXPECT_EQ(std::strtod(format_number(x, 17).c_str(), nullptr), x);
  EXPECT_NE(format_number(x, 17), format_number(0.3, 17));
}

TEST(FormatNumber, NonFiniteAndClampedDigits) {
  EXPECT_EQ(format_number(std::numeric_limits<double>::quiet_NaN()), "nan");
  EXPECT_EQ(format_number(-std::numeric_limits<double>::quiet_NaN()), "nan");
  EXPECT_EQ(format_number(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(format_number(-std::numeric_limits<double>::infinity()), "-inf");
  EXPECT_EQ(format_number(123.456, 0), "1e+02");   // clamped to 1 digit
  EXPECT_EQ(format_number(0.1, 40), format_number(0.1, 17));
}

TEST(FormatNumberExact, FewestDigitsThatReadBack) {
  EXPECT_EQ(format_number_exact(1e-12), "1e-12");  // std::to_string gave "0.000000"
  EXPECT_EQ(format_number_exact(0.1), "0.1");
  EXPECT_EQ(format_number_exact(1.0000001), "1.0000001");
  EXPECT_EQ(format_number_exact(-2.5), "-2.5");
  EXPECT_EQ(format_number_exact(150.0), "150");   // not "1.5e+02"
  EXPECT_EQ(format_number_exact(-20.0), "-20");
  EXPECT_EQ(format_number_exact(1e6), "1e+06");
  EXPECT_EQ(format_number_exact(1e13), "1e+13");
  EXPECT_EQ(format_number_exact(0.1 + 0.2), "0.30000000000000004");
  EXPECT_EQ(format_number_exact(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(format_number_exact(std::numeric_limits<double>::quiet_NaN()), "nan");
}

TEST(FormatNumberFixed, DecimalsAfterThePoint) {
  EXPECT_EQ(format_number_fixed(158.34, 1), "158.3");
  EXPECT_EQ(format_number_fixed(200.0, 1), "200.0");
  EXPECT_EQ(format_number_fixed(-174.46, 1), "-174.5");
  EXPECT_EQ(format_number_fixed(12.5, 0), "12");  // round half to even, as printf
  EXPECT_EQ(format_number_fixed(1e-12, 2), "0.00");
  EXPECT_EQ(format_number_fixed(1e300, 0).size(), 301u);
  EXPECT_EQ(format_number_fixed(0.5, -3), "0");  // clamped to 0 decimals
  EXPECT_EQ(format_number_fixed(std::numeric_limits<double>::infinity(), 2), "inf");
  EXPECT_EQ(format_number_fixed(std::numeric_limits<double>::quiet_NaN(), 2), "nan");
}

}  // namespace
}  // namespace piezobench
