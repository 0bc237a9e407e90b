// The bench file: the examples of docs/examples read, and the refusals before anything moves.
#include "piezobench/rt/bench_file.hpp"

#include <gtest/gtest.h>

#include <string>

#include "piezobench/core/error.hpp"
#include "comedi_bench_text.hpp"
#include "test_util.hpp"

namespace piezobench::rt {
namespace {

// The rt tests' Comedi bench with a name and the encoder's resolution, no Va monitor.
const std::string kComedi =
    test::replace_once(test::replace_once(test::comedi_bench_text("/dev/comedi0", "auto"), "[bench]\n", "[bench]\nname = \"report bench\"\n"),
                       "[comedi]\n", "[encoder]\nresolution_m = 2.5e-9\n[comedi]\n");


std::string error_of(const std::string& text) {
  try {
    parse_bench_description(text, "bench.toml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(BenchFile, ReadsTheComediBench) {
  const BenchDescription d = parse_bench_description(kComedi, "bench.toml");
  EXPECT_EQ(d.backend, "comedi");
  EXPECT_DOUBLE_EQ(d.limits.u_min(), -1.0);
  EXPECT_DOUBLE_EQ(d.limits.u_max(), 7.5);
  EXPECT_EQ(d.de.kind, "counter");
  EXPECT_DOUBLE_EQ(d.de.scale, 2.5e-9);  // a counter's scale defaults to the encoder's resolution
  EXPECT_EQ(d.vs.channel, 2);
  EXPECT_FALSE(d.va.has_value());
}

TEST(BenchFile, RefusesARangeThatCannotExpressTheLimits) {
  // 150 V / 20 V/V = 7.5 V at the DAC: a 0..5 V output cannot reach it (nor -1 V).
  const std::string e = error_of(test::replace_once(kComedi, "range = [-10, 10]\nscale = 1.0\nunit = \"V\"\n[signals.d_e]",
                                         "range = [0, 5]\nscale = 1.0\nunit = \"V\"\n[signals.d_e]"));
  EXPECT_TRUE(test::contains(e, "signals.u.range")) << e;
  EXPECT_TRUE(test::contains(e, "-1 .. 7.5 V at the DAC")) << e;
}

TEST(BenchFile, RefusesAMissingChannel) {
  const std::string text = kComedi.substr(0, kComedi.find("[signals.Vs]"));
  const std::string e = error_of(text);
  EXPECT_TRUE(test::contains(e, "signals.Vs")) << e;
  EXPECT_TRUE(test::contains(e, "missing channel")) << e;
  EXPECT_TRUE(test::contains(error_of(test::replace_once(kComedi, "subdevice = 0\nchannel = 2", "subdevice = 0")), "signals.Vs.channel"));
}

TEST(BenchFile, RefusesAWrongSignFromUToVa) {
  std::string e = error_of(test::replace_once(kComedi, "range = [-10, 10]\nscale = 1.0\nunit = \"V\"\n[signals.d_e]",
                                   "range = [-10, 10]\nscale = -1.0\nunit = \"V\"\n[signals.d_e]"));
  EXPECT_TRUE(test::contains(e, "signals.u.scale")) << e;
  e = error_of(test::replace_once(kComedi, "gain_V_per_V = 20", "gain_V_per_V = -20"));
  EXPECT_TRUE(test::contains(e, "amplifier.gain_V_per_V")) << e;
}

TEST(BenchFile, AHardwareBenchNeedsItsLimits) {
  std::string e = error_of(test::replace_once(kComedi, "va_max_V = 150\n", ""));
  EXPECT_TRUE(test::contains(e, "limits.va_max_V")) << e;
  e = error_of(test::replace_once(kComedi, "slew_rate_V_per_s = 1e5\n", ""));
  EXPECT_TRUE(test::contains(e, "limits.slew_rate_V_per_s")) << e;
  const std::string udp = "[bench]\nbackend = \"udp\"\nsample_rate_Hz = 10000\n[udp]\naddress = \"127.0.0.1:5600\"\n";
  e = error_of(udp);
  EXPECT_TRUE(test::contains(e, "amplifier.gain_V_per_V")) << e;
  // The virtual bench has the report's limits by default.
  const BenchDescription v = parse_bench_description("[bench]\nbackend = \"virtual\"\nsample_rate_Hz = 10000\n", "v.toml");
  EXPECT_DOUBLE_EQ(v.limits.va_max, 150.0);
}

TEST(BenchFile, NamesUnknownKeysAndBadValues) {
  EXPECT_TRUE(test::contains(error_of(test::replace_once(kComedi, "[encoder]", "[encoder]\nresolution = 1")), "encoder.resolution"));
  EXPECT_TRUE(test::contains(error_of(test::replace_once(kComedi, "backend = \"comedi\"", "backend = \"nidaq\"")), "bench.backend"));
  EXPECT_TRUE(test::contains(error_of(test::replace_once(kComedi, "unit = \"m\"", "unit = \"mm\"")), "signals.d_e.unit"));
  EXPECT_TRUE(test::contains(error_of("[bench\n"), "bench.toml"));
}

// Issue 21.2: bench files go through the TOML reader with limits (a 100,000-part header recursed
// 30,000 frames deep in toml++); an integer is a number, and a directory is an InputError.
TEST(BenchFile, HostileTomlIsAnInputError) {
  std::string deep = "[a";
  for (int i = 0; i < 100000; ++i) deep += ".a";
  const std::string e = error_of(deep + "]\n");
  EXPECT_TRUE(test::contains(e, "bench.toml")) << e;
  EXPECT_TRUE(test::contains(e, "more than 64 parts")) << e;
  // Not "expected a number, found a number": the rate check sees 9.2e18.
  const std::string big = error_of("[bench]\nbackend = \"virtual\"\nsample_rate_Hz = 9223372036854775807\n");
  EXPECT_TRUE(test::contains(big, "a rate in (0, 1e6] Hz")) << big;
  EXPECT_THROW(read_bench_file(std::filesystem::path(PIEZOBENCH_SOURCE_DIR) / "docs"), InputError);
}

TEST(BenchFile, TheDocumentedExamplesRead) {
  for (const char* name : {"bench-virtual.toml", "bench-udp.toml", "bench-comedi.toml"}) {
    const auto path = std::filesystem::path(PIEZOBENCH_SOURCE_DIR) / "docs" / "examples" / name;
    EXPECT_NO_THROW(read_bench_file(path)) << path;
  }
}

TEST(BenchFile, LimitsArePlausibleForTheNamedActuator) {
  // Issue 35: limits checked against each other only; now against the APA300ML's datasheet
  // (-20 .. 150 V) and physical bounds, each refusal naming the key (exit 3).
  std::string e = error_of(test::replace_once(kComedi, "va_max_V = 150\n", "va_max_V = 1e308\n"));
  EXPECT_TRUE(test::contains(e, "bench.toml: limits.va_max_V: expected at most 150 V (APA300ML's datasheet)")) << e;
  e = error_of(test::replace_once(kComedi, "slew_rate_V_per_s = 1e5\n", "slew_rate_V_per_s = 1e308\n"));
  EXPECT_TRUE(test::contains(e, "limits.slew_rate_V_per_s")) << e;
  e = error_of(test::replace_once(kComedi, "[limits]\n", "[limits]\nramp_s = 1e300\n"));
  EXPECT_TRUE(test::contains(e, "limits.ramp_s: expected a duration in [0, 60] s, found 1e+300")) << e;
  e = error_of(test::replace_once(kComedi, "[limits]\n", "[limits]\nactuator = \"APA3000ML\"\n"));
  EXPECT_TRUE(test::contains(e, "limits.actuator")) << e;
}

TEST(BenchFile, IntegersAndDurationsAreRangeCheckedBeforeConversion) {
  std::string e = error_of(test::replace_once(kComedi, "[limits]\n", "[limits]\nstale_cycles = 9223372036854775807\n"));
  EXPECT_TRUE(test::contains(e, "bench.toml: line 14: limits.stale_cycles: expected an integer in 0 .. 1000, found 9223372036854775807")) << e;
  e = error_of(test::replace_once(kComedi, "[limits]\n", "[limits]\nwatchdog_s = 1e300\n"));
  EXPECT_TRUE(test::contains(e, "limits.watchdog_s: expected a duration in [1e-06, 60] s")) << e;
  e = error_of(test::replace_once(kComedi, "[limits]\n", "[limits]\nstale_cycles = 3.5e20\n"));
  EXPECT_TRUE(test::contains(e, "limits.stale_cycles: expected an integer")) << e;
  e = error_of(test::replace_once(kComedi, "subdevice = 0\nchannel = 2", "subdevice = 0\nchannel = 4294967298"));
  EXPECT_TRUE(test::contains(e, "signals.Vs.channel: expected an integer in 0 .. 65535")) << e;
  e = error_of("[bench]\nbackend = \"virtual\"\nsample_rate_Hz = 10000\n[virtual]\nunit = 4294967297\n");
  EXPECT_TRUE(test::contains(e, "virtual.unit: expected an integer in 1 .. 7")) << e;
}

}  // namespace
}  // namespace piezobench::rt
