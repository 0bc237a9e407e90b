#include <gtest/gtest.h>

#include <sstream>

#include "piezobench/station/phase_runner.hpp"
#include "station_test_data.hpp"
#include "test_util.hpp"

namespace piezobench::station {
namespace {

TEST(Operator, TheTerminalAsksUntilItGetsAnAnswer) {
  const StationFile st = parse_station_file(testdata::kSmallStation, "st.toml");
  const PhaseSpec& stroke = *st.phase("stroke");
  std::istringstream in("what\ny\nx\nr\nc\n");
  std::ostringstream out;
  TerminalOperator op(in, out, "me");
  EXPECT_EQ(op.step(stroke, 0), StepAnswer::kConfirm);
  EXPECT_TRUE(test::contains(out.str(), "phase stroke (1/1): mount the actuator; [y] confirm")) << out.str();
  EXPECT_EQ(op.check_failed(stroke, 1, "saturation"), CheckAnswer::kRetry);
  EXPECT_EQ(op.check_failed(stroke, 2, "saturation"), CheckAnswer::kContinue);
  EXPECT_EQ(op.step(stroke, 0), StepAnswer::kAbort);  // the end of the input aborts
  EXPECT_EQ(op.name(), "me");
}

TEST(Operator, TypedCapacitancesOnTheTerminal) {
  const StationFile st = parse_station_file("name = \"s\"\n[[phases]]\nname = \"c\"\nexperiment = \"capacitance\"\nsource = \"typed\"\n", "st.toml");
  std::istringstream in("4.95\n9.9\n");
  std::ostringstream out;
  TerminalOperator op(in, out, "");
  const PhaseValues v = op.values(st.phases[0]);
  EXPECT_DOUBLE_EQ(*v.sensor_uF, 4.95);
  EXPECT_DOUBLE_EQ(*v.actuator_uF, 9.9);
  std::istringstream bad("4.9x\n");
  TerminalOperator op2(bad, out, "");
  test::expect_input_error([&] { (void)op2.values(st.phases[0]); }, {"c.sensor_uF", "a capacitance > 0 in uF", "'4.9x'"});
}

TEST(Operator, AnswersAreUsedInOrderThenContinue) {
  const StationFile st = parse_station_file(testdata::kSmallStation, "st.toml");
  AnswersOperator op(parse_answers("operator = \"A\"\n[phases.stroke]\nsteps = [\"abort\"]\non_check_fail = [\"retry\", \"abort\"]\n", "a.toml", st));
  const PhaseSpec& stroke = *st.phase("stroke");
  EXPECT_EQ(op.step(stroke, 0), StepAnswer::kAbort);
  EXPECT_EQ(op.check_failed(stroke, 1, ""), CheckAnswer::kRetry);
  EXPECT_EQ(op.check_failed(stroke, 2, ""), CheckAnswer::kAbort);
  EXPECT_EQ(op.check_failed(stroke, 3, ""), CheckAnswer::kContinue);
  EXPECT_EQ(op.check_failed(*st.phase("capacitance"), 1, ""), CheckAnswer::kContinue);
  EXPECT_EQ(op.name(), "A");
}

}  // namespace
}  // namespace piezobench::station
