// Tests of the 2-DoF parameters TOML file.
#include "piezobench/apa/two_dof_file.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "piezobench/core/error.hpp"
#include "test_util.hpp"

namespace piezobench::apa {
namespace {

TEST(TwoDofFile, KeysOverrideTheDefaultsAndIntegersAreNumbers) {
  const TwoDofParams p = parse_two_dof_params("m = 5\nk1 = 0.5e6\n", "p.toml");
  EXPECT_EQ(p.m, 5.0);
  EXPECT_EQ(p.k1, 0.5e6);
  EXPECT_EQ(p.ke, TwoDofParams{}.ke);
}

TEST(TwoDofFile, BadKeysAndValuesNameTheFileAndKey) {
  test::expect_input_error([] { (void)parse_two_dof_params("mass = 5\n", "p.toml"); }, {"p.toml", "mass"});
  const std::string e = test::input_error([] { (void)parse_two_dof_params("m = \"5\"\n", "p.toml"); }, "m");
  EXPECT_TRUE(test::contains(e, "found a string")) << e;
  test::input_error([] { (void)parse_two_dof_params("m = -5\n", "p.toml"); }, "m");
  test::TempDir dir;
  test::input_error([&] { (void)read_two_dof_params(dir.path()); }, "file");
}

// Issue 21.2: the TOML limits apply here too.
TEST(TwoDofFile, DeepDottedKeyIsRefusedBeforeParsing) {
  std::string key = "m";
  for (int i = 0; i < 100000; ++i) key += ".m";
  test::expect_input_error([&] { (void)parse_two_dof_params(key + " = 1\n", "deep.toml"); }, {"deep.toml", "line 1", "parts"});
}

}  // namespace
}  // namespace piezobench::apa
