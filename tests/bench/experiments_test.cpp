// The report's experiments on the virtual bench (bench/experiments.hpp): the channel contract,
// option checks (an amplitude beyond the stack range is refused with the limit named), and what
// each record shows: stroke, hysteresis loops, creep in the stiffness test, IFF damping, the
// bending modes, flatness and capacitance readings.
#include "piezobench/bench/experiments.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

#include "flatness.hpp"
#include "test_util.hpp"

namespace piezobench::bench {
namespace {

using test::near;

io::TimeSeries run(Experiment e, int unit = 1, ExperimentOptions o = {}, std::uint64_t seed = 1) {
  return simulate(e, batch_unit(unit, seed), o, seed);
}

double setting(const io::TimeSeries& ts, const std::string& key) { return std::get<double>(ts.settings.at(key)); }

TEST(Experiments, NamesRoundTripAndUnknownNamesAreListed) {
  EXPECT_EQ(all_experiments().size(), 10U);
  for (const Experiment e : all_experiments()) EXPECT_EQ(experiment_from_string(to_string(e)), e);
  const std::string message = test::input_error([] { (void)experiment_from_string("frf"); }, "experiment");
  EXPECT_TRUE(test::contains(message, "frf-noise")) << message;
  EXPECT_TRUE(test::contains(message, "capacitance")) << message;
}

TEST(Experiments, RefuseOptionsTheyDoNotTakeAndBadValues) {
  ExperimentOptions o;
  o.amplitude = 10.0;
  (void)test::input_error([&] { (void)run(Experiment::kStroke, 1, o); }, "amplitude");
  o = {};
  o.duration = 5.0;
  (void)test::input_error([&] { (void)run(Experiment::kHammer, 1, o); }, "duration");
  o = {};
  o.gain = 1e5;
  (void)test::input_error([&] { (void)run(Experiment::kFrfNoise, 1, o); }, "gain");
  o = {};
  o.duration = -1.0;
  (void)test::input_error([&] { (void)run(Experiment::kFrfNoise, 1, o); }, "duration");
  o = {};
  o.amplitude = std::nan("");
  (void)test::input_error([&] { (void)run(Experiment::kHysteresis, 1, o); }, "amplitude");
  (void)test::input_error([] { (void)batch_unit(9, 1); }, "unit");
}

TEST(Experiments, AmplitudeBeyondTheStackRangeIsRefusedWithTheLimitNamed) {
  ExperimentOptions o;
  o.amplitude = 86.0;  // 65 +- 86 V leaves -20..150 V
  std::string message = test::input_error([&] { (void)run(Experiment::kHysteresis, 1, o); }, "amplitude");
  EXPECT_TRUE(test::contains(message, "85 V")) << message;
  EXPECT_TRUE(test::contains(message, "-20 V .. 150 V")) << message;
  o.amplitude = 85.0;  // exactly at the limits: accepted
  EXPECT_NO_THROW((void)run(Experiment::kHysteresis, 1, o));
  o = {};
  o.amplitude = 10.0;  // 10 V rms of noise about 0 V: peaks beyond -20 V
  o.duration = 2.0;
  message = test::input_error([&] { (void)run(Experiment::kFrfNoise, 1, o); }, "amplitude");
  EXPECT_TRUE(test::contains(message, "limit -20 V")) << message;
  o.amplitude = 25.0;
  message = test::input_error([&] { (void)run(Experiment::kFrfSweep, 1, o); }, "amplitude");
  EXPECT_TRUE(test::contains(message, "20 V")) << message;
}

TEST(Experiments, ChannelContract) {
  ExperimentOptions shortened;
  shortened.duration = 1.0;
  struct Case {
    Experiment e;
    std::vector<std::string> names;
    std::vector<std::string> units;
    bool time;
  };
  const std::vector<Case> cases = {
      {Experiment::kStroke, {"u", "Va", "de"}, {"V", "V", "m"}, true},
      {Experiment::kHysteresis, {"u", "Va", "de"}, {"V", "V", "m"}, true},
      {Experiment::kStiffness, {"de", "added_mass"}, {"m", "kg"}, true},
      {Experiment::kFrfNoise, {"u", "Va", "de", "Vs"}, {"V", "V", "m", "V"}, true},
      {Experiment::kFrfSweep, {"u", "Va", "de", "Vs"}, {"V", "V", "m", "V"}, true},
      {Experiment::kIff, {"u_prime", "u", "Va", "de", "Vs"}, {"V", "V", "V", "m", "V"}, true},
      {Experiment::kHammer, {"F", "v"}, {"N", "m/s"}, true},
      {Experiment::kFlatness, {"x", "y", "z", "interface"}, {"m", "m", "m", ""}, false},
      {Experiment::kCapacitance, {"C_sensor", "C_actuator"}, {"F", "F"}, false},
  };
  for (const Case& c : cases) {
    const bool takes_duration = c.e == Experiment::kFrfNoise || c.e == Experiment::kFrfSweep || c.e == Experiment::kIff;
    const io::TimeSeries ts = run(c.e, 2, takes_duration ? shortened : ExperimentOptions{}, 9);
    SCOPED_TRACE(to_string(c.e));
    EXPECT_EQ(ts.names, c.names);
    EXPECT_EQ(ts.units, c.units);
    EXPECT_EQ(ts.t.size() > 0, c.time);
    EXPECT_EQ(std::get<std::string>(ts.settings.at("experiment")), to_string(c.e));
    EXPECT_EQ(setting(ts, "unit"), 2.0);
    EXPECT_EQ(setting(ts, "seed"), 9.0);
    if (takes_duration) {
      EXPECT_EQ(setting(ts, "duration_s"), 1.0);
      EXPECT_EQ(ts.samples(), 10000);
      EXPECT_EQ(ts.sample_rate, 10e3);
    }
  }
}

TEST(Experiments, SameSeedSameRecord) {
  ExperimentOptions o;
  o.duration = 0.5;
  const io::TimeSeries a = run(Experiment::kFrfNoise, 4, o, 21), b = run(Experiment::kFrfNoise, 4, o, 21);
  const io::TimeSeries c = run(Experiment::kFrfNoise, 4, o, 22);
  EXPECT_EQ(a.data, b.data);
  EXPECT_NE(a.data, c.data);
  EXPECT_EQ(run(Experiment::kFlatness, 4, {}, 21).data, run(Experiment::kFlatness, 4, {}, 21).data);
}

// The virtual runner, noting the seed of each open-loop run it is given.
class SeedRecordingRunner final : public BenchRunner {
 public:
  SeedRecordingRunner(const UnitTruth& unit, const BenchOptions& options) : inner_(unit, options) {}
  void open_loop(const Eigen::VectorXd& u, std::uint64_t seed, Eigen::MatrixXd& out, const Progress& progress) override {
    seeds.push_back(seed);
    inner_.open_loop(u, seed, out, progress);
  }
  std::uint64_t open_loop_feedforward(const Eigen::VectorXd& u_prime, const Eigen::VectorXd& w, const ident::HysteresisModel& model,
                                      std::uint64_t seed, Eigen::MatrixXd& out, const Progress& progress) override {
    return inner_.open_loop_feedforward(u_prime, w, model, seed, out, progress);
  }
  std::uint64_t iff(const Eigen::VectorXd& u_prime, double gain, std::uint64_t seed, Eigen::MatrixXd& out,
                    const Progress& progress) override {
    return inner_.iff(u_prime, gain, seed, out, progress);
  }
  std::vector<double> hold(Eigen::Index n, const std::vector<OperatorStep>& steps, std::uint64_t seed, Eigen::MatrixXd& out,
                           const Progress& progress) override {
    return inner_.hold(n, steps, seed, out, progress);
  }
  void describe(io::TimeSeries& record) const override { inner_.describe(record); }
  std::vector<std::uint64_t> seeds;

 private:
  VirtualRunner inner_;
};

TEST(Experiments, TheMainRunGetsTheExperimentsBenchSeed) {
  const UnitTruth unit = batch_unit(4, 21);
  for (const Experiment e : {Experiment::kFrfNoise, Experiment::kHysteresis}) {
    ExperimentOptions o;
    if (e == Experiment::kFrfNoise) o.duration = 0.2;
    SeedRecordingRunner runner(unit, o.bench);
    const io::TimeSeries ts = run_experiment(e, runner, unit, o, 21);
    ASSERT_EQ(runner.seeds.size(), 1u) << to_string(e);
    EXPECT_EQ(runner.seeds.front(), experiment_bench_seed(e, 21)) << to_string(e);
    EXPECT_EQ(ts.data, simulate(e, unit, o, 21).data) << to_string(e);
  }
  // One stream per experiment and per seed.
  EXPECT_NE(experiment_bench_seed(Experiment::kFrfNoise, 21), experiment_bench_seed(Experiment::kHysteresis, 21));
  EXPECT_NE(experiment_bench_seed(Experiment::kFrfNoise, 21), experiment_bench_seed(Experiment::kFrfNoise, 22));
}

TEST(Experiments, StrokeOfAGoodUnitAndOfTheDefectiveOne) {
  const auto stroke = [](int unit) {
    const io::TimeSeries ts = run(Experiment::kStroke, unit);
    EXPECT_EQ(ts.sample_rate, 1000.0);
    EXPECT_NEAR(ts.channel("Va").maxCoeff(), 150.0, 0.5);
    EXPECT_NEAR(ts.channel("Va").minCoeff(), -20.0, 0.5);
    return ts.channel("de").maxCoeff() - ts.channel("de").minCoeff();
  };
  const double good = stroke(1), bad = stroke(3);
  EXPECT_GT(good, 220e-6);  // report: about 250 um with two stacks
  EXPECT_LT(good, 290e-6);
  EXPECT_LT(bad, 0.75 * good);  // unit 3: clearly off
}

// Width of the loop at the offset (d_e going up minus going down through 65 V) relative to its
// stroke, in the last period.
double loop_ratio(const io::TimeSeries& ts) {
  const auto va = ts.channel("Va"), de = ts.channel("de");
  const Eigen::Index n = ts.samples();
  const Eigen::Index start = n - static_cast<Eigen::Index>(2.0 * ts.sample_rate);  // the last period before the ramp down
  const Eigen::Index end = start + static_cast<Eigen::Index>(ts.sample_rate);
  double up = 0.0, down = 0.0, lo = 1.0, hi = -1.0;
  for (Eigen::Index k = start + 1; k < end; ++k) {
    lo = std::min(lo, de(k));
    hi = std::max(hi, de(k));
    if ((va(k - 1) - 65.0) * (va(k) - 65.0) <= 0.0) (va(k) > va(k - 1) ? up : down) = de(k);
  }
  return std::abs(up - down) / (hi - lo);
}

TEST(Experiments, HysteresisLoopsWidenWithAmplitude) {
  ExperimentOptions o;
  o.amplitude = 20.0;
  const double small = loop_ratio(run(Experiment::kHysteresis, 1, o));
  o.amplitude = 80.0;
  const double large = loop_ratio(run(Experiment::kHysteresis, 1, o));
  EXPECT_GT(small, 0.02);
  EXPECT_GT(large, 1.5 * small);
  EXPECT_LT(large, 0.3);
  o.bench.hysteresis = false;
  EXPECT_LT(loop_ratio(run(Experiment::kHysteresis, 1, o)), 0.02);  // creep and dynamics only
}

TEST(Experiments, StiffnessReadingsShowCreep) {
  const io::TimeSeries ts = run(Experiment::kStiffness, 2);
  const double weight = 6.4 * 9.8;
  const auto mean = [&](double t0, double t1) {
    return ts.channel("de").segment(static_cast<Eigen::Index>(t0 * 1e4), static_cast<Eigen::Index>((t1 - t0) * 1e4)).mean();
  };
  const double before = mean(2.0, 2.9), loaded = mean(12.0, 12.9), after = mean(14.0, 15.0);
  const double k1 = weight / (before - loaded), k2 = weight / (after - loaded);
  EXPECT_GT(k1, 1.5e6);
  EXPECT_LT(k2, 2.2e6);
  EXPECT_LT(k1, k2);  // the APA kept sinking while loaded (Table 2.1)
  // It does not come back to where it started within the record (creep recovers slowly).
  EXPECT_LT(mean(19.0, 19.9), before - 0.5e-6);
  EXPECT_NEAR(ts.channel("added_mass").maxCoeff(), 6.4, 1e-12);
  EXPECT_EQ(ts.channel("added_mass")(0), 0.0);
}

TEST(Experiments, IffDampsTheResonance) {
  ExperimentOptions o;
  o.duration = 4.0;
  o.gain = 0.0;
  const io::TimeSeries open = run(Experiment::kIff, 1, o);
  o.gain = 2.8e5;
  const io::TimeSeries closed = run(Experiment::kIff, 1, o);
  EXPECT_EQ(open.channel("u_prime"), closed.channel("u_prime"));  // the same excitation
  EXPECT_EQ(open.channel("u"), open.channel("u_prime"));          // no feedback at g = 0
  const auto rms = [](const io::TimeSeries& ts) {
    const Eigen::VectorXd de = ts.channel("de").tail(ts.samples() / 2);  // a copy: channel() returns a temporary Ref
    return std::sqrt((de.array() - de.mean()).square().mean());
  };
  // White noise on u' excites the 95 Hz resonance (Q ~ 80); damped, it no longer dominates d_e.
  EXPECT_LT(rms(closed), 0.3 * rms(open));
}

TEST(Experiments, HammerShowsBothBendingModes) {
  const UnitTruth unit = batch_unit(6, 1);
  const io::TimeSeries ts = simulate(Experiment::kHammer, unit, {}, 1);
  EXPECT_EQ(setting(ts, "impacts"), 5.0);
  EXPECT_GT(ts.channel("F").maxCoeff(), 50.0);
  EXPECT_LT(ts.channel("F").maxCoeff(), 151.0);
  // |DFT| of the velocity after the first impact, 150..600 Hz in 0.5 Hz steps: the two largest
  // local maxima are the modes.
  const Eigen::VectorXd v = ts.channel("v").segment(5000, 19000);
  std::vector<double> mag;
  for (double f = 150.0; f <= 600.0; f += 0.5) {
    std::complex<double> sum = 0.0;
    for (Eigen::Index k = 0; k < v.size(); ++k) sum += v(k) * std::polar(1.0, -2 * std::numbers::pi * f * k / 1e4);
    mag.push_back(std::abs(sum));
  }
  std::vector<std::pair<double, double>> peaks;
  for (std::size_t i = 1; i + 1 < mag.size(); ++i) {
    if (mag[i] > mag[i - 1] && mag[i] >= mag[i + 1]) peaks.emplace_back(mag[i], 150.0 + 0.5 * static_cast<double>(i));
  }
  std::sort(peaks.rbegin(), peaks.rend());
  ASSERT_GE(peaks.size(), 2U);
  const double f1 = std::min(peaks[0].second, peaks[1].second), f2 = std::max(peaks[0].second, peaks[1].second);
  EXPECT_NEAR(f1, unit.mode_y_Hz, 1.0);
  EXPECT_NEAR(f2, unit.mode_x_Hz, 1.0);
}

TEST(Experiments, FlatnessAndCapacitanceReadings) {
  const UnitTruth unit = batch_unit(7, 3);
  const Eigen::Matrix<double, 8, 3> p = detail::probe_layout();
  const double truth = detail::plane_flatness(p.col(0), p.col(1), detail::probe_heights(unit));
  for (const bool noise : {false, true}) {
    ExperimentOptions o;
    o.bench.noise = noise;
    const io::TimeSeries f = simulate(Experiment::kFlatness, unit, o, 3);
    EXPECT_EQ(f.samples(), 8);
    const double measured = detail::plane_flatness(f.channel("x"), f.channel("y"), f.channel("z"));
    // The probe's error is within +-0.5 um per point: at most 1 um on the peak-to-valley.
    EXPECT_NEAR(measured, truth, noise ? 1e-6 : 1e-12);
    const io::TimeSeries c = simulate(Experiment::kCapacitance, unit, o, 3);
    EXPECT_EQ(c.samples(), 1);
    EXPECT_TRUE(near(c.channel("C_sensor")(0), unit.capacitance_sensor, noise ? 5e-4 : 1e-15));
    EXPECT_TRUE(near(c.channel("C_actuator")(0), unit.capacitance_actuator, noise ? 5e-4 : 1e-15));
  }
}

}  // namespace
}  // namespace piezobench::bench
