// End-to-end tests of `piezobench twin`: a twin built from records the virtual bench wrote (the
// records form), the file used by `simulate --twin`, `measure --bench` ([virtual] twin) and refused
// when it is bad; the command line's refusals.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "run_cli.hpp"
#include "test_util.hpp"

namespace piezobench {
namespace {

using test::run_cli;

TEST(TwinCli, FromRecordsThenSimulateAndMeasureOnIt) {
  test::TempDir dir;
  const auto file = [&](const std::string& name) { return (dir.path() / name).string(); };
  ASSERT_EQ(run_cli("simulate frf-noise --unit 4 --duration 20 --out " + file("frf.mat")).exit_code, 0);
  ASSERT_EQ(run_cli("simulate hysteresis --unit 4 --amplitude 20 --out " + file("h20.mat")).exit_code, 0);
  ASSERT_EQ(run_cli("simulate hysteresis --unit 4 --amplitude 80 --out " + file("h80.mat")).exit_code, 0);
  ASSERT_EQ(run_cli("simulate stiffness --unit 4 --out " + file("stiff.mat")).exit_code, 0);
  ASSERT_EQ(run_cli("simulate capacitance --unit 4 --out " + file("cap.mat")).exit_code, 0);
  const test::CliRun t = run_cli("twin --unit 4 --frf " + file("frf.mat") + " --hysteresis " + file("h20.mat") + "," + file("h80.mat") +
                                 " --stiffness " + file("stiff.mat") + " --capacitance " + file("cap.mat") + " --out " + file("twin.toml") +
                                 " --json");
  ASSERT_TRUE(t.exit_code == 0 || t.exit_code == 6) << t.err;  // 6: a check above its limit (a 20 s FRF)
  const auto j = nlohmann::json::parse(t.out);
  EXPECT_EQ(j["unit"], 4);
  // The document's keys, as scripts read them: TwinBuild's declared fields (campaign/twin.hpp), the
  // file and the model.
  std::set<std::string> keys;
  for (const auto& [k, v] : j.items()) keys.insert(k);
  EXPECT_EQ(keys, (std::set<std::string>{"file", "model", "unit", "name", "chain", "frf_error", "frf_error_tuned", "hysteresis",
                                         "hysteresis_thresholds_V", "hysteresis_weights", "creep", "noise", "iff", "notes", "seconds",
                                         "quality", "quality_problems", "quality_advice", "quality_impossible"}));
  EXPECT_EQ(j["model"].size(), 8u);
  EXPECT_EQ(j["creep"].size(), 4u);
  EXPECT_EQ(j["noise"][0].size(), 6u);  // channel, measured, source, seconds, measured_rms, white_rms (not the spectrum)
  EXPECT_LT(j["frf_error"]["de"]["median_dB"].get<double>(), 0.5);
  EXPECT_LT(j["frf_error"]["Vs"]["median_dB"].get<double>(), 0.5);
  EXPECT_EQ(j["hysteresis"].size(), 2u);
  EXPECT_EQ(j["hysteresis_weights"].size(), 8u);
  EXPECT_GT(j["iff"]["optimal_gain"].get<double>(), 1e5);
  // The stiffness record's first 3 s are d_e's quiet segment; Vs has none (a note says so).
  EXPECT_TRUE(j["noise"][0]["measured"].get<bool>());
  EXPECT_FALSE(j["noise"][1]["measured"].get<bool>());
  EXPECT_TRUE(test::contains(j["notes"].dump(), "no quiet segment of Vs"));

  const test::CliRun s = run_cli("simulate frf-noise --twin " + file("twin.toml") + " --duration 2 --out " + file("tf.mat") + " --json");
  ASSERT_EQ(s.exit_code, 0) << s.err;
  EXPECT_EQ(nlohmann::json::parse(s.out)["unit"], 4);

  test::write_text(dir.path() / "bench.toml", "[bench]\nbackend = \"virtual\"\nsample_rate_Hz = 10000\n\n[virtual]\ntwin = \"twin.toml\"\n");
  const test::CliRun m = run_cli("measure hysteresis --bench " + file("bench.toml") + " --amplitude 40 --out " + file("m40.mat"));
  EXPECT_EQ(m.exit_code, 0) << m.err;

  test::write_text(dir.path() / "bad.toml", "format = \"piezobench-twin-1\"\nname = \"x\"\nunit = 1\n");
  const test::CliRun bad = run_cli("simulate frf-noise --twin " + file("bad.toml") + " --duration 1 --out " + file("x.mat"));
  EXPECT_EQ(bad.exit_code, 3);
  EXPECT_TRUE(test::contains(bad.err, "model")) << bad.err;
}

TEST(TwinCli, RefusesAMissingFrfOrBothForms) {
  EXPECT_EQ(run_cli("twin --out /dev/null").exit_code, 2);
  EXPECT_EQ(run_cli("twin campaign.toml --frf frf.mat").exit_code, 2);
  EXPECT_EQ(run_cli("twin --frf /nonexistent/frf.mat --out /dev/null").exit_code, 3);
}

}  // namespace
}  // namespace piezobench
