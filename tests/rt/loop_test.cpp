#include "piezobench/rt/loop.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <random>
#include <thread>
#include <vector>

#include "alloc_counter.hpp"
#include "fake_backend.hpp"
#include "piezobench/control/iff.hpp"
#include "piezobench/lti/conversions.hpp"
#include "piezobench/lti/discretize.hpp"
#include "piezobench/lti/interconnect.hpp"
#include "test_util.hpp"

namespace piezobench::rt {
using fake::FakeBackend;
}

namespace piezobench::rt {
namespace {

constexpr double kFs = 10e3;

// The report's IFF plant u -> Vs (eq. 2.3), exact ZOH discretization at 10 kHz, delayed by one
// sample: a sensor read at the start of a cycle reflects the commands up to the previous one
// (eq. 2.3 is biproper, and its feedthrough must not act within the cycle). The delay is a state
// (u of the previous sample), so that lti::feedback can close the loop in the reference.
lti::StateSpace discrete_plant() {
  const lti::StateSpace g = lti::c2d(lti::to_state_space(control::iff_plant()), 1.0 / kFs);
  const lti::Index n = g.states();
  lti::Matrix a = lti::Matrix::Zero(n + 1, n + 1), b = lti::Matrix::Zero(n + 1, 1), c(1, n + 1);
  a.topLeftCorner(n, n) = g.A;
  a.topRightCorner(n, 1) = g.B;
  b(n, 0) = 1.0;
  c << g.C, g.D;
  return lti::StateSpace(a, b, c, lti::Matrix::Zero(1, 1), g.sample_time);
}


LoopOptions lockstep_options(double duration) {
  LoopOptions o;
  o.realtime = false;
  o.duration = duration;
  o.keep_log = true;
  return o;
}

std::uint64_t run_all(Loop& loop) {
  loop.start();
  std::uint64_t n = 0;
  while (loop.cycle()) ++n;
  return n;
}

// Without ramps or limits, the loop is exactly the discrete interconnection u = u' + g K(z) Vs,
// Vs = G(z) u: the logged Vs and u equal lsim of the closed loop built with lti::feedback.
TEST(Loop, ClosedLoopEqualsTheDiscreteInterconnection) {
  const lti::StateSpace plant = discrete_plant();
  FakeBackend backend(plant, kFs);
  LoopOptions o = lockstep_options(0.3);
  o.gain = 1.5e5;
  o.limits.ramp_in = 0.0;
  o.limits.ramp_out = 0.0;
  o.excitation = test::gaussian_noise(3000, 0.05, 11);
  Loop loop(backend, o);
  EXPECT_GE(run_all(loop), 3000u);  // + the wind-down cycle (no ramp out here)
  const LoopReport rep = loop.finish();
  EXPECT_LE(rep.wind_down_cycles, 1u);
  EXPECT_EQ(rep.cycles, 3000u);
  EXPECT_EQ(rep.clamped_samples, 0u);
  EXPECT_EQ(rep.slew_limited_samples, 0u);
  EXPECT_EQ(rep.safe_state_events, 0u);
  EXPECT_EQ(rep.dropped_log_samples, 0u);
  const io::TimeSeries& log = loop.log();
  ASSERT_EQ(log.samples(), 3000);

  const lti::StateSpace k = lti::scale(loop.controller().model(), o.gain);
  const lti::StateSpace closed = lti::feedback(plant, k, lti::FeedbackSign::kPositive);
  const Eigen::VectorXd vs_ref = lti::lsim(closed, o.excitation).y.col(0);
  const Eigen::VectorXd u_ref = o.excitation + lti::lsim(k, vs_ref).y.col(0);
  const double vs_scale = vs_ref.cwiseAbs().maxCoeff();
  const double u_scale = u_ref.cwiseAbs().maxCoeff();
  EXPECT_TRUE(test::all_near(log.channel("Vs"), vs_ref, test::Tolerance{0.0, 1e-10 * vs_scale}));
  EXPECT_TRUE(test::all_near(log.channel("u"), u_ref, test::Tolerance{0.0, 1e-10 * u_scale}));
  EXPECT_TRUE(test::all_near(log.channel("u_prime"), o.excitation, test::Tolerance{0.0, 0.0}));
  // The feedback really acts: u differs from u' by much more than round-off.
  EXPECT_GT((log.channel("u") - o.excitation).cwiseAbs().maxCoeff(), 0.1 * u_scale);
  // Va: the fake backend measures none, so the log holds the command times 20 V/V.
  EXPECT_TRUE(test::all_near(log.channel("Va"), 20.0 * u_ref, test::Tolerance{0.0, 1e-9 * u_scale}));
  EXPECT_TRUE(backend.stopped);
}

// The cycle allocates nothing: controller, safety, backend, log push, a fault and the safe state,
// with the logger thread draining the ring at the same time.
TEST(Loop, CycleAllocatesNothing) {
  FakeBackend backend(discrete_plant(), kFs);
  backend.nan_at = 2500;
  backend.writes_u.resize(4000);
  LoopOptions o = lockstep_options(0.35);
  o.gain = 2.8e5;
  o.limits.ramp_in = 0.01;
  o.limits.ramp_out = 0.01;
  o.excitation = test::gaussian_noise(1000, 2.0, 5);  // large: clamps and slew limits too
  o.realtime = true;                   // the real-time path (push, timing), paced by the test
  ident::HysteresisModel m;            // with the inverse hysteresis feedforward and its creep states
  m.hysteresis = {1.0, {10.0, 30.0}, {0.2, 0.3}};
  m.creep_time_constants = {1.0};
  m.creep_coefficients = {0.01};
  m.gain = -1.6e-6;
  o.feedforward = m;
  Loop loop(backend, o);
  loop.start();
  std::uint64_t n = 0;
  {
    test::AllocationCounter count;
    const std::int64_t t0 = monotonic_ns();
    while (loop.cycle(t0 + static_cast<std::int64_t>(n) * 100'000, monotonic_ns())) ++n;
    EXPECT_EQ(count.allocations(), 0u);
  }
  const LoopReport rep = loop.finish();
  EXPECT_EQ(n, 3500u + rep.wind_down_cycles);
  EXPECT_GT(rep.clamped_samples, 0u);
  EXPECT_GT(rep.slew_limited_samples, 0u);
  EXPECT_EQ(rep.safe_state_reason, "non-finite sensor");
  EXPECT_EQ(rep.step_time_us.count, 3500u);
}

// The log tap (the station's live page) gets every N-th record on the logger's thread, in order,
// then an empty batch at the run's end; a tap that does not return (a page that stops reading)
// holds neither the cycles nor makes them allocate, and nothing is dropped from the log.
TEST(Loop, TheLogTapGetsEveryNthRecordOffTheLoopAndNeverHoldsIt) {
  FakeBackend backend(discrete_plant(), kFs);
  LoopOptions o = lockstep_options(0.2);  // 2000 cycles
  o.realtime = true;                      // push, never wait: paced by the test
  o.controller = false;
  o.excitation = test::gaussian_noise(500, 0.5, 3);
  std::atomic<bool> open{false};
  std::atomic<int> calls_while_closed{0};
  std::vector<LogRecord> tapped;
  std::vector<std::size_t> batch_sizes;
  std::thread::id tap_thread;
  o.log_tap.every = 10;
  o.log_tap.deliver = [&](std::span<const LogRecord> records) {
    if (!open.load()) calls_while_closed.fetch_add(1);
    while (!open.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    tap_thread = std::this_thread::get_id();
    tapped.insert(tapped.end(), records.begin(), records.end());
    batch_sizes.push_back(records.size());
  };
  Loop loop(backend, o);
  loop.start();
  std::uint64_t n = 0;
  const std::int64_t t0 = monotonic_ns();
  {
    test::AllocationCounter count;
    while (loop.cycle(t0 + static_cast<std::int64_t>(n) * 100'000, monotonic_ns())) ++n;
    EXPECT_EQ(count.allocations(), 0u);
  }
  EXPECT_EQ(n, 2000u);
  EXPECT_LE(calls_while_closed.load(), 1);  // the logger waits in the first delivery
  open.store(true);
  const LoopReport rep = loop.finish();
  EXPECT_EQ(rep.dropped_log_samples, 0u);
  const io::TimeSeries& log = loop.log();
  ASSERT_EQ(tapped.size(), 200u);
  for (std::size_t k = 0; k < tapped.size(); ++k) {
    const auto row = static_cast<Eigen::Index>(10 * k);
    EXPECT_DOUBLE_EQ(tapped[k].t, log.t(row));
    EXPECT_DOUBLE_EQ(tapped[k].u, log.channel("u")(row));
    EXPECT_DOUBLE_EQ(tapped[k].vs, log.channel("Vs")(row));
  }
  EXPECT_NE(tap_thread, std::this_thread::get_id());
  ASSERT_FALSE(batch_sizes.empty());
  EXPECT_EQ(batch_sizes.back(), 0u);  // the run's end
  // Each record's measurement time: its cycle's wake-up, as the test paced it.
  EXPECT_GE(tapped.front().measured_ns, t0);
  for (std::size_t k = 1; k < tapped.size(); ++k) EXPECT_GT(tapped[k].measured_ns, tapped[k - 1].measured_ns);
}

// Ramps: the command starts and ends at the safe output, linearly in between (open loop, u' = 1 V).
TEST(Loop, RampsInAndOut) {
  FakeBackend backend(discrete_plant(), kFs);
  LoopOptions o = lockstep_options(0.1);  // 1000 cycles
  o.controller = false;
  o.limits.ramp_in = 0.01;   // 100 cycles
  o.limits.ramp_out = 0.02;  // 200 cycles
  o.excitation = Eigen::VectorXd::Constant(1, 1.0);
  Loop loop(backend, o);
  run_all(loop);
  const LoopReport rep = loop.finish();
  const auto u = loop.log().channel("u");
  const auto flags = loop.log().channel("flags");
  ASSERT_EQ(u.size(), 1000);
  EXPECT_EQ(u(0), 0.0);
  EXPECT_DOUBLE_EQ(u(50), 0.5);
  EXPECT_DOUBLE_EQ(u(100), 1.0);
  EXPECT_DOUBLE_EQ(u(799), 1.0);
  EXPECT_DOUBLE_EQ(u(899), 0.5);
  EXPECT_EQ(u(999), 0.0);
  EXPECT_EQ(static_cast<unsigned>(flags(50)) & kFlagRamping, kFlagRamping);
  EXPECT_EQ(static_cast<unsigned>(flags(500)) & kFlagRamping, 0u);
  EXPECT_EQ(rep.slew_limited_samples, 0u);  // 0.01 V per sample, far below 0.5
  EXPECT_EQ(rep.wind_down_cycles, 0u);
}

// Pushed into saturation (a huge gain, or a large excitation), the commanded stack voltage never
// leaves -20..150 V nor moves faster than the slew limit, and the limiting is counted.
TEST(Loop, SaturationKeepsTheVoltageInRangeAndSlewLimited) {
  for (const double gain : {5e7, 2.8e5}) {
    SCOPED_TRACE("gain " + std::to_string(gain));
    FakeBackend backend(discrete_plant(), kFs);
    LoopOptions o = lockstep_options(0.5);
    o.gain = gain;
    o.excitation.resize(500);  // 20 Hz, 10 V at the DAC (200 V at the stacks): 2.5 V per sample at most
    for (Eigen::Index k = 0; k < 500; ++k) o.excitation(k) = 10.0 * std::sin(2 * M_PI * k / 500.0);
    o.limits.slew_rate = 2e4;  // 2 V per sample at the stacks
    o.limits.saturation_time = 10.0;  // the saturation policy is tested below
    Loop loop(backend, o);
    run_all(loop);
    const LoopReport rep = loop.finish();
    EXPECT_GT(rep.clamped_samples, 100u);
    if (gain > 1e6) {
      EXPECT_GT(rep.slew_limited_samples, 100u);  // the unstable loop oscillates
    }
    EXPECT_EQ(rep.safe_state_reason, "none");
    const auto va = loop.log().channel("Va_cmd");
    EXPECT_GE(va.minCoeff(), -20.0);
    EXPECT_LE(va.maxCoeff(), 150.0);
    double max_step = std::abs(va(0));
    for (Eigen::Index k = 1; k < va.size(); ++k) max_step = std::max(max_step, std::abs(va(k) - va(k - 1)));
    EXPECT_LE(max_step, 2.0 + 1e-9);
    EXPECT_DOUBLE_EQ(rep.max_va_cmd_step, max_step);
    EXPECT_DOUBLE_EQ(rep.va_cmd_min, va.minCoeff());
    EXPECT_DOUBLE_EQ(rep.va_cmd_max, va.maxCoeff());
    if (gain < 1e6) {  // the stable loop follows the large excitation up to both limits
      EXPECT_NEAR(va.minCoeff(), -20.0, 1e-9);
      EXPECT_NEAR(va.maxCoeff(), 150.0, 1e-9);
    }
  }
}

// An output pinned to the upper limit (open loop, u' = 10 V at the DAC, above 7.5 V) goes to the
// safe state after saturation_time (100 samples at 10 kHz) and the report says why.
TEST(Loop, OutputSaturatedForTheSaturationTimeEntersTheSafeState) {
  FakeBackend backend(discrete_plant(), kFs);
  LoopOptions o = lockstep_options(0.1);
  o.controller = false;
  o.limits.ramp_in = 0.0;
  o.limits.slew_rate = 1e12;
  o.limits.saturation_time = 0.01;
  o.excitation = Eigen::VectorXd::Constant(1, 10.0);
  Loop loop(backend, o);
  run_all(loop);
  const LoopReport rep = loop.finish();
  EXPECT_EQ(rep.safe_state_reason, "output saturated");
  EXPECT_EQ(rep.safe_state_cycle, 99);  // the 100th clamped sample
  EXPECT_EQ(rep.clamped_samples, 100u);
  const auto u = loop.log().channel("u");
  EXPECT_EQ(u(99), 7.5);
  EXPECT_EQ(u(100), 0.0);
}

// The inverse hysteresis feedforward sits before the clamp and the slew limit: a command that
// would exceed the limits (and whose inverse asks for more still) leaves the stack voltage within
// -20..150 V and the slew limit; where nothing limits it, u is the feedforward's output.
TEST(Loop, FeedforwardStaysWithinTheLimits) {
  ident::HysteresisModel m;
  m.hysteresis = {1.0, {10.0, 30.0, 50.0}, {0.2, 0.3, 0.2}};
  m.gain = -1.6e-6;
  m.reference_slope = 1.6;
  m.reference_intercept = -5.0;
  // With the default saturation policy the clamped output trips the safe state; with a long
  // saturation time the run clamps to the end. Either way the limits hold.
  for (const double saturation_time : {0.1, 10.0}) {
    SCOPED_TRACE("saturation_time " + std::to_string(saturation_time));
    FakeBackend backend(discrete_plant(), kFs);
    LoopOptions o = lockstep_options(0.5);
    o.controller = false;
    o.feedforward = m;
    o.limits.ramp_in = 0.0;
    o.limits.ramp_out = 0.0;
    o.limits.slew_rate = 2e4;  // 2 V per sample at the stacks
    o.limits.saturation_time = saturation_time;
    o.excitation.resize(1000);  // 10 Hz, 9 V at the DAC (180 V at the stacks) about 3 V
    for (Eigen::Index k = 0; k < 1000; ++k) o.excitation(k) = 3.0 + 9.0 * std::sin(2 * M_PI * k / 1000.0);
    Loop loop(backend, o);
    run_all(loop);
    const LoopReport rep = loop.finish();
    EXPECT_TRUE(rep.feedforward);
    EXPECT_GT(rep.clamped_samples, 100u);
    EXPECT_GT(rep.slew_limited_samples, 0u);
    EXPECT_EQ(rep.safe_state_reason, saturation_time < 1.0 ? "output saturated" : "none");
    const auto va = loop.log().channel("Va_cmd");
    EXPECT_GE(va.minCoeff(), -20.0);
    EXPECT_LE(va.maxCoeff(), 150.0);
    EXPECT_NEAR(va.maxCoeff(), 150.0, 1e-9);
    double max_step = std::abs(va(0));
    for (Eigen::Index k = 1; k < va.size(); ++k) max_step = std::max(max_step, std::abs(va(k) - va(k - 1)));
    EXPECT_LE(max_step, 2.0 + 1e-9);
    if (saturation_time < 1.0) continue;
    // Unlimited samples carry the feedforward's output.
    control::HysteresisFeedforward ff(m, kFs);
    const auto u = loop.log().channel("u");
    const auto flags = loop.log().channel("flags");
    std::size_t checked = 0;
    for (Eigen::Index k = 0; k < u.size(); ++k) {
      const double expected = ff.step(20.0 * o.excitation(k % 1000)) / 20.0;
      if (flags(k) == 0.0) {
        ASSERT_NEAR(u(k), expected, 1e-12) << k;
        ++checked;
      }
    }
    EXPECT_GT(checked, 1000u);
  }
}

// The feedforward's weight w per cycle: u = u' + w (stage - u'), the stage stepping on every u'
// (its memory follows the whole command, blended or not): w = 0 gives u', w = 1 the stage's output.
TEST(Loop, FeedforwardWeightBlendsTheStageInAndOut) {
  ident::HysteresisModel m;
  m.hysteresis = {1.0, {10.0, 30.0, 50.0}, {0.2, 0.3, 0.2}};
  m.gain = -1.6e-6;
  m.reference_slope = 1.3;
  m.reference_intercept = 4.0;
  FakeBackend backend(discrete_plant(), kFs);
  LoopOptions o = lockstep_options(0.1);
  o.controller = false;
  o.feedforward = m;
  o.limits.ramp_in = o.limits.ramp_out = 0.0;
  const Eigen::Index n = 1000;
  o.excitation.resize(n);
  o.feedforward_weight.resize(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    o.excitation(k) = 2.5 - 2.5 * std::cos(2 * M_PI * 3.0 * static_cast<double>(k) / static_cast<double>(n));  // 0..100 V
    o.feedforward_weight(k) = std::min(1.0, static_cast<double>(k) / 300.0);
  }
  Loop loop(backend, o);
  run_all(loop);
  const LoopReport rep = loop.finish();
  EXPECT_EQ(rep.clamped_samples + rep.slew_limited_samples, 0u);
  control::HysteresisFeedforward ff(m, kFs);
  const auto u = loop.log().channel("u");
  ASSERT_EQ(u.size(), n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double stage = ff.step(20.0 * o.excitation(k)) / 20.0;  // the stage alone, then blended by hand
    ASSERT_NEAR(u(k), o.excitation(k) + o.feedforward_weight(k) * (stage - o.excitation(k)), 1e-12) << k;
  }
  EXPECT_NEAR(u(0), o.excitation(0), 1e-12);
}

// A NaN sample: safe state at that cycle, output to the safe value at the slew limit, controller
// reset, the log stays finite and flags the sample.
TEST(Loop, NonFiniteSensorSampleEntersTheSafeState) {
  FakeBackend backend(discrete_plant(), kFs);
  backend.nan_at = 500;
  LoopOptions o = lockstep_options(0.1);
  o.gain = 1e5;
  o.excitation = Eigen::VectorXd::Constant(1, 2.0);  // 40 V at the stacks when the fault hits
  o.limits.ramp_in = 0.0;
  o.limits.slew_rate = 4e4;                          // 0.2 V per sample at the DAC
  Loop loop(backend, o);
  run_all(loop);
  const LoopReport rep = loop.finish();
  EXPECT_EQ(rep.safe_state_events, 1u);
  EXPECT_EQ(rep.safe_state_reason, "non-finite sensor");
  EXPECT_EQ(rep.safe_state_cycle, 500);
  EXPECT_EQ(rep.nonfinite_sensor_samples, 1u);
  const io::TimeSeries& log = loop.log();
  const auto u = log.channel("u");
  const auto y = log.channel("y");
  const auto flags = log.channel("flags");
  const double before = u(499);
  EXPECT_GT(before, 0.5);
  EXPECT_NEAR(u(500), before - 0.2, 1e-12);  // slewing down, not a jump
  for (Eigen::Index k = 500; k < u.size(); ++k) {
    ASSERT_EQ(y(k), 0.0);  // controller off and reset
    ASSERT_NE(static_cast<unsigned>(flags(k)) & kFlagSafeState, 0u);
  }
  EXPECT_EQ(u(u.size() - 1), 0.0);
  EXPECT_NE(static_cast<unsigned>(flags(500)) & kFlagSensorFault, 0u);
  EXPECT_EQ(log.channel("Vs")(500), 0.0);
  EXPECT_TRUE(log.data.allFinite());
  EXPECT_EQ(static_cast<unsigned>(flags(499)) & kFlagSafeState, 0u);
}

TEST(Loop, AStopRequestRampsToTheSafeOutputAndEndsTheRun) {
  FakeBackend backend(discrete_plant(), kFs);
  std::atomic<bool> stop{false};
  LoopOptions o = lockstep_options(0.1);
  o.controller = false;
  o.excitation = Eigen::VectorXd::Constant(1, 2.0);  // 40 V at the stacks when Ctrl-C comes
  o.limits.ramp_in = 0.0;
  o.limits.ramp_out = 0.0;
  o.limits.slew_rate = 4e4;                          // 0.2 V per sample at the DAC: 10 cycles
  o.stop = &stop;
  Loop loop(backend, o);
  loop.start();
  for (int k = 0; k < 300; ++k) ASSERT_TRUE(loop.cycle());
  stop = true;  // what the SIGINT handler does
  int more = 0;
  while (loop.cycle()) ++more;
  const LoopReport rep = loop.finish();
  EXPECT_TRUE(rep.interrupted);
  EXPECT_EQ(rep.safe_state_reason, "interrupted");
  EXPECT_EQ(rep.safe_state_cycle, 300);
  // 2 V at 0.2 V per cycle (one more for the round-off of ten steps), then the run ends.
  EXPECT_GE(more, 10);
  EXPECT_LE(more, 11);
  const io::TimeSeries& log = loop.log();
  ASSERT_EQ(log.samples(), 300 + more);  // every cycle up to the end, the ramp included
  EXPECT_NEAR(log.channel("u")(299), 2.0, 1e-12);
  EXPECT_NEAR(log.channel("u")(300), 1.8, 1e-12);
  EXPECT_EQ(log.channel("u")(299 + more), 0.0);
}

TEST(Loop, StaleSensorEntersTheSafeStateAfterTheToleratedReads) {
  FakeBackend backend(discrete_plant(), kFs);
  backend.stale_from = 300;  // reads 300.. repeat the sequence number of read 299
  LoopOptions o = lockstep_options(0.05);
  o.gain = 1e5;
  o.limits.stale_cycles = 3;
  Loop loop(backend, o);
  run_all(loop);
  const LoopReport rep = loop.finish();
  EXPECT_EQ(rep.safe_state_reason, "stale sensor");
  EXPECT_EQ(rep.safe_state_cycle, 303);  // reads 300, 301, 302 tolerated, 303 trips
  EXPECT_EQ(rep.stale_sensor_samples, 500u - 300u);
}

// Real time: the backend stalls 120 ms in one read; the watchdog (20 ms) trips, calls the
// backend's on_watchdog and the loop goes to its safe state.
TEST(RunLoop, WatchdogTripsOnAStalledLoop) {
  FakeBackend backend(discrete_plant(), kFs);
  backend.stall_at = 100;
  backend.stall = std::chrono::milliseconds(120);
  LoopOptions o;
  o.duration = 0.03;
  o.gain = 1e5;
  o.limits.watchdog_timeout = 0.02;
  const LoopReport rep = run_loop(backend, o);
  EXPECT_EQ(rep.safe_state_reason, "watchdog");
  EXPECT_GE(rep.watchdog_trips, 1u);
  EXPECT_GE(backend.watchdog_calls.load(), 1);
  EXPECT_LE(rep.safe_state_cycle, 100);
  EXPECT_GE(rep.skipped_deadlines, 1000u);  // 120 ms late: the missed deadlines are skipped
  EXPECT_GE(rep.overruns, 1u);
}

// A real-time run reports its timing and either got SCHED_FIFO / mlockall or says why not.
TEST(RunLoop, RealTimeRunReportsTimingAndPrivileges) {
  FakeBackend backend(discrete_plant(), kFs);
  LoopOptions o;
  o.duration = 0.05;
  o.gain = 2.8e5;
  std::vector<std::string> printed;
  o.on_warning = [&](const std::string& w) { printed.push_back(w); };
  const LoopReport rep = run_loop(backend, o);
  EXPECT_TRUE(rep.realtime);
  EXPECT_EQ(rep.cycles, 500u);
  EXPECT_EQ(rep.step_time_us.count, 500u);
  EXPECT_EQ(rep.wake_latency_us.count, 500u);
  EXPECT_EQ(rep.period_jitter_us.count, 499u);
  EXPECT_LE(rep.step_time_us.p50, rep.step_time_us.max);
  EXPECT_LE(rep.period_jitter_us.p99, rep.period_jitter_us.p999 + 1e-12);
  EXPECT_LE(rep.overruns, rep.cycles);
  EXPECT_EQ(rep.overruns_late_wakeup + rep.overruns_long_step, rep.overruns);
  EXPECT_GE(rep.host_wait_ms, -1.0);
  auto warned = [&](const std::string& what) {
    for (const auto& w : rep.warnings) {
      if (test::contains(w, what)) return true;
    }
    return false;
  };
  EXPECT_TRUE(rep.sched_fifo || warned("SCHED_FIFO"));
  EXPECT_TRUE(rep.memory_locked || warned("mlockall"));
  EXPECT_EQ(printed.size(), rep.warnings.size());
}

// An overrun is charged to the larger of its parts: a wake-up 900 us after its deadline (then a
// step of ~100 us) is the host's late wake-up; a wake-up 10 us late followed by 140 us until the
// end of the cycle is a long step. Wake-up and deadline times are given, the end is the clock's.
TEST(Loop, OverrunsAreChargedToTheLateWakeUpOrTheLongStep) {
  FakeBackend backend(discrete_plant(), kFs);
  LoopOptions o;
  o.duration = 1.0;
  o.limits.watchdog_timeout = 10.0;
  Loop loop(backend, o);
  loop.start();
  const std::int64_t now = monotonic_ns();
  ASSERT_TRUE(loop.cycle(now - 1'000'000, now - 100'000));  // late by 900 us, step >= 100 us
  const std::int64_t later = monotonic_ns();
  ASSERT_TRUE(loop.cycle(later - 150'000, later - 140'000));  // late by 10 us, step >= 140 us
  const LoopReport rep = loop.finish();
  EXPECT_EQ(rep.overruns, 2u);
  EXPECT_EQ(rep.overruns_late_wakeup, 1u);
  EXPECT_EQ(rep.overruns_long_step, 1u);
}

TEST(Loop, OptionsAreValidated) {
  FakeBackend backend(discrete_plant(), kFs);
  auto bad = [&](auto mutate, const std::string& field) {
    LoopOptions o;
    mutate(o);
    test::input_error([&] { Loop loop(backend, o); }, field);
  };
  bad([](LoopOptions& o) { o.duration = 0.0; }, "duration");
  bad([](LoopOptions& o) { o.priority = 100; }, "priority");
  bad([](LoopOptions& o) { o.gain = std::nan(""); }, "gain");
  bad([](LoopOptions& o) { o.excitation = Eigen::VectorXd::Constant(3, std::nan("")); }, "excitation");
  bad([](LoopOptions& o) { o.limits.va_max = -100.0; }, "va_max");
  bad([](LoopOptions& o) { o.discrete.prewarp = 1e6; }, "prewarp");
  bad([](LoopOptions& o) { o.excitation = Eigen::VectorXd::Ones(4); o.feedforward_weight = Eigen::VectorXd::Ones(4); }, "feedforward_weight");
  ident::HysteresisModel m;
  m.hysteresis = {1.0, {10.0}, {0.2}};
  m.gain = -1.6e-6;
  bad([&](LoopOptions& o) { o.feedforward = m; o.excitation = Eigen::VectorXd::Ones(4); o.feedforward_weight = Eigen::VectorXd::Ones(3); },
      "feedforward_weight");
  bad([&](LoopOptions& o) { o.feedforward = m; o.excitation = Eigen::VectorXd::Ones(2); o.feedforward_weight = Eigen::Vector2d(0.5, 1.5); },
      "feedforward_weight");
}

}  // namespace
}  // namespace piezobench::rt
