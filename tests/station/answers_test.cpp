#include "piezobench/station/answers.hpp"

#include <gtest/gtest.h>

#include "station_test_data.hpp"
#include "test_util.hpp"

namespace piezobench::station {
namespace {

using test::expect_input_error;
namespace fs = std::filesystem;

TEST(Answers, TheDocumentedExampleAnswersTheExampleStation) {
  const fs::path docs = fs::path(PIEZOBENCH_SOURCE_DIR) / "docs/examples";
  const StationFile st = read_station_file(docs / "station.toml");
  const Answers a = read_answers(docs / "station-answers.toml", st);
  EXPECT_EQ(a.operator_name, "A. Operator");
  ASSERT_EQ(a.phases.at("stiffness-open").steps.size(), 2U);
  EXPECT_EQ(a.phases.at("frf").on_check_fail, std::vector<CheckAnswer>{CheckAnswer::kRetry});
}

TEST(Answers, ATypoOrAMissingAnswerIsRefusedNamingTheLine) {
  const StationFile st = parse_station_file(testdata::kSmallStation, "st.toml");
  const fs::path f = "a.toml";
  // A phase name with a typo.
  expect_input_error([&] { parse_answers("operator = \"x\"\n\n[phases.strok]\nsteps = [\"confirm\"]\n", f, st); },
                     {"a.toml: line 3", "phases.strok", "a phase of st.toml (capacitance, stroke, hysteresis-20V)", "'strok'"});
  // A word that is not an answer.
  expect_input_error([&] { parse_answers("[phases.stroke]\nsteps = [\"confrim\"]\n", f, st); },
                     {"a.toml: line 2", "phases.stroke.steps[0]", "confirm or abort", "'confrim'"});
  // Too few answers.
  expect_input_error([&] { parse_answers("[phases.stroke]\nsteps = []\n", f, st); },
                     {"a.toml: line 2", "phases.stroke.steps", "each of the 1 operator steps", "station file line 20", "0 answers"});
  // No answers at all for a phase with operator steps.
  expect_input_error([&] { parse_answers("operator = \"x\"\n", f, st); }, {"a.toml", "phases.stroke", "no [phases.stroke] table"});
  // An unknown key.
  expect_input_error([&] { parse_answers("[phases.stroke]\nsteps = [\"confirm\"]\nretry = 1\n", f, st); },
                     {"line 3", "phases.stroke.retry", "an unknown key"});
  const Answers ok = parse_answers(testdata::kSmallAnswers, f, st);
  EXPECT_EQ(ok.phases.at("stroke").steps, std::vector<StepAnswer>{StepAnswer::kConfirm});
}

TEST(Answers, TypedValuesAndFilesAreRequiredWhereThePhaseNeedsThem) {
  test::TempDir dir;
  const std::string station = "name = \"s\"\n[[phases]]\nname = \"c\"\nexperiment = \"capacitance\"\nsource = \"typed\"\n"
                              "[[phases]]\nname = \"f\"\nexperiment = \"flatness\"\nsource = \"file\"\n";
  const StationFile st = parse_station_file(station, dir.path() / "st.toml");
  test::write_text(dir.path() / "probe.csv", "x,y,z\n0,0,0\n");
  expect_input_error([&] { parse_answers("[phases.c]\nsensor_uF = 4.9\n[phases.f]\nfile = \"probe.csv\"\n", dir.path() / "a.toml", st); },
                     {"phases.c.actuator_uF", "the capacitance typed in"});
  expect_input_error([&] { parse_answers("[phases.c]\nsensor_uF = 4.9\nactuator_uF = 9.8\n[phases.f]\nfile = \"nope.csv\"\n", dir.path() / "a.toml", st); },
                     {"phases.f.file", "does not exist"});
  const Answers a = parse_answers("[phases.c]\nsensor_uF = 4.9\nactuator_uF = 9.8\n[phases.f]\nfile = \"probe.csv\"\n", dir.path() / "a.toml", st);
  EXPECT_DOUBLE_EQ(*a.phases.at("c").actuator_uF, 9.8);
  EXPECT_EQ(*a.phases.at("f").file, dir.path() / "probe.csv");
}

}  // namespace
}  // namespace piezobench::station
