// Tests for src/lti/state_space.cpp: construction, delays, validation.
#include "piezobench/lti/state_space.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "piezobench/core/error.hpp"
#include "test_util.hpp"

namespace piezobench::lti {
namespace {

StateSpace two_states() {
  Matrix a(2, 2), b(2, 1), c(1, 2), d(1, 1);
  a << 0.0, 1.0, -4.0, -0.4;
  b << 0.0, 1.0;
  c << 1.0, 0.0;
  d << 0.0;
  return StateSpace(a, b, c, d);
}

using test::input_error;

TEST(StateSpace, SizesAndKind) {
  const StateSpace sys = two_states();
  EXPECT_EQ(sys.states(), 2);
  EXPECT_EQ(sys.inputs(), 1);
  EXPECT_EQ(sys.outputs(), 1);
  EXPECT_FALSE(sys.is_discrete());
  EXPECT_FALSE(sys.has_delay());
  const StateSpace d(Matrix::Identity(2, 2) * 0.5, Matrix::Ones(2, 3), Matrix::Ones(4, 2), Matrix::Zero(4, 3), 1e-3);
  EXPECT_TRUE(d.is_discrete());
  EXPECT_EQ(d.inputs(), 3);
  EXPECT_EQ(d.outputs(), 4);
}

TEST(StateSpace, StaticGainAndEmptyShapes) {
  Matrix k(2, 3);
  k << 1, 2, 3, 4, 5, 6;
  const StateSpace g = StateSpace::gain(k, 1e-4);
  EXPECT_EQ(g.states(), 0);
  EXPECT_EQ(g.inputs(), 3);
  EXPECT_EQ(g.outputs(), 2);
  EXPECT_EQ(g.B.rows(), 0);
  EXPECT_EQ(g.B.cols(), 3);
  EXPECT_EQ(g.C.rows(), 2);
  EXPECT_EQ(g.sample_time, 1e-4);
  EXPECT_EQ(g.D, k);
  // No states: B and C may be given as 0x0.
  const StateSpace e(Matrix(0, 0), Matrix(0, 0), Matrix(0, 0), k);
  EXPECT_EQ(e.inputs(), 3);
  EXPECT_EQ(e.B.cols(), 3);
  // States but an empty D: no feedthrough.
  const StateSpace nd(Matrix::Identity(2, 2), Matrix::Ones(2, 3), Matrix::Ones(1, 2), Matrix());
  EXPECT_EQ(nd.D, Matrix::Zero(1, 3));
}

TEST(StateSpace, DelaysPerChannel) {
  StateSpace sys(Matrix::Identity(1, 1), Matrix::Ones(1, 2), Matrix::Ones(3, 1), Matrix::Zero(3, 2));
  EXPECT_EQ(sys.channel_delay(2, 1), 0.0);
  sys.input_delay = Vector{{0.0, 0.25}};
  EXPECT_TRUE(sys.has_delay());
  sys.output_delay = Vector{{0.5, 0.0, 0.125}};
  EXPECT_EQ(sys.channel_delay(0, 0), 0.5);
  EXPECT_EQ(sys.channel_delay(2, 1), 0.375);
  EXPECT_EQ(sys.channel_delay(1, 1), 0.25);
  sys.validate();
  sys.input_delay = Vector::Zero(2);
  sys.output_delay = Vector::Zero(3);
  EXPECT_FALSE(sys.has_delay());
  input_error([&] { (void)sys.channel_delay(3, 0); }, "output");
  input_error([&] { (void)sys.channel_delay(0, -1); }, "input");
}

TEST(StateSpace, ValidateNamesTheBadField) {
  const std::string msg = input_error(
      [] { StateSpace(Matrix::Zero(2, 3), Matrix::Zero(2, 1), Matrix::Zero(1, 2), Matrix::Zero(1, 1)); }, "A");
  EXPECT_NE(msg.find("square"), std::string::npos);
  EXPECT_NE(msg.find("2x3"), std::string::npos);
  input_error([] { StateSpace(Matrix::Zero(2, 2), Matrix::Zero(3, 1), Matrix::Zero(1, 2), Matrix::Zero(1, 1)); }, "B");
  input_error([] { StateSpace(Matrix::Zero(2, 2), Matrix::Zero(2, 1), Matrix::Zero(1, 3), Matrix::Zero(1, 1)); }, "C");
  input_error([] { StateSpace(Matrix::Zero(2, 2), Matrix::Zero(2, 1), Matrix::Zero(1, 2), Matrix::Zero(2, 1)); }, "D");
  input_error([] { StateSpace(Matrix::Zero(2, 2), Matrix::Zero(2, 1), Matrix::Zero(1, 2), Matrix::Zero(1, 2)); }, "D");

  StateSpace sys = two_states();
  sys.A(0, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(input_error([&] { sys.validate("plant.mat"); }, "A(0, 1)").find("plant.mat"), std::string::npos);
  sys = two_states();
  sys.C(0, 1) = std::numeric_limits<double>::infinity();
  input_error([&] { sys.validate(); }, "C(0, 1)");
  sys = two_states();
  sys.sample_time = -1e-3;
  input_error([&] { sys.validate(); }, "sample_time");
  sys = two_states();
  sys.input_delay = Vector::Zero(2);
  EXPECT_NE(input_error([&] { sys.validate(); }, "input_delay").find("found 2 entries"), std::string::npos);
  sys.input_delay = Vector::Constant(1, -0.1);
  input_error([&] { sys.validate(); }, "input_delay(0)");
  sys.input_delay.resize(0);
  sys.output_delay = Vector::Constant(1, std::numeric_limits<double>::quiet_NaN());
  input_error([&] { sys.validate(); }, "output_delay(0)");
  sys.output_delay = Vector::Zero(3);
  input_error([&] { sys.validate(); }, "output_delay");
}

}  // namespace
}  // namespace piezobench::lti
