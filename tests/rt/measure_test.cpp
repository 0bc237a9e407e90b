// The bench experiments through rt::BackendRunner: on the virtual bench's backend they give the
// records bench::simulate gives (so the path a card takes is the simulator's), the operator's
// steps are prompted and confirmed, a safety trip refuses the record.
#include "piezobench/rt/measure.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <sstream>

#include "piezobench/bench/tracking.hpp"
#include "piezobench/bench/virtual_bench.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/ident/hysteresis.hpp"
#include "piezobench/rt/virtual_backend.hpp"
#include "test_util.hpp"

namespace piezobench::rt {
namespace {

// The watchdog at 1 s: a loaded CI machine is no real-time target.
BenchDescription virtual_bench(double ramp) {
  return parse_bench_description("[bench]\nbackend = \"virtual\"\nsample_rate_Hz = 10000\n[limits]\nwatchdog_s = 1.0\nramp_s = " +
                                     std::to_string(ramp) + "\n",
                                 "virtual.toml");
}

TEST(BackendRunner, OnTheVirtualBenchItWritesTheSimulatedRecord) {
  const bench::UnitTruth unit = bench::batch_unit(2, 5);
  for (const bench::Experiment e : {bench::Experiment::kFrfNoise, bench::Experiment::kIff, bench::Experiment::kHysteresis}) {
    bench::ExperimentOptions eo;
    if (e != bench::Experiment::kHysteresis) eo.duration = 0.5;
    const io::TimeSeries simulated = bench::simulate(e, unit, eo, 5);
    VirtualBenchBackend backend(unit, eo.bench, bench::experiment_bench_seed(e, 5));
    MeasureOptions mo;
    mo.bench = virtual_bench(0.0);  // the experiments' commands as they are: no ramps
    mo.lockstep = true;
    BackendRunner runner(backend, mo);
    const io::TimeSeries measured = bench::run_experiment(e, runner, unit, eo, 5);
    ASSERT_EQ(measured.names, simulated.names);
    ASSERT_EQ(measured.units, simulated.units);
    ASSERT_EQ(measured.samples(), simulated.samples());
    const double diff = (measured.data - simulated.data).cwiseAbs().maxCoeff();
    EXPECT_LE(diff, 1e-9 * simulated.data.cwiseAbs().maxCoeff()) << bench::to_string(e);
    // The same settings, plus where it was made.
    for (const auto& [key, value] : simulated.settings) {
      if (key == "defective" || key == "noise" || key == "suspended_mass_kg" || key == "hpf_resistance_ohm" || key == "sensor_shunt_ohm" ||
          key == "model" || key == "delay_s" || key == "nmp_zero" || key == "hysteresis" || key == "creep" ||
          key == "recorded_at" || key == "bench") {
        continue;  // what only the simulator knows
      }
      ASSERT_TRUE(measured.settings.count(key)) << key;
      EXPECT_EQ(measured.settings.at(key), value) << key;
    }
    EXPECT_EQ(std::get<std::string>(measured.settings.at("backend")), "virtual");
    EXPECT_EQ(runner.report().runs.size(), 1u);
  }
}

// `measure tracking` on a backend (the virtual bench's, with the Bouc-Wen law: not the identified
// family): both runs go through the real-time loop and its safety layer, the compensated one through
// the loop's own feedforward stage (LoopOptions::feedforward), live; the figures come out of
// it (printed: docs/performance.md), and the record is the one `simulate tracking` makes.
TEST(BackendRunner, TrackingCompensatesTheHysteresisLiveInTheLoop) {
  const bench::UnitTruth unit = bench::batch_unit(2, 1);
  bench::ExperimentOptions eo;
  eo.bench.hysteresis_law = bench::HysteresisLaw::kBoucWen;
  VirtualBenchBackend backend(unit, eo.bench, bench::experiment_bench_seed(bench::Experiment::kTracking, 1));
  MeasureOptions mo;
  mo.bench = virtual_bench(0.0);
  mo.lockstep = true;
  BackendRunner runner(backend, mo);
  const io::TimeSeries r = bench::run_experiment(bench::Experiment::kTracking, runner, unit, eo, 1);
  const bench::TrackingSummary s = bench::tracking_summary(r);
  ASSERT_EQ(runner.report().runs.size(), 2u);
  EXPECT_FALSE(runner.report().runs[0].feedforward);
  EXPECT_TRUE(runner.report().runs[1].feedforward);  // the loop's stage did the compensation
  for (const LoopReport& lr : runner.report().runs) EXPECT_EQ(lr.safe_state_reason, "none");
  for (const auto& [name, f] : {std::pair<const char*, const bench::TrackingFigures&>{"sine", s.sine}, {"triangle", s.triangle}}) {
    std::printf("measure tracking (loop's feedforward stage), bouc-wen 80 V, %-8s width %.2f %% -> %.2f %%, rms %.3f um -> %.3f um (%.1fx)\n",
                name, 100.0 * f.width_open, 100.0 * f.width_ff, 1e6 * f.rms_open, 1e6 * f.rms_ff, f.rms_reduction());
    EXPECT_GT(f.width_open, 0.15) << name;
    EXPECT_LT(f.width_ff, 0.03) << name;
    EXPECT_GE(f.rms_reduction(), 5.0) << name;
  }
  // The same record as the simulator's (its VirtualRunner steps the same stage sample by sample).
  const io::TimeSeries simulated = bench::simulate(bench::Experiment::kTracking, unit, eo, 1);
  ASSERT_EQ(r.samples(), simulated.samples());
  EXPECT_LE((r.data - simulated.data).cwiseAbs().maxCoeff(), 1e-9 * simulated.data.cwiseAbs().maxCoeff());
  EXPECT_EQ(r.settings.at("clamped_samples"), simulated.settings.at("clamped_samples"));
}

// The compensation on and a command it cannot follow: the model of the bench's 80 V hysteresis
// record, whose inverse asks for less than -20 V at the bottom of the 80 V sine (as in the demo), on a
// bench file with a slew limit below what the compensated 1 Hz sine needs. The commanded stack voltage stays within -20..150 V and the slew
// limit; the limited samples are counted; the loop does not trip (the clamping is intermittent).
TEST(BackendRunner, TrackingWithTheFeedforwardStaysWithinTheLimits) {
  const bench::UnitTruth unit = bench::batch_unit(1, 1);
  bench::ExperimentOptions eo;
  eo.amplitude = 80.0;
  const io::TimeSeries h = bench::simulate(bench::Experiment::kHysteresis, unit, eo, 1);
  const Eigen::VectorXd va = h.channel("Va"), de = h.channel("de");
  ident::HysteresisModel m =
      ident::fit_hysteresis({va.data(), static_cast<std::size_t>(va.size())}, {de.data(), static_cast<std::size_t>(de.size())}, h.sample_rate)
          .model;
  eo.feedforward = m;
  const double slew = 400.0;  // V/s; the uncompensated sine needs 2 pi 80 = 503 V/s, the compensated one more
  VirtualBenchBackend backend(unit, eo.bench, 1);
  MeasureOptions mo;
  mo.bench = parse_bench_description("[bench]\nbackend = \"virtual\"\nsample_rate_Hz = 10000\n[limits]\nwatchdog_s = 1.0\nslew_rate_V_per_s = " +
                                         std::to_string(slew) + "\n",
                                     "virtual.toml");
  mo.lockstep = true;
  BackendRunner runner(backend, mo);
  const io::TimeSeries r = bench::run_experiment(bench::Experiment::kTracking, runner, unit, eo, 1);
  ASSERT_EQ(runner.report().runs.size(), 2u);
  const LoopReport& ff = runner.report().runs[1];
  EXPECT_TRUE(ff.feedforward);
  std::printf("feedforward asking beyond the limits: %llu clamped, %llu slew-limited samples; Va commanded %.2f .. %.2f V, largest step %.4f V\n",
              static_cast<unsigned long long>(ff.clamped_samples), static_cast<unsigned long long>(ff.slew_limited_samples), ff.va_cmd_min,
              ff.va_cmd_max, ff.max_va_cmd_step);
  EXPECT_GT(ff.clamped_samples, 100u);
  EXPECT_GT(ff.slew_limited_samples, 100u);
  EXPECT_GE(ff.va_cmd_min, -20.0 - 1e-9);
  EXPECT_LE(ff.va_cmd_max, 150.0 + 1e-9);
  EXPECT_LE(ff.max_va_cmd_step, slew / 10000.0 * (1.0 + 1e-9));
  EXPECT_EQ(ff.safe_state_reason, "none");
  EXPECT_EQ(std::get<double>(r.settings.at("clamped_samples")), static_cast<double>(ff.clamped_samples));
  // The applied command, sample by sample (the record's u column is not kept: the log's is).
  EXPECT_GE(r.channel("Va_ff").minCoeff(), -20.0 - 1.0);
  EXPECT_LE(r.channel("Va_ff").maxCoeff(), 150.0 + 1.0);
}

TEST(BackendRunner, PromptsTheOperatorAndRecordsTheConfirmations) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  ASSERT_EQ(write(fds[1], "\n\n", 2), 2);  // the operator presses Enter at each prompt
  close(fds[1]);
  VirtualBenchBackend backend(bench::batch_unit(1, 1), bench::BenchOptions{}, 1);
  std::ostringstream prompts;
  MeasureOptions mo;
  mo.bench = virtual_bench(0.01);
  mo.operator_fd = fds[0];
  mo.operator_out = &prompts;
  BackendRunner runner(backend, mo);
  const std::vector<bench::OperatorStep> steps = {{0.1, "put the 6.4 kg mass on", 6.4, 0.0}, {0.3, "take it off", 0.0, 0.0}};
  Eigen::MatrixXd out;
  const std::vector<double> done = runner.hold(6000, steps, 0, out, {});
  close(fds[0]);
  ASSERT_EQ(done.size(), 2u);
  // Confirmed as soon as asked (the answers were waiting), give or take a loaded machine.
  EXPECT_GE(done[0], 0.1);
  EXPECT_LT(done[0], 0.25);
  EXPECT_GE(done[1], 0.3);
  EXPECT_LT(done[1], 0.45);
  EXPECT_TRUE(test::contains(prompts.str(), "put the 6.4 kg mass on; press Enter")) << prompts.str();
  EXPECT_TRUE(test::contains(prompts.str(), "confirmed")) << prompts.str();
  const auto row = [&](double t) { return static_cast<Eigen::Index>(std::llround(t * 1e4)); };
  EXPECT_EQ(out(row(done[0]) - 1, 1), 0.0);
  EXPECT_EQ(out(row(done[0]) + 1, 1), 6.4);
  EXPECT_EQ(out(row(done[1]) + 1, 1), 0.0);
  ASSERT_EQ(runner.report().operator_steps.size(), 2u);
  EXPECT_EQ(runner.report().operator_steps[1].prompt, "take it off");
}

TEST(BackendRunner, AsksForTheSetUpBeforeAnythingMoves) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  ASSERT_EQ(write(fds[1], "\n", 1), 1);  // one confirmation, then the end of the input
  close(fds[1]);
  VirtualBenchBackend backend(bench::batch_unit(1, 1), bench::BenchOptions{}, 1);
  std::ostringstream prompts;
  MeasureOptions mo;
  mo.bench = virtual_bench(0.01);
  mo.operator_fd = fds[0];
  mo.operator_out = &prompts;
  BackendRunner runner(backend, mo);
  runner.prepare({"disconnect the amplifier from the actuator stacks (open circuit)"});
  EXPECT_TRUE(test::contains(prompts.str(), "before the record (nothing moves): disconnect the amplifier")) << prompts.str();
  ASSERT_EQ(runner.report().operator_steps.size(), 1u);
  EXPECT_TRUE(runner.report().runs.empty());  // nothing ran
  EXPECT_THROW(runner.prepare({"take the 80.6 kOhm resistor off the sensor stack"}), InputError);
  close(fds[0]);
}

TEST(BackendRunner, AnUnconfirmedStepRefusesTheRecord) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  ASSERT_EQ(write(fds[1], "\n", 1), 1);  // only the first step is confirmed, then end of input
  close(fds[1]);
  VirtualBenchBackend backend(bench::batch_unit(1, 1), bench::BenchOptions{}, 1);
  std::ostringstream prompts;
  MeasureOptions mo;
  mo.bench = virtual_bench(0.01);
  mo.operator_fd = fds[0];
  mo.operator_out = &prompts;
  BackendRunner runner(backend, mo);
  Eigen::MatrixXd out;
  try {
    runner.hold(2000, {{0.05, "put the mass on", 6.4, 0.0}, {0.1, "take it off", 0.0, 0.0}}, 0, out, {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_TRUE(test::contains(e.what(), "take it off")) << e.what();
  }
  close(fds[0]);
}

TEST(BackendRunner, ASafetyTripRefusesTheRecordAndKeepsTheLog) {
  VirtualBenchBackend backend(bench::batch_unit(1, 1), bench::BenchOptions{}, 1);
  std::atomic<bool> stop{true};  // Ctrl-C before the run
  test::TempDir dir;
  MeasureOptions mo;
  mo.bench = virtual_bench(0.0);
  mo.lockstep = true;
  mo.stop = &stop;
  mo.raw_log = dir.path() / "raw.mat";
  BackendRunner runner(backend, mo);
  Eigen::MatrixXd out;
  try {
    runner.open_loop(Eigen::VectorXd::Constant(100, 1.0), 0, out, {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_TRUE(test::contains(e.what(), "interrupted")) << e.what();
    EXPECT_TRUE(test::contains(e.what(), "raw.mat")) << e.what();
  }
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "raw.mat"));
  EXPECT_TRUE(runner.report().runs.at(0).interrupted);
}

// The virtual bench behind a target that lies or stalls (issue 35): from read `from` on, d_e is
// `de` (a sensor reading no actuator gives), or every `hold_every`-th read repeats the previous
// sample (a held, stale input).
class LyingBackend final : public Backend {
 public:
  explicit LyingBackend(Backend& inner) : inner_(inner) {}
  std::uint64_t from = ~0ULL, hold_every = 0;
  double de = 0.0;
  [[nodiscard]] std::string name() const override { return "lying"; }
  [[nodiscard]] double sample_rate() const override { return inner_.sample_rate(); }
  void start() override { inner_.start(); }
  SensorSample read() noexcept override {
    ++reads_;
    if (hold_every > 0 && reads_ % hold_every == 0) return last_;
    last_ = inner_.read();
    if (reads_ >= from) last_.de = de;
    return last_;
  }
  void write(double u) noexcept override { inner_.write(u); }
  void stop() noexcept override { inner_.stop(); }

 private:
  Backend& inner_;
  std::uint64_t reads_ = 0;
  SensorSample last_;
};

// An open-loop run of `samples` samples at 1 V through `backend` on the bench file's limits
// (lockstep): the runner's report and the InputError's message ("" when the record was accepted).
std::string open_loop_error(Backend& backend, Eigen::Index samples, MeasureReport* report = nullptr) {
  MeasureOptions mo;
  mo.bench = virtual_bench(0.0);
  mo.lockstep = true;
  BackendRunner runner(backend, mo);
  Eigen::MatrixXd out;
  std::string error;
  try {
    runner.open_loop(Eigen::VectorXd::Constant(samples, 1.0), 0, out, {});
  } catch (const InputError& e) {
    error = e.what();
    EXPECT_EQ(out.size(), 0);  // no record
  }
  if (report != nullptr) *report = runner.report();
  return error;
}

TEST(BackendRunner, ASensorReadingOutOfRangeEndsTheRunInTheSafeState) {
  VirtualBenchBackend virt(bench::batch_unit(1, 1), bench::BenchOptions{}, 1);
  LyingBackend lying(virt);
  lying.from = 50;
  lying.de = 1e300;  // metres
  const std::string e = open_loop_error(lying, 1000);
  EXPECT_TRUE(test::contains(e, "the safe state (sensor out of range) at t = 0.0049 s")) << e;
}

TEST(BackendRunner, HeldSamplesBeyondTheBudgetRefuseTheRecord) {
  // 1 read in 200 held: 0.5 % of the samples, above the 0.1 % budget; each alone is tolerated
  // (stale_cycles = 3), so the loop itself never trips.
  VirtualBenchBackend virt(bench::batch_unit(1, 1), bench::BenchOptions{}, 1);
  LyingBackend lying(virt);
  lying.hold_every = 200;
  const std::string e = open_loop_error(lying, 10000);
  EXPECT_TRUE(test::contains(e, "stale samples: expected at most 10 held samples (0.1 % of the run's 10000 cycles")) << e;
  EXPECT_TRUE(test::contains(e, "found 50")) << e;
  // Within the budget (1 in 2000: 5 held samples) the record is accepted.
  VirtualBenchBackend virt2(bench::batch_unit(1, 1), bench::BenchOptions{}, 1);
  LyingBackend rare(virt2);
  rare.hold_every = 2000;
  MeasureReport report;
  EXPECT_EQ(open_loop_error(rare, 10000, &report), "");
  EXPECT_EQ(report.runs.at(0).stale_sensor_samples, 5u);
}

}  // namespace
}  // namespace piezobench::rt
