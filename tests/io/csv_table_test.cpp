// The CSV table reader: dialects detected and forced, units in headers, messages that say which
// dialect was used.
#include "csv_table.hpp"

#include "piezobench/io/timeseries.hpp"

#include <gtest/gtest.h>

#include "test_util.hpp"

namespace piezobench::io::detail {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

struct Parsed {
  char delimiter;
  char decimal;
  std::vector<CsvColumn> columns;
  Eigen::MatrixXd data;
};

Parsed parse(const std::string& text, CsvDialect dialect = {}) {
  TempDir dir;
  const fs::path file = dir.path() / "x.csv";
  test::write_text(file, text);
  const CsvTable t(file, dialect);
  std::vector<int> target;
  for (size_t c = 0; c < t.columns().size(); ++c) target.push_back(static_cast<int>(c));
  return {t.delimiter(), t.decimal(), t.columns(), t.read(target, static_cast<Eigen::Index>(target.size()))};
}

TEST(CsvTable, DetectsEachDelimiterAndTheDecimalComma) {
  struct Case {
    const char* text;
    char delimiter;
    char decimal;
  };
  const Case cases[] = {
      {"a,b\n1.5,2\n", ',', '.'},
      {"a;b\n1.5;2\n", ';', '.'},
      {"a;b\n1,5;2\n", ';', ','},
      {"a\tb\n1,5\t2\n", '\t', ','},
      {"a\tb\n1.5\t2\n", '\t', '.'},
      {"a  b\n 1.5   2\n", ' ', '.'},
      {"\xEF\xBB\xBF" "a,b\r\n1.5,2\r\n", ',', '.'},  // byte order mark, CRLF
  };
  for (const Case& c : cases) {
    const Parsed p = parse(c.text);
    EXPECT_EQ(p.delimiter, c.delimiter) << c.text;
    EXPECT_EQ(p.decimal, c.decimal) << c.text;
    ASSERT_EQ(p.columns.size(), 2u) << c.text;
    EXPECT_EQ(p.columns[0].name, "a");
    EXPECT_EQ(p.data(0, 0), 1.5) << c.text;
    EXPECT_EQ(p.data(0, 1), 2.0) << c.text;
  }
}

TEST(CsvTable, UnitsInBracketsOrParenthesesAlsoWhenBlankSeparated) {
  const Parsed p = parse("Time [ms]  u (V)  d_e [um]  x\n0 1 2 3\n");
  ASSERT_EQ(p.columns.size(), 4u);
  EXPECT_EQ(p.columns[0].name, "Time");
  EXPECT_EQ(p.columns[0].unit, "ms");
  EXPECT_EQ(p.columns[1].name, "u");
  EXPECT_EQ(p.columns[1].unit, "V");
  EXPECT_EQ(p.columns[2].unit, "um");
  EXPECT_EQ(p.columns[3].unit, "");
}

TEST(CsvTable, ForcedDialectWins) {
  // One column named "a;b" when ',' is forced, and a decimal comma read as such when forced.
  test::expect_input_error([] { (void)parse("a;b\n1;2\n", {',', '.'}); },
                           {"a;b (line 2)", "','-separated, decimal point)", "'1;2'"});
  const Parsed forced = parse("a;b\n1,5;2\n", {';', ','});
  EXPECT_EQ(forced.data(0, 0), 1.5);
  test::expect_input_error([] { (void)parse("a,b\n1,2\n", {',', ','}); }, {"decimal", "',' for both"});
}

TEST(CsvTable, MessagesSayWhichDialectWasUsed) {
  TempDir dir;
  const fs::path file = dir.path() / "m.csv";
  test::write_text(file, "u;d_e\n1,5;2\n3;4;5\n");
  const CsvTable t(file, {});
  test::expect_input_error([&] { (void)t.read({0, 1}, 2); },
                           {"m.csv", "line 3", "2 fields", "';'-separated (detected), decimal comma (detected)", "found 3"});
  test::write_text(file, "u,d_e\n1.5,2\n3,4;5\n");
  const CsvTable u(file, {});
  test::expect_input_error([&] { (void)u.read({0, 1}, 2); }, {"d_e (line 3)", "a number", "','-separated (detected)", "'4;5'"});
}

TEST(CsvTable, OptionSpellings) {
  EXPECT_EQ(io::csv_delimiter_from_string("auto"), 0);
  EXPECT_EQ(io::csv_delimiter_from_string("tab"), '\t');
  EXPECT_EQ(io::csv_delimiter_from_string(";"), ';');
  EXPECT_EQ(io::csv_delimiter_from_string("space"), ' ');
  EXPECT_EQ(io::csv_decimal_from_string(","), ',');
  EXPECT_EQ(io::csv_decimal_from_string("point"), '.');
  test::expect_input_error([] { (void)io::csv_delimiter_from_string("|"); }, {"--delimiter", "'|'"});
  test::expect_input_error([] { (void)io::csv_decimal_from_string(";"); }, {"--decimal"});
}

}  // namespace
}  // namespace piezobench::io::detail
