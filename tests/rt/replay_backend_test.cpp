#include "piezobench/rt/replay_backend.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "piezobench/control/discrete_iff.hpp"
#include "piezobench/io/timeseries.hpp"
#include "piezobench/rt/loop.hpp"
#include "test_util.hpp"

namespace piezobench::rt {
namespace {

io::TimeSeries sine_record(Eigen::Index n, double fs = 10e3) {
  io::TimeSeries ts;
  ts.names = {"u", "de", "Vs"};
  ts.data.resize(n, 3);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / fs;
    ts.data(k, 0) = 0.1 * std::sin(2 * M_PI * 50 * t);
    ts.data(k, 1) = 1e-6 * std::sin(2 * M_PI * 95 * t);
    ts.data(k, 2) = 0.3 * std::sin(2 * M_PI * 95 * t + 0.4) + 0.05 * std::sin(2 * M_PI * 700 * t);
  }
  ts.sample_rate = fs;
  return ts;
}

TEST(ReplayBackend, ReturnsTheRecordRowByRow) {
  const io::TimeSeries ts = sine_record(5);
  ReplayBackend b(ts);
  EXPECT_EQ(b.name(), "replay");
  EXPECT_EQ(b.sample_rate(), 10e3);
  EXPECT_EQ(b.samples(), 5u);
  b.start();
  for (Eigen::Index k = 0; k < 5; ++k) {
    EXPECT_FALSE(b.finished());
    const SensorSample s = b.read();
    EXPECT_EQ(s.de, ts.data(k, 1));
    EXPECT_EQ(s.vs, ts.data(k, 2));
    EXPECT_TRUE(std::isnan(s.va));  // not measured
    EXPECT_EQ(s.sequence, static_cast<std::uint64_t>(k + 1));
    b.write(0.25 * static_cast<double>(k));
  }
  EXPECT_TRUE(b.finished());
  EXPECT_EQ(b.last_command(), 1.0);
  EXPECT_EQ(b.read().sequence, 5u);  // past the end: stale
}

TEST(ReplayBackend, MissingChannelsAndBadRecords) {
  io::TimeSeries ts = sine_record(5);
  ts.names = {"u", "d", "Vs"};
  const std::string what = test::input_error([&] { ReplayBackend b(ts); });
  EXPECT_TRUE(test::contains(what, "de")) << what;
  ts = sine_record(5);
  ts.data(2, 2) = std::nan("");
  test::input_error([&] { ReplayBackend b(ts); });
  test::TempDir dir;
  test::input_error([&] { ReplayBackend b(dir.path() / "missing.mat"); });
}

// The loop against a replayed file: the controller output in the log is the discrete IFF run
// directly on the recorded Vs, and the run stops at the end of the record.
TEST(ReplayBackend, LoopReplaysTheControllerOnRecordedData) {
  test::TempDir dir;
  const auto file = dir.path() / "rec.mat";
  io::write_timeseries(sine_record(4000), file);
  ReplayBackend b(file);
  LoopOptions o;
  o.realtime = false;
  o.duration = 10.0;  // longer than the record
  o.gain = 2.8e5;
  o.keep_log = true;
  o.limits.ramp_in = 0.0;
  o.limits.slew_rate = 1e12;
  o.log_file = dir.path() / "log.mat";
  io::TimeSeries log;
  const LoopReport rep = run_loop(b, o, &log);
  EXPECT_EQ(rep.cycles, 4000u);
  EXPECT_EQ(rep.backend, "replay");
  EXPECT_EQ(rep.dropped_log_samples, 0u);
  EXPECT_EQ(rep.logged_samples, 4000u);
  control::DiscreteIff iff({}, {}, 2.8e5);
  const io::TimeSeries rec = sine_record(4000);
  ASSERT_EQ(log.samples(), 4000);
  for (Eigen::Index k = 0; k < 4000; ++k) {
    const double y = iff.step(rec.data(k, 2));
    ASSERT_EQ(log.channel("y")(k), y) << k;
    ASSERT_EQ(log.channel("Vs")(k), rec.data(k, 2));
  }
  // The file holds the same as the in-memory log.
  const io::TimeSeries back = io::read_timeseries(*o.log_file);
  EXPECT_EQ(back.samples(), 4000);
  EXPECT_EQ(back.channel("y")(1234), log.channel("y")(1234));
  EXPECT_EQ(std::get<std::string>(back.settings.at("backend")), "replay");
}

}  // namespace
}  // namespace piezobench::rt
