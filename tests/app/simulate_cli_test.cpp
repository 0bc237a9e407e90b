// End-to-end tests of `piezobench simulate`: the files it writes, its JSON summary with the unit's
// truth, reproducibility, and how it refuses bad input.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "piezobench/io/timeseries.hpp"
#include "run_cli.hpp"
#include "test_util.hpp"

namespace piezobench {
namespace {

using test::run_cli;

TEST(SimulateCli, FrfNoiseWritesTheMatFileAndSummarizesIt) {
  test::TempDir dir;
  const std::string mat = (dir.path() / "frf.mat").string();
  const test::CliRun r = run_cli("simulate frf-noise --unit 2 --seed 5 --duration 2 --out " + mat + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["file"], mat);
  EXPECT_EQ(j["experiment"], "frf-noise");
  EXPECT_EQ(j["unit"], 2);
  EXPECT_EQ(j["seed"], 5);
  EXPECT_EQ(j["samples"], 20000);
  EXPECT_EQ(j["channels"], nlohmann::json({"u", "Va", "de", "Vs"}));
  EXPECT_EQ(j["units"]["de"], "m");
  EXPECT_EQ(j["settings"]["duration_s"], 2.0);
  EXPECT_EQ(j["settings"]["nmp_zero"], 1.0);
  EXPECT_NEAR(j["truth"]["resonance_Hz"].get<double>(), 95.0, 3.0);
  EXPECT_TRUE(j["truth"]["zero_is_nonminimum_phase"].get<bool>());
  const io::TimeSeries ts = io::read_timeseries(mat);
  EXPECT_EQ(ts.samples(), 20000);
  EXPECT_EQ(ts.sample_rate, 10000.0);
  EXPECT_EQ(ts.unit("Vs"), "V");
  EXPECT_EQ(std::get<std::string>(ts.settings.at("experiment")), "frf-noise");
  (void)ts.channel("u");
  (void)ts.channel("Va");
  (void)ts.channel("de");
}

TEST(SimulateCli, SameSeedSameFileAndSwitchesAreRecorded) {
  test::TempDir dir;
  const auto file = [&](const std::string& name) { return (dir.path() / name).string(); };
  ASSERT_EQ(run_cli("simulate hysteresis --amplitude 40 --seed 3 --out " + file("a.csv")).exit_code, 0);
  ASSERT_EQ(run_cli("simulate hysteresis --amplitude 40 --seed 3 --out " + file("b.csv")).exit_code, 0);
  ASSERT_EQ(run_cli("simulate hysteresis --amplitude 40 --seed 4 --out " + file("c.csv")).exit_code, 0);
  EXPECT_EQ(test::read_text(file("a.csv")), test::read_text(file("b.csv")));
  EXPECT_NE(test::read_text(file("a.csv")), test::read_text(file("c.csv")));
  EXPECT_TRUE(test::contains(test::read_text(file("a.csv")), "de [m]"));
  const test::CliRun r = run_cli("simulate stiffness --no-creep --no-hysteresis --no-noise --no-delay --no-nmp-zero --out " +
                                 file("s.mat") + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["settings"]["creep"], 0.0);
  EXPECT_EQ(j["settings"]["noise"], 0.0);
  EXPECT_EQ(j["settings"]["nmp_zero"], 0.0);
  EXPECT_DOUBLE_EQ(j["settings"]["delay_s"].get<double>(), 50e-6);  // only the DAC's hold
  EXPECT_FALSE(j["truth"]["zero_is_nonminimum_phase"].get<bool>());
}

TEST(SimulateCli, TextSummaryWithoutJson) {
  test::TempDir dir;
  const test::CliRun r = run_cli("simulate capacitance --unit 3 --out " + (dir.path() / "c.mat").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(test::contains(r.out, "capacitance on unit 3 (defective)")) << r.out;
}

TEST(SimulateCli, RefusesBadInput) {
  test::TempDir dir;
  const std::string out = " --out " + (dir.path() / "x.mat").string();
  test::CliRun r = run_cli("simulate frf" + out);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(test::contains(r.err, "frf-noise")) << r.err;  // the known names are listed
  r = run_cli("simulate stroke --unit 9" + out);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(test::contains(r.err, "1 to 7")) << r.err;
  r = run_cli("simulate frf-noise --duration -5" + out);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(test::contains(r.err, "--duration")) << r.err;
  r = run_cli("simulate hysteresis --amplitude 90" + out);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(test::contains(r.err, "--amplitude")) << r.err;
  EXPECT_TRUE(test::contains(r.err, "85 V")) << r.err;  // the limit is named
  r = run_cli("simulate stroke --amplitude 10" + out);
  EXPECT_EQ(r.exit_code, 2);
  r = run_cli("simulate frf-noise --duration abc" + out);
  EXPECT_EQ(r.exit_code, 2);
  r = run_cli("simulate frf-noise --duration 1 --out " + (dir.path() / "missing" / "x.mat").string());
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "x.mat"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "missing"));
}

}  // namespace
}  // namespace piezobench
