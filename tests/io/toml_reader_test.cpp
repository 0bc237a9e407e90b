// Tests of the one typed TOML reader: each error's exact words (file and line, full key path,
// expected, found with numbers as written), the unit a key names, and the values read.
#include "piezobench/io/toml_reader.hpp"

#include <gtest/gtest.h>

#include "piezobench/core/error.hpp"
#include "piezobench/io/toml_table.hpp"
#include "test_util.hpp"

namespace piezobench::io {
namespace {

// The message of the InputError f throws ("" and a failure when it throws none).
template <typename F>
std::string message(F&& f) {
  return test::input_error(std::forward<F>(f));
}

const char* const kText =
    "title = 'APA'\n"                 // line 1
    "count = 3\n"                     // 2
    "[bench]\n"                       // 3
    "gain_V_per_m = 1e-12\n"          // 4
    "rate_Hz = -5\n"                  // 5
    "flag = 1\n"                      // 6
    "kind = 'udp'\n"                  // 7
    "limits = [1, 'x']\n"             // 8
    "range = [2, 1]\n"                // 9
    "names = ['a', 2]\n"              // 10
    "[[units]]\n"                     // 11
    "id = 1\n"                        // 12
    "[[units]]\n"                     // 13
    "id = 2.5\n"                      // 14
    "frf = { file = 3 }\n";           // 15

class TomlReaderTest : public ::testing::Test {
 protected:
  toml::table root = parse_toml(kText, "c.toml");
  TomlReader r{root, "c.toml"};
  TomlReader bench = r.required_table("bench");
};

TEST_F(TomlReaderTest, ReadsValuesOfEachType) {
  EXPECT_EQ(r.string("title"), "APA");
  EXPECT_EQ(r.integer("count", 0, 10), 3);
  EXPECT_EQ(r.number("count"), 3.0);
  EXPECT_EQ(bench.number("gain_V_per_m"), 1e-12);
  EXPECT_EQ(bench.choice("kind", {"virtual", "udp"}), "udp");
  EXPECT_EQ(bench.pair("range"), (std::pair{2.0, 1.0}));
  EXPECT_EQ(bench.path(), "bench");
  EXPECT_FALSE(r.number("absent").has_value());
  EXPECT_FALSE(r.table("absent").has_value());
  EXPECT_TRUE(r.strings("absent").empty());
  EXPECT_FALSE(r.table_or_empty("absent").number("x").has_value());
  EXPECT_EQ(r.table_or_empty("absent").key("x"), "absent.x");
  EXPECT_EQ(r.table_or_empty("bench").number("rate_Hz"), -5.0);
  const std::vector<TomlReader> units = r.tables("units");
  ASSERT_EQ(units.size(), 2u);
  EXPECT_EQ(units[1].path(), "units[1]");
  EXPECT_EQ(units[0].integer("id", 1, 7), 1);
}

TEST_F(TomlReaderTest, NumbersOutOfBoundsNameFileLineKeyAndUnit) {
  EXPECT_EQ(message([&] { (void)bench.number("rate_Hz", NumberBounds::positive()); }),
            "c.toml: line 5: bench.rate_Hz: expected a number > 0 Hz, found -5");
  // The value as written, not std::to_string's "0.000000".
  EXPECT_EQ(message([&] { (void)bench.number("gain_V_per_m", NumberBounds::closed(1, 2)); }),
            "c.toml: line 4: bench.gain_V_per_m: expected a number in [1, 2] V/m, found 1e-12");
  EXPECT_EQ(message([&] { (void)bench.number("rate_Hz", NumberBounds::half_open(0, 1)); }),
            "c.toml: line 5: bench.rate_Hz: expected a number in [0, 1) Hz, found -5");
  EXPECT_EQ(message([&] { (void)bench.number("kind"); }), "c.toml: line 7: bench.kind: expected a number, found a string");
  EXPECT_EQ(message([&] { (void)bench.required_number("speed_m_per_s", NumberBounds::non_negative()); }),
            "c.toml: line 3: bench.speed_m_per_s: expected a number >= 0 m/s, found nothing (the key is required)");
  EXPECT_EQ(message([&] { (void)bench.required_number("speed", {}, "the loop's speed"); }),
            "c.toml: line 3: bench.speed: expected the loop's speed, found nothing (the key is required)");
}

TEST_F(TomlReaderTest, NonFiniteNumbersAreRefused) {
  const toml::table t = parse_toml("a = inf\nb = nan\n", "n.toml");
  const TomlReader n(t, "n.toml");
  EXPECT_EQ(message([&] { (void)n.number("a"); }), "n.toml: line 1: a: expected a finite number, found inf");
  EXPECT_EQ(message([&] { (void)n.number("b", NumberBounds::positive()); }), "n.toml: line 2: b: expected a number > 0, found nan");
}

TEST_F(TomlReaderTest, ArraysNameTheirElement) {
  EXPECT_EQ(message([&] { (void)bench.numbers("limits"); }), "c.toml: line 8: bench.limits[1]: expected a number, found a string");
  EXPECT_EQ(message([&] { (void)bench.strings("names"); }), "c.toml: line 10: bench.names[1]: expected a string, found a number");
  EXPECT_EQ(message([&] { (void)bench.numbers("kind"); }), "c.toml: line 7: bench.kind: expected an array of numbers, found a string");
  EXPECT_EQ(message([&] { (void)bench.pair("limits"); }), "c.toml: line 8: bench.limits[1]: expected a number, found a string");
  EXPECT_EQ(message([&] { (void)bench.pair("names", "[lo, hi] in volts"); }),
            "c.toml: line 10: bench.names[0]: expected a number, found a string");
  EXPECT_EQ(message([&] { (void)bench.integers("limits", 0, 9); }), "c.toml: line 8: bench.limits[1]: expected an integer, found a string");
  EXPECT_EQ(message([&] { (void)bench.integers("range", 0, 1); }), "c.toml: line 9: bench.range[0]: expected an integer in 0 .. 1, found 2");
  EXPECT_EQ(message([&] { (void)r.required_numbers("weights"); }),
            "c.toml: weights: expected an array of numbers, found nothing (the key is required)");
}

TEST_F(TomlReaderTest, TypesIntegersChoicesAndTables) {
  EXPECT_EQ(message([&] { (void)bench.boolean("flag"); }), "c.toml: line 6: bench.flag: expected true or false, found a number");
  EXPECT_EQ(message([&] { (void)bench.choice("kind", {"virtual", "comedi", "none"}); }),
            "c.toml: line 7: bench.kind: expected \"virtual\", \"comedi\" or \"none\", found 'udp'");
  EXPECT_EQ(message([&] { (void)r.integer("count", 5, 9); }), "c.toml: line 2: count: expected an integer in 5 .. 9, found 3");
  const std::vector<TomlReader> units = r.tables("units");
  EXPECT_EQ(message([&] { (void)units[1].integer("id", 1, 7); }), "c.toml: line 14: units[1].id: expected an integer, found a number");
  EXPECT_EQ(message([&] { (void)units[1].required_table("frf").required_string("file", "the measurement file"); }),
            "c.toml: line 15: units[1].frf.file: expected a string, found a number");
  EXPECT_EQ(message([&] { (void)units[0].required_table("frf"); }),
            "c.toml: line 11: units[0].frf: expected a table [units[0].frf], found nothing (the table is required)");
  EXPECT_EQ(message([&] { (void)r.table("title"); }), "c.toml: line 1: title: expected a table, found a string");
  EXPECT_EQ(message([&] { (void)r.tables("bench"); }), "c.toml: line 3: bench: expected an array of tables ([[bench]]), found a table");
  EXPECT_EQ(message([&] { (void)r.string("count"); }), "c.toml: line 2: count: expected a string, found a number");
}

TEST_F(TomlReaderTest, UnknownKeysListTheKnownOnes) {
  EXPECT_EQ(message([&] { r.only({"title", "bench", "units"}); }), "c.toml: line 2: count: expected one of title, bench, units, found an unknown key");
  EXPECT_NO_THROW(r.only({"title", "count", "bench", "units"}));
}

TEST_F(TomlReaderTest, ErrorsAreInputErrorsWithFieldAndSource) {
  try {
    (void)bench.number("rate_Hz", NumberBounds::positive());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), "c.toml: line 5");
    EXPECT_EQ(e.field(), "bench.rate_Hz");
  }
}

TEST(TomlReaderKeyUnit, TheUnitAKeyEndsIn) {
  EXPECT_EQ(key_unit("fmin_Hz"), "Hz");
  EXPECT_EQ(key_unit("stiffness_N_per_um"), "N/um");
  EXPECT_EQ(key_unit("gravity_m_per_s2"), "m/s2");
  EXPECT_EQ(key_unit("stroke_min_um"), "um");
  EXPECT_EQ(key_unit("ramp_s"), "s");
  EXPECT_EQ(key_unit("gain"), "");
  EXPECT_EQ(key_unit("hpf_resistance_ohm"), "");
  EXPECT_EQ(key_unit("outlier_min_relative_deviation"), "");
  EXPECT_EQ(key_unit("de_m_rms"), "");
}

TEST(TomlReaderBounds, Words) {
  EXPECT_EQ(NumberBounds::any().describe(), "a number");
  EXPECT_EQ(NumberBounds::open(0, 1e13).describe("Pa"), "a number in (0, 1e+13) Pa");
  EXPECT_EQ((NumberBounds{-std::numeric_limits<double>::infinity(), 3, false, true}).describe(), "a number < 3");
  EXPECT_TRUE(NumberBounds::half_open(0, 1).contains(0.0));
  EXPECT_FALSE(NumberBounds::half_open(0, 1).contains(1.0));
  EXPECT_FALSE(NumberBounds::positive().contains(0.0));
}

}  // namespace
}  // namespace piezobench::io
