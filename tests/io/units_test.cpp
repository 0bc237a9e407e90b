// The unit table: every listed unit converts to SI by its factor, aliases of micro, unknown units
// are refused with the list of known ones.
#include "piezobench/io/units.hpp"

#include <gtest/gtest.h>

#include "test_util.hpp"

namespace piezobench::io {
namespace {

double factor(const char* symbol) { return find_unit(symbol).value().to_si; }

TEST(Units, FactorsToSi) {
  EXPECT_EQ(factor("nm"), 1e-9);
  EXPECT_EQ(factor("um"), 1e-6);
  EXPECT_EQ(factor("mm"), 1e-3);
  EXPECT_EQ(factor("m"), 1.0);
  EXPECT_EQ(factor("us"), 1e-6);
  EXPECT_EQ(factor("ms"), 1e-3);
  EXPECT_EQ(factor("min"), 60.0);
  EXPECT_EQ(factor("uV"), 1e-6);
  EXPECT_EQ(factor("mV"), 1e-3);
  EXPECT_EQ(factor("kV"), 1e3);
  EXPECT_EQ(factor("mN"), 1e-3);
  EXPECT_EQ(factor("kN"), 1e3);
  EXPECT_EQ(factor("kHz"), 1e3);
  EXPECT_EQ(factor("nF"), 1e-9);
  EXPECT_EQ(factor("uF"), 1e-6);
  EXPECT_EQ(factor("F"), 1.0);
  EXPECT_EQ(find_unit("um")->si_symbol, "m");
  EXPECT_EQ(find_unit("ms")->quantity, Quantity::kTime);
  EXPECT_EQ(find_unit("mV")->si_symbol, "V");
  EXPECT_EQ(find_unit("kN")->si_symbol, "N");
  EXPECT_EQ(find_unit("uF")->si_symbol, "F");
  EXPECT_EQ(find_unit("-")->quantity, Quantity::kDimensionless);
}

TEST(Units, MicroIsWrittenThreeWaysAndCaseMatters) {
  EXPECT_EQ(factor("\xC2\xB5m"), 1e-6);  // micro sign
  EXPECT_EQ(factor("\xCE\xBCm"), 1e-6);  // Greek mu
  EXPECT_EQ(factor(" um "), 1e-6);
  EXPECT_FALSE(find_unit("MV").has_value());  // megavolt is not millivolt
  EXPECT_FALSE(find_unit("M").has_value());
}

// Windows-era writers (UFF labels, CSV headers) store 8-bit Latin-1 text: byte 0xB5 is the micro
// sign, 0xB2 the superscript two.
TEST(Units, Latin1LabelsAreReadAsTheUnitTheyName) {
  EXPECT_EQ(factor("\xB5m"), 1e-6);
  EXPECT_EQ(find_unit("m/s\xB2")->si_symbol, "m/s^2");
  EXPECT_EQ(find_unit("(1/N)*(m/s\xB2)")->si_symbol, "m/N/s^2");
  EXPECT_FALSE(find_unit("\xB5").has_value());
}

TEST(Units, UnknownUnitNamesSourceFieldAndTheKnownUnits) {
  test::expect_input_error([] { (void)unit_from_string("furlong", "rec.csv", "column d_e"); },
                           {"rec.csv", "column d_e", "'furlong'", "nm, um, mm", "kHz", "uF"});
  EXPECT_EQ(known_units().find("\xC2\xB5"), std::string::npos);  // aliases are not listed
}

TEST(Units, CompoundUnitsParseIntoAnSiFactorAndADimension) {
  const Unit a = find_unit("(1/N)*(m/s^2)").value();
  EXPECT_EQ(a.to_si, 1.0);
  EXPECT_EQ(a.si_symbol, "m/N/s^2");
  EXPECT_EQ(a.dimension, (Dimension{0, -1, 0, 0}));  // m s^-2 / (kg m s^-2)
  EXPECT_EQ(a.quantity, Quantity::kCompound);
  const Unit umv = find_unit("um/V").value();
  EXPECT_EQ(umv.to_si, 1e-6);
  EXPECT_EQ(umv.si_symbol, "m/V");
  EXPECT_EQ(umv.dimension, (Dimension{-1, -1, 3, 1}));
  EXPECT_EQ(find_unit("mV/V")->to_si, 1e-3);
  EXPECT_EQ(find_unit("mV/V")->quantity, Quantity::kDimensionless);
  EXPECT_EQ(find_unit("N/mm^2")->to_si, 1e6);  // MPa
  EXPECT_EQ(find_unit("N/mm^2")->si_symbol, "Pa");
  EXPECT_EQ(find_unit("1/s")->quantity, Quantity::kFrequency);
  EXPECT_EQ(find_unit("m/s/s")->si_symbol, "m/s^2");
  EXPECT_EQ(find_unit("mm/s2")->to_si, 1e-3);
  EXPECT_EQ(find_unit("m/s\xC2\xB2")->si_symbol, "m/s^2");
  EXPECT_EQ(find_unit("N.m")->si_symbol, "N*m");
  EXPECT_FALSE(find_unit("um/furlong").has_value());
  EXPECT_FALSE(find_unit("(m/s").has_value());
  EXPECT_FALSE(find_unit("m//s").has_value());
  EXPECT_FALSE(find_unit("((nm^9)^9)^9").has_value());  // a factor of 1e-6561 is no unit
  EXPECT_FALSE(find_unit("(((((m^9)^9)^9)^9)^9)^9").has_value());
  EXPECT_EQ(divide(find_unit("um").value(), find_unit("V").value()).to_si, 1e-6);
  EXPECT_EQ(divide(find_unit("um").value(), find_unit("V").value()).si_symbol, "m/V");
}

}  // namespace
}  // namespace piezobench::io
