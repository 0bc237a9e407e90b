// End-to-end tests of `piezobench superelement update`: the shipped APA300ML super element updated
// against a results.json of two accepted units (a third, rejected, is left out), its exit codes.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "run_cli.hpp"
#include "test_util.hpp"

namespace piezobench {
namespace {

using test::run_cli;
namespace fs = std::filesystem;

const std::string kStacks = " --stack 40895:40899:29.4e9,0.31,7800,1e-4 --stack 40899:40897:29.4e9,0.31,7800,1e-4";

fs::path write_batch(const test::TempDir& dir) {
  const fs::path d = fs::path(PIEZOBENCH_SOURCE_DIR) / "data/superelement/apa300ml";
  test::write_text(dir.path() / "c.toml", "[[units]]\nid = 1\n[superelement]\nk_file = \"" + (d / "apa300ml_K.mtx").string() + "\"\nm_file = \"" +
                                              (d / "apa300ml_M.mtx").string() + "\"\nnodes_file = \"" + (d / "apa300ml_dofs.txt").string() +
                                              "\"\nfix = [40893]\nactuator = \"40895:40899:x\"\nsensor = \"40899:40897:x\"\noutput = \"40891:y\"\n");
  test::write_text(dir.path() / "r.json",
                   R"({"campaign": "c.toml", "units": [{"name": "A", "accepted": true, "frf": {"resonance_Hz": 100.0, "antiresonance_Hz": 40.0}},
                      {"name": "B", "accepted": true, "frf": {"resonance_Hz": 100.5, "antiresonance_Hz": 40.1}},
                      {"name": "C", "accepted": false, "frf": {"resonance_Hz": 50.0, "antiresonance_Hz": 20.0}}]})");
  return dir.path() / "r.json";
}

// The two accepted units' geometric means (100.25, 40.05 Hz) are met; scipy's update to 100 and
// 40 Hz (tests/campaign/superelement_update_test.cpp) gives shell x 0.9470 and stacks x 1.2227,
// so these scales lie within a per cent of it; the standard errors are finite and positive.
TEST(SuperElementUpdateCli, UpdatesTheShippedElementAgainstTheAcceptedUnits) {
  test::TempDir dir;
  const fs::path results = write_batch(dir);
  const test::CliRun r = run_cli("superelement update " + results.string() + kStacks + " --shell-modulus 210.8e9 --json --out " +
                                 (dir.path() / "updated").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["units"], 2);
  EXPECT_NEAR(j["updated"]["resonance_Hz"].get<double>(), std::sqrt(100.0 * 100.5), 1e-6);
  EXPECT_NEAR(j["updated"]["antiresonance_Hz"].get<double>(), std::sqrt(40.0 * 40.1), 1e-6);
  EXPECT_NEAR(j["parameters"][0]["scale"].get<double>(), 0.9470, 0.01);
  EXPECT_NEAR(j["parameters"][1]["scale"].get<double>(), 1.2227, 0.015);
  EXPECT_NEAR(j["parameters"][0]["modulus_Pa"].get<double>(), 210.8e9 * j["parameters"][0]["scale"].get<double>(), 1.0);
  for (const auto& p : j["parameters"]) EXPECT_GT(p["standard_error"].get<double>(), 0.0);
  EXPECT_EQ(j["rank"], 2);
  EXPECT_TRUE(fs::exists(dir.path() / "updated" / "updated_K.mtx"));
  const test::CliRun text = run_cli("superelement update " + results.string() + kStacks);
  EXPECT_EQ(text.exit_code, 0);
  EXPECT_TRUE(test::contains(text.out, "correlation shell / stacks")) << text.out;
}

TEST(SuperElementUpdateCli, RefusesUndeterminedParametersAndBadInput) {
  test::TempDir dir;
  const fs::path results = write_batch(dir);
  const test::CliRun three = run_cli("superelement update " + results.string() + kStacks +
                                     " --parameter shell --parameter stack:40895:40899 --parameter stack:40899:40897");
  EXPECT_EQ(three.exit_code, 3);
  EXPECT_TRUE(test::contains(three.err, "is not determined by the data")) << three.err;
  EXPECT_EQ(run_cli("superelement update " + results.string()).exit_code, 2);  // --stack is required
  EXPECT_EQ(run_cli("superelement update /nonexistent/results.json" + kStacks).exit_code, 3);
  test::write_text(dir.path() / "bad.json", "{\"units\": [");
  EXPECT_EQ(run_cli("superelement update " + (dir.path() / "bad.json").string() + kStacks).exit_code, 3);
}

}  // namespace
}  // namespace piezobench
