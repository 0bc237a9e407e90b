// End-to-end tests of `piezobench rt` and `piezobench iff study`.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "piezobench/core/fields.hpp"
#include "piezobench/io/timeseries.hpp"
#include "piezobench/rt/loop.hpp"
#include "piezobench/rt/safety.hpp"
#include "run_cli.hpp"
#include "declared_keys.hpp"
#include "test_util.hpp"

namespace piezobench {
namespace {

using test::run_cli;

using test::declared_keys;
using test::keys_of;

// `rt --json` is rt::LoopReport's declared keys (a dotted key under its first part), "host" and
// "code" (the timing figures grouped by origin), and the command's own: the bench's source, the
// options, the log and the logged signals. The limits, the I/O and the timing summaries are
// rt::ActuatorLimits', rt::IoStats' (rejected included, as measure's) and rt::TimingSummary's declared keys.
TEST(RtCli, JsonKeysComeFromTheDeclarations) {
  const test::CliRun r = run_cli("rt --bench virtual --gain 1e8 --excitation noise --amplitude 5 --duration 0.1 --realtime false --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  std::set<std::string> top = {"code", "source", "controller", "gain", "duration_s", "limits", "log", "signals"};
  for (const std::string& key : declared_keys<rt::LoopReport>()) top.insert(key.substr(0, key.find('.')));
  EXPECT_EQ(keys_of(j), top);
  EXPECT_TRUE(top.count("rate_Hz") == 1 && top.count("overrun_causes") == 1 && top.count("va_cmd_max_V") == 1);
  EXPECT_EQ(keys_of(j["overrun_causes"]), (std::set<std::string>{"late_wakeup", "long_step"}));
  EXPECT_EQ(keys_of(j["host"]), (std::set<std::string>{"wait_ms", "preemptions", "overruns_late_wakeup", "skipped_deadlines"}));
  EXPECT_TRUE(j["host"]["wait_ms"].is_null());  // lockstep: unknown
  EXPECT_EQ(keys_of(j["limits"]), declared_keys<rt::ActuatorLimits>());
  EXPECT_EQ(keys_of(j["limits"]), (std::set<std::string>{"actuator", "va_min_V", "va_max_V", "amplifier_gain", "slew_rate_V_per_s",
                                                          "ramp_s", "watchdog_s", "saturation_time_s", "stale_cycles"}));
  EXPECT_EQ(j["limits"]["va_max_V"], 150.0);
  EXPECT_EQ(j["limits"]["amplifier_gain"], 20.0);
  EXPECT_EQ(keys_of(j["io"]), declared_keys<rt::IoStats>());
  EXPECT_EQ(j["io"]["rejected"], 0);
  const std::set<std::string> timing = declared_keys<rt::TimingSummary>();
  EXPECT_EQ(timing, (std::set<std::string>{"p50", "p99", "p999", "max", "mean", "count"}));
  EXPECT_EQ(keys_of(j["step_time_us"]), timing);
  EXPECT_EQ(j["code"]["step_time_us"], j["step_time_us"]);
  EXPECT_EQ(keys_of(j["io"]["round_trip_us"]), timing);
  EXPECT_TRUE(j["period_jitter_us"].is_null());  // lockstep: no pacing
  EXPECT_EQ(j["cycles"], 1000);                  // 0.1 s at 10 kHz
  EXPECT_EQ(j["step_time_us"]["count"], 1000);
  EXPECT_EQ(j["rate_Hz"], 10000.0);
}

// The command, shortened to 0.3 s: real time, IFF at the report's optimal gain on the
// virtual bench. Every cycle logged, timing reported, the damped loop stays at rest (no
// excitation: only the bench's noise drives it), nothing limited.
TEST(RtCli, VirtualBenchInRealTimeLogsEveryCycle) {
  test::TempDir dir;
  const auto log = dir.path() / "L.mat";
  const test::CliRun r = run_cli("rt --bench virtual --controller iff --gain 280000 --duration 0.3 --log " + log.string() + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["cycles"], 3000);
  EXPECT_EQ(j["dropped_log_samples"], 0);
  EXPECT_EQ(j["logged_samples"], 3000);
  EXPECT_EQ(j["clamped_samples"], 0);
  EXPECT_EQ(j["safe_state_reason"], "none");
  EXPECT_TRUE(j["realtime"].get<bool>());
  for (const char* key : {"p50", "p99", "p999", "max"}) EXPECT_TRUE(j["period_jitter_us"].contains(key)) << key;
  EXPECT_TRUE(j["step_time_us"].contains("p50"));
  EXPECT_TRUE(j["step_time_us"].contains("max"));
  EXPECT_TRUE(j.contains("overruns"));
  // Either the privileges were granted or a warning says why not (on stderr and in the JSON).
  if (!j["sched_fifo"].get<bool>()) {
    EXPECT_TRUE(test::contains(r.err, "SCHED_FIFO")) << r.err;
  }
  if (!j["memory_locked"].get<bool>()) {
    EXPECT_TRUE(test::contains(r.err, "mlockall")) << r.err;
  }

  const io::TimeSeries ts = io::read_timeseries(log);
  EXPECT_EQ(ts.samples(), 3000);
  EXPECT_DOUBLE_EQ(ts.sample_rate, 10e3);
  for (const char* name : {"u_prime", "u", "Va", "de", "Vs"}) EXPECT_NO_THROW((void)ts.index(name)) << name;
  ASSERT_EQ(ts.t.size(), 3000);
  EXPECT_DOUBLE_EQ(ts.t(2999), 0.2999);
  // Stable and at rest: the stack voltage stays within a few LSB-sized volts of 0.
  EXPECT_LT(ts.channel("Va").cwiseAbs().maxCoeff(), 1.0);
  EXPECT_LT(ts.channel("de").cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_EQ(std::get<std::string>(ts.settings.at("backend")), "virtual");
}

// Pushed into saturation (a huge gain and a large excitation, lockstep): the amplifier voltage the
// bench measured never leaves -20..150 V nor moves faster than the slew limit (plus one DAC LSB
// of quantization, 20 V/V x 20 V / 2^16), and the limiting is counted.
TEST(RtCli, SaturatedLoopKeepsTheVoltageInRangeAndSlewLimited) {
  test::TempDir dir;
  const auto log = dir.path() / "sat.mat";
  const test::CliRun r = run_cli("rt --bench virtual --gain 1e8 --excitation noise --amplitude 5 --duration 0.3 --realtime false "
                                 "--slew-rate 50000 --log " + log.string() + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_GT(j["clamped_samples"].get<int>(), 100);
  EXPECT_GT(j["slew_limited_samples"].get<int>(), 100);
  EXPECT_TRUE(j["period_jitter_us"].is_null());  // lockstep: no period
  const io::TimeSeries ts = io::read_timeseries(log);
  const auto va = ts.channel("Va");
  EXPECT_GE(va.minCoeff(), -20.0);
  EXPECT_LE(va.maxCoeff(), 150.0);
  const double limit = 50000.0 / 10e3 + 20.0 * 20.0 / 65536.0;
  for (Eigen::Index k = 1; k < va.size(); ++k) ASSERT_LE(std::abs(va(k) - va(k - 1)), limit) << "sample " << k;
  const auto cmd = ts.channel("Va_cmd");
  EXPECT_GE(cmd.minCoeff(), -20.0);
  EXPECT_LE(cmd.maxCoeff(), 150.0);
  EXPECT_LE(j["max_va_cmd_step_V"].get<double>(), 5.0 + 1e-9);
}

// Issue 21.8: `rt --gain 1e12` pinned Va to the limits without ever going safe. Now the loop goes
// to its safe state after --saturation-time (0.1 s by default) and the report says why.
TEST(RtCli, OutputSaturatedTooLongGoesToTheSafeState) {
  const test::CliRun r = run_cli("rt --bench virtual --gain 1e12 --excitation noise --duration 0.5 --realtime false --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["safe_state_reason"], "output saturated");
  EXPECT_GE(j["safe_state_cycle"].get<int>(), 999);  // at least 0.1 s of saturation at 10 kHz
  EXPECT_EQ(j["limits"]["saturation_time_s"].get<double>(), 0.1);
  const test::CliRun text = run_cli("rt --bench virtual --gain 1e12 --duration 0.3 --realtime false --saturation-time 0.05");
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_TRUE(test::contains(text.out, "safe state: output saturated")) << text.out;
  EXPECT_TRUE(test::contains(text.out, "saturated for 0.05 s")) << text.out;
}

// Issue 21.5: `rt --rate 1e12` reached 2.4 GB; the rate is capped (exit 2 for the command line).
TEST(RtCli, RateAboveTheCapIsACommandLineError) {
  const test::CliRun r = run_cli("rt --bench virtual --gain 1 --rate 1e12 --duration 1 --realtime false");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(test::contains(r.err, "--rate")) << r.err;
}

TEST(RtCli, ReplaysARecordedFile) {
  test::TempDir dir;
  io::TimeSeries rec;
  rec.names = {"de", "Vs"};
  rec.data.resize(2000, 2);
  for (Eigen::Index k = 0; k < 2000; ++k) {
    rec.data(k, 0) = 1e-6 * std::sin(0.06 * k);
    rec.data(k, 1) = 0.2 * std::sin(0.06 * k + 0.3);
  }
  rec.sample_rate = 10e3;
  const auto file = dir.path() / "rec.mat";
  io::write_timeseries(rec, file);
  const test::CliRun r = run_cli("rt --bench replay --replay " + file.string() + " --gain 280000 --duration 5 --realtime false --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["cycles"], 2000);  // the record ends before the duration
  EXPECT_EQ(j["source"]["bench"], "replay");
  // A rate that contradicts the record is refused.
  const test::CliRun bad = run_cli("rt --bench replay --replay " + file.string() + " --gain 1 --rate 5000 --json");
  EXPECT_EQ(bad.exit_code, 3) << bad.err;
  EXPECT_TRUE(test::contains(bad.err, "--rate")) << bad.err;
}

TEST(RtCli, BadInputIsReported) {
  test::TempDir dir;
  auto expect = [](int code, const std::string& args, const std::string& needle) {
    const test::CliRun r = run_cli(args);
    EXPECT_EQ(r.exit_code, code) << args << "\n" << r.err;
    EXPECT_TRUE(test::contains(r.err, needle)) << args << "\n" << r.err;
    EXPECT_TRUE(test::no_result(r)) << r.out;
  };
  expect(2, "rt --bench hardware --gain 1 --json", "--bench");
  expect(2, "rt --bench replay --gain 1 --json", "--replay");
  expect(2, "rt --bench virtual --gain 1 --controller pid --json", "--controller");
  expect(2, "rt --bench virtual --gain 1 --realtime maybe --json", "--realtime");
  expect(3, "rt --bench virtual --gain 1 --duration 0 --json", "duration");
  expect(3, "rt --bench virtual --gain 1 --va-min 200 --json", "va_max");
  expect(3, "rt --bench virtual --gain 1 --unit 12 --json", "unit");
  const std::string csv = test::write_text_file(dir, "rec.csv", "# sample_rate_Hz: 10000\nde,V\n0,1\n0,2\n");
  expect(3, "rt --bench replay --replay " + csv + " --gain 1 --json", "Vs");
  EXPECT_EQ(run_cli("rt --bench virtual --json").exit_code, 2);  // --gain is required
}

TEST(RtCli, HumanReadableTimingReport) {
  const test::CliRun r = run_cli("rt --bench virtual --gain 100000 --duration 0.05");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(test::contains(r.out, "cycles 500")) << r.out;
  EXPECT_TRUE(test::contains(r.out, "period jitter")) << r.out;
  EXPECT_TRUE(test::contains(r.out, "step time")) << r.out;
  EXPECT_TRUE(test::contains(r.out, "clamped samples 0")) << r.out;
}

// `iff study` with two gains: the identified damped poles follow the model's root locus.
TEST(IffStudyCli, IdentifiedPolesWithinFivePercentOfTheRootLocus) {
  const test::CliRun r = run_cli("iff study --gains 0,150000 --duration 2 --settle 1 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["gains"].size(), 2u);
  ASSERT_EQ(j["identified_poles"].size(), 2u);
  ASSERT_EQ(j["model_poles"].size(), 2u);
  for (const auto& e : j["relative_errors"]) EXPECT_LT(e.get<double>(), 0.05);
  EXPECT_TRUE(j["within_tolerance"].get<bool>());
  EXPECT_TRUE(j["damping_increases_to_optimum"].get<bool>());
  EXPECT_GT(j["identified_damping"][1].get<double>(), 5 * j["identified_damping"][0].get<double>());
  EXPECT_GT(j["optimal_gain"].get<double>(), 1e5);
  const test::CliRun bad = run_cli("iff study --gains 0,-5 --json");
  EXPECT_EQ(bad.exit_code, 3) << bad.err;
}

}  // namespace
}  // namespace piezobench
