// Tests of the private MAT-file layer's helpers (reading and writing are tested through
// mat_reader_test, timeseries_test and frf_file_test).
#include "io/mat_file.hpp"

#include <gtest/gtest.h>

namespace piezobench::io::detail {
namespace {

TEST(MatlabIdentifier, FollowsMatlabRules) {
  EXPECT_TRUE(is_matlab_identifier("d_enc2"));
  EXPECT_FALSE(is_matlab_identifier("2d"));
  EXPECT_FALSE(is_matlab_identifier("_x"));
  EXPECT_FALSE(is_matlab_identifier("a b"));
  EXPECT_FALSE(is_matlab_identifier(std::string(64, 'a')));
  EXPECT_TRUE(is_matlab_identifier(std::string(63, 'a')));
}

}  // namespace
}  // namespace piezobench::io::detail
