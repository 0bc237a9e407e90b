// End-to-end tests of `piezobench qualify` and `piezobench db` (docs/station.md): the demo batch on
// the virtual bench against `run` on the export, answers refused before anything moves, two
// stations writing one database, a UDP bench that stops answering mid-phase.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "run_cli.hpp"
#include "test_util.hpp"

namespace piezobench {
namespace {

using test::run_cli;
namespace fs = std::filesystem;

// The report's acceptance on shorter records (the demo's --fast FRF): what decides units 1..7.
const std::string kStation = R"(name = "demo batch station"
[campaign.bench]
suspended_mass_kg = 5.7
[[phases]]
name = "flatness"
experiment = "flatness"
[[phases.measurements]]
name = "flatness_um"
max = 25.0
[[phases]]
name = "capacitance"
experiment = "capacitance"
[[phases.measurements]]
name = "capacitance_sensor_uF"
min = 4.0
max = 6.0
[[phases.measurements]]
name = "capacitance_actuator_uF"
min = 8.0
max = 12.0
[[phases]]
name = "stroke"
experiment = "stroke"
steps = ["mount the actuator"]
[[phases.measurements]]
name = "stroke_um"
min = 200.0
[[phases]]
name = "hysteresis-80V"
experiment = "hysteresis"
amplitude_V = 80.0
[[phases.measurements]]
name = "hysteresis_relative_width"
[[phases]]
name = "stiffness"
experiment = "stiffness"
[[phases.measurements]]
name = "k1_N_per_um"
min = 1.5
max = 2.5
[[phases]]
name = "frf"
experiment = "frf-noise"
duration_s = 8.0
min_coherence = 0.9
[[phases.measurements]]
name = "resonance_Hz"
[[phases.measurements]]
name = "antiresonance_Hz"
[[phases.measurements]]
name = "k_resonance_N_per_um"
min = 1.5
max = 2.5
)";

// A unit's results without the campaign keys of its records (units[0] in the unit's own
// campaign, units[i] in the export).
nlohmann::json without_keys(nlohmann::json j) {
  if (j.is_object()) {
    j.erase("key");
    for (auto& [k, v] : j.items()) v = without_keys(v);
  } else if (j.is_array()) {
    for (auto& v : j) v = without_keys(v);
  }
  return j;
}

const std::string kAnswers = "operator = \"CI\"\n[phases.stroke]\nsteps = [\"confirm\"]\n";

struct Files {
  test::TempDir dir;
  std::string bench = test::write_text_file(dir, "bench.toml", "[bench]\nbackend = \"virtual\"\nsample_rate_Hz = 10000\n[virtual]\nunit = 1\nseed = 1\n");
  std::string station = test::write_text_file(dir, "station.toml", kStation);
  std::string answers = test::write_text_file(dir, "answers.toml", kAnswers);
  [[nodiscard]] std::string common() const {
    return "--bench " + bench + " --station " + station + " --answers " + answers + " --db " + (dir.path() / "st.db").string() + " --data " +
           (dir.path() / "data").string();
  }
};

TEST(QualifyCli, TheDemoBatchMatchesRunOnTheExport) {
  Files f;
  std::map<int, nlohmann::json> qualified;
  for (int unit = 1; unit <= 7; ++unit) {
    const auto r = run_cli("qualify " + f.common() + " --serial APA-" + std::to_string(unit) + " --unit " + std::to_string(unit) +
                           " --batch demo --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["status"], "complete");
    EXPECT_EQ(j["verdict"], unit == 3 ? "fail" : "pass") << unit << ": " << j["reasons"].dump();
    const auto show = run_cli("db show APA-" + std::to_string(unit) + " --json --db " + (f.dir.path() / "st.db").string());
    ASSERT_EQ(show.exit_code, 0) << show.err;
    qualified[unit] = without_keys(nlohmann::json::parse(show.out)["results"]);
  }
  const std::string campaign = (f.dir.path() / "campaign.toml").string();
  const auto e = run_cli("db export --batch demo --out " + campaign + " --db " + (f.dir.path() / "st.db").string());
  ASSERT_EQ(e.exit_code, 0) << e.err;
  const auto run = run_cli("run " + campaign + " --out " + (f.dir.path() / "results").string() + " --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json results = nlohmann::json::parse(run.out);
  ASSERT_EQ(results["units"].size(), 7U);
  for (const auto& unit : results["units"]) {
    const nlohmann::json u = without_keys(unit);
    const int id = u["id"];
    EXPECT_EQ(u["accepted"], id != 3) << id;
    const nlohmann::json& q = qualified[id];
    for (const char* key : {"flatness_um", "stroke_um", "capacitance_uF", "stiffness_N_per_um", "hysteresis", "model_2dof"}) {
      EXPECT_EQ(u[key], q[key]) << "unit " << id << " " << key;
    }
    EXPECT_EQ(u["frf"]["resonance_Hz"], q["frf"]["resonance_Hz"]) << id;
    EXPECT_EQ(u["frf"]["antiresonance_Hz"], q["frf"]["antiresonance_Hz"]) << id;
  }
  // Unit 3 for the report's reasons: its capacitances and its stroke.
  const std::string reasons = results["units"][2]["reasons"].dump();
  EXPECT_TRUE(test::contains(reasons, "capacitance of the sensor stack")) << reasons;
  EXPECT_TRUE(test::contains(reasons, "below the minimum 200.0 um")) << reasons;
  EXPECT_EQ(qualified[3]["accepted"], false);
  // The certificate regenerated from the database is the one qualify wrote, byte for byte.
  const std::string db = (f.dir.path() / "st.db").string(), cert = (f.dir.path() / "APA-3.html").string();
  const auto c = run_cli("db certificate APA-3 --out " + cert + " --db " + db);
  ASSERT_EQ(c.exit_code, 0) << c.err << c.out;
  EXPECT_TRUE(test::contains(c.out, "equal to the one stored")) << c.out;
  EXPECT_EQ(test::read_text(cert), test::read_text(f.dir.path() / "data/APA-3/certificate-q3.html"));
  const auto charts = run_cli("db charts --batch demo --out " + (f.dir.path() / "charts.html").string() + " --db " + db);
  ASSERT_EQ(charts.exit_code, 0) << charts.err;
  EXPECT_TRUE(test::contains(charts.err, "stroke_um: 7 units")) << charts.err;
  EXPECT_TRUE(test::contains(charts.err, "capacitance_sensor_uF: 7 units")) << charts.err;
}

TEST(QualifyCli, AnswersWithATypoOrAMissingAnswerAreRefusedBeforeAnythingMoves) {
  Files f;
  const std::string typo = test::write_text_file(f.dir, "typo.toml", "operator = \"CI\"\n[phases.strok]\nsteps = [\"confirm\"]\n");
  auto r = run_cli("qualify --bench " + f.bench + " --station " + f.station + " --answers " + typo + " --serial X --db " +
                   (f.dir.path() / "st.db").string() + " --data " + (f.dir.path() / "data").string());
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_TRUE(test::contains(r.err, "typo.toml: line 2: phases.strok")) << r.err;
  const std::string missing = test::write_text_file(f.dir, "missing.toml", "operator = \"CI\"\n[phases.stroke]\nsteps = []\n");
  r = run_cli("qualify --bench " + f.bench + " --station " + f.station + " --answers " + missing + " --serial X --db " +
              (f.dir.path() / "st.db").string() + " --data " + (f.dir.path() / "data").string());
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_TRUE(test::contains(r.err, "missing.toml: line 3: phases.stroke.steps")) << r.err;
  EXPECT_FALSE(fs::exists(f.dir.path() / "st.db"));
  EXPECT_FALSE(fs::exists(f.dir.path() / "data"));
  r = run_cli("qualify " + f.common() + " --serial '../x'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
}

TEST(QualifyCli, TwoStationsWritingOneDatabaseAtOnce) {
  Files f;
  const std::string cmd = std::string(PIEZOBENCH_BINARY) + " qualify " + f.common();
  const std::string both = "(" + cmd + " --serial A --unit 2 >/dev/null 2>&1 & " + cmd + " --serial B --unit 4 >/dev/null 2>&1 & wait)";
  ASSERT_EQ(std::system(both.c_str()), 0);
  const auto list = run_cli("db list --json --db " + (f.dir.path() / "st.db").string());
  ASSERT_EQ(list.exit_code, 0) << list.err;
  const nlohmann::json j = nlohmann::json::parse(list.out);
  ASSERT_EQ(j.size(), 2U);
  for (const auto& q : j) EXPECT_EQ(q["status"], "complete") << q.dump();
  const auto check = run_cli("db check --db " + (f.dir.path() / "st.db").string());
  EXPECT_EQ(check.exit_code, 0) << check.err;
  EXPECT_EQ(check.out, "ok\n");
}

// bench serve in the background at 5 kHz; its address from the first line it prints. After the
// target dies the loop waits udp.timeout_s per remaining cycle (rt/loop.hpp runs to the end of the
// record in the safe state): a short record and time-out keep that to seconds.
struct Server {
  Server(const test::TempDir& dir, const std::string& name) : out(dir.path() / (name + ".out")), pidfile(dir.path() / (name + ".pid")) {
    const std::string cmd = std::string(PIEZOBENCH_BINARY) + " bench serve --udp 127.0.0.1:0 --rate 5000 --idle-timeout 60 > " + out.string() +
                            " 2>/dev/null & echo $! > " + pidfile.string();
    if (std::system(cmd.c_str()) != 0) return;
    for (int i = 0; i < 200 && address.empty(); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(25));
      std::ifstream in(out);
      std::string word;
      while (in >> word) {
        if (word.find("127.0.0.1:") == 0) address = word;
      }
    }
    std::ifstream(pidfile) >> pid;
  }
  void kill() {
    if (pid > 0) ::kill(pid, SIGKILL);
    pid = 0;
  }
  ~Server() { kill(); }
  fs::path out, pidfile;
  std::string address;
  pid_t pid = 0;
};

std::string udp_bench(const test::TempDir& dir, const std::string& address, const std::string& timeout_s) {
  return test::write_text_file(dir, "udp-" + timeout_s + ".toml",
                               "[bench]\nbackend = \"udp\"\nsample_rate_Hz = 5000\n[udp]\naddress = \"" + address +
                                   "\"\ntimeout_s = " + timeout_s + "\n[amplifier]\ngain_V_per_V = 20\n[limits]\nva_min_V = -20\nva_max_V = 150\n"
                                   "slew_rate_V_per_s = 1e5\nwatchdog_s = 5.0\n");
}

TEST(QualifyCli, ABenchThatStopsAnsweringFailsThePhaseAndTheQualificationResumes) {
  test::TempDir dir;
  const std::string station = test::write_text_file(
      dir, "station.toml",
      "name = \"udp\"\n[[phases]]\nname = \"frf\"\nexperiment = \"frf-noise\"\nduration_s = 1.0\n[[phases.measurements]]\nname = \"resonance_Hz\"\n");
  const std::string db = (dir.path() / "st.db").string(), data = (dir.path() / "data").string();
  Server server(dir, "first");
  ASSERT_FALSE(server.address.empty());
  std::thread killer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(700));  // the record runs from ~0.1 s to ~1.1 s
    server.kill();
  });
  auto r = run_cli("qualify --bench " + udp_bench(dir, server.address, "0.0005") + " --station " + station + " --serial U1 --db " + db + " --data " + data);
  killer.join();
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_TRUE(test::contains(r.err, "failed (resume with: piezobench qualify")) << r.err;
  auto show = run_cli("db show U1 --json --db " + db);
  nlohmann::json j = nlohmann::json::parse(show.out);
  EXPECT_EQ(j["status"], "failed");
  ASSERT_EQ(j["phase_tries"].size(), 1U);
  EXPECT_EQ(j["phase_tries"][0]["status"], "failed");
  EXPECT_TRUE(test::contains(j["phase_tries"][0]["reason"].get<std::string>(), "bench: measure on udp")) << j.dump();
  Server again(dir, "second");
  ASSERT_FALSE(again.address.empty());
  r = run_cli("qualify --bench " + udp_bench(dir, again.address, "0.2") + " --station " + station + " --resume U1 --db " + db + " --data " + data);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  show = run_cli("db show U1 --json --db " + db);
  j = nlohmann::json::parse(show.out);
  EXPECT_EQ(j["status"], "complete");
  ASSERT_EQ(j["phase_tries"].size(), 2U);
  EXPECT_EQ(j["phase_tries"][1]["status"], "complete");
}

}  // namespace
}  // namespace piezobench
