#include "piezobench/campaign/campaign_file.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "test_util.hpp"

namespace piezobench::campaign {
namespace {

namespace fs = std::filesystem;
using test::contains;

// A folder with empty measurement files named in the campaigns below (parse_campaign only checks
// that they exist).
struct Folder {
  test::TempDir dir;
  Folder() {
    fs::create_directories(dir.path() / "data");
    for (const char* f : {"data/a_stroke.csv", "data/a_frf.mat", "data/a_iff1.mat", "data/a_iff2.mat", "data/b_frf.mat",
                          "data/b_cap.csv", "data/h1.mat", "data/h2.mat"}) {
      std::ofstream(dir.path() / f) << "x";
    }
  }
  Campaign parse(const std::string& text) const { return parse_campaign(text, dir.path() / "campaign.toml"); }
  std::string error(const std::string& text, const std::string& field) const {
    return test::input_error([&] { (void)parse(text); }, field);
  }
};

const char* kComplete = R"(
title = "APA300ML batch"
[bench]
amplifier_gain = 20.0
suspended_mass_kg = 5.7
added_mass_kg = 6.4
gravity_m_per_s2 = 9.81
hpf_resistance_ohm = 80.6e3
probe_accuracy_um = 0.5
[specs]
flatness_um = 25.0
flatness_method = "minimum-zone"
capacitance_sensor_uF = [4.0, 6.0]
capacitance_actuator_uF = [8.0, 12.0]
stroke_min_um = 200.0
stiffness_N_per_um = [1.5, 2.5]
outlier_threshold = 4.0
[analysis]
window = "hann-periodic"
nfft = 20000
fmin_Hz = 10.0
fmax_Hz = 400.0
iff_unit = 2
iff_controller = { gain = -12.0, hpf_Hz = 3.0 }
threads = 1
[channels]
de = "d_encoder"
[[units]]
id = 1
stroke = { file = "data/a_stroke.csv", channels = { Va = "V_stack", de = "probe" }, sample_rate_Hz = 1000.0 }
frf = "data/a_frf.mat"
[units.channels]
Vs = "V_sensor"
[[units]]
id = 2
name = "spare"
frf = "data/b_frf.mat"
capacitance = "data/b_cap.csv"
hysteresis = ["data/h1.mat", { file = "data/h2.mat", channels = { Va = "Va2" } }]
iff = [{ file = "data/a_iff1.mat", gain = 1e5 }, "data/a_iff2.mat"]
)";

TEST(CampaignFile, CompleteExample) {
  const Folder f;
  const Campaign c = f.parse(kComplete);
  EXPECT_EQ(c.title, "APA300ML batch");
  EXPECT_DOUBLE_EQ(c.bench.gravity, 9.81);
  EXPECT_DOUBLE_EQ(c.bench.probe_accuracy, 0.5e-6);
  ASSERT_TRUE(c.specs.flatness_max);
  EXPECT_DOUBLE_EQ(*c.specs.flatness_max, 25e-6);
  EXPECT_EQ(c.specs.flatness_method, metrology::FlatnessMethod::kMinimumZone);
  EXPECT_DOUBLE_EQ(c.specs.capacitance_sensor->min, 4e-6);
  EXPECT_DOUBLE_EQ(c.specs.stiffness->max, 2.5e6);
  EXPECT_DOUBLE_EQ(*c.specs.stroke_min, 200e-6);
  EXPECT_DOUBLE_EQ(c.specs.outliers.threshold, 4.0);
  EXPECT_EQ(c.analysis.nfft, 20000);
  EXPECT_DOUBLE_EQ(c.analysis.fmax_Hz, 400.0);
  EXPECT_DOUBLE_EQ(c.analysis.controller.gain, -12.0);
  EXPECT_NEAR(c.analysis.controller.w_hpf, 2 * M_PI * 3.0, 1e-12);
  EXPECT_NEAR(c.analysis.controller.w_lpf, 2 * M_PI * 20.0, 1e-12);  // default kept
  ASSERT_EQ(c.units.size(), 2u);
  const UnitSpec& a = c.units[0];
  EXPECT_EQ(a.name, "APA 1");
  // Paths are relative to the campaign's folder.
  EXPECT_EQ(a.stroke->path, f.dir.path() / "data/a_stroke.csv");
  EXPECT_DOUBLE_EQ(a.stroke->sample_rate, 1000.0);
  // Channel names: file entry > unit > campaign > the bench's name.
  EXPECT_EQ(a.stroke->channels.at("Va"), "V_stack");
  EXPECT_EQ(a.stroke->channels.at("de"), "probe");
  EXPECT_EQ(a.frf->channels.at("de"), "d_encoder");
  EXPECT_EQ(a.frf->channels.at("Vs"), "V_sensor");
  EXPECT_EQ(a.frf->channels.at("u"), "u");
  EXPECT_FALSE(a.has(Experiment::kStiffness));
  const UnitSpec& b = c.units[1];
  EXPECT_EQ(b.name, "spare");
  ASSERT_EQ(b.hysteresis.size(), 2u);
  EXPECT_EQ(b.hysteresis[1].channels.at("Va"), "Va2");
  EXPECT_EQ(b.hysteresis[1].key, "units[1].hysteresis[1]");
  ASSERT_EQ(b.iff.size(), 2u);
  EXPECT_DOUBLE_EQ(b.iff[0].gain, 1e5);
  EXPECT_DOUBLE_EQ(b.iff[1].gain, 0.0);  // from the file's settings
  EXPECT_TRUE(b.has(Experiment::kCapacitance));
}

TEST(CampaignFile, DefaultsAndTypedCapacitance) {
  const Folder f;
  const Campaign c = f.parse("[[units]]\nid = 4\ncapacitance_uF = { sensor = 5.1, actuator = 10.03 }\n");
  EXPECT_EQ(c.title, "APA characterization campaign");
  EXPECT_DOUBLE_EQ(c.bench.amplifier_gain, 20.0);
  EXPECT_FALSE(c.specs.flatness_max);
  EXPECT_DOUBLE_EQ(*c.units[0].capacitance_sensor, 5.1e-6);
  EXPECT_TRUE(c.units[0].has(Experiment::kCapacitance));
  EXPECT_FALSE(c.units[0].has(Experiment::kFrf));
}

TEST(CampaignFile, ChannelUnitsOfAFileEntry) {
  // Issue 12: the unit of a channel whose file says none, from the one unit table.
  const Folder f;
  const Campaign c = f.parse(
      "[[units]]\nid = 1\nstroke = { file = \"data/a_stroke.csv\", channels = { de = \"laser\" }, units = { de = \"um\", Va = \"V\" } }\n");
  EXPECT_EQ(c.units[0].stroke->units.at("de"), "um");
  EXPECT_EQ(c.units[0].stroke->units.at("Va"), "V");
  const std::string msg = f.error("[[units]]\nid = 1\nstroke = { file = \"data/a_stroke.csv\", units = { de = \"microns\" } }\n",
                                  "units[0].stroke.units.de");
  EXPECT_TRUE(contains(msg, "'microns'") && contains(msg, "nm, um, mm")) << msg;
}

TEST(CampaignFile, UnknownKeysNameFileAndKey) {
  const Folder f;
  const std::string top = f.error("titel = \"x\"\n[[units]]\nid = 1\n", "titel");
  EXPECT_TRUE(contains(top, "campaign.toml")) << top;
  EXPECT_TRUE(contains(top, "unknown key")) << top;
  f.error("[specs]\nflatnes_um = 3.0\n[[units]]\nid = 1\n", "specs.flatnes_um");
  f.error("[[units]]\nid = 1\nstrok = \"data/a_stroke.csv\"\n", "units[0].strok");
  f.error("[[units]]\nid = 1\nstroke = { file = \"data/a_stroke.csv\", chanels = {} }\n", "units[0].stroke.chanels");
  // A channel role that no experiment has, and a role of another experiment on a file entry.
  f.error("[channels]\nforce = \"F2\"\n[[units]]\nid = 1\n", "channels.force");
  f.error("[[units]]\nid = 1\nstroke = { file = \"data/a_stroke.csv\", channels = { Vs = \"x\" } }\n", "units[0].stroke.channels.Vs");
  f.error("[analysis]\niff_controller = { gain = -10.0, lpf = 3.0 }\n[[units]]\nid = 1\n", "analysis.iff_controller.lpf");
}

TEST(CampaignFile, MissingFilesAndDuplicateUnits) {
  const Folder f;
  // A unit's missing measurement file is read as given: that unit is then not analysed, the batch
  // goes on (pipeline.hpp, issue 33).
  const Campaign c = f.parse("[[units]]\nid = 1\nfrf = \"data/nope.mat\"\n");
  ASSERT_TRUE(c.units[0].frf);
  EXPECT_EQ(c.units[0].frf->given, "data/nope.mat");
  EXPECT_EQ(c.units[0].frf->path.filename(), "nope.mat");
  const std::string twice = f.error("[[units]]\nid = 2\n[[units]]\nid = 3\n[[units]]\nid = 2\n", "units[2].id");
  EXPECT_TRUE(contains(twice, "unit 2 listed twice")) << twice;
  EXPECT_TRUE(contains(twice, "units[0]")) << twice;
  f.error("title = \"no units\"\n", "units");
  f.error("[[units]]\nname = \"no id\"\n", "units[0].id");
  f.error("[analysis]\niff_unit = 9\n[[units]]\nid = 1\n", "analysis.iff_unit");
}

TEST(CampaignFile, BadValues) {
  const Folder f;
  f.error("[specs]\ncapacitance_sensor_uF = [6.0, 4.0]\n[[units]]\nid = 1\n", "specs.capacitance_sensor_uF");
  f.error("[specs]\nflatness_method = \"best-fit\"\n[[units]]\nid = 1\n", "specs.flatness_method");
  f.error("[specs]\nstroke_min_um = \"big\"\n[[units]]\nid = 1\n", "specs.stroke_min_um");
  f.error("[bench]\nsuspended_mass_kg = -5.7\n[[units]]\nid = 1\n", "bench.suspended_mass_kg");
  f.error("[bench]\namplifier_gain = nan\n[[units]]\nid = 1\n", "bench.amplifier_gain");
  f.error("[analysis]\nwindow = \"triangle\"\n[[units]]\nid = 1\n", "analysis.window");
  f.error("[analysis]\nfmin_Hz = 100.0\nfmax_Hz = 50.0\n[[units]]\nid = 1\n", "analysis.fmax_Hz");
  f.error("[analysis]\noverlap = 1.0\n[[units]]\nid = 1\n", "analysis.overlap");
  f.error("[[units]]\nid = 1\nstroke = 3\n", "units[0].stroke");
  f.error("[[units]]\nid = 1\nstroke = { channels = { de = \"x\" } }\n", "units[0].stroke.file");
  f.error("[[units]]\nid = 1\ncapacitance = \"data/b_cap.csv\"\ncapacitance_uF = { sensor = 1.0, actuator = 2.0 }\n",
          "units[0].capacitance_uF");
  f.error("[[units]]\nid = 1\ncapacitance_uF = { sensor = 1.0 }\n", "units[0].capacitance_uF.actuator");
  // Integers beyond their range, or floats where an integer is expected, are refused before any
  // conversion (issue 35: `id = 92233720368547758e07` was converted to int first, UB).
  const std::string huge = f.error("[[units]]\nid = 92233720368547758e07\n", "units[0].id");
  EXPECT_TRUE(contains(huge, "expected an integer, found")) << huge;
  const std::string big = f.error("[[units]]\nid = 9223372036854775807\n", "units[0].id");
  EXPECT_TRUE(contains(big, "expected an integer in 0 .. 1000000, found 9223372036854775807")) << big;
  f.error("[analysis]\niff_unit = 4294967297\n[[units]]\nid = 1\n", "analysis.iff_unit");
  f.error("[analysis]\nthreads = 1e300\n[[units]]\nid = 1\n", "analysis.threads");
  // TOML syntax: the line is named.
  const std::string syntax = test::input_error([&] { (void)f.parse("[[units]]\nid = = 1\n"); });
  EXPECT_TRUE(contains(syntax, "line 2")) << syntax;
  EXPECT_TRUE(contains(syntax, "valid TOML")) << syntax;
  // A header deeper than the TOML limits (issue 21.2: it overflowed the stack in toml++).
  std::string deep = "[a";
  for (int i = 0; i < 100000; ++i) deep += ".a";
  const std::string limit = test::input_error([&] { (void)f.parse(deep + "]\n"); }, "line 1");
  EXPECT_TRUE(contains(limit, "more than 64 parts")) << limit;
}

TEST(CampaignFile, ReadFromDisk) {
  const Folder f;
  std::ofstream(f.dir.path() / "campaign.toml") << kComplete;
  EXPECT_EQ(read_campaign(f.dir.path() / "campaign.toml").units.size(), 2u);
  test::input_error([&] { (void)read_campaign(f.dir.path() / "nope.toml"); }, "file");
}

// The documented example (docs/examples/campaign.toml) stays valid (its files are not in the
// repository: existence not checked).
TEST(CampaignFile, DocumentedExampleParses) {
  const fs::path file = fs::path(PIEZOBENCH_SOURCE_DIR) / "docs/examples/campaign.toml";
  const Campaign c = parse_campaign(test::read_text(file), file, /*check_files=*/false);
  ASSERT_EQ(c.units.size(), 2u);
  EXPECT_EQ(c.units[0].hysteresis.size(), 4u);
  EXPECT_EQ(c.units[0].iff.size(), 3u);
  EXPECT_EQ(c.units[0].frf->channels.at("Vs"), "V_force_sensor");
  EXPECT_EQ(c.units[0].frf->channels.at("de"), "d_e");
  EXPECT_EQ(c.units[0].hammer->channels.at("F"), "force");
  // The open-circuit stiffness test and u -> Vs without the resistor (report 2.2, 2.5).
  ASSERT_TRUE(c.units[0].stiffness_open && c.units[0].frf_no_resistor);
  EXPECT_EQ(c.units[0].frf_no_resistor->channels.at("Vs"), "V_force_sensor");
  EXPECT_EQ(c.units[0].stiffness_open->given, "apa1/added_mass_open.mat");
  EXPECT_TRUE(c.units[0].has(Experiment::kStiffnessOpen));
  EXPECT_FALSE(c.units[1].has(Experiment::kFrfNoResistor));
  EXPECT_EQ(c.analysis.iff_unit, 1);
  ASSERT_TRUE(c.superelement);
  EXPECT_EQ(c.superelement->setup.model.forces.at(0).to_string(), fem::ForcePair::parse("3:4:z", "").to_string());
  EXPECT_EQ(c.superelement->setup.model.outputs.at(1).node_b, 5);
  EXPECT_DOUBLE_EQ(c.superelement->modal_damping, 0.02);
}

TEST(CampaignFile, ExperimentNames) {
  for (const Experiment e : all_experiments()) EXPECT_EQ(experiment_from_string(to_string(e)), e);
  test::input_error([] { (void)experiment_from_string("frf-noise"); }, "experiment");
}

}  // namespace
}  // namespace piezobench::campaign
