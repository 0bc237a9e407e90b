#include "toml_reader.hpp"

#include <gtest/gtest.h>

#include "piezobench/io/toml_table.hpp"
#include "test_util.hpp"

namespace piezobench::station::detail {
namespace {

using test::expect_input_error;

TEST(StationTomlReader, ErrorsNameTheFileTheLineAndTheFullKey) {
  const toml::table t = io::parse_toml("a = 1\n\n[[p]]\nname = \"x\"\nretries = -1\n", "s.toml");
  const TableReader r(t, "s.toml", "");
  const auto phases = r.tables("p");
  ASSERT_EQ(phases.size(), 1U);
  expect_input_error([&] { (void)phases[0].integer("retries", 0); }, {"s.toml: line 5", "p[0].retries", "an integer >= 0", "-1"});
  expect_input_error([&] { r.only({"p"}); }, {"s.toml: line 1", "a: expected one of p", "an unknown key"});
  expect_input_error([&] { (void)phases[0].number("name"); }, {"line 4", "p[0].name", "a number", "a string"});
  EXPECT_EQ(*phases[0].text("name"), "x");
  EXPECT_FALSE(phases[0].flag("missing").has_value());
}

TEST(StationTomlReader, ArraysOfStringsAndSubTables) {
  const toml::table t = io::parse_toml("s = [\"a\", 2]\n[x]\ny = true\n", "f.toml");
  const TableReader r(t, "f.toml", "");
  expect_input_error([&] { (void)r.texts("s"); }, {"line 1", "s[1]", "a string"});
  EXPECT_EQ(*r.sub("x")->flag("y"), true);
  EXPECT_EQ(r.sub("x")->key("y"), "x.y");
}

}  // namespace
}  // namespace piezobench::station::detail
