#include "piezobench/io/json.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace piezobench::io {
namespace {

TEST(Json, ComplexNumbersArePairs) {
  EXPECT_EQ(to_json(std::complex<double>(1.5, -2.0)).dump(), "[1.5,-2.0]");
  Eigen::VectorXcd v(2);
  v << std::complex<double>(0, 1), std::complex<double>(3, 0);
  EXPECT_EQ(to_json(v).dump(), "[[0.0,1.0],[3.0,0.0]]");
}

TEST(Json, NonFiniteNumbersBecomeStrings) {
  EXPECT_EQ(to_json(std::numeric_limits<double>::infinity()).dump(), "\"inf\"");
  EXPECT_EQ(to_json(-std::numeric_limits<double>::infinity()).dump(), "\"-inf\"");
  EXPECT_EQ(to_json(std::numeric_limits<double>::quiet_NaN()).dump(), "\"nan\"");
}

TEST(Json, DoublesRoundTripExactly) {
  const double x = 0.1 + 0.2;
  EXPECT_EQ(nlohmann::json::parse(to_json(x).dump()).get<double>(), x);
}

TEST(Json, MatricesAreListsOfRows) {
  Eigen::MatrixXd m(2, 3);
  m << 1, 2, 3, 4, 5, 6;
  EXPECT_EQ(to_json(m).dump(), "[[1.0,2.0,3.0],[4.0,5.0,6.0]]");
  EXPECT_EQ(to_json(std::vector<double>{1.0, 2.5}).dump(), "[1.0,2.5]");
}

}  // namespace
}  // namespace piezobench::io
