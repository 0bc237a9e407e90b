// Tests of the one TOML reader: the limits checked before toml++ parses, syntax errors naming the
// line, integers as numbers.
#include "piezobench/io/toml_table.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "piezobench/core/error.hpp"
#include "test_util.hpp"

namespace piezobench::io {
namespace {

namespace fs = std::filesystem;

std::string repeat(const std::string& part, int n) {
  std::string s;
  for (int i = 0; i < n; ++i) s += part;
  return s;
}

TEST(TomlDescribe, NamesEachKindOfValue) {
  const toml::table t = parse_toml("s = 'x'\ni = 3\nf = 1.5\nb = true\na = [1, 2, 3]\nt = {}\nd = 2024-01-01\n", "t.toml");
  EXPECT_EQ(describe_toml(*t.get("s")), "a string");
  EXPECT_EQ(describe_toml(*t.get("i")), "a number");
  EXPECT_EQ(describe_toml(*t.get("f")), "a number");
  EXPECT_EQ(describe_toml(*t.get("b")), "a boolean");
  EXPECT_EQ(describe_toml(*t.get("a")), "an array of 3");
  EXPECT_EQ(describe_toml(*t.get("t")), "a table");
  EXPECT_EQ(describe_toml(*t.get("d")), "a date or time");
}

// Issue 21.2: a header or dotted key with 100,000 parts overflowed the stack inside toml++.
TEST(TomlTable, DeepHeadersAndDottedKeysAreRefusedBeforeParsing) {
  const std::string header = "x = 1\n[a" + repeat(".a", 100000) + "]\n";
  const std::string e1 = test::input_error([&] { (void)parse_toml(header, "h.toml"); }, "line 2");
  EXPECT_TRUE(test::contains(e1, "h.toml")) << e1;
  EXPECT_TRUE(test::contains(e1, "more than 64 parts")) << e1;
  const std::string dotted = std::string("a") + repeat(".a", 100000) + " = 1\n";
  test::input_error([&] { (void)parse_toml(dotted, "d.toml"); }, "line 1");
  const std::string inline_key = "t = { a" + repeat(".b", 100) + " = 1 }\n";
  test::input_error([&] { (void)parse_toml(inline_key, "i.toml"); }, "line 1");
  const std::string nested = "v = " + repeat("[", 40) + repeat("]", 40) + "\n";
  const std::string e2 = test::input_error([&] { (void)parse_toml(nested, "n.toml"); }, "line 1");
  EXPECT_TRUE(test::contains(e2, "nested more than 32 deep")) << e2;
}

// 64 parts, 32 levels, and dots, brackets and newlines inside strings and comments are fine.
TEST(TomlTable, LimitsCountOnlyKeysAndValuesNotStringsOrComments) {
  const std::string key = std::string("a") + repeat(".a", 63);
  const std::string text = "[" + key + "]\n" + "s = \"" + repeat(".[{", 500) + "\"\n" + "m = '''\n" + repeat("a.b.[\n", 100) +
                           "'''\n# " + repeat(".", 1000) + "\n" + "v = " + repeat("[", 32) + repeat("]", 32) + "\n" +
                           "f = [1.5, 2.5, 3.5]\nt = {}\nu = { x = 1, y.z = [1, 2] }\n";
  const toml::table t = parse_toml(text, "ok.toml");
  const toml::node* leaf = &t;
  for (int i = 0; i < 64; ++i) leaf = leaf->as_table()->get("a");
  ASSERT_NE(leaf, nullptr);
  EXPECT_EQ(leaf->as_table()->get("f")->as_array()->size(), 3u);
  EXPECT_EQ(*leaf->as_table()->get("u")->as_table()->get("y")->as_table()->get("z")->as_array()->get(1)->value<int>(), 2);
  EXPECT_EQ(t.size(), 1u);
}

TEST(TomlTable, SyntaxErrorsNameTheLineAndColumn) {
  const std::string e = test::input_error([] { (void)parse_toml("a = 1\nb = = 2\n", "s.toml"); }, "line 2, column 5");
  EXPECT_TRUE(test::contains(e, "expected valid TOML")) << e;
}

TEST(TomlTable, FilesTooLargeMissingOrDirectoriesAreInputErrors) {
  test::TempDir dir;
  TomlLimits small;
  small.max_bytes = 100;
  std::ofstream(dir.path() / "big.toml") << "a = \"" << std::string(200, 'x') << "\"\n";
  const std::string e = test::input_error([&] { (void)read_toml_file(dir.path() / "big.toml", small); }, "file size");
  EXPECT_TRUE(test::contains(e, "at most 100 bytes")) << e;
  test::input_error([&] { (void)read_toml_file(dir.path()); }, "file");
  test::input_error([&] { (void)read_toml_file(dir.path() / "none.toml"); }, "file");
  std::ofstream(dir.path() / "ok.toml") << "a = 2\n";
  EXPECT_EQ(*toml_number(*read_toml_file(dir.path() / "ok.toml").get("a")), 2.0);
}

// Issue 21.8: 9223372036854775807 is an integer toml++ cannot give as an exact double; it is still
// a number (the nearest double), never "expected a number, found a number".
TEST(TomlTable, IntegersAreNumbersToTheNearestDouble) {
  const toml::table t = parse_toml("i = 9223372036854775807\nf = 2.5\ns = \"1\"\n", "n.toml");
  EXPECT_EQ(*toml_number(*t.get("i")), 9223372036854775807.0);
  EXPECT_EQ(*toml_number(*t.get("f")), 2.5);
  EXPECT_FALSE(toml_number(*t.get("s")).has_value());
  EXPECT_EQ(describe_toml(*t.get("s")), "a string");
}

}  // namespace
}  // namespace piezobench::io
