// The twin file (bench/twin.hpp) and the bench's own play operators (UnitTruth::hysteresis_*).
#include "piezobench/bench/twin.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "piezobench/bench/experiments.hpp"
#include "piezobench/core/error.hpp"
#include "test_util.hpp"

namespace piezobench::bench {
namespace {

Twin example() {
  Twin t;
  t.name = "APA 9";
  t.unit = batch_unit(2, 1);
  t.unit.id = 9;
  t.unit.hysteresis_thresholds = {10.0, 20.0, 40.0};
  t.unit.hysteresis_weights = {0.2, 0.0, 0.3};
  t.unit.creep_coefficient = 0.01;
  t.unit.load_creep_coefficient = 0.25;
  t.options.delay = 150e-6;
  t.options.hpf_resistance = 68e3;
  t.options.ground_resistance = 0.1;
  t.options.encoder_noise = 2e-9;
  t.options.vs_noise = 2.5e-3;
  t.de_noise = {{2.0, 10.0}, {1e-21, 2e-21}};
  t.sources = {{"frf", "data/frf.csv"}};
  return t;
}

TEST(TwinFile, RoundTripKeepsEveryParameter) {
  const Twin t = example();
  const Twin r = parse_twin(twin_toml(t), "twin.toml");
  EXPECT_EQ(r.name, "APA 9");
  EXPECT_EQ(r.unit.id, 9);
  for (const auto& name : apa::TwoDofParams::names()) {
    if (name != "m") EXPECT_NEAR(r.unit.model.get(name), t.unit.model.get(name), 1e-9 * std::abs(t.unit.model.get(name))) << name;
  }
  EXPECT_EQ(r.unit.hysteresis_weights, t.unit.hysteresis_weights);
  EXPECT_EQ(r.unit.hysteresis_thresholds, t.unit.hysteresis_thresholds);
  EXPECT_DOUBLE_EQ(r.unit.load_creep_coefficient, 0.25);
  EXPECT_DOUBLE_EQ(r.options.delay, 150e-6);
  EXPECT_DOUBLE_EQ(r.options.encoder_noise, 2e-9);
  EXPECT_NEAR(r.unit.capacitance_sensor, t.unit.capacitance_sensor, 1e-9 * t.unit.capacitance_sensor);  // 10 digits in the file
  EXPECT_EQ(r.de_noise.psd.size(), 2u);
  ASSERT_EQ(r.sources.size(), 1u);
  EXPECT_EQ(r.sources[0].second, "data/frf.csv");
  // apply_chain copies the chain, not the switches.
  BenchOptions o;
  o.noise = false;
  apply_chain(r, o);
  EXPECT_DOUBLE_EQ(o.hpf_resistance, 68e3);
  EXPECT_DOUBLE_EQ(o.ground_resistance, 0.1);
  EXPECT_FALSE(o.noise);
}

// fuzz_twin_toml: a twin read and written back reads the same; a file's -0.0 was written back as
// "-0", a TOML integer that reads as 0.
TEST(TwinFile, NegativeZeroIsReadAsZeroSoAWrittenTwinReadsTheSame) {
  std::string text = twin_toml(example());
  const std::string key = "ground_resistance_ohm = ";
  const std::size_t at = text.find(key) + key.size();
  text.replace(at, text.find('\n', at) - at, "-0.0");
  const Twin r = parse_twin(text, "twin.toml");
  EXPECT_EQ(r.options.ground_resistance, 0.0);
  EXPECT_FALSE(std::signbit(r.options.ground_resistance));
  const std::string written = twin_toml(r);
  EXPECT_EQ(twin_toml(parse_twin(written, "twin.toml")), written);
}

TEST(TwinFile, RefusesUnknownMissingAndInvalidKeys) {
  const std::string good = twin_toml(example());
  const auto refused = [&](const std::string& text, const std::string& field) {
    try {
      (void)parse_twin(text, "t.toml");
    } catch (const InputError& e) {
      EXPECT_TRUE(test::contains(e.what(), field)) << e.what();
      return;
    }
    ADD_FAILURE() << "accepted: " << field;
  };
  refused(good + "\n[extra]\n", "extra");
  refused(std::string(good).replace(good.find("k1 = "), 5, "kk = "), "model.kk");
  refused(std::string(good).replace(good.find("weights = ["), 11, "weights = [1, "), "hysteresis_weights");
  refused(std::string(good).replace(good.find("piezobench-twin-1"), 17, "piezobench-twin-0"), "format");
  refused(std::string(good).replace(good.find("delay_s = "), 10, "delay_s = -"), "delay");
}

// Own operators equal to the default ones give the same bench, sample for sample.
TEST(TwinFile, OwnOperatorsEqualToTheDefaultOnesGiveTheSameRecord) {
  UnitTruth a = batch_unit(1, 1);
  a.hysteresis_scale = 1.3;
  UnitTruth b = a;
  for (int i = 1; i <= 8; ++i) {
    b.hysteresis_thresholds.push_back(10.0 * i);
    b.hysteresis_weights.push_back(0.163 * 1.3);
  }
  ExperimentOptions eo;
  eo.amplitude = 60.0;
  const io::TimeSeries ra = simulate(Experiment::kHysteresis, a, eo, 5), rb = simulate(Experiment::kHysteresis, b, eo, 5);
  EXPECT_EQ((ra.data - rb.data).cwiseAbs().maxCoeff(), 0.0);
  b.hysteresis_weights.push_back(0.1);
  b.hysteresis_thresholds.push_back(90.0);
  EXPECT_THROW(b.validate(), InputError);  // 9 operators
}

}  // namespace
}  // namespace piezobench::bench
