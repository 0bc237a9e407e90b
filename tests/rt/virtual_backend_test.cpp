#include "piezobench/rt/virtual_backend.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "piezobench/rt/loop.hpp"
#include "test_util.hpp"

namespace piezobench::rt {
namespace {


TEST(VirtualBenchBackend, SteppedInLockstep) {
  const bench::UnitTruth unit = bench::batch_unit(1, 1);
  VirtualBenchBackend b(unit, bench::BenchOptions{}, 4);
  EXPECT_EQ(b.name(), "virtual");
  EXPECT_EQ(b.sample_rate(), 10e3);
  bench::VirtualBench reference(unit, bench::BenchOptions{}, 4);
  b.start();
  SensorSample s = b.read();
  EXPECT_EQ(s.sequence, 0u);  // at rest before the first command
  for (int k = 0; k < 200; ++k) {
    const double u = 0.5 * std::sin(0.05 * k);
    b.write(u);
    const bench::BenchSample m = reference.step(u);
    s = b.read();
    ASSERT_EQ(s.de, m.de);
    ASSERT_EQ(s.vs, m.vs);
    ASSERT_EQ(s.va, m.va);
    ASSERT_EQ(s.sequence, static_cast<std::uint64_t>(k + 1));
  }
  // start() puts the bench back at rest with the same noise: the same run again.
  b.start();
  b.write(0.5);
  const double de1 = b.read().de;
  b.start();
  b.write(0.5);
  EXPECT_EQ(b.read().de, de1);
}

// The loop on the virtual bench: the log holds what the bench measured for the commands the loop
// wrote (replayed on an independent bench with the same seed, sample for sample).
TEST(VirtualBenchBackend, LogHoldsTheCommandsAndTheBenchMeasurements) {
  const bench::UnitTruth unit = bench::batch_unit(2, 7);
  VirtualBenchBackend b(unit, bench::BenchOptions{}, 7);
  LoopOptions o;
  o.realtime = false;
  o.duration = 0.3;
  o.gain = 2.8e5;
  o.keep_log = true;
  o.excitation = test::gaussian_noise(3000, 0.05, 3);
  io::TimeSeries log;
  const LoopReport rep = run_loop(b, o, &log);
  ASSERT_EQ(log.samples(), 3000);
  EXPECT_EQ(rep.safe_state_events, 0u);
  EXPECT_EQ(rep.clamped_samples, 0u);
  bench::VirtualBench reference(unit, bench::BenchOptions{}, 7);
  bench::BenchSample m = reference.step(0.0);  // the loop writes the safe output before cycle 0
  const auto u = log.channel("u");
  for (Eigen::Index k = 0; k < 3000; ++k) {
    ASSERT_EQ(log.channel("de")(k), m.de) << k;
    ASSERT_EQ(log.channel("Vs")(k), m.vs) << k;
    ASSERT_EQ(log.channel("Va")(k), m.va) << k;
    ASSERT_EQ(log.channel("Va_cmd")(k), 20.0 * u(k));
    m = reference.step(u(k));
  }
  // The controller did act (y reaches a tenth of the excitation within the 0.3 s).
  EXPECT_GT(log.channel("y").cwiseAbs().maxCoeff(), 0.01);
}

// Pushed into saturation on the bench: the measured stack voltage stays in -20..150 V and moves at
// most by the slew limit per sample (plus one DAC step, 20 V/V x 20 V / 2^16, of quantization).
TEST(VirtualBenchBackend, SaturatedLoopKeepsTheMeasuredVoltageInRange) {
  const bench::UnitTruth unit = bench::batch_unit(1, 1);
  VirtualBenchBackend b(unit, bench::BenchOptions{}, 1);
  LoopOptions o;
  o.realtime = false;
  o.duration = 0.3;
  o.gain = 1e8;
  o.keep_log = true;
  o.excitation = test::gaussian_noise(3000, 5.0, 8);
  io::TimeSeries log;
  const LoopReport rep = run_loop(b, o, &log);
  EXPECT_GT(rep.clamped_samples, 0u);
  EXPECT_GT(rep.slew_limited_samples, 0u);
  const auto va = log.channel("Va");
  EXPECT_GE(va.minCoeff(), -20.0);
  EXPECT_LE(va.maxCoeff(), 150.0);
  const double step_limit = o.limits.slew_rate / 10e3 + 20.0 * 20.0 / 65536.0;
  for (Eigen::Index k = 1; k < va.size(); ++k) ASSERT_LE(std::abs(va(k) - va(k - 1)), step_limit) << k;
}

}  // namespace
}  // namespace piezobench::rt
