#include "piezobench/station/station_file.hpp"

#include <gtest/gtest.h>

#include "station_test_data.hpp"
#include "test_util.hpp"

namespace piezobench::station {
namespace {

using test::expect_input_error;
namespace fs = std::filesystem;

TEST(StationFile, TheDocumentedExampleIsValid) {
  const StationFile st = read_station_file(fs::path(PIEZOBENCH_SOURCE_DIR) / "docs/examples/station.toml");
  EXPECT_EQ(st.name, "APA300ML acceptance");
  ASSERT_EQ(st.phases.size(), 16U);
  EXPECT_EQ(st.phases[0].name, "flatness");
  EXPECT_EQ(st.phases[8].record, campaign::Experiment::kStiffnessOpen);
  EXPECT_EQ(st.phases[8].steps.size(), 2U);
  EXPECT_EQ(st.phases[10].record, campaign::Experiment::kFrfNoResistor);
  EXPECT_DOUBLE_EQ(*st.phases[11].gain, 30000.0);
  EXPECT_DOUBLE_EQ(st.phases[9].min_coherence, 0.9);
  // The limits the campaign can express become its [specs] (the acceptance `run` applies).
  const std::string specs = st.campaign_specs();
  EXPECT_TRUE(test::contains(specs, "flatness_um = 25\n")) << specs;
  EXPECT_TRUE(test::contains(specs, "capacitance_sensor_uF = [4, 6]\n")) << specs;
  EXPECT_TRUE(test::contains(specs, "stroke_min_um = 200\n")) << specs;
  EXPECT_TRUE(test::contains(specs, "stiffness_N_per_um = [1.5, 2.5]\n")) << specs;
  EXPECT_TRUE(test::contains(st.campaign_tables, "suspended_mass_kg = 5.7")) << st.campaign_tables;
}

TEST(StationFile, ProblemsNameTheLine) {
  const fs::path f = "st.toml";
  const std::string base = testdata::kSmallStation;
  expect_input_error([&] { parse_station_file(base + "[[phases]]\nname = \"x\"\nexperiment = \"stroke\"\n", f); },
                     {"st.toml: line", "phases[3].experiment", "one phase per record", "is phase 'stroke'"});
  expect_input_error([&] { parse_station_file(base + "[[phases]]\nname = \"stroke\"\nexperiment = \"hysteresis\"\n", f); },
                     {"phases[3].name", "not used before"});
  expect_input_error([&] { parse_station_file(base + "[[phases]]\nname = \"h\"\nexperiment = \"hysteresis\"\nampltude_V = 3\n", f); },
                     {"st.toml: line 39", "phases[3].ampltude_V", "an unknown key"});
  expect_input_error(
      [&] { parse_station_file(base + "[[phases]]\nname = \"k\"\nexperiment = \"stiffness\"\n[[phases.measurements]]\nname = \"k3_N_per_um\"\n", f); },
      {"st.toml: line 40", "phases[3].measurements[0].name", "k1_N_per_um, k2_N_per_um", "'k3_N_per_um'"});
  expect_input_error(
      [&] { parse_station_file(base + "[[phases]]\nname = \"s\"\nexperiment = \"stiffness\"\n[[phases.measurements]]\nname = \"k1_N_per_um\"\nmin = 3\nmax = 2\n", f); },
      {"measurements[0].max", "a maximum >= the minimum 3"});
  expect_input_error([&] { parse_station_file(base + "[[phases]]\nname = \"i\"\nexperiment = \"iff\"\n", f); }, {"phases[3].gain", "IFF gain"});
  expect_input_error([&] { parse_station_file(base + "[[phases]]\nname = \"s2\"\nexperiment = \"stroke\"\nduration_s = 3\n", f); },
                     {"phases[3].settings", "duration"});
  expect_input_error([&] { parse_station_file(base + "[[phases]]\nname = \"h\"\nexperiment = \"hysteresis\"\namplitude_V = 3\nretries = 9223372036854775807\n", f); },
                     {"line 40", "phases[3].retries", "an integer in 0 .. 20", "9223372036854775807"});
  expect_input_error([&] { parse_station_file("name = \"x\"\n[campaign.bench]\namplifier_gane = 3\n[[phases]]\nname = \"a\"\nexperiment = \"stroke\"\n", f); },
                     {"st.toml: campaign", "amplifier_gane"});
}

}  // namespace
}  // namespace piezobench::station
