// The Comedi backend through the test comedilib (fake_comedi.hpp: the virtual bench behind a
// simulated card): channel mapping, ranges, calibration, counter unwrapping, a saturated loop, a
// failing input that ramps the output to zero, and the refusals before anything moves.
#include "piezobench/rt/comedi_backend.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "comedi_bench_text.hpp"
#include "fake_comedi.hpp"
#include "piezobench/bench/virtual_bench.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/rt/loop.hpp"
#include "test_util.hpp"

namespace piezobench::rt {
namespace {

namespace fc = test::fake_comedi;

// The rt tests' Comedi bench on the simulated card, with a ramp time and the Va monitor.
std::string bench_text(const std::string& calibration = "soft") {
  return test::replace_once(test::comedi_bench_text("/dev/comedi-fake0", calibration), "slew_rate_V_per_s = 1e5\n",
                            "slew_rate_V_per_s = 1e5\nramp_s = 0.01\n") +
         "[signals.Va]\nsubdevice = 0\nchannel = 3\nrange = [-0.4, 3.0]\nscale = 50.0\nunit = \"V\"\n";
}


fc::Card& fresh_card() { return fc::reset(bench::batch_unit(1, 1), bench::BenchOptions{}, 7); }

constexpr double kLsb10 = 20.0 / 65535.0;  // V, one step of a 16-bit +-10 V converter

TEST(ComediBackend, MapsChannelsAndUnwrapsTheEncoder) {
  fc::Card& card = fresh_card();
  ComediBackend backend(parse_bench_description(bench_text(), "fake.toml"));
  LoopOptions lo;
  lo.duration = 0.3;
  lo.realtime = false;
  lo.controller = false;
  lo.keep_log = true;
  lo.limits = parse_bench_description(bench_text(), "fake.toml").limits;
  lo.excitation = Eigen::VectorXd::LinSpaced(3000, 0.0, 6.0);  // up to 120 V: d_e moves tens of um
  io::TimeSeries log;
  const LoopReport r = run_loop(backend, lo, &log);
  ASSERT_EQ(r.cycles, 3000u);
  EXPECT_EQ(r.safe_state_reason, "none");
  ASSERT_EQ(card.sampled.size(), 3001u);  // the origin read in start() and one per cycle
  EXPECT_EQ(backend.setup("Vs").range_max, 10.0);
  EXPECT_EQ(backend.setup("Va").range_max, 5.0);  // the smallest range that covers [-0.4, 3] V
  EXPECT_EQ(backend.setup("Vs").calibration, "soft");
  double de_err = 0.0, vs_err = 0.0, va_err = 0.0, de_span = 0.0;
  const double de0 = card.sampled[0].de;
  for (Eigen::Index k = 0; k < 3000; ++k) {
    const bench::BenchSample& s = card.sampled[static_cast<std::size_t>(k) + 1];
    de_err = std::max(de_err, std::abs(log.channel("de")(k) - (s.de - de0)));
    de_span = std::max(de_span, std::abs(s.de - de0));
    vs_err = std::max(vs_err, std::abs(log.channel("Vs")(k) - s.vs));
    va_err = std::max(va_err, std::abs(log.channel("Va")(k) - s.va));
  }
  // The counter starts 256 counts below its 24-bit wrap: 40 um is 16,000 counts across it.
  EXPECT_GT(de_span, 5e-6);
  EXPECT_LE(de_err, 2 * 2.5e-9);
  EXPECT_LE(vs_err, kLsb10);
  EXPECT_LE(va_err, 50.0 * kLsb10);
}

TEST(ComediBackend, CalibratesTheConverters) {
  for (const std::string mode : {"soft", "hard", "none"}) {
    fc::Card& card = fresh_card();
    ComediBackend backend(parse_bench_description(bench_text(mode), "fake.toml"));
    backend.start();
    card.now.vs = 2.0;
    const SensorSample s = backend.read();
    backend.write(5.0);  // 5 V of u at the DAC
    if (mode == "none") {
      // The converters' errors show: 1.02 x 2 + 0.01 V read, 0.99 x 5 - 0.004 V written.
      EXPECT_NEAR(s.vs, 2.05, kLsb10);
      EXPECT_NEAR(card.dac_volts, 4.946, kLsb10);
      EXPECT_FALSE(card.hard_applied);
    } else {
      EXPECT_NEAR(s.vs, 2.0, kLsb10) << mode;
      EXPECT_NEAR(card.dac_volts, 5.0, kLsb10) << mode;
      EXPECT_EQ(card.hard_applied, mode == "hard");
      EXPECT_EQ(backend.setup("u").calibration, mode);
    }
    backend.stop();
    // stop() leaves the safe output (0 V, but for the uncalibrated DAC's offset).
    EXPECT_NEAR(card.dac_volts, mode == "none" ? -0.004 : 0.0, kLsb10) << mode;
  }
  // Soft calibration without the board's file: refused, naming the program that makes it.
  fc::Card& card = fresh_card();
  card.calibration_file = false;
  ComediBackend backend(parse_bench_description(bench_text("soft"), "fake.toml"));
  try {
    backend.start();
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_TRUE(test::contains(e.what(), "comedi_soft_calibrate")) << e.what();
  }
}

TEST(ComediBackend, RefusesTheCardBeforeAnythingMoves) {
  const auto start_error = [](const std::string& text) {
    fc::Card& card = fresh_card();
    ComediBackend backend(parse_bench_description(text, "fake.toml"));
    std::string what;
    try {
      backend.start();
    } catch (const InputError& e) {
      what = e.what();
    }
    EXPECT_EQ(card.writes + card.direct_writes, 0u) << "the output moved before the error: " << what;
    return what;
  };
  const std::string base = bench_text();
  std::string e = start_error(test::replace_once(base, "subdevice = 0\nchannel = 2", "subdevice = 0\nchannel = 20"));
  EXPECT_TRUE(test::contains(e, "signals.Vs.channel")) << e;
  EXPECT_TRUE(test::contains(e, "missing channel")) << e;
  e = start_error(test::replace_once(base, "subdevice = 1\nchannel = 0", "subdevice = 0\nchannel = 0"));
  EXPECT_TRUE(test::contains(e, "analog output")) << e;
  e = start_error(test::replace_once(base, "channel = 2\nrange = [-10, 10]", "channel = 2\nrange = [-20, 20]"));
  EXPECT_TRUE(test::contains(e, "signals.Vs.range")) << e;
  EXPECT_TRUE(test::contains(e, "[-10, 10], [-5, 5], [-1, 1]")) << e;
  e = start_error(test::replace_once(base, "/dev/comedi-fake0", "/dev/comedi-none"));
  EXPECT_TRUE(test::contains(e, "comedi.device")) << e;
}

TEST(ComediBackend, ASaturatedLoopKeepsVaInsideTheRangeAndTheSlewLimit) {
  fc::Card& card = fresh_card();
  const BenchDescription d = parse_bench_description(bench_text(), "fake.toml");
  ComediBackend backend(d);
  LoopOptions lo;
  lo.duration = 0.5;
  lo.realtime = false;
  lo.gain = 2.8e6;  // ten times the optimum
  lo.limits = d.limits;
  Eigen::VectorXd u(5000);
  for (Eigen::Index k = 0; k < u.size(); ++k) u(k) = 6.0 * std::sin(2.0 * 3.14159265358979 * 97.0 * k / 1e4) + 3.0 * ((k / 100) % 2 ? 1 : -1);
  lo.excitation = u;  // far beyond the range and the slew limit
  const LoopReport r = run_loop(backend, lo);
  EXPECT_EQ(r.cycles, 5000u);
  EXPECT_EQ(r.safe_state_reason, "none");
  EXPECT_GT(r.clamped_samples, 100u);
  EXPECT_GT(r.slew_limited_samples, 100u);
  // The DAC's true output (the soft calibration removes its gain error) times the amplifier's gain.
  EXPECT_GE(20.0 * card.dac_min, -20.0 - 20.0 * kLsb10);
  EXPECT_LE(20.0 * card.dac_max, 150.0 + 20.0 * kLsb10);
  EXPECT_LE(20.0 * card.max_dac_step, 1e5 / 1e4 + 20.0 * kLsb10);
  EXPECT_LT(20.0 * card.dac_min, -19.0);  // it did saturate
  EXPECT_GE(card.va_min, -20.0 - 0.05);
  EXPECT_LE(card.va_max, 150.0 + 0.05);
  EXPECT_LE(card.max_va_step, 1e5 / 1e4 + 0.05);  // V per sample at the stacks
}

TEST(ComediBackend, AFailingInputRampsTheOutputToZero) {
  fc::Card& card = fresh_card();
  card.fail_reads_after = 3000;  // the origin read and 2999 cycles
  const BenchDescription d = parse_bench_description(bench_text(), "fake.toml");
  ComediBackend backend(d);
  LoopOptions lo;
  lo.duration = 0.5;
  lo.realtime = false;
  lo.controller = false;
  lo.keep_log = true;
  lo.limits = d.limits;
  lo.excitation = Eigen::VectorXd::Constant(1, 7.0);  // 140 V at the stacks when the input fails
  io::TimeSeries log;
  const LoopReport r = run_loop(backend, lo, &log);
  EXPECT_EQ(r.safe_state_reason, "non-finite sensor");
  EXPECT_EQ(r.safe_state_cycle, 2999);
  EXPECT_EQ(backend.io_stats().errors, 2001u);
  ASSERT_EQ(log.samples(), 5000);  // the log is complete, the safe state included
  EXPECT_NEAR(log.channel("Va_cmd")(2998), 140.0, 1e-9);
  // 140 V at 1e5 V/s: 1.4 ms, 14 cycles at 10 kHz (docs/hardware.md "Safety").
  EXPECT_GT(log.channel("Va_cmd")(2999 + 12), 0.0);
  EXPECT_EQ(log.channel("Va_cmd")(2999 + 14), 0.0);
  EXPECT_NEAR(card.dac_volts, 0.0, kLsb10);
}

TEST(ComediBackend, RunsInRealTimeAtTenKilohertz) {
  fresh_card();
  const BenchDescription d = parse_bench_description(bench_text(), "fake.toml");
  ComediBackend backend(d);
  LoopOptions lo;
  lo.duration = 0.2;
  lo.gain = 280000.0;
  lo.limits = d.limits;
  lo.limits.watchdog_timeout = 1.0;  // a loaded CI machine is no real-time target
  lo.sched_fifo = lo.lock_memory = false;
  const LoopReport r = run_loop(backend, lo);
  EXPECT_EQ(r.cycles, 2000u);
  EXPECT_EQ(r.io.exchanges, 2000u);
  EXPECT_EQ(r.io.errors, 0u);
  EXPECT_EQ(r.io.round_trip_us.count, 2000u);
  EXPECT_EQ(r.safe_state_reason, "none");
}

}  // namespace
}  // namespace piezobench::rt
