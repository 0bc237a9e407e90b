#include <gtest/gtest.h>

#include "piezobench/bench/experiments.hpp"
#include "piezobench/campaign/unit_analysis.hpp"
#include "piezobench/core/file.hpp"
#include "piezobench/io/timeseries.hpp"
#include "piezobench/rt/bench_file.hpp"
#include "piezobench/rt/measure.hpp"
#include "piezobench/station/phase_runner.hpp"
#include "piezobench/station/record_store.hpp"
#include "station_test_data.hpp"
#include "test_util.hpp"

namespace piezobench::station {
namespace {

namespace fs = std::filesystem;

rt::BenchDescription virtual_bench() {
  return rt::parse_bench_description("[bench]\nbackend = \"virtual\"\nsample_rate_Hz = 10000\n[virtual]\nunit = 3\nseed = 1\n", "b.toml");
}

TEST(Instrument, TheVirtualBenchGivesMeasuresRecord) {
  test::TempDir dir;
  BenchInstrumentOptions o;
  o.bench = virtual_bench();
  o.unit = 3;
  BenchInstrument inst(o);
  const StationFile st = parse_station_file(testdata::kSmallStation, "st.toml");
  const Acquired a = inst.acquire(*st.phase("hysteresis-20V"), {}, dir.path() / "h");
  EXPECT_EQ(a.file, dir.path() / "h.mat");
  // The same record as `measure hysteresis --amplitude 20` on this bench (bench::simulate).
  bench::ExperimentOptions eo;
  eo.bench = rt::bench_options(o.bench);
  eo.amplitude = 20.0;
  const io::TimeSeries expected = bench::simulate(bench::Experiment::kHysteresis, bench::batch_unit(3, 1), eo, 1);
  const io::TimeSeries got = io::read_timeseries(a.file);
  ASSERT_EQ(got.samples(), expected.samples());
  EXPECT_EQ((got.channel("de") - expected.channel("de")).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_DOUBLE_EQ(std::get<double>(a.settings.at("amplitude_V")), 20.0);
}

TEST(Instrument, TypedValuesAndFiles) {
  test::TempDir dir;
  BenchInstrumentOptions o;
  o.bench = virtual_bench();
  BenchInstrument inst(o);
  const StationFile st = parse_station_file(
      "name = \"s\"\n[[phases]]\nname = \"c\"\nexperiment = \"capacitance\"\nsource = \"typed\"\n"
      "[[phases]]\nname = \"f\"\nexperiment = \"flatness\"\nsource = \"file\"\n",
      "st.toml");
  const Acquired c = inst.acquire(st.phases[0], PhaseValues{4.95, 9.9, std::nullopt}, dir.path() / "c");
  // The campaign reads the typed values back as LCR readings.
  const campaign::Campaign cp = campaign::parse_campaign("[[units]]\nid = 1\ncapacitance = \"" + c.file.string() + "\"\n", dir.path() / "c.toml");
  const campaign::UnitAnalysis ua = campaign::analyze_unit(cp, cp.units[0]);
  EXPECT_DOUBLE_EQ(*capacitance_sensor_of(ua), 4.95e-6);
  EXPECT_DOUBLE_EQ(*capacitance_actuator_of(ua), 9.9e-6);
  test::write_text(dir.path() / "probe.csv", "x,y,z\n0,0,1e-6\n0.01,0,0\n0,0.01,0\n");
  const Acquired f = inst.acquire(st.phases[1], PhaseValues{std::nullopt, std::nullopt, dir.path() / "probe.csv"}, dir.path() / "f");
  EXPECT_EQ(f.file, dir.path() / "f.csv");
  EXPECT_EQ(sha256_file(f.file), sha256_file(dir.path() / "probe.csv"));  // the operator's file, byte for byte
}

TEST(Instrument, AHardwareBenchRefusesWhatItCannotMeasureBeforeAnythingMoves) {
  BenchInstrumentOptions o;
  o.bench.backend = "udp";
  BenchInstrument inst(o);
  const StationFile st = parse_station_file(testdata::kSmallStation, "st.toml");
  test::expect_input_error([&] { inst.check(st); }, {"st.toml: line 8", "phases.capacitance", "source = \"file\" or \"typed\""});
}

}  // namespace
}  // namespace piezobench::station
