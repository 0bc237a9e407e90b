// `piezobench demo` and `piezobench run` end to end.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <nlohmann/json.hpp>

#include "app/run_cli.hpp"
#include "piezobench/io/output_dir.hpp"
#include "piezobench/io/timeseries.hpp"
#include "test_util.hpp"

namespace piezobench::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// One demo run shared by the tests below: units 1 (with the IFF records) and 3 (defective).
const fs::path& demo_dir() {
  static const TempDir dir;  // lives for the whole test program, removed at its exit (63 MB)
  static bool done = false;
  if (!done) {
    const CliRun r = run_cli("demo --fast --units 1,3 --threads 2 --out " + dir.path().string());
    EXPECT_EQ(r.exit_code, 0) << r.err;
    done = true;
  }
  return dir.path();
}

TEST(RunCli, DemoWritesDataCampaignAndReport) {
  const fs::path& d = demo_dir();
  for (const char* f : {"campaign.toml", "data/truth.json", "data/unit1_frf-noise.mat", "data/unit3_stroke.mat",
                        "data/unit1_iff_g30000.mat", "results.json", "results.mat", "report.html"}) {
    EXPECT_TRUE(fs::exists(d / f)) << f;
  }
  const json r = json::parse(read_text(d / "results.json"));
  ASSERT_EQ(r["units"].size(), 2u);
  EXPECT_TRUE(r["units"][0]["accepted"].get<bool>());
  EXPECT_FALSE(r["units"][1]["accepted"].get<bool>());
  EXPECT_FALSE(r["iff"]["optimal_gain"].is_null());
  // --strict turns the rejection into exit code 5; --json prints the results.
  TempDir out;
  const CliRun strict = run_cli("run " + (d / "campaign.toml").string() + " --strict --json --out " + out.path().string());
  EXPECT_EQ(strict.exit_code, 5) << strict.err;
  const json printed = json::parse(strict.out);
  EXPECT_EQ(printed["units"].size(), 2u);
  EXPECT_EQ(printed["outputs"].size(), 3u);
  EXPECT_TRUE(contains(strict.err, "report written to")) << strict.err;
}

// A limit within a unit's value +- U (docs/uncertainty.md, section 7) makes it marginal: neither
// accepted nor rejected, said in results.json and the summary; `--strict` exits 5 on it too.
TEST(RunCli, MarginalUnitIsNeitherAcceptedNorRejectedAndStrictFailsOnIt) {
  const fs::path& d = demo_dir();
  const json demo = json::parse(read_text(d / "results.json"));
  const double stroke = demo["units"][0]["stroke_um"].get<double>();  // unit 1, U ~ 0.5 um (0.1 % scale)
  std::string text = read_text(d / "campaign.toml");
  const auto at = text.find("stroke_min_um = ");
  ASSERT_NE(at, std::string::npos);
  std::ostringstream limit;
  limit.precision(17);
  limit << "stroke_min_um = " << stroke - 0.1;
  text.replace(at, text.find('\n', at) - at, limit.str());
  // Unit 1 only: the [[units]] tables are last, unit 1's first.
  const auto second = text.find("[[units]]", text.find("[[units]]") + 1);
  ASSERT_NE(second, std::string::npos);
  text.erase(second);
  std::ofstream(d / "campaign_marginal.toml") << text;
  TempDir out, out_strict;
  const std::string campaign = (d / "campaign_marginal.toml").string();
  const CliRun plain = run_cli("run " + campaign + " --out " + out.path().string());
  EXPECT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_TRUE(contains(plain.out, "1 units: 0 accepted, 1 marginal, 0 rejected")) << plain.out;
  EXPECT_TRUE(contains(plain.out, "APA 1    MARGINAL")) << plain.out;
  const json r = json::parse(read_text(out.path() / "results.json"));
  EXPECT_EQ(r["summary"]["marginal"], 1);
  const json& u = r["units"][0];
  EXPECT_FALSE(u["accepted"].get<bool>());
  EXPECT_TRUE(u["marginal"].get<bool>());
  bool found = false;
  for (const json& c : u["checks"]) {
    if (c["quantity"] != "stroke") continue;
    found = true;
    EXPECT_EQ(c["verdict"], "marginal");
    EXPECT_GT(c["expanded_uncertainty"].get<double>(), 0.1);  // the limit is inside the interval
    EXPECT_GT(c["probability_of_conformity"].get<double>(), 0.5);
    EXPECT_LT(c["probability_of_conformity"].get<double>(), 0.99);
  }
  EXPECT_TRUE(found);
  EXPECT_TRUE(contains(read_text(out.path() / "report.html"), "<td class=\"status\">marginal</td>"));
  EXPECT_EQ(run_cli("run " + campaign + " --strict --out " + out_strict.path().string()).exit_code, 5);
}

// The demo campaign split in two parts and merged gives the demo run's results.json, results.mat
// and report.html byte for byte (docs/cluster.md); bad parts are refused with exit 3 naming them.
TEST(RunCli, PartsMergedEqualTheSingleRun) {
  const fs::path& d = demo_dir();
  const std::string campaign = (d / "campaign.toml").string();
  const CliRun list = run_cli("run " + campaign + " --list-units");
  EXPECT_EQ(list.exit_code, 0) << list.err;
  EXPECT_EQ(list.out, "1\tAPA 1\n3\tAPA 3\n");
  TempDir out;
  const std::string p1 = (out.path() / "p1").string(), p2 = (out.path() / "p2").string(), m = (out.path() / "m").string();
  const CliRun a = run_cli("run " + campaign + " --part 1/2 --threads 1 --out " + p1);
  EXPECT_EQ(a.exit_code, 0) << a.err;
  EXPECT_TRUE(contains(a.out, "part 1/2: 1 of 2 units (1)")) << a.out;
  const CliRun b = run_cli("run " + campaign + " --units 3 --json --out " + p2);
  EXPECT_EQ(b.exit_code, 0) << b.err;
  EXPECT_EQ(json::parse(b.out)["units"], json::array({3}));
  const CliRun merged = run_cli("merge " + p2 + " " + p1 + " --out " + m);
  ASSERT_EQ(merged.exit_code, 0) << merged.err;
  for (const std::string f : {"results.json", "results.mat", "report.html"}) {
    const std::size_t from = f == "results.mat" ? 116 : 0;  // the MAT-file's text header holds its creation time
    EXPECT_TRUE(read_text(d / f).substr(from) == read_text(fs::path(m) / f).substr(from)) << f;
  }
  EXPECT_FALSE(fs::exists(fs::path(p1) / "results.json"));  // a part writes part.json only
  // Missing, duplicated and foreign parts: exit 3 naming them.
  const CliRun missing = run_cli("merge " + p1 + " --out " + m);
  EXPECT_EQ(missing.exit_code, 3);
  EXPECT_TRUE(contains(missing.err, "unit 3 in none of them")) << missing.err;
  EXPECT_FALSE(fs::exists(fs::path(m) / "results.json"));  // the earlier set is gone, none written
  const CliRun twice = run_cli("merge " + p1 + " " + p2 + " " + p1 + " --out " + m);
  EXPECT_EQ(twice.exit_code, 3);
  EXPECT_TRUE(contains(twice.err, "also in")) << twice.err;
  std::string text = read_text(fs::path(p2) / "part.json");
  const auto at = text.find("fnv1a64:");
  ASSERT_NE(at, std::string::npos);
  text.replace(at + 8, 16, "0123456789abcdef");
  write_text(fs::path(p2) / "part.json", text);
  const CliRun foreign = run_cli("merge " + p1 + " " + p2 + " --out " + m);
  EXPECT_EQ(foreign.exit_code, 3);
  EXPECT_TRUE(contains(foreign.err, "p2/part.json") && contains(foreign.err, "another campaign")) << foreign.err;
  // Bad command lines: exit 2.
  EXPECT_EQ(run_cli("run " + campaign + " --part 3/2 --out " + p1).exit_code, 2);
  EXPECT_EQ(run_cli("run " + campaign + " --units 2 --out " + p1).exit_code, 2);
  EXPECT_EQ(run_cli("run " + campaign + " --units 1-x --out " + p1).exit_code, 2);
  EXPECT_EQ(run_cli("run " + campaign + " --units 1 --part 1/2 --out " + p1).exit_code, 2);
}

// A campaign assembled by hand from the demo's records converted to CSV with other channel names,
// next to a .mat file, gives the same results.
TEST(RunCli, RunOnACampaignOfCsvAndMatFiles) {
  const fs::path& d = demo_dir();
  TempDir dir;
  io::ReadOptions ro;
  ro.channels = {"u", "de", "Vs"};
  io::TimeSeries frf = io::read_timeseries(d / "data/unit1_frf-noise.mat", ro);
  frf.names = {"dac", "encoder", "force_sensor"};
  frf.settings.clear();
  io::write_timeseries(frf, dir.path() / "apa1_frf.csv");
  io::TimeSeries stiff = io::read_timeseries(d / "data/unit1_stiffness.mat");
  for (auto& n : stiff.names) n = n == "de" ? "laser" : n;
  io::write_timeseries(stiff, dir.path() / "apa1_stiffness.mat");
  fs::copy_file(d / "data/unit1_stroke.mat", dir.path() / "stroke.mat");
  std::ofstream(dir.path() / "campaign.toml") << R"(
title = "assembled"
[specs]
stroke_min_um = 200.0
[[units]]
id = 1
frf = { file = "apa1_frf.csv", channels = { u = "dac", de = "encoder", Vs = "force_sensor" } }
stiffness = { file = "apa1_stiffness.mat", channels = { de = "laser" } }
stroke = "stroke.mat"
capacitance_uF = { sensor = 5.10, actuator = 10.03 }
)";
  const fs::path out = dir.path() / "out";
  const CliRun r = run_cli("run " + (dir.path() / "campaign.toml").string() + " --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "report: ")) << r.out;
  const json a = json::parse(read_text(out / "results.json"));
  const json b = json::parse(read_text(d / "results.json"));
  const json& ua = a["units"][0];
  const json& ub = b["units"][0];
  EXPECT_EQ(ua["id"], 1);  // unit 1's records: their settings.unit says so, and run checks it
  EXPECT_TRUE(ua["accepted"].get<bool>()) << ua["reasons"].dump();
  // The CSV keeps 17 digits: the same numbers as from the .mat files.
  EXPECT_TRUE(near(ua["frf"]["resonance_Hz"].get<double>(), ub["frf"]["resonance_Hz"].get<double>(), 1e-9));
  EXPECT_TRUE(near(ua["stiffness_N_per_um"]["k1"].get<double>(), ub["stiffness_N_per_um"]["k1"].get<double>(), 1e-12));
  EXPECT_EQ(ua["frf"]["provenance"]["channels"]["de"], "encoder");
  EXPECT_EQ(ua["not_measured"].size(), 7u);  // flatness, hysteresis, stiffness_open_circuit, frf_without_resistor, iff, hammer, tracking
}

// A second run on a --out another run holds is refused with exit 3 and leaves the folder alone.
// results.json of a one-unit run whose unit was refused: written, the unit not analysed and not accepted.
void expect_not_analysed(const fs::path& results) {
  ASSERT_TRUE(fs::exists(results));
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(results));
  ASSERT_EQ(j["units"].size(), 1u);
  EXPECT_FALSE(j["units"][0]["not_analysed"].is_null()) << j["units"][0].dump();
  EXPECT_NE(j["units"][0]["accepted"], true);
}

// Issue 35's reproducers of item 2, through the command: unit 1's files given for unit 3, an FRF
// record given as a stroke: the unit is not analysed (exit 7, issue 33's code for a unit that could
// not be analysed), the reason names both, and the unit is never accepted with another's numbers.
TEST(RunCli, RecordsOfAnotherUnitOrKindAreRefused) {
  test::TempDir dir;
  const auto file = [&dir](const std::string& name) { return (dir.path() / name).string(); };
  ASSERT_EQ(run_cli("simulate capacitance --unit 1 --out " + file("c1.mat")).exit_code, 0);
  ASSERT_EQ(run_cli("simulate stroke --unit 1 --out " + file("s1.mat")).exit_code, 0);
  ASSERT_EQ(run_cli("simulate frf-noise --unit 3 --duration 1 --out " + file("f3.mat")).exit_code, 0);
  std::ofstream(dir.path() / "swapped.toml") << "[[units]]\nid = 3\ncapacitance = \"c1.mat\"\nstroke = \"s1.mat\"\n";
  CliRun r = run_cli("run " + file("swapped.toml") + " --out " + file("out1"));
  EXPECT_EQ(r.exit_code, 7) << r.err;
  EXPECT_TRUE(test::contains(r.err, "expected a record of unit 3 (units[0].id)")) << r.err;
  EXPECT_TRUE(test::contains(r.err, "a record of unit 1 (its settings.unit)")) << r.err;
  expect_not_analysed(dir.path() / "out1" / "results.json");
  std::ofstream(dir.path() / "kind.toml") << "[[units]]\nid = 3\nstroke = \"f3.mat\"\n";
  r = run_cli("run " + file("kind.toml") + " --out " + file("out2"));
  EXPECT_EQ(r.exit_code, 7) << r.err;
  EXPECT_TRUE(test::contains(r.err, "expected a stroke record (stroke), found '" )) << r.err;
  EXPECT_TRUE(test::contains(r.err, "a frf-noise record (its settings.experiment)")) << r.err;
  expect_not_analysed(dir.path() / "out2" / "results.json");
}

TEST(RunCli, BusyOutFolderIsRefused) {
  const fs::path& d = demo_dir();
  TempDir dir;
  const fs::path out = dir.path() / "busy";
  const io::OutputLock held(out);
  const CliRun r = run_cli("run " + (d / "campaign.toml").string() + " --out " + out.string());
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_TRUE(contains(r.err, "locked by another run")) << r.err;
  EXPECT_FALSE(fs::exists(out / "results.json"));
}

std::string fmt_name(int i) {
  std::string name = std::to_string(i);
  name.insert(0, 1, 'c');
  name.append(".toml");
  return name;
}

// Issue 33: a unit whose file is missing or whose channel is not in its file is not analysed; the
// other unit is, every output is written, and the exit code is 7 (docs/cli.md); --json prints the
// results with the unit's not_analysed entry.
TEST(RunCli, BadUnitIsNotAnalysedWithExit7) {
  const fs::path& d = demo_dir();
  TempDir dir;
  const std::string stroke = (d / "data/unit1_stroke.mat").string();
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      {"frf = \"missing.mat\"\n", {"units[1].frf", "missing.mat"}},
      {"stroke = { file = \"" + stroke + "\", channels = { de = \"laser\" } }\n", {"units[1].stroke", "laser"}},
  };
  int i = 0;
  for (const auto& [bad, expected] : cases) {
    const fs::path file = dir.path() / fmt_name(i++);
    std::ofstream(file) << "[[units]]\nid = 1\nstroke = \"" + stroke + "\"\n[[units]]\nid = 2\n" + bad;
    const fs::path out = dir.path() / ("out" + std::to_string(i));
    const CliRun r = run_cli("run " + file.string() + " --out " + out.string());
    EXPECT_EQ(r.exit_code, 7) << bad << r.err;
    EXPECT_TRUE(contains(r.out, "1 accepted, 0 rejected, 1 not analysed")) << r.out;
    EXPECT_TRUE(contains(r.out, "APA 2    NOT ANALYSED")) << r.out;
    for (const auto& e : expected) EXPECT_TRUE(contains(r.out, e)) << e << " in " << r.out;
    for (const char* f : {"results.json", "results.mat", "report.html"}) EXPECT_TRUE(fs::exists(out / f)) << f;
    EXPECT_FALSE(fs::exists(out / ".piezobench.lock"));
    const json results = json::parse(read_text(out / "results.json"));
    EXPECT_EQ(results["summary"]["not_analysed"], 1);
    EXPECT_TRUE(results["units"][0]["accepted"].get<bool>());
    EXPECT_EQ(results["units"][1]["not_analysed"]["key"], expected[0]);
  }
}

// --json on a failure: one JSON error document on stdout, the same exit code.
TEST(RunCli, JsonErrorDocument) {
  TempDir dir;
  const CliRun missing = run_cli("run " + (dir.path() / "none.toml").string() + " --json --out " + (dir.path() / "o").string());
  EXPECT_EQ(missing.exit_code, 3) << missing.err;
  const json e = json::parse(missing.out);
  EXPECT_EQ(e["error"]["kind"], "input");
  EXPECT_EQ(e["error"]["exit_code"], 3);
  EXPECT_TRUE(contains(e["error"]["message"].get<std::string>(), "none.toml")) << missing.out;
  const CliRun usage = run_cli("demo --seeed 2 --json");
  EXPECT_EQ(usage.exit_code, 2);
  EXPECT_EQ(json::parse(usage.out)["error"]["kind"], "usage");
  EXPECT_TRUE(contains(usage.err, "did you mean --seed")) << usage.err;
}

// Bad campaigns: exit 3, the campaign file and the key named, no results left in --out.
TEST(RunCli, BadInputNamesFileAndKeyAndWritesNothing) {
  const fs::path& d = demo_dir();
  TempDir dir;
  const std::string stroke = (d / "data/unit1_stroke.mat").string();
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      {"[[units]]\nid = 1\n[[units]]\nid = 1\n", {"units[1].id", "listed twice"}},
      {"[[units]]\nid = 1\nfrequency = 3\n", {"units[0].frequency", "unknown key"}},
  };
  int i = 0;
  for (const auto& [text, expected] : cases) {
    const fs::path file = dir.path() / fmt_name(i++);
    std::ofstream(file) << text;
    const fs::path out = dir.path() / "out";
    fs::create_directories(out);
    std::ofstream(out / "results.json") << "{\"stale\": true}";
    const CliRun r = run_cli("run " + file.string() + " --out " + out.string());
    EXPECT_EQ(r.exit_code, 3) << text << r.err;
    EXPECT_TRUE(contains(r.err, file.string())) << r.err;
    for (const auto& e : expected) EXPECT_TRUE(contains(r.err, e)) << e << " in " << r.err;
    EXPECT_FALSE(fs::exists(out / "results.json")) << text;
    EXPECT_FALSE(fs::exists(out / "report.html")) << text;
    EXPECT_FALSE(fs::exists(out / "results.mat")) << text;
  }
  // A bad command line is exit 2.
  EXPECT_EQ(run_cli("run").exit_code, 2);
  EXPECT_EQ(run_cli("demo --units 9 --out " + dir.path().string()).exit_code, 2);
}

}  // namespace
}  // namespace piezobench::test
