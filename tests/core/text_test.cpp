// Tests of core/text.hpp: the text helpers shared by the io and fem readers.
#include "piezobench/core/text.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "piezobench/core/format.hpp"

namespace piezobench::text {
namespace {

TEST(ParseDouble, AcceptsWholeNumbersOnly) {
  EXPECT_EQ(parse_double(" 1.5 ").value(), 1.5);
  EXPECT_EQ(parse_double("+2e3").value(), 2000.0);
  EXPECT_EQ(parse_double("-0.25E-1").value(), -0.025);
  EXPECT_EQ(parse_double("1.0D+02", /*fortran=*/true).value(), 100.0);
  EXPECT_FALSE(parse_double("1.0D+02").has_value());
  EXPECT_FALSE(parse_double("1.5x").has_value());
  EXPECT_FALSE(parse_double("").has_value());
  EXPECT_FALSE(parse_double("abc").has_value());
  EXPECT_FALSE(parse_double("+-1").has_value());
  EXPECT_TRUE(std::isnan(parse_double("nan").value()));
  EXPECT_TRUE(std::isinf(parse_double("1e999").value()));
  EXPECT_EQ(parse_double("0.1").value(), 0.1);
  EXPECT_EQ(parse_double(format_number(0.1 + 0.2, 17)).value(), 0.1 + 0.2);
}

TEST(ParseInt, RejectsFractionsAndText) {
  EXPECT_EQ(parse_int("   58").value(), 58);
  EXPECT_EQ(parse_int("-1").value(), -1);
  EXPECT_FALSE(parse_int("5.0").has_value());
  EXPECT_FALSE(parse_int("5b").has_value());
}

TEST(TakeDouble, AdvancesPastTheNumberOnly) {
  std::string_view s = "  +1.25e2, 7";
  EXPECT_EQ(take_double(s).value(), 125.0);
  EXPECT_EQ(s, ", 7");
  std::string_view bad = "x1";
  EXPECT_FALSE(take_double(bad).has_value());
  EXPECT_EQ(bad, "x1");
  std::string_view n = " 42 3";
  EXPECT_EQ(take_int(n).value(), 42);
  EXPECT_EQ(n, " 3");
}

TEST(Tokens, SplitsAtBlanksAndOptionallyCommas) {
  EXPECT_EQ(tokens("  a\tb  c "), (std::vector<std::string_view>{"a", "b", "c"}));
  EXPECT_EQ(tokens("1, 2,3", /*commas=*/true), (std::vector<std::string_view>{"1", "2", "3"}));
  EXPECT_EQ(split("a,,b", ','), (std::vector<std::string_view>{"a", "", "b"}));
}

TEST(ForEachLine, NumbersLinesAndDropsCarriageReturns) {
  std::vector<std::string> lines;
  for_each_line("one\r\ntwo\nthree", [&](std::size_t number, std::string_view line) {
    lines.push_back(std::to_string(number) + ":" + std::string(line));
    return number < 2;
  });
  EXPECT_EQ(lines, (std::vector<std::string>{"1:one", "2:two"}));
}

TEST(Quote, ShortensAndEscapes) {
  EXPECT_EQ(quote("abc"), "'abc'");
  EXPECT_EQ(quote(std::string("a\x01", 2)), "'a\\x01'");
  EXPECT_EQ(quote(std::string(50, 'x')), "'" + std::string(40, 'x') + "...'");
  EXPECT_EQ(trim(" \t x y \r\n"), "x y");
  EXPECT_EQ(to_lower("HeLLo.MAT"), "hello.mat");
  EXPECT_EQ(join({"a", "b", "c"}), "a, b, c");
}

TEST(Text, Utf8CodePointsAreTakenAndAppended) {
  for (const char32_t c : {U'\x00', U'\x7F', U'\x80', U'\x7FF', U'\x800', U'\xFFFF', U'\x10000', U'\x10FFFF'}) {
    std::string s;
    append_utf8(s, c);
    size_t i = 0;
    EXPECT_EQ(take_utf8(s, i), std::optional<char32_t>(c)) << static_cast<unsigned>(c);
    EXPECT_EQ(i, s.size());
  }
  const std::string emoji = "a\xF0\x9F\x98\x80";
  size_t i = 1;
  EXPECT_EQ(take_utf8(emoji, i), std::optional<char32_t>(0x1F600));
  EXPECT_EQ(i, 5u);
  i = 0;
  const std::string overlong = "\xC0\xAF";
  EXPECT_FALSE(take_utf8(overlong, i).has_value());
  EXPECT_EQ(i, 0u);  // unchanged
}

TEST(Text, Utf8IsKeptAndLatin1IsDecoded) {
  EXPECT_TRUE(is_utf8("m/s^2"));
  EXPECT_TRUE(is_utf8("m/s\xC2\xB2"));            // U+00B2
  EXPECT_TRUE(is_utf8("\xE2\x82\xAC"));           // U+20AC
  EXPECT_TRUE(is_utf8("\xF0\x9F\x98\x80"));       // U+1F600
  EXPECT_FALSE(is_utf8("m/s\xB2"));                // a Latin-1 byte alone
  EXPECT_FALSE(is_utf8("\xC0\xAF"));               // overlong '/'
  EXPECT_FALSE(is_utf8("\xE0\x80\xAF"));           // overlong, 3 bytes
  EXPECT_FALSE(is_utf8("\xED\xA0\x80"));           // a surrogate
  EXPECT_FALSE(is_utf8("\xF4\x90\x80\x80"));       // past U+10FFFF
  EXPECT_FALSE(is_utf8("\xE2\x82"));               // truncated at the end
  EXPECT_FALSE(is_utf8("\xE2\x28\xA1"));           // a bad continuation byte
  EXPECT_EQ(utf8_from_legacy("m/s\xC2\xB2"), "m/s\xC2\xB2");
  EXPECT_EQ(utf8_from_legacy("(1/N)*(m/s\xB2)"), "(1/N)*(m/s\xC2\xB2)");
  EXPECT_EQ(utf8_from_legacy("\xB5m"), "\xC2\xB5m");
  EXPECT_EQ(utf8_from_legacy("Kraft \xDC\xFF"), "Kraft \xC3\x9C\xC3\xBF");
  EXPECT_EQ(utf8_from_legacy(""), "");
}

}  // namespace
}  // namespace piezobench::text
