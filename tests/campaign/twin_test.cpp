// The digital twin (campaign/twin.hpp) of a held-out unit: a virtual actuator with other
// parameters than the demo's batch (stiffer shell, softer stacks, more damping, other gains,
// hysteresis 1.35 times wider, creep, 150 us delay, a 68 kOhm resistor, twice the encoder noise,
// 2.5 times the sensor noise), its records written as a lab writes them (CSV, its own channel
// names, um and mV), the twin built from them, and the twin checked against the unit's records and
// its truth: the limits (FRF within 1 dB where the coherence exceeds 0.9, hysteresis width
// within 10 %, noise PSD within 3 dB, IFF optimum within 5 %).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <memory>
#include <set>
#include <string>

#include "piezobench/bench/experiments.hpp"
#include "piezobench/bench/twin.hpp"
#include "piezobench/campaign/campaign_file.hpp"
#include "piezobench/campaign/twin.hpp"
#include "piezobench/dsp/welch.hpp"
#include "piezobench/io/fields_json.hpp"
#include "piezobench/io/timeseries.hpp"
#include "piezobench/metrology/stroke.hpp"
#include "declared_keys.hpp"
#include "test_util.hpp"

namespace piezobench::campaign {
namespace {

namespace fs = std::filesystem;
using Eigen::Index;
using Eigen::VectorXd;

bench::UnitTruth held_out_unit() {
  bench::UnitTruth u = bench::batch_unit(1, 1);
  u.id = 9;
  apa::TwoDofParams& p = u.model;
  p.k1 *= 1.12;
  p.c1 *= 1.6;
  p.ka *= 0.88;
  p.ke *= 0.88;
  p.ca *= 1.3;
  p.ce *= 1.3;
  p.ga *= 0.92;
  p.gs *= 1.08;
  u.capacitance_sensor *= 1.06;
  u.capacitance_actuator *= 0.95;
  u.hysteresis_scale = 1.35;
  u.creep_coefficient = 0.02;
  u.load_creep_coefficient = 0.2;
  return u;
}

bench::BenchOptions held_out_bench() {
  bench::BenchOptions b;
  b.delay = 150e-6;
  b.hpf_resistance = 68e3;
  b.ground_resistance = 0.1;
  b.encoder_noise = 2e-9;
  b.vs_noise = 2.5e-3;
  return b;
}

struct LabChannel {
  std::string from, name, unit;
  double scale = 1.0;  // lab unit per SI unit
};

// The record as a lab's CSV: "time [s]" first, its own names and units.
void write_lab_csv(const io::TimeSeries& ts, const std::vector<LabChannel>& channels, const fs::path& file) {
  std::ofstream out(file);
  out << "time [s]";
  for (const auto& c : channels) out << "," << c.name << " [" << c.unit << "]";
  out << "\n";
  std::vector<VectorXd> cols;
  for (const auto& c : channels) cols.push_back(ts.channel(c.from) * c.scale);
  char buf[64];
  for (Index k = 0; k < ts.data.rows(); ++k) {
    std::snprintf(buf, sizeof buf, "%.7f", static_cast<double>(k) / ts.sample_rate);
    out << buf;
    for (const auto& col : cols) {
      std::snprintf(buf, sizeof buf, ",%.9g", col(k));
      out << buf;
    }
    out << "\n";
  }
}

const std::vector<LabChannel> kFrf = {{"u", "cmd", "V", 1.0}, {"de", "enc", "um", 1e6}, {"Vs", "sensor", "mV", 1e3}};
const std::vector<LabChannel> kHyst = {{"Va", "stack", "V", 1.0}, {"de", "enc", "um", 1e6}};
const std::vector<LabChannel> kStiff = {{"de", "enc", "um", 1e6}, {"added_mass", "load", "kg", 1.0}};

// u = 0 for `seconds`: the quiet record a lab takes before exciting (channels u, Va, de, Vs).
io::TimeSeries quiet_record(const bench::UnitTruth& unit, const bench::BenchOptions& options, double seconds, std::uint64_t seed) {
  bench::VirtualRunner runner(unit, options);
  Eigen::MatrixXd out;
  runner.open_loop(VectorXd::Zero(static_cast<Index>(seconds * options.sample_rate)), seed, out, {});
  io::TimeSeries ts;
  ts.names = {"u", "Va", "de", "Vs"};
  ts.data = out;
  ts.sample_rate = options.sample_rate;
  return ts;
}

struct HeldOut {
  test::TempDir dir;
  bench::UnitTruth unit = held_out_unit();
  bench::BenchOptions options = held_out_bench();
  io::TimeSeries frf, quiet;
  std::vector<io::TimeSeries> hysteresis;
  fs::path campaign_file;
  std::vector<double> amplitudes = {20.0, 40.0, 80.0};
};

HeldOut& held_out() {
  static const std::unique_ptr<HeldOut> h = [] {
    auto p = std::make_unique<HeldOut>();
    HeldOut& s = *p;
    bench::ExperimentOptions eo;
    eo.bench = s.options;
    bench::ExperimentOptions fo = eo;
    fo.duration = 60.0;  // a minute of noise: at 20 s the unit's own model is 1.4 dB off the estimate at the dip
    s.frf = bench::simulate(bench::Experiment::kFrfNoise, s.unit, fo, 11);
    write_lab_csv(s.frf, kFrf, s.dir.path() / "frf.csv");
    std::string hyst_list;
    for (const double a : s.amplitudes) {
      bench::ExperimentOptions ho = eo;
      ho.amplitude = a;
      s.hysteresis.push_back(bench::simulate(bench::Experiment::kHysteresis, s.unit, ho, 12));
      const std::string name = "hyst_" + std::to_string(static_cast<int>(a)) + "V.csv";
      write_lab_csv(s.hysteresis.back(), kHyst, s.dir.path() / name);
      hyst_list += (hyst_list.empty() ? "\"" : ", \"") + name + "\"";
    }
    write_lab_csv(bench::simulate(bench::Experiment::kStiffness, s.unit, eo, 13), kStiff, s.dir.path() / "stiffness.csv");
    const io::TimeSeries cap = bench::simulate(bench::Experiment::kCapacitance, s.unit, eo, 14);
    s.quiet = quiet_record(s.unit, s.options, 10.0, 15);
    write_lab_csv(s.quiet, {{"u", "cmd", "V", 1.0}, {"Va", "stack", "V", 1.0}, {"de", "enc", "um", 1e6}, {"Vs", "sensor", "mV", 1e3}},
                  s.dir.path() / "quiet.csv");
    s.campaign_file = s.dir.path() / "campaign.toml";
    test::write_text(s.campaign_file,
                     "[bench]\nhpf_resistance_ohm = 68e3\n\n[channels]\nu = \"cmd\"\nde = \"enc\"\nVs = \"sensor\"\nVa = \"stack\"\n"
                     "added_mass = \"load\"\n\n[[units]]\nid = 9\nname = \"APA 9\"\nfrf = \"frf.csv\"\nstiffness = \"stiffness.csv\"\n"
                     "hysteresis = [" + hyst_list + "]\n" +
                         fmt::format("capacitance_uF = {{ sensor = {:.6g}, actuator = {:.6g} }}\n", 1e6 * cap.data(0, 0), 1e6 * cap.data(0, 1)));
    return p;
  }();
  return *h;
}

const TwinBuild& build() {
  static const TwinBuild b = [] {
    const Campaign c = read_campaign(held_out().campaign_file);
    TwinOptions o;
    o.quiet = {held_out().dir.path() / "quiet.csv"};
    return build_twin(c, c.units.front(), o);
  }();
  return b;
}

TEST(Twin, FrfWithinOneDecibelWhereTheCoherenceExceeds09) {
  const TwinBuild& b = build();
  // The unit's FRF estimated here (Welch H1, 4 s segments) against the twin bench's response.
  const io::TimeSeries& r = held_out().frf;
  dsp::WelchOptions w;
  w.nfft = 40000;
  w.detrend = dsp::Detrend::kMean;
  const VectorXd u = r.channel("u"), de = r.channel("de"), vs = r.channel("Vs");
  const dsp::FrfEstimate est = dsp::estimate_frf(dsp::channel("u", u), {dsp::channel("de", de), dsp::channel("Vs", vs)}, r.sample_rate, w);
  const dsp::Frf twin = bench_frf(b.twin.unit, b.twin.options, est.frf.freq_Hz);
  for (std::size_t o = 0; o < 2; ++o) {
    double worst = 0.0;
    long points = 0;
    for (Index k = 0; k < est.frf.freq_Hz.size(); ++k) {
      const double f = est.frf.freq_Hz(k);
      if (f < 20.0 || f > 500.0 || est.frf.coherence[o](k) <= 0.9) continue;
      worst = std::max(worst, std::abs(20.0 * std::log10(std::abs(twin.H[o](k) / est.frf.H[o](k)))));
      ++points;
    }
    EXPECT_GT(points, 1000) << est.frf.outputs[o];
    EXPECT_LT(worst, 1.0) << est.frf.outputs[o];
  }
  EXPECT_LT(b.de.max_dB, 1.0);
  EXPECT_LT(b.vs.max_dB, 1.0);
  // The refinement on the twin's own bench is what brings it there: the tuned model alone is worse.
  EXPECT_LT(b.de.max_dB + b.vs.max_dB, b.de_tuned.max_dB + b.vs_tuned.max_dB);
}

TEST(Twin, HysteresisWidthWithinTenPercentAtEachAmplitude) {
  const TwinBuild& b = build();
  for (std::size_t i = 0; i < held_out().amplitudes.size(); ++i) {
    const io::TimeSeries& unit = held_out().hysteresis[i];
    bench::ExperimentOptions eo;
    eo.bench = b.twin.options;
    eo.amplitude = held_out().amplitudes[i];
    const io::TimeSeries twin = bench::simulate(bench::Experiment::kHysteresis, b.twin.unit, eo, 21);
    const double wu = metrology::analyze_hysteresis(unit.channel("Va"), unit.channel("de")).relative_width;
    const double wt = metrology::analyze_hysteresis(twin.channel("Va"), twin.channel("de")).relative_width;
    EXPECT_GT(wu, 0.02) << eo.amplitude.value();
    EXPECT_LT(std::abs(wt / wu - 1.0), 0.10) << eo.amplitude.value() << " V: twin " << wt << ", unit " << wu;
  }
  ASSERT_EQ(b.hysteresis.size(), held_out().amplitudes.size());
}

TEST(Twin, NoisePsdWithinThreeDecibels) {
  const TwinBuild& b = build();
  const io::TimeSeries twin = quiet_record(b.twin.unit, b.twin.options, 10.0, 31);
  for (const char* ch : {"de", "Vs"}) {
    const QuietSpectrum u = quiet_spectrum(held_out().quiet.channel(ch), held_out().quiet.sample_rate);
    const QuietSpectrum t = quiet_spectrum(twin.channel(ch), twin.sample_rate);
    EXPECT_LT(std::abs(10.0 * std::log10(t.median_level / u.median_level)), 3.0) << ch;
    // Line by line, 1 Hz lines averaged over 10 Hz bands from 2 Hz to 4 kHz.
    double worst = 0.0;
    for (Index k = 2; k + 10 < u.psd.size() && u.freq_Hz(k) < 4000.0; k += 10) {
      worst = std::max(worst, std::abs(10.0 * std::log10(t.psd.segment(k, 10).sum() / u.psd.segment(k, 10).sum())));
    }
    EXPECT_LT(worst, 3.0) << ch;
  }
  EXPECT_TRUE(b.de_noise.measured);
  EXPECT_TRUE(b.vs_noise.measured);
}

TEST(Twin, IffOptimumWithinFivePercentOfTheUnits) {
  const TwinBuild& b = build();
  const auto [truth, damping] = bench_iff_optimum(held_out().unit, held_out().options, control::IffControllerParams{});
  EXPECT_LT(std::abs(b.iff_optimal_gain / truth - 1.0), 0.05) << "twin " << b.iff_optimal_gain << ", unit " << truth;
  EXPECT_GT(damping, 0.1);
  EXPECT_EQ(b.quality.verdict, core::FitVerdict::kGood) << b.quality.summary();
}

// The dotted results key of a declaration ("frf_error.de") as a JSON pointer ("/frf_error/de").
nlohmann::json::json_pointer pointer_of(std::string key) {
  for (char& c : key) {
    if (c == '.') c = '/';
  }
  return nlohmann::json::json_pointer("/" + key);
}

using test::declared_keys;
using test::keys_of;

TEST(Twin, BuildJsonKeysComeFromTheDeclarations) {
  const TwinBuild& b = build();
  const nlohmann::json j = io::results_object(b);  // what `twin --json` prints besides "file" and "model"
  std::set<std::string> top;
  core::for_each_field<TwinBuild>([&](const auto& f) {
    if (!f.in(core::kResults)) return;
    const std::string key = core::results_key(f);
    if (key == ".") {
      for (const std::string& k : declared_keys<core::FitQuality>()) top.insert(k);
    } else {
      EXPECT_TRUE(j.contains(pointer_of(key))) << key;
      top.insert(key.substr(0, key.find('.')));
    }
  });
  EXPECT_EQ(keys_of(j), top);
  EXPECT_EQ(top, (std::set<std::string>{"unit", "name", "chain", "frf_error", "frf_error_tuned", "hysteresis", "hysteresis_thresholds_V",
                                        "hysteresis_weights", "creep", "noise", "iff", "notes", "seconds", "quality", "quality_problems",
                                        "quality_advice", "quality_impossible"}));
  // Every declared TwinFrfError field under each of the four errors, and nothing else.
  const std::set<std::string> frf_keys = declared_keys<TwinFrfError>();
  EXPECT_EQ(frf_keys, (std::set<std::string>{"points", "max_dB", "median_dB"}));
  for (const char* e : {"/frf_error/de", "/frf_error/Vs", "/frf_error_tuned/de", "/frf_error_tuned/Vs"}) {
    EXPECT_EQ(keys_of(j.at(nlohmann::json::json_pointer(e))), frf_keys) << e;
  }
  EXPECT_EQ(j["frf_error"]["Vs"]["points"].get<long>(), b.vs.points);
  EXPECT_EQ(j["frf_error_tuned"]["de"]["max_dB"].get<double>(), b.de_tuned.max_dB);
  // noise: the two channels in a list, each with TwinNoise's declared keys (its spectrum is part.json's).
  ASSERT_EQ(j["noise"].size(), 2U);
  EXPECT_EQ(keys_of(j["noise"][0]), declared_keys<TwinNoise>());
  EXPECT_EQ(keys_of(j["noise"][1]), (std::set<std::string>{"channel", "measured", "source", "seconds", "measured_rms", "white_rms"}));
  EXPECT_EQ(j["noise"][1]["channel"], "Vs");
  EXPECT_EQ(j["noise"][1]["white_rms"].get<double>(), b.vs_noise.white_rms);
  ASSERT_EQ(j["hysteresis"].size(), b.hysteresis.size());
  EXPECT_EQ(keys_of(j["hysteresis"][0]), (std::set<std::string>{"amplitude_V", "unit_width", "twin_width"}));
  EXPECT_EQ(j["hysteresis"][0]["amplitude_V"].get<double>(), b.hysteresis[0].amplitude);
  // The units shown are SI (factor 1): the values are the build's, bit for bit.
  EXPECT_EQ(j["iff"]["optimal_gain"].get<double>(), b.iff_optimal_gain);
  EXPECT_EQ(j["chain"]["delay_s"].get<double>(), b.twin.options.delay);
  EXPECT_EQ(j["creep"]["load_per_decade"].get<double>(), b.twin.unit.load_creep_coefficient);
  EXPECT_EQ(j["unit"], 9);
  EXPECT_EQ(j["name"], "APA 9");
}

TEST(Twin, FileRoundTripAndTheRecordsItMakes) {
  const TwinBuild& b = build();
  const fs::path file = held_out().dir.path() / "twin.toml";
  bench::write_twin(file, b.twin);
  const bench::Twin t = bench::read_twin(file);
  EXPECT_NEAR(t.unit.model.k1, b.twin.unit.model.k1, 1e-9 * b.twin.unit.model.k1);
  EXPECT_NEAR(t.options.delay, b.twin.options.delay, 1e-9 * b.twin.options.delay);
  EXPECT_EQ(t.unit.hysteresis_weights.size(), bench::kMaxPlayOperators);
  EXPECT_EQ(t.name, "APA 9");
  // The same bench from the file as built (10 significant digits in the file).
  const VectorXd f = VectorXd::LinSpaced(50, 10.0, 1000.0);
  const dsp::Frf a = bench_frf(t.unit, t.options, f), c = bench_frf(b.twin.unit, b.twin.options, f);
  for (std::size_t o = 0; o < 2; ++o) EXPECT_LT(((a.H[o] - c.H[o]).array() / c.H[o].array()).abs().maxCoeff(), 1e-7);
}

}  // namespace
}  // namespace piezobench::campaign
