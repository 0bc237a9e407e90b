#include "piezobench/web/live_hub.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <random>
#include <thread>

#include "piezobench/dsp/welch.hpp"

namespace piezobench::web {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

station::StationFile two_phases() {
  station::StationFile st;
  st.name = "test station";
  station::PhaseSpec a;
  a.name = "hysteresis-20V", a.experiment = "hysteresis";
  station::PhaseSpec b;
  b.name = "frf", b.experiment = "frf-noise";
  st.phases = {a, b};
  return st;
}

// A record of `seconds` at `rate`: Va = 10 t V, de = 1e-6 sin(2 pi t) m, Vs = 2 V.
io::TimeSeries ramp_record(double rate, double seconds) {
  io::TimeSeries ts;
  const Eigen::Index n = static_cast<Eigen::Index>(rate * seconds);
  ts.names = {"t", "u", "Va", "de", "Vs"};
  ts.units = {"s", "V", "V", "m", "V"};
  ts.sample_rate = rate;
  ts.data.resize(n, 5);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / rate;
    ts.data.row(k) << t, 0.5 * t, 10.0 * t, 1e-6 * std::sin(2 * M_PI * t), 2.0;
  }
  ts.settings["experiment"] = std::string("hysteresis");
  return ts;
}

// Everything a fresh client's mailbox gives until it has nothing new.
nlohmann::json drain(EventStream& s) {
  nlohmann::json all = {{"samples", nlohmann::json::array()}};
  while (auto m = s.next()) {
    const nlohmann::json j = nlohmann::json::parse(*m);
    if (j.contains("state")) all["state"] = j["state"];
    if (j.contains("frf")) all["frf"] = j["frf"];
    for (const auto& x : j.value("samples", nlohmann::json::array())) all["samples"].push_back(x);
  }
  return all;
}

TEST(LiveHub, DecimatesARecordToTheScreenRateWithMinMaxAndLast) {
  LiveHub hub;
  hub.plan(two_phases(), "SN1", "B1");
  hub.phase_started("SN1", two_phases().phases[0], 1);
  // A record already measured (its first sample 10 s ago): released at once.
  hub.record(ramp_record(1000.0, 2.0), Clock::now() - 10s);
  std::this_thread::sleep_for(50ms);
  auto client = hub.mailbox();
  const nlohmann::json got = drain(*client);
  ASSERT_EQ(got["samples"].size(), 40u);  // 2 s at 20 screen samples per second
  for (int k = 0; k < 40; ++k) {
    const auto& s = got["samples"][k];
    const double t0 = 0.05 * k, t1 = 0.05 * k + 0.049;  // the block's first and last sample
    EXPECT_NEAR(s["t"].get<double>(), t0, 1e-9);
    EXPECT_NEAR(s["va"][0].get<double>(), 10 * t0, 1e-9);
    EXPECT_NEAR(s["va"][1].get<double>(), 10 * t1, 1e-9);
    EXPECT_NEAR(s["va"][2].get<double>(), 10 * t1, 1e-9);
    EXPECT_NEAR(s["de"][2].get<double>(), std::sin(2 * M_PI * t1), 1e-9);  // um
    EXPECT_EQ(s["phase"], "hysteresis-20V");
  }
  EXPECT_EQ(got["state"]["phases"][0]["state"], "running");
  EXPECT_DOUBLE_EQ(got["state"]["phases"][0]["record_s"].get<double>(), 2.0);
  EXPECT_FALSE(client->next().has_value());  // nothing new
}

TEST(LiveHub, APacedRecordIsReleasedAsItsSamplesAreMeasured) {
  LiveHub hub;
  hub.plan(two_phases(), "SN1", "B1");
  hub.phase_started("SN1", two_phases().phases[0], 1);
  const auto start = Clock::now();
  hub.record(ramp_record(1000.0, 2.0), start);
  std::this_thread::sleep_for(500ms);
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  const auto released = static_cast<double>(hub.samples_released());
  // Block k (its last sample at 0.05 k + 0.049 s) is due then; the feeder wakes every 10 ms.
  EXPECT_LE(released, elapsed / 0.05 + 1);
  EXPECT_GE(released, (elapsed - 0.03) / 0.05 - 1);
  auto client = hub.mailbox();
  const nlohmann::json got = drain(*client);
  for (const auto& s : got["samples"]) {
    // Measurement time of the block's first sample: start + t, on the wall clock.
    const double now_ms = std::chrono::duration<double, std::milli>(std::chrono::system_clock::now().time_since_epoch()).count();
    EXPECT_LE(s["at"].get<double>(), now_ms);
  }
}

TEST(LiveHub, ASlowClientGetsTheNewestWindowNotABacklog) {
  LiveHubOptions o;
  o.window_s = 1.0;  // 20 screen samples kept
  LiveHub hub(o);
  hub.plan(two_phases(), "SN1", "B1");
  hub.phase_started("SN1", two_phases().phases[0], 1);
  auto fast = hub.mailbox(), slow = hub.mailbox();
  hub.record(ramp_record(1000.0, 2.0), Clock::now() - 10s);
  std::this_thread::sleep_for(50ms);
  const nlohmann::json a = drain(*fast);
  hub.record(ramp_record(1000.0, 2.0), Clock::now() - 10s);
  std::this_thread::sleep_for(50ms);
  const nlohmann::json b = drain(*fast), c = drain(*slow);
  EXPECT_EQ(a["samples"].size(), 20u);
  EXPECT_EQ(b["samples"].size(), 20u);
  ASSERT_EQ(c["samples"].size(), 20u);  // 80 were released; the slow client gets the newest 20
  EXPECT_EQ(c["samples"].back()["seq"], 80);
  EXPECT_EQ(c["samples"].front()["seq"], 61);
}

TEST(LiveHub, ALoopTapShowsTheSignalsWhileTheRecordRunsAndOnlyOnce) {
  LiveHub hub;
  hub.plan(two_phases(), "SN1", "B1");
  hub.phase_started("SN1", two_phases().phases[0], 1);
  const rt::LogTap tap = hub.loop_tap(10000.0);
  ASSERT_EQ(tap.every, 10u);  // 1,000 tapped records per second: 50 per screen sample
  // The loop's logger delivers what the ring held, every millisecond: 1 s of a 10 kHz run
  // (Va = 10 t V, de = 1e-6 sin(2 pi t) m, Vs = 2 V) whose cycle 0 was measured 2 s ago, every
  // record with its measurement time.
  const std::int64_t first_ns = std::chrono::duration_cast<std::chrono::nanoseconds>((Clock::now() - 2s).time_since_epoch()).count();
  std::vector<rt::LogRecord> batch;
  for (int k = 0; k < 10000; k += 10) {
    rt::LogRecord r;
    r.t = k / 10000.0;
    r.measured_ns = first_ns + k * 100'000;
    r.va = 10.0 * r.t, r.de = 1e-6 * std::sin(2 * M_PI * r.t), r.vs = 2.0;
    batch.push_back(r);
    if (batch.size() == 3) {
      tap.deliver(batch);
      batch.clear();
    }
  }
  // Before the run's end: the complete blocks only (the last one, 49 records, waits for its 50th).
  EXPECT_EQ(hub.samples_released(), 19u);
  tap.deliver(batch);
  tap.deliver({});  // the run is over
  EXPECT_EQ(hub.samples_released(), 20u);
  auto client = hub.mailbox();
  const nlohmann::json got = drain(*client);
  ASSERT_EQ(got["samples"].size(), 20u);
  const double first_ms = std::chrono::duration<double, std::milli>(std::chrono::system_clock::now().time_since_epoch()).count() - 2000.0;
  for (int b = 0; b < 20; ++b) {
    const auto& s = got["samples"][b];
    const double t0 = 0.05 * b, t1 = 0.05 * b + 0.049;  // the block's first and last tapped record
    EXPECT_NEAR(s["t"].get<double>(), t0, 1e-9);
    EXPECT_NEAR(s["va"][0].get<double>(), 10 * t0, 1e-9);
    EXPECT_NEAR(s["va"][1].get<double>(), 10 * t1, 1e-9);
    EXPECT_NEAR(s["de"][2].get<double>(), std::sin(2 * M_PI * t1), 1e-9);
    EXPECT_NEAR(s["at"].get<double>(), first_ms + 1e3 * t0, 50.0);  // the two clocks read apart
    EXPECT_EQ(s["phase"], "hysteresis-20V");
  }
  // The whole record afterwards (as the instrument hands it): no second copy of the signals.
  hub.record(ramp_record(10000.0, 1.0), Clock::now() - 1s);
  std::this_thread::sleep_for(50ms);
  EXPECT_EQ(hub.samples_released(), 20u);
  EXPECT_DOUBLE_EQ(nlohmann::json::parse(hub.state_json())["phases"][0]["record_s"].get<double>(), 1.0);
  // The next phase's record, with no tap, shows its signals from the record.
  hub.phase_started("SN1", two_phases().phases[1], 1);
  hub.record(ramp_record(1000.0, 1.0), Clock::now() - 10s);
  std::this_thread::sleep_for(50ms);
  EXPECT_EQ(hub.samples_released(), 40u);
}

TEST(LiveHub, BuildsTheFrfAverageByAverage) {
  // d_e = 2 um/V times u: |H| = 2 um/V and coherence 1 at every frequency.
  io::TimeSeries ts = ramp_record(10000.0, 4.0);
  ts.settings["experiment"] = std::string("frf-noise");
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise;
  for (Eigen::Index k = 0; k < ts.samples(); ++k) {
    ts.data(k, 1) = noise(rng);
    ts.data(k, 3) = 2e-6 * ts.data(k, 1);
  }
  LiveHub hub;
  hub.plan(two_phases(), "SN1", "B1");
  hub.phase_started("SN1", two_phases().phases[1], 1);
  auto client = hub.mailbox();
  hub.record(ts, Clock::now() - 10s);
  const dsp::WelchOptions w = dsp::welch_options_for_record(ts.samples(), ts.sample_rate);
  const long expected = 1 + (ts.samples() - w.nfft) / (w.nfft - w.noverlap());
  nlohmann::json frf = nlohmann::json::object();
  for (int i = 0; i < 200 && frf.value("averages", 0) < expected; ++i) {
    std::this_thread::sleep_for(10ms);
    const nlohmann::json got = drain(*client);
    if (got.contains("frf")) frf = got["frf"];
  }
  ASSERT_EQ(frf["averages"].get<long>(), expected);
  EXPECT_EQ(frf["phase"], "frf");
  ASSERT_GT(frf["f_Hz"].size(), 100u);
  for (std::size_t i = 0; i < frf["f_Hz"].size(); ++i) {
    EXPECT_NEAR(frf["mag_um_per_V"][i].get<double>(), 2.0, 1e-9);
    EXPECT_NEAR(frf["coherence"][i].get<double>(), 1.0, 1e-9);
  }
  EXPECT_GE(frf["f_Hz"].front().get<double>(), 5.0 - 0.25);
  EXPECT_LE(frf["f_Hz"].back().get<double>(), 2000.0 + 0.25);
}

TEST(LiveHub, PhaseStatesFollowTheRunner) {
  LiveHub hub;
  const station::StationFile st = two_phases();
  hub.plan(st, "SN1", "B1", {{"frf", 21.5}});
  station::PhaseTryRow row;
  row.phase_name = "hysteresis-20V", row.status = "failed", row.verdict = "fail", row.reason = "saturation";
  hub.phase_started("SN1", st.phases[0], 1);
  hub.phase_finished("SN1", row);
  nlohmann::json s = nlohmann::json::parse(hub.state_json());
  EXPECT_EQ(s["phases"][0]["state"], "failed");
  EXPECT_EQ(s["phases"][0]["reason"], "saturation");
  hub.phase_started("SN1", st.phases[0], 2);
  EXPECT_EQ(nlohmann::json::parse(hub.state_json())["phases"][0]["state"], "retried");
  row.status = "complete", row.verdict = "marginal", row.reason = "";
  row.measurements.push_back({"hysteresis_relative_width", "1", 0.2499, std::nullopt, 0.25, "marginal", "", false});
  hub.phase_finished("SN1", row);
  hub.verdict("SN1", station::Verdict::kMarginal, "hysteresis-20V", "hysteresis_relative_width");
  hub.finished("complete", true);
  s = nlohmann::json::parse(hub.state_json());
  EXPECT_EQ(s["phases"][0]["state"], "marginal");
  EXPECT_EQ(s["phases"][0]["tries"], 2);
  EXPECT_DOUBLE_EQ(s["phases"][0]["measurements"][0]["value"].get<double>(), 0.2499);
  EXPECT_EQ(s["phases"][1]["state"], "waiting");
  EXPECT_DOUBLE_EQ(s["phases"][1]["expected_s"].get<double>(), 21.5);
  EXPECT_EQ(s["verdict"], "marginal");
  EXPECT_EQ(s["status"], "complete");
  EXPECT_TRUE(s["certificate"].get<bool>());
}

TEST(LiveHub, OnlyTheOpenPromptTakesOneOfItsAnswers) {
  LiveHub hub;
  const std::uint64_t id = hub.open_prompt("frf", "connect the resistor", {"confirm", "abort"});
  EXPECT_EQ(hub.answer(id + 1, "confirm").status, AnswerResult::Status::kNotOpen);
  EXPECT_EQ(hub.answer(id, "retry").status, AnswerResult::Status::kNotOpen);
  EXPECT_FALSE(hub.wait_answer(id, 10ms).has_value());
  std::thread page([&] {
    std::this_thread::sleep_for(20ms);
    EXPECT_EQ(hub.answer(id, "confirm").status, AnswerResult::Status::kTaken);
  });
  const auto a = hub.wait_answer(id, 2000ms);
  page.join();
  ASSERT_TRUE(a.has_value());
  EXPECT_EQ(*a, "confirm");
  EXPECT_EQ(hub.answer(id, "abort").status, AnswerResult::Status::kNotOpen);  // answered once
  hub.close_prompt(id);
  EXPECT_TRUE(nlohmann::json::parse(hub.state_json())["prompt"].is_null());
}

}  // namespace
}  // namespace piezobench::web
