// Time-series files: .mat (v5, v7.3, compressed, made by scipy) and CSV; validation messages;
// atomic writes.
#include "piezobench/io/timeseries.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <csignal>
#include <fstream>
#include <limits>
#include <tuple>
#include <nlohmann/json.hpp>

#include "mat_file.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/text.hpp"
#include "piezobench/core/error.hpp"
#include "test_util.hpp"

namespace piezobench::io {
namespace {

namespace fs = std::filesystem;
using test::all_near;
using test::TempDir;
using test::Tolerance;
using test::kExact;


// A record with a time vector, three channels with units and two settings.
TimeSeries sample_series(Eigen::Index n = 257) {
  TimeSeries ts;
  ts.names = {"u", "de", "Vs"};
  ts.sample_rate = 10000.0;
  ts.t.resize(n);
  ts.data.resize(n, 3);
  for (Eigen::Index k = 0; k < n; ++k) {
    ts.t(k) = static_cast<double>(k) / ts.sample_rate;
    ts.data(k, 0) = std::sin(0.1 * static_cast<double>(k)) + 0.1;
    ts.data(k, 1) = -1.7e-5 * std::cos(0.37 * static_cast<double>(k)) / 3.0;
    ts.data(k, 2) = std::exp(-1e-3 * static_cast<double>(k)) / 7.0;
  }
  ts.units = {"V", "m", "V"};
  ts.settings["experiment"] = std::string("frf-noise");
  ts.settings["seed"] = 42.0;
  return ts;
}

void expect_same(const TimeSeries& got, const TimeSeries& want) {
  EXPECT_EQ(got.names, want.names);
  EXPECT_TRUE(all_near(got.data, want.data, kExact));
  EXPECT_TRUE(all_near(got.t, want.t, kExact));
  EXPECT_EQ(got.sample_rate, want.sample_rate);
  EXPECT_EQ(got.units, want.units);
}

// The message of the InputError thrown by f (fails the test if none is thrown).
using test::contains;
using test::input_error;

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

nlohmann::json expected_json() {
  return nlohmann::json::parse(test::read_text(test::fixture_path("io/scipy_mat_expected.json")));
}

// ---- round trips ----------------------------------------------------------------------------

TEST(TimeSeriesMat, V5RoundTripIsExact) {
  TempDir dir;
  const TimeSeries ts = sample_series();
  const fs::path file = dir.path() / "rec.mat";
  write_timeseries(ts, file);
  const TimeSeries back = read_timeseries(file);
  expect_same(back, ts);
  EXPECT_EQ(back.source, file.string());
  ASSERT_EQ(back.settings.size(), 2u);
  EXPECT_EQ(std::get<std::string>(back.settings.at("experiment")), "frf-noise");
  EXPECT_EQ(std::get<double>(back.settings.at("seed")), 42.0);
}

TEST(TimeSeriesMat, V73RoundTripIsExact) {
  TempDir dir;
  const TimeSeries ts = sample_series();
  const fs::path file = dir.path() / "rec73.mat";
  write_timeseries_mat(ts, file, {.version = MatVersion::kV73});
  // A v7.3 file is HDF5 underneath.
  const std::string head = test::read_text(file).substr(512, 4);
  EXPECT_EQ(head, "\x89HDF");
  const TimeSeries back = read_timeseries_mat(file);
  expect_same(back, ts);
  EXPECT_EQ(std::get<std::string>(back.settings.at("experiment")), "frf-noise");
}

TEST(TimeSeriesMat, CompressedRoundTripAndChannelSelection) {
  TempDir dir;
  const TimeSeries ts = sample_series(1000);
  const fs::path file = dir.path() / "rec.mat";
  write_timeseries_mat(ts, file, {.version = MatVersion::kV5, .compress = true});
  ReadOptions options;
  options.channels = {"Vs", "u"};
  const TimeSeries back = read_timeseries_mat(file, options);
  ASSERT_EQ(back.names, (std::vector<std::string>{"Vs", "u"}));
  EXPECT_TRUE(all_near(back.channel("Vs"), ts.channel("Vs"), kExact));
  EXPECT_TRUE(all_near(back.channel("u"), ts.channel("u"), kExact));
  EXPECT_EQ(back.unit("Vs"), "V");
}

TEST(TimeSeriesMat, WithoutTimeVectorTheRateComesFromFs) {
  TempDir dir;
  TimeSeries ts = sample_series();
  ts.t.resize(0);
  ts.sample_rate = 12345.678;
  const fs::path file = dir.path() / "no_t.mat";
  write_timeseries_mat(ts, file);
  const TimeSeries back = read_timeseries_mat(file);
  EXPECT_EQ(back.sample_rate, 12345.678);
  EXPECT_EQ(back.t.size(), 0);
  // An explicit rate that contradicts the file's fs overrides it, with a warning naming both.
  ReadOptions options;
  options.fs = 1000.0;
  const TimeSeries forced = read_timeseries_mat(file, options);
  EXPECT_EQ(forced.sample_rate, 1000.0);
  ASSERT_EQ(forced.warnings.size(), 1u);
  EXPECT_TRUE(contains(forced.warnings[0], "--fs 1000 Hz overrides the file's fs = 12345.678 Hz")) << forced.warnings[0];
}

TEST(TimeSeriesCsv, RoundTripIsExact) {
  TempDir dir;
  const TimeSeries ts = sample_series();
  const fs::path file = dir.path() / "rec.csv";
  write_timeseries(ts, file);
  const std::string text = test::read_text(file);
  EXPECT_EQ(text.substr(0, text.find('\n')), "t [s],u [V],de [m],Vs [V]");
  const TimeSeries back = read_timeseries(file);
  expect_same(back, ts);
}

TEST(TimeSeriesCsv, WithoutTimeVectorTheRateIsKeptInAComment) {
  TempDir dir;
  TimeSeries ts = sample_series(10);
  ts.t.resize(0);
  ts.units.clear();
  ts.sample_rate = 3333.3333333333335;
  const fs::path file = dir.path() / "no_t.csv";
  write_timeseries_csv(ts, file);
  const TimeSeries back = read_timeseries_csv(file);
  EXPECT_EQ(back.sample_rate, ts.sample_rate);
  EXPECT_TRUE(all_near(back.data, ts.data, kExact));
}

TEST(TimeSeriesCsv, CommentsUnitsAndExplicitRate) {
  TempDir dir;
  const fs::path file = dir.path() / "hand.csv";
  write_text(file, "# bench 2, unit 3\n\n u , de [um] ,Vs[V]\r\n# a comment in the data\n1,2,3\r\n4,5e-1,+6\n7, -8 ,9\n");
  ReadOptions options;
  options.fs = 500.0;
  const TimeSeries ts = read_timeseries_csv(file, options);
  EXPECT_EQ(ts.names, (std::vector<std::string>{"u", "de", "Vs"}));
  // de [um] is converted to metres (issue 12: it was read as metres, a factor 1e6 off).
  EXPECT_EQ(ts.units, (std::vector<std::string>{"", "m", "V"}));
  Eigen::MatrixXd expected(3, 3);
  expected << 1, 2e-6, 3, 4, 0.5e-6, 6, 7, -8e-6, 9;
  EXPECT_TRUE(all_near(ts.data, expected, kExact));
  EXPECT_EQ(ts.sample_rate, 500.0);
  // Without t and without fs there is no rate.
  const std::string msg = input_error([&] { (void)read_timeseries_csv(file); });
  EXPECT_TRUE(contains(msg, file.string()) && contains(msg, "fs")) << msg;
}

TEST(TimeSeriesCsv, RateFromTimeAndConsistencyWithFs) {
  TempDir dir;
  const fs::path file = dir.path() / "t.csv";
  std::string text = "t,x\n";
  for (int k = 0; k < 100; ++k) text += format_number(k * 0.001, 17) + "," + std::to_string(k) + "\n";
  write_text(file, text);
  EXPECT_NEAR(read_timeseries_csv(file).sample_rate, 1000.0, 1e-9);
  ReadOptions ok;
  ok.fs = 1000.0;
  EXPECT_EQ(read_timeseries_csv(file, ok).sample_rate, 1000.0);
  // An explicit rate overrides the time column, with a warning that shows both.
  ReadOptions other;
  other.fs = 1001.0;
  const TimeSeries ts = read_timeseries_csv(file, other);
  EXPECT_EQ(ts.sample_rate, 1001.0);
  ASSERT_EQ(ts.warnings.size(), 2u);  // the rate, and x without a unit
  EXPECT_TRUE(contains(ts.warnings[1], file.string() + ": --fs 1001 Hz overrides the time vector's 1000 Hz (0.1 %)")) << ts.warnings[1];
}

// ---- files made elsewhere (scipy.io.savemat, scripts/fixtures/make_io_fixtures.py) ------------

TEST(TimeSeriesScipy, TwoOutputsFileReadsExactly) {
  const nlohmann::json expected = expected_json()["two_outputs"];
  for (const char* name : {"io/scipy_two_outputs.mat", "io/scipy_compressed.mat"}) {
    SCOPED_TRACE(name);
    const TimeSeries ts = read_timeseries(test::fixture_path(name));
    EXPECT_EQ(ts.names, expected["names"].get<std::vector<std::string>>());
    ASSERT_EQ(ts.samples(), expected["samples"].get<Eigen::Index>());
    EXPECT_TRUE(test::near(ts.sample_rate, expected["fs"].get<double>(), test::kRoundoff));
    for (const std::string channel : {"u_dac", "d_enc", "V_force"}) {
      const auto first = expected["first"][channel].get<std::vector<double>>();
      for (size_t k = 0; k < first.size(); ++k) EXPECT_EQ(ts.channel(channel)(static_cast<Eigen::Index>(k)), first[k]) << channel;
      EXPECT_EQ(ts.channel(channel)(ts.samples() - 1), expected["last"][channel].get<double>()) << channel;
      const double sum = ts.channel(channel).sum();
      const double scale = ts.channel(channel).cwiseAbs().sum();
      EXPECT_TRUE(test::near(sum, expected["sum"][channel].get<double>(), Tolerance{0.0, 1e-13 * scale})) << channel;
    }
    EXPECT_EQ(ts.t(4), expected["first"]["t"][4].get<double>());
  }
}

// read_mat_readings on scipy's files: double vectors as stored, at 1 Hz without a time vector;
// anything else (single, a matrix, a missing variable, a CSV file) is not readings.
TEST(TimeSeriesScipy, ReadingsAreTheDoubleVectorsAsStored) {
  const nlohmann::json expected = expected_json()["two_outputs"];
  const fs::path file = test::fixture_path("io/scipy_two_outputs.mat");
  const std::optional<TimeSeries> ts = read_mat_readings(file, {"d_enc", "u_dac"});
  ASSERT_TRUE(ts.has_value());
  EXPECT_EQ(ts->names, (std::vector<std::string>{"d_enc", "u_dac"}));
  ASSERT_EQ(ts->samples(), expected["samples"].get<Eigen::Index>());
  EXPECT_EQ(ts->sample_rate, 1.0);
  EXPECT_EQ(ts->t.size(), 0);
  EXPECT_EQ(ts->source, file.string());
  for (const std::string channel : {"u_dac", "d_enc"}) {
    const auto first = expected["first"][channel].get<std::vector<double>>();
    for (size_t k = 0; k < first.size(); ++k) EXPECT_EQ(ts->channel(channel)(static_cast<Eigen::Index>(k)), first[k]) << channel;
    EXPECT_EQ(ts->channel(channel)(ts->samples() - 1), expected["last"][channel].get<double>()) << channel;
  }
  const fs::path types = test::fixture_path("io/scipy_types.mat");
  EXPECT_FALSE(read_mat_readings(types, {"a"}).has_value());        // single
  EXPECT_FALSE(read_mat_readings(types, {"M"}).has_value());        // 3x2 matrix
  EXPECT_FALSE(read_mat_readings(types, {"t", "nope"}).has_value());  // a missing variable
  EXPECT_FALSE(read_mat_readings(types, {"t", "b"}).has_value());   // int16
  const test::TempDir dir;
  const fs::path csv = dir.path() / "readings.csv";
  { std::ofstream(csv) << "C_sensor\n5.1e-6\n"; }
  EXPECT_FALSE(read_mat_readings(csv, {"C_sensor"}).has_value());   // not a .mat file
}

TEST(TimeSeriesScipy, ChannelsInAStruct) {
  const nlohmann::json expected = expected_json()["struct"];
  const fs::path file = test::fixture_path("io/scipy_struct.mat");
  const TimeSeries ts = read_timeseries(file);  // the only struct is found without being named
  EXPECT_EQ(ts.names, (std::vector<std::string>{"u", "y"}));
  EXPECT_TRUE(test::near(ts.sample_rate, expected["fs"].get<double>(), test::kRoundoff));
  EXPECT_EQ(ts.channel("y")(ts.samples() - 1), expected["y_last"].get<double>());
  ReadOptions options;
  options.group = "meas";
  options.channels = {"y"};
  const TimeSeries y = read_timeseries(file, options);
  EXPECT_EQ(y.names, std::vector<std::string>{"y"});
  EXPECT_EQ(y.channel("y")(y.samples() - 1), expected["y_last"].get<double>());
  ReadOptions wrong;
  wrong.group = "operator";
  const std::string msg = input_error([&] { (void)read_timeseries(file, wrong); });
  EXPECT_TRUE(contains(msg, "operator") && contains(msg, "struct") && contains(msg, "char")) << msg;
}

TEST(TimeSeriesScipy, NumericClassesAreConvertedAndOtherVariablesRejected) {
  const nlohmann::json expected = expected_json()["types"];
  const fs::path file = test::fixture_path("io/scipy_types.mat");
  ReadOptions options;
  options.channels = {"a", "b"};
  const TimeSeries ts = read_timeseries(file, options);
  const auto a = expected["a"].get<std::vector<double>>(), b = expected["b"].get<std::vector<double>>();
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(ts.channel("a")(static_cast<Eigen::Index>(k)), a[k]);
    EXPECT_EQ(ts.channel("b")(static_cast<Eigen::Index>(k)), b[k]);
  }
  for (const auto& [channel, found] : std::vector<std::pair<std::string, std::string>>{
           {"c", "complex double"}, {"M", "double 3x2"}, {"note", "char"}}) {
    ReadOptions o;
    o.channels = {channel};
    const std::string msg = input_error([&] { (void)read_timeseries(file, o); });
    EXPECT_TRUE(contains(msg, file.string()) && contains(msg, channel) && contains(msg, found)) << msg;
  }
}

TEST(TimeSeriesScipy, NonUniformTimeIsAnErrorNamingFileAndT) {
  const fs::path file = test::fixture_path("io/scipy_bad_time.mat");
  const std::string msg = input_error([&] { (void)read_timeseries(file); });
  EXPECT_TRUE(contains(msg, file.string()) && contains(msg, ": t: ") && contains(msg, "t[17]")) << msg;
}

// ---- validation -----------------------------------------------------------------------------

TEST(TimeSeriesValidation, UnknownChannelListsTheAvailableOnes) {
  const fs::path file = test::fixture_path("io/scipy_two_outputs.mat");
  ReadOptions options;
  options.channels = {"u_dac", "de"};
  const std::string msg = input_error([&] { (void)read_timeseries(file, options); });
  EXPECT_TRUE(contains(msg, file.string()) && contains(msg, "'de'") && contains(msg, "V_force, d_enc, u_dac")) << msg;
  const TimeSeries ts = read_timeseries(file);
  const std::string msg2 = input_error([&] { (void)ts.channel("Vs"); });
  EXPECT_TRUE(contains(msg2, "u_dac")) << msg2;
}

// A .mat file written with matio directly (no validation on the way in).
void write_raw_mat(const fs::path& file, const std::vector<std::pair<std::string, Eigen::VectorXd>>& vars, bool v73 = false) {
  detail::write_mat_atomically(file, v73, false, [&](detail::MatWriter& w) {
    for (const auto& [name, v] : vars) w.write(detail::make_real_column(name, v));
  });
}

TEST(TimeSeriesValidation, LengthsThatDiffer) {
  TempDir dir;
  const fs::path file = dir.path() / "len.mat";
  write_raw_mat(file, {{"t", Eigen::VectorXd::LinSpaced(10, 0, 0.9)}, {"a", Eigen::VectorXd::Ones(10)}, {"b", Eigen::VectorXd::Ones(9)}});
  const std::string msg = input_error([&] { (void)read_timeseries(file); });
  EXPECT_TRUE(contains(msg, file.string()) && contains(msg, "b: ") && contains(msg, "10 samples") && contains(msg, "found 9")) << msg;
  const fs::path file2 = dir.path() / "len_t.mat";
  write_raw_mat(file2, {{"t", Eigen::VectorXd::LinSpaced(11, 0, 1.0)}, {"a", Eigen::VectorXd::Ones(10)}});
  const std::string msg2 = input_error([&] { (void)read_timeseries(file2); });
  EXPECT_TRUE(contains(msg2, ": t: ") && contains(msg2, "found 11")) << msg2;
}

TEST(TimeSeriesValidation, NanAndInfNameChannelAndSample) {
  TempDir dir;
  Eigen::VectorXd x = Eigen::VectorXd::Ones(20);
  x(13) = std::numeric_limits<double>::quiet_NaN();
  const fs::path file = dir.path() / "nan.mat";
  write_raw_mat(file, {{"t", Eigen::VectorXd::LinSpaced(20, 0, 1.9)}, {"ok", Eigen::VectorXd::Ones(20)}, {"bad", x}}, /*v73=*/true);
  const std::string msg = input_error([&] { (void)read_timeseries(file); });
  EXPECT_TRUE(contains(msg, file.string()) && contains(msg, "bad") && contains(msg, "NaN at sample 13")) << msg;

  const fs::path csv = dir.path() / "inf.csv";
  write_text(csv, "t,a,b\n0,1,2\n0.1,1,inf\n");
  const std::string msg2 = input_error([&] { (void)read_timeseries(csv); });
  EXPECT_TRUE(contains(msg2, csv.string()) && contains(msg2, "b (line 3)") && contains(msg2, "'inf' at sample 1")) << msg2;
}

TEST(TimeSeriesValidation, EmptyAndNonMonotonicTime) {
  TempDir dir;
  const fs::path empty = dir.path() / "empty.mat";
  write_raw_mat(empty, {{"a", Eigen::VectorXd()}});
  EXPECT_TRUE(contains(input_error([&] { (void)read_timeseries(empty); }), empty.string()));
  const fs::path back = dir.path() / "back.mat";
  Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(8, 0, 0.7);
  std::swap(t(3), t(4));
  write_raw_mat(back, {{"t", t}, {"a", Eigen::VectorXd::Ones(8)}});
  const std::string msg = input_error([&] { (void)read_timeseries(back); });
  EXPECT_TRUE(contains(msg, ": t: ") && contains(msg, "strictly increasing") && contains(msg, "t[4]")) << msg;
}

// ---- large records: the reader takes .mat channels in pieces of 2^15 samples (256 kB) and checks
// each piece as it arrives; a problem anywhere, in particular across a piece boundary, must give
// the same message as a full scan. 200,000 samples = 6 whole pieces and a partial 7th.

constexpr Eigen::Index kLarge = 200000;
constexpr Eigen::Index kPiece = Eigen::Index{1} << 15;
constexpr double kLargeFs = 10000.0;

Eigen::VectorXd large_time() {
  Eigen::VectorXd t(kLarge);
  for (Eigen::Index k = 0; k < kLarge; ++k) t(k) = static_cast<double>(k) / kLargeFs;
  return t;
}

// Distinct values at every sample, so a piece read to the wrong place cannot go unnoticed.
Eigen::VectorXd large_channel(double phase) {
  Eigen::VectorXd x(kLarge);
  for (Eigen::Index k = 0; k < kLarge; ++k) x(k) = std::sin(1e-3 * static_cast<double>(k) + phase) + 1e-6 * static_cast<double>(k);
  return x;
}

const char* version_name(bool v73) { return v73 ? "v7.3" : "v5"; }

TEST(TimeSeriesLargeMat, NanLateInAChannelAndInfAtTheLastSampleNameFileChannelAndSample) {
  TempDir dir;
  const Eigen::VectorXd t = large_time(), a = large_channel(0.0), b = large_channel(1.0);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  struct Case {
    const char* channel;  // "a" or "b"
    Eigen::Index index;
    double value;
    const char* found;
  };
  const Case cases[] = {
      {"b", 100000, nan, "NaN at sample 100000"},           // in the 4th piece
      {"b", kLarge - 1, inf, "Inf at sample 199999"},       // the very last sample (partial piece)
      {"a", kLarge - 1, -inf, "-Inf at sample 199999"},     // first channel, sign kept
      {"a", kPiece, nan, "NaN at sample 32768"},            // first sample of the 2nd piece
      {"b", kPiece - 1, inf, "Inf at sample 32767"},        // last sample of the 1st piece
  };
  for (bool v73 : {false, true}) {
    for (const Case& c : cases) {
      SCOPED_TRACE(std::string(version_name(v73)) + " " + c.channel + " " + c.found);
      Eigen::VectorXd bad = std::string(c.channel) == "a" ? a : b;
      bad(c.index) = c.value;
      const fs::path file = dir.path() / "late.mat";
      write_raw_mat(file, {{"t", t}, {"a", std::string(c.channel) == "a" ? bad : a}, {"b", std::string(c.channel) == "b" ? bad : b}},
                    v73);
      const std::string msg = input_error([&] { (void)read_timeseries(file); }, c.channel);
      EXPECT_EQ(msg, file.string() + ": " + c.channel + ": expected finite samples, found " + c.found);
    }
  }
}

TEST(TimeSeriesLargeMat, TimeRepeatingOrJitteringAtAPieceBoundary) {
  TempDir dir;
  const Eigen::VectorXd t = large_time(), a = large_channel(0.0);
  const double jitter = 0.05 / kLargeFs;  // 5 % of a sample period, 5x the default tolerance
  for (bool v73 : {false, true}) {
    SCOPED_TRACE(version_name(v73));
    const fs::path file = dir.path() / "t.mat";
    const auto message = [&](const Eigen::VectorXd& bad_t) {
      write_raw_mat(file, {{"t", bad_t}, {"a", a}}, v73);
      return input_error([&] { (void)read_timeseries(file); }, "t");
    };
    // Repeats: the step t[k] - t[k-1] that crosses from one piece to the next, and the last one.
    for (Eigen::Index k : {kPiece, 2 * kPiece, kLarge - 1}) {
      Eigen::VectorXd bad = t;
      bad(k) = bad(k - 1);
      const std::string msg = message(bad);
      EXPECT_TRUE(contains(msg, file.string() + ": t: expected a strictly increasing time vector") &&
                  contains(msg, "found t[" + std::to_string(k) + "] = ") &&
                  contains(msg, " after t[" + std::to_string(k - 1) + "] = "))
          << k << ": " << msg;
    }
    // Jitter on the last sample of a piece, the first of the next, and the last sample checked
    // for uniformity (the very last one defines dt).
    for (const auto& [k, sign] : {std::pair{kPiece - 1, 1.0}, std::pair{kPiece, -1.0}, std::pair{3 * kPiece, 1.0},
                                  std::pair{kLarge - 2, -1.0}}) {
      Eigen::VectorXd bad = t;
      bad(k) += sign * jitter;
      const std::string msg = message(bad);
      EXPECT_TRUE(contains(msg, file.string() + ": t: expected uniform sampling: jitter at most 1 % of a sample period") &&
                  contains(msg, "found t[" + std::to_string(k) + "] = ") && contains(msg, "of a sample period off the stamps' fitted rate"))
          << k << " " << sign << ": " << msg;
    }
    // Below the tolerance: accepted, and the rate is the end-to-end one.
    Eigen::VectorXd fine = t;
    fine(kPiece) += 1e-8 / kLargeFs;
    write_raw_mat(file, {{"t", fine}, {"a", a}}, v73);
    const TimeSeries ts = read_timeseries(file);
    EXPECT_EQ(ts.sample_rate, 1.0 / ((t(kLarge - 1) - t(0)) / static_cast<double>(kLarge - 1)));
    EXPECT_EQ(ts.t, fine);
  }
}

TEST(TimeSeriesLargeMat, NanOrInfInTimeNamesTAndTheSample) {
  TempDir dir;
  const Eigen::VectorXd t = large_time(), a = large_channel(0.0);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (bool v73 : {false, true}) {
    SCOPED_TRACE(version_name(v73));
    const fs::path file = dir.path() / "tnan.mat";
    for (const auto& [k, value, found] : {std::tuple{Eigen::Index{100000}, nan, "NaN at sample 100000"},
                                          std::tuple{kPiece, inf, "Inf at sample 32768"},
                                          std::tuple{Eigen::Index{0}, -inf, "-Inf at sample 0"},
                                          std::tuple{kLarge - 1, nan, "NaN at sample 199999"}}) {
      Eigen::VectorXd bad = t;
      bad(k) = value;
      write_raw_mat(file, {{"t", bad}, {"a", a}}, v73);
      EXPECT_EQ(input_error([&] { (void)read_timeseries(file); }, "t"),
                file.string() + ": t: expected finite samples, found " + found);
    }
  }
}

// A 1xN variable (MATLAB's row vector), as written by `x = x.'; save`.
detail::MatValue make_real_row(const std::string& name, const Eigen::VectorXd& v) {
  return detail::make_matrix(name, 1, static_cast<size_t>(v.size()), std::vector<double>(v.data(), v.data() + v.size()));
}

TEST(TimeSeriesLargeMat, RowVectorsAreReadExactlyAcrossPieces) {
  TempDir dir;
  const Eigen::VectorXd t = large_time(), a = large_channel(0.0), r = large_channel(2.0);
  for (bool v73 : {false, true}) {
    for (bool t_row : {false, true}) {
      SCOPED_TRACE(std::string(version_name(v73)) + (t_row ? " row t" : " column t"));
      const fs::path file = dir.path() / "row.mat";
      detail::write_mat_atomically(file, v73, false, [&](detail::MatWriter& w) {
        w.write(t_row ? make_real_row("t", t) : detail::make_real_column("t", t));
        w.write(detail::make_real_column("a", a));
        w.write(make_real_row("r", r));
      });
      const TimeSeries ts = read_timeseries(file);
      ASSERT_EQ(ts.names, (std::vector<std::string>{"a", "r"}));
      EXPECT_EQ(ts.t, t);
      EXPECT_EQ(ts.data.col(0), a);
      EXPECT_EQ(ts.data.col(1), r);
      EXPECT_EQ(ts.sample_rate, 1.0 / ((t(kLarge - 1) - t(0)) / static_cast<double>(kLarge - 1)));
      // A NaN in a row vector is found at the same sample.
      Eigen::VectorXd bad = r;
      bad(3 * kPiece + 5) = std::numeric_limits<double>::quiet_NaN();
      detail::write_mat_atomically(file, v73, false, [&](detail::MatWriter& w) {
        w.write(t_row ? make_real_row("t", t) : detail::make_real_column("t", t));
        w.write(detail::make_real_column("a", a));
        w.write(make_real_row("r", bad));
      });
      EXPECT_EQ(input_error([&] { (void)read_timeseries(file); }, "r"),
                file.string() + ": r: expected finite samples, found NaN at sample 98309");
    }
  }
}

TEST(TimeSeriesValidation, MalformedCsvFiles) {
  TempDir dir;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "header"},
      {"# only a comment\n", "header"},
      {"a,b\n", "data row"},
      {"a,b\n1,2\n3\n", "line 3"},
      {"a,b\n1,2\n3,4,5\n", "line 3"},
      {"a,b\n1,x2\n", "b (line 2)"},
      {"a,b\n1,\n", "empty cell"},
      {"a,a\n1,2\n", "twice"},
      {"t [V],a\n0,1\n1,2\n", "a time unit (us, ms, s, min)"},
      {"t,a [furlong]\n0,1\n1,2\n", "channel a: expected a known unit (nm, um"},
      {"a,b [V\n1,2\n", "NAME [UNIT]"},
      {std::string("a,b\n1,2\0\n", 10), "binary"},
  };
  for (const auto& [text, expected] : cases) {
    const fs::path file = dir.path() / "bad.csv";
    write_text(file, text);
    ReadOptions options;
    options.fs = 100.0;
    const std::string msg = input_error([&] { (void)read_timeseries(file, options); });
    EXPECT_TRUE(contains(msg, file.string()) && contains(msg, expected)) << "case " << text::quote(text) << ": " << msg;
  }
  EXPECT_TRUE(contains(input_error([&] { (void)read_timeseries(dir.path() / "missing.csv"); }), "no such file"));
  EXPECT_TRUE(contains(input_error([&] { (void)read_timeseries(dir.path() / "x.txt"); }), ".txt"));
}

TEST(TimeSeriesValidation, TruncatedAndCorruptMatFilesAreInputErrors) {
  TempDir dir;
  const fs::path v5 = dir.path() / "full5.mat";
  const fs::path v73 = dir.path() / "full73.mat";
  write_timeseries_mat(sample_series(300), v5);
  write_timeseries_mat(sample_series(300), v73, {.version = MatVersion::kV73});
  const std::string compressed = test::read_text(test::fixture_path("io/scipy_compressed.mat"));
  for (const auto& [name, content] : std::vector<std::pair<std::string, std::string>>{
           {"v5", test::read_text(v5)}, {"v73", test::read_text(v73)}, {"zlib", compressed}}) {
    for (const double fraction : {0.0, 0.01, 0.05, 0.2, 0.5, 0.8, 0.95, 0.999}) {
      const size_t size = static_cast<size_t>(fraction * static_cast<double>(content.size()));
      SCOPED_TRACE(name + " truncated to " + std::to_string(size) + " bytes");
      const fs::path file = dir.path() / "cut.mat";
      write_text(file, content.substr(0, size));
      const std::string msg = input_error([&] { (void)read_timeseries(file); });
      EXPECT_TRUE(contains(msg, file.string())) << msg;
    }
  }
  // A MATLAB header followed by garbage.
  std::string garbage = test::read_text(v5).substr(0, 128);
  for (int i = 0; i < 4096; ++i) garbage += static_cast<char>((i * 7919) & 0xff);
  const fs::path file = dir.path() / "garbage.mat";
  write_text(file, garbage);
  EXPECT_TRUE(contains(input_error([&] { (void)read_timeseries(file); }), file.string()));
  // A CSV renamed .mat.
  write_text(file, "t,a\n0,1\n");
  EXPECT_TRUE(contains(input_error([&] { (void)read_timeseries(file); }), "MAT file"));
}

// ---- read_timeseries_view: in place from the file's mapping, same checks and results ----------

// The view of `file` holds what read_timeseries gives, bit for bit; `mapped` says whether it used
// the file in place.
void expect_view_matches(const fs::path& file, const ReadOptions& options, bool mapped) {
  SCOPED_TRACE(file.string());
  const TimeSeries ts = read_timeseries(file, options);
  const TimeSeriesView view = read_timeseries_view(file, options);
  EXPECT_EQ(view.mapped, mapped);
  EXPECT_EQ(view.names, ts.names);
  EXPECT_EQ(view.units, ts.units);
  EXPECT_EQ(view.sample_rate, ts.sample_rate);
  EXPECT_EQ(view.source, ts.source);
  ASSERT_EQ(view.samples, ts.samples());
  ASSERT_EQ(view.columns.size(), ts.names.size());
  for (const std::string& name : ts.names) {
    EXPECT_EQ(view.channel(name), ts.channel(name)) << name;
    EXPECT_EQ(view.unit(name), ts.unit(name)) << name;
  }
  EXPECT_TRUE(contains(input_error([&] { (void)view.channel("nope"); }), "nope"));
}

TEST(TimeSeriesView, UncompressedDoublesAreUsedInPlaceAnythingElseIsRead) {
  TempDir dir;
  expect_view_matches(test::fixture_path("io/scipy_two_outputs.mat"), {}, true);   // scipy, v5
  expect_view_matches(test::fixture_path("io/scipy_compressed.mat"), {}, false);   // zlib
  expect_view_matches(test::fixture_path("io/scipy_struct.mat"), {}, false);       // channels in a struct
  ReadOptions ab;
  ab.channels = {"a", "b"};
  expect_view_matches(test::fixture_path("io/scipy_types.mat"), ab, false);        // integer classes
  const fs::path v5 = dir.path() / "v5.mat", v73 = dir.path() / "v73.mat", csv = dir.path() / "r.csv";
  write_timeseries_mat(sample_series(3000), v5);
  write_timeseries_mat(sample_series(3000), v73, {.version = MatVersion::kV73});
  write_timeseries_csv(sample_series(300), csv);
  expect_view_matches(v5, {}, true);
  ReadOptions vs_u;
  vs_u.channels = {"Vs", "u"};
  expect_view_matches(v5, vs_u, true);
  expect_view_matches(v73, {}, false);
  expect_view_matches(csv, {}, false);
  // A channel in mV is converted to V: read, not used in place.
  TimeSeries mv = sample_series(3000);
  mv.units = {"mV", "m", "V"};
  const fs::path mv_file = dir.path() / "mv.mat";
  write_timeseries_mat(mv, mv_file);
  expect_view_matches(mv_file, {}, false);
  // Row vectors (1xN) and a time vector in ms.
  const Eigen::VectorXd t = large_time(), a = large_channel(0.0), r = large_channel(2.0);
  const fs::path rows = dir.path() / "rows.mat";
  write_raw_mat(rows, {{"t", t}, {"a", a}});
  expect_view_matches(rows, {}, true);
  const fs::path wrong_length = dir.path() / "short_t.mat";
  write_raw_mat(wrong_length, {{"t", t.head(kLarge - 1)}, {"a", a}});
  EXPECT_EQ(input_error([&] { (void)read_timeseries_view(wrong_length); }),
            input_error([&] { (void)read_timeseries(wrong_length); }));
}

TEST(TimeSeriesView, BadSamplesAndDamagedFilesGiveTheReadersMessages) {
  TempDir dir;
  const Eigen::VectorXd t = large_time(), a = large_channel(0.0), b = large_channel(1.0);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const fs::path file = dir.path() / "bad.mat";
  const auto same_message = [&](const std::vector<std::pair<std::string, Eigen::VectorXd>>& vars) {
    write_raw_mat(file, vars);
    const std::string want = input_error([&] { (void)read_timeseries(file); });
    EXPECT_EQ(input_error([&] { (void)read_timeseries_view(file); }), want);
  };
  for (const Eigen::Index k : {Eigen::Index{0}, kPiece - 1, kPiece, kLarge - 1}) {
    SCOPED_TRACE(k);
    Eigen::VectorXd bad = b;
    bad(k) = k % 2 == 0 ? nan : -inf;
    same_message({{"t", t}, {"a", a}, {"b", bad}});
    Eigen::VectorXd bad_t = t;
    bad_t(k) = nan;
    same_message({{"t", bad_t}, {"a", a}});
    if (k > 0 && k < kLarge - 1) {
      bad_t = t;
      bad_t(k) += 0.05 / kLargeFs;  // jitter
      same_message({{"t", bad_t}, {"a", a}});
      bad_t = t;
      bad_t(k) = bad_t(k - 1);  // repeat
      same_message({{"t", bad_t}, {"a", a}});
    }
  }
  // Truncated anywhere, or a data element that declares more than the variable holds: the checks
  // made when the file is opened refuse it before anything is mapped.
  write_raw_mat(file, {{"t", t}, {"a", a}, {"b", b}});
  const std::string content = test::read_text(file);
  for (const double fraction : {0.0, 0.01, 0.3, 0.6, 0.999}) {
    const auto size = static_cast<size_t>(fraction * static_cast<double>(content.size()));
    SCOPED_TRACE("truncated to " + std::to_string(size));
    const fs::path cut = dir.path() / "cut.mat";
    write_text(cut, content.substr(0, size));
    EXPECT_EQ(input_error([&] { (void)read_timeseries_view(cut); }), input_error([&] { (void)read_timeseries(cut); }));
  }
}

TEST(TimeSeriesView, FiniteCheckByTheCallerLeavesMappedChannelsAloneButNotTheTimeVector) {
  TempDir dir;
  const Eigen::VectorXd t = large_time(), a = large_channel(0.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const fs::path file = dir.path() / "caller.mat";
  Eigen::VectorXd bad = a;
  bad(kPiece + 3) = nan;
  write_raw_mat(file, {{"t", t}, {"a", bad}});
  // The reader would refuse it; with kCaller the channel is given as it is, in place.
  EXPECT_NE(input_error([&] { (void)read_timeseries_view(file); }), "");
  const TimeSeriesView view = read_timeseries_view(file, {}, FiniteCheck::kCaller);
  ASSERT_TRUE(view.mapped);
  EXPECT_TRUE(std::isnan(view.channel("a")(kPiece + 3)));
  EXPECT_EQ(view.channel("a")(kPiece + 2), a(kPiece + 2));
  // The time vector gives the sample rate: it is checked whoever checks the channels.
  Eigen::VectorXd bad_t = t;
  bad_t(kPiece) = nan;
  write_raw_mat(file, {{"t", bad_t}, {"a", a}});
  EXPECT_EQ(input_error([&] { (void)read_timeseries_view(file, {}, FiniteCheck::kCaller); }),
            input_error([&] { (void)read_timeseries(file); }));
}

// ---- writers --------------------------------------------------------------------------------

TEST(TimeSeriesWrite, InvalidDataWritesNothing) {
  TempDir dir;
  TimeSeries ts = sample_series(50);
  ts.data(7, 1) = std::numeric_limits<double>::infinity();
  for (const char* name : {"x.mat", "x.csv"}) {
    const fs::path file = dir.path() / name;
    const std::string msg = input_error([&] { write_timeseries(ts, file); });
    EXPECT_TRUE(contains(msg, file.string()) && contains(msg, "de") && contains(msg, "sample 7")) << msg;
    EXPECT_FALSE(fs::exists(file));
  }
  TimeSeries bad_name = sample_series(5);
  bad_name.names[1] = "2de";
  EXPECT_TRUE(contains(input_error([&] { write_timeseries(bad_name, dir.path() / "y.mat"); }), "MATLAB"));
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(TimeSeriesWrite, FailingWriteLeavesNoFileAndKeepsTheOldOne) {
  TempDir dir;
  const fs::path file = dir.path() / "rec.mat";
  const TimeSeries small = sample_series(10);
  write_timeseries_mat(small, file);
  const std::string before = test::read_text(file);
  // A file-size limit makes matio's writes fail part-way, as a full disk would.
  struct rlimit old_limit {};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old_limit), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  struct rlimit limit = old_limit;
  limit.rlim_cur = 64 * 1024;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limit), 0);
  std::string msg_v5, msg_csv, msg_v73;
  const TimeSeries big = sample_series(20000);  // ~640 kB
  msg_v5 = input_error([&] { write_timeseries_mat(big, file); });
  msg_v73 = input_error([&] { write_timeseries_mat(big, dir.path() / "new73.mat", {.version = MatVersion::kV73}); });
  msg_csv = input_error([&] { write_timeseries_csv(big, dir.path() / "new.csv"); });
  setrlimit(RLIMIT_FSIZE, &old_limit);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_TRUE(contains(msg_v5, file.string())) << msg_v5;
  EXPECT_TRUE(contains(msg_v73, "new73.mat")) << msg_v73;
  EXPECT_TRUE(contains(msg_csv, "new.csv")) << msg_csv;
  EXPECT_EQ(test::read_text(file), before);
  // Only the old file is left: no temporary, no partial new file.
  size_t count = 0;
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    ++count;
    EXPECT_EQ(entry.path().filename(), "rec.mat");
  }
  EXPECT_EQ(count, 1u);
}

TEST(TimeSeriesOptions, ValidateNamesTheField) {
  ReadOptions o;
  o.fs = -1.0;
  EXPECT_TRUE(contains(input_error([&] { o.validate(); }), "fs"));
  o = ReadOptions{};
  o.time_tolerance = 0.0;
  EXPECT_TRUE(contains(input_error([&] { o.validate(); }), "time_tolerance"));
  o = ReadOptions{};
  o.channels = {"a", "a"};
  EXPECT_TRUE(contains(input_error([&] { o.validate(); }), "channels"));
  EXPECT_EQ(mat_version_from_string("-v7.3"), MatVersion::kV73);
  EXPECT_EQ(mat_version_from_string(to_string(MatVersion::kV5)), MatVersion::kV5);
  EXPECT_THROW((void)mat_version_from_string("v4"), InputError);
}

// ---- files as labs have them (scripts/fixtures/make_io_lab_fixtures.py) -----------------------

nlohmann::json lab_expected() { return nlohmann::json::parse(test::read_text(test::fixture_path("io/lab/expected.json"))); }

// Every lab file holds the same record; read in SI it must give the same samples and rate.
void expect_lab_record(const fs::path& file, double rel_tol, const ReadOptions& base = {}) {
  SCOPED_TRACE(file.filename().string());
  const nlohmann::json ref = lab_expected();
  ReadOptions o = base;
  o.channels = {"u", "d_e", "Vs"};
  const TimeSeries ts = read_timeseries(file, o);
  ASSERT_EQ(ts.samples(), ref["samples"].get<Eigen::Index>());
  EXPECT_TRUE(test::near(ts.sample_rate, ref["fs"].get<double>(), {1e-9, 0.0}));
  for (Eigen::Index k = 0; k < 3; ++k) {
    for (size_t j = 0; j < 3; ++j) {
      const double want = ref["first"][ts.names[j]][static_cast<size_t>(k)].get<double>();
      EXPECT_TRUE(test::near(ts.data(k, static_cast<Eigen::Index>(j)), want, {rel_tol, 0.0})) << ts.names[j] << "[" << k << "]";
    }
  }
}

TEST(TimeSeriesLabFiles, CsvDialectsAndUnitsAreReadInSi) {
  // 10 significant digits in the files.
  expect_lab_record(test::fixture_path("io/lab/daq_tab_decimal_comma.csv"), 1e-9);
  expect_lab_record(test::fixture_path("io/lab/semicolon_mm.csv"), 1e-9);
  expect_lab_record(test::fixture_path("io/lab/blanks_us.csv"), 1e-9);
  const TimeSeries ts = read_timeseries(test::fixture_path("io/lab/daq_tab_decimal_comma.csv"));
  EXPECT_EQ(ts.names, (std::vector<std::string>{"u", "d_e", "Vs"}));
  EXPECT_EQ(ts.units, (std::vector<std::string>{"V", "m", "V"}));
  EXPECT_TRUE(test::near(ts.t(1), 0.5e-3, {1e-12, 0.0}));  // Time [ms]
}

TEST(TimeSeriesLabFiles, MatV73FromMatlabH5pyAndHdf5storage) {
  expect_lab_record(test::fixture_path("io/lab/v73_matlab.mat"), 1e-15);
  expect_lab_record(test::fixture_path("io/lab/v73_h5py.mat"), 1e-15);         // d_e in um (attribute), Fs
  expect_lab_record(test::fixture_path("io/lab/v73_hdf5storage.mat"), 1e-15);  // NULLPAD classes, deflated
  const TimeSeries h = read_timeseries(test::fixture_path("io/lab/v73_hdf5storage.mat"));
  EXPECT_EQ(h.names, (std::vector<std::string>{"Vs", "d_e", "u"}));  // HDF5 lists fields by name
  EXPECT_EQ(h.unit("d_e"), "m");
}

TEST(TimeSeriesLabFiles, ForcedDialectAndUnitsGivenByTheCaller) {
  ReadOptions o;
  o.delimiter = '\t';
  o.decimal = ',';
  expect_lab_record(test::fixture_path("io/lab/daq_tab_decimal_comma.csv"), 1e-9, o);
  // A file that says nothing about units, and the caller (a campaign file) who knows them.
  TempDir dir;
  const fs::path file = dir.path() / "raw.csv";
  write_text(file, "t,d_e,F\n0,1,2\n0.001,3,4\n");
  ReadOptions u;
  u.units = {{"d_e", "mm"}, {"F", "kN"}};
  const TimeSeries ts = read_timeseries(file, u);
  EXPECT_EQ(ts.data(1, 0), 3e-3);
  EXPECT_EQ(ts.data(1, 1), 4e3);
  EXPECT_EQ(ts.units, (std::vector<std::string>{"m", "N"}));
  // The file and the caller disagree: refused, not guessed.
  write_text(file, "t,d_e [um]\n0,1\n0.001,3\n");
  ReadOptions mm;
  mm.units = {{"d_e", "mm"}};
  test::expect_input_error([&] { (void)read_timeseries(file, mm); }, {"raw.csv", "channel d_e", "(mm)", "'um' in the file"});
}

TEST(TimeSeriesLabFiles, SampleRateSpellings) {
  TempDir dir;
  const fs::path file = dir.path() / "rate.csv";
  for (const char* comment : {"# fs: 250", "# Fs = 250 Hz", "# sample_rate: 0.25 kHz", "# sample rate [Hz]: 250",
                              "# sample_rate_Hz: 250"}) {
    write_text(file, std::string(comment) + "\nx\n1\n2\n");
    EXPECT_EQ(read_timeseries(file).sample_rate, 250.0) << comment;
  }
  write_text(file, "# fs: fast\nx\n1\n2\n");
  test::expect_input_error([&] { (void)read_timeseries(file); }, {"rate.csv", "comment (line 1)", "a positive sample rate"});
}

// ---- a lab's files, second round (scripts/fixtures/make_io_units_fixtures.py) ------------------

nlohmann::json units_expected() { return nlohmann::json::parse(test::read_text(test::fixture_path("io/units/expected.json"))); }

// The record of every file: u, d_e, Vs in SI equal to scipy's, at 2048 Hz.
TimeSeries expect_units_record(const std::string& name, double rel_tol, const ReadOptions& base = {}) {
  SCOPED_TRACE(name);
  const nlohmann::json ref = units_expected();
  ReadOptions o = base;
  o.channels = {"u", "d_e", "Vs"};
  const TimeSeries ts = read_timeseries(test::fixture_path("io/units/" + name), o);
  EXPECT_EQ(ts.samples(), ref["samples"].get<Eigen::Index>());
  EXPECT_TRUE(test::near(ts.sample_rate, 2048.0, {1e-7, 0.0})) << format_number(ts.sample_rate, 17);
  EXPECT_EQ(ts.units, (std::vector<std::string>{"V", "m", "V"}));
  for (Eigen::Index k = 0; k < 8 && k < ts.samples(); ++k) {
    for (size_t j = 0; j < 3; ++j) {
      const double want = ref["first"][ts.names[j]][static_cast<size_t>(k)].get<double>();
      EXPECT_TRUE(test::near(ts.data(k, static_cast<Eigen::Index>(j)), want, {rel_tol, 0.0})) << ts.names[j] << "[" << k << "]";
    }
  }
  return ts;
}

TEST(TimeSeriesUnits, EveryPlaceAWriterPutsUnits) {
  for (const char* name : {"h5_dataset_attrs_in_group.mat", "h5_group_attr_map.mat", "h5_group_attrs_per_channel.mat",
                           "h5_root_attr_map.mat", "h5_root_attrs_per_channel.mat", "v73_units_cell_pairs.mat",
                           "v73_units_cell_list.mat", "v5_units_struct_in_record.mat", "v5_units_cell_pairs.mat",
                           "v5_units_cell_list.mat"}) {
    const TimeSeries ts = expect_units_record(name, 1e-15);
    EXPECT_TRUE(ts.warnings.empty()) << name << ": " << text::join(ts.warnings, "; ");
  }
}

TEST(TimeSeriesUnits, AUnitNamingNoChannelOrAnUnmatchedCellIsRefused) {
  test::expect_input_error([] { (void)read_timeseries(test::fixture_path("io/units/v5_units_typo.mat")); },
                           {"v5_units_typo.mat", "units.d_ee", "'d_ee', which names no channel", "d_e"});
  test::expect_input_error([] { (void)read_timeseries(test::fixture_path("io/units/h5_root_attr_typo.mat")); },
                           {"h5_root_attr_typo.mat", "file (attribute units)", "'d_ee', which names no channel", "d_e"});
  test::expect_input_error([] { (void)read_timeseries(test::fixture_path("io/units/v5_units_cell_unmatched.mat")); },
                           {"v5_units_cell_unmatched.mat", "units", "`channels`", "without names"});
  ReadOptions o;
  o.unit_overrides = {{"de", "um"}};  // the file's channel is d_e
  test::expect_input_error([&] { (void)read_timeseries(test::fixture_path("io/units/time_f6.csv"), o); },
                           {"time_f6.csv", "--units de", "'de', which names no channel", "d_e"});
}

TEST(TimeSeriesUnits, OverridesReplaceTheFilesUnitWithAWarningAndAMissingUnitWarns) {
  TempDir dir;
  const fs::path file = dir.path() / "raw.csv";
  write_text(file, "t,d_e [um],F\n0,1,2\n0.001,3,4\n");
  TimeSeries ts = read_timeseries(file);
  EXPECT_EQ(ts.data(1, 0), 3e-6);
  ASSERT_EQ(ts.warnings.size(), 1u);
  EXPECT_TRUE(contains(ts.warnings[0], "raw.csv: channel F has no unit: taken as SI")) << ts.warnings[0];
  ReadOptions o;
  o.unit_overrides = {{"d_e", "mm"}, {"F", "kN"}};
  ts = read_timeseries(file, o);
  EXPECT_EQ(ts.data(1, 0), 3e-3);
  EXPECT_EQ(ts.data(1, 1), 4e3);
  ASSERT_EQ(ts.warnings.size(), 1u);
  EXPECT_TRUE(contains(ts.warnings[0], "channel d_e: unit 'mm' from --units replaces 'um'")) << ts.warnings[0];
}

TEST(TimeSeriesTimeStamps, StampsAsFilesStoreThemAreUniform) {
  // float32, %.6f s, ms with 3 decimals, epoch + %.6f, 0.1 % jitter: all accepted at 2048 Hz.
  for (const char* name : {"time_float32.csv", "time_f6.csv", "time_ms3.csv", "time_epoch.csv", "time_jitter_0p1.csv"}) {
    const TimeSeries ts = expect_units_record(name, 1e-15);
    EXPECT_NEAR(ts.sample_rate, 2048.0, 2048.0 * 1e-6) << name;
  }
  const TimeSeries m = expect_units_record("time_float32.mat", 1e-15);
  EXPECT_EQ(m.sample_rate, 2048.0);  // float32 multiples of 1/2048 are exact
}

TEST(TimeSeriesTimeStamps, JitterBeyondTheToleranceAndADroppedSampleAreRefusedWithTheFigure) {
  const std::string msg = input_error([] { (void)read_timeseries(test::fixture_path("io/units/time_jitter_5.csv")); });
  EXPECT_TRUE(contains(msg, "time_jitter_5.csv: t: expected uniform sampling: jitter at most 1 % of a sample period") &&
              contains(msg, "of a sample period off the stamps' fitted rate"))
      << msg;
  const std::string dropped = input_error([] { (void)read_timeseries(test::fixture_path("io/units/time_dropped.csv")); });
  EXPECT_TRUE(contains(dropped, "time_dropped.csv: t: expected uniform sampling") && contains(dropped, "% of a sample period"))
      << dropped;
  // --fs overrides the stamps: read, with a warning that shows the jitter.
  ReadOptions o;
  o.fs = 2048.0;
  const TimeSeries ts = read_timeseries(test::fixture_path("io/units/time_jitter_5.csv"), o);
  EXPECT_EQ(ts.sample_rate, 2048.0);
  ASSERT_FALSE(ts.warnings.empty());
  EXPECT_TRUE(contains(ts.warnings[0], "non-uniform time stamps")) << ts.warnings[0];
}

TEST(TimeSeriesTimeStamps, FsOverridesATimeColumnWithAWarningShowingTheDisagreement) {
  ReadOptions o;
  o.fs = 2000.0;
  const TimeSeries ts = read_timeseries(test::fixture_path("io/units/time_f6.csv"), o);
  EXPECT_EQ(ts.sample_rate, 2000.0);
  ASSERT_EQ(ts.warnings.size(), 1u);
  EXPECT_TRUE(contains(ts.warnings[0], "--fs 2000 Hz overrides the time vector's 2048 Hz (-2.34 %)")) << ts.warnings[0];
}

TEST(TimeSeriesUff58, TimeHistoriesSingleAndMultiRecordAsciiAndBinary) {
  for (const char* name : {"th_multi_ascii.uff", "th_multi_58b.uff"}) {
    const TimeSeries ts = expect_units_record(name, 1e-11);  // 4E20.12: 13 digits (58b: exact)
    EXPECT_EQ(ts.sample_rate, 2048.0);  // 4.88281E-04 s in record 7: the whole rate it rounds
    EXPECT_TRUE(ts.warnings.empty()) << text::join(ts.warnings, "; ");
  }
  const nlohmann::json ref = units_expected();
  for (const char* name : {"th_single_ascii.uff", "th_single_58b.uff"}) {
    SCOPED_TRACE(name);
    const TimeSeries ts = read_timeseries(test::fixture_path(std::string("io/units/") + name));
    EXPECT_EQ(ts.names, (std::vector<std::string>{"Mic 01"}));
    EXPECT_EQ(ts.units, (std::vector<std::string>{"Pa"}));
    EXPECT_EQ(ts.sample_rate, 2048.0);
    for (size_t k = 0; k < 8; ++k) {
      EXPECT_TRUE(test::near(ts.data(static_cast<Eigen::Index>(k), 0), ref["pa_float32_first"][k].get<double>(), {1e-5, 0.0}));
    }
  }
  const TimeSeries g = read_timeseries(test::fixture_path("io/units/th_g_58b.uff"));
  EXPECT_EQ(g.names, (std::vector<std::string>{"sine 5 Hz"}));
  EXPECT_EQ(g.units, (std::vector<std::string>{"m/s^2"}));
  for (size_t k = 0; k < 8; ++k) {
    EXPECT_TRUE(test::near(g.data(static_cast<Eigen::Index>(k), 0), ref["acc_g_first_m_per_s2"][k].get<double>(), {1e-15, 1e-300}));
  }
  test::expect_input_error([] { (void)read_timeseries(test::fixture_path("io/units/frf_compound.uff")); },
                           {"frf_compound.uff", "datasets", "function type 1 (time response)"});
  ReadOptions o;
  o.channels = {"u", "x"};
  test::expect_input_error([&] { (void)read_timeseries(test::fixture_path("io/units/th_multi_ascii.uff"), o); },
                           {"th_multi_ascii.uff", "channel x", "Vs, d_e, u"});
}

// pyuff's sample time histories (tests/fixtures/io/pyuff/README.md), written by the programs pyuff's
// authors collected: the same record in ASCII (6 printed digits) and binary 58b (float32), and a
// float64 58b record in g with CR LF lines.
TEST(TimeSeriesUff58, PyuffSampleFiles) {
  const TimeSeries ascii = read_timeseries(test::fixture_path("io/pyuff/Sample_UFF58_ascii.uff"));
  const TimeSeries binary = read_timeseries(test::fixture_path("io/pyuff/Sample_UFF58b_bin.uff"));
  for (const TimeSeries* ts : {&ascii, &binary}) {
    EXPECT_EQ(ts->names, (std::vector<std::string>{"Mic 01"}));
    EXPECT_EQ(ts->units, (std::vector<std::string>{"Pa"}));
    ASSERT_EQ(ts->data.rows(), 79292);
    EXPECT_TRUE(test::near(ts->sample_rate, 1.0 / 1.52588e-05, {1e-5, 0.0})) << ts->sample_rate;
  }
  // The ASCII file's first line of values, as printed.
  const double first[] = {-1.47553e-02, -1.72957e-02, -1.66101e-02, -1.61988e-02, -1.68925e-02, -1.53669e-02};
  for (Eigen::Index k = 0; k < 6; ++k) EXPECT_EQ(ascii.data(k, 0), first[k]) << k;
  // float32 against 6 printed digits: within half a unit of the 6th digit of each value.
  const Eigen::ArrayXd diff = (ascii.data.col(0) - binary.data.col(0)).array().abs();
  const Eigen::ArrayXd bound = 5e-6 * ascii.data.col(0).array().abs() + 1e-12;
  EXPECT_TRUE((diff <= bound).all()) << "largest difference " << diff.maxCoeff();

  const TimeSeries g = read_timeseries(test::fixture_path("io/pyuff/binary8byte.uff"));
  EXPECT_EQ(g.names, (std::vector<std::string>{"sine 5 Hz"}));
  EXPECT_EQ(g.units, (std::vector<std::string>{"m/s^2"}));  // g converted
  ASSERT_EQ(g.data.rows(), 250);
  EXPECT_EQ(g.sample_rate, 100.0);
  // A 5 Hz sine sampled at 100 Hz: 20 samples per period.
  EXPECT_TRUE(test::near(g.data(5, 0), g.data(25, 0), {1e-12, 1e-12}));
}

}  // namespace
}  // namespace piezobench::io
