// End-to-end tests of `piezobench frf` and `piezobench fit`.
#include <gtest/gtest.h>

#include <complex>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "piezobench/core/fields.hpp"
#include "piezobench/dsp/frf.hpp"
#include "run_cli.hpp"
#include "test_util.hpp"

namespace piezobench {
namespace {

using test::run_cli;

std::complex<double> pair(const nlohmann::json& j) { return {j[0].get<double>(), j[1].get<double>()}; }

TEST(FrfCli, MatFileMadeByScipyGivesScipysH1AndCoherence) {
  const std::string mat = test::fixture_path("io/scipy_two_outputs.mat").string();
  const test::CliRun r = run_cli("frf " + mat + " --input u_dac --output d_enc,V_force --nfft 512 --overlap 0.5 --detrend none --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto got = nlohmann::json::parse(r.out);
  const auto ref = nlohmann::json::parse(test::read_text(test::fixture_path("app/scipy_two_outputs_frf.json")));
  ASSERT_EQ(got["freq_Hz"].size(), ref["freq_Hz"].size());
  EXPECT_EQ(got["window"]["name"], "hann-periodic");
  EXPECT_EQ(got["averages"], 15);  // (4096 - 512) / 256 + 1
  for (std::size_t k = 0; k < ref["freq_Hz"].size(); ++k) {
    EXPECT_TRUE(test::near(got["freq_Hz"][k].get<double>(), ref["freq_Hz"][k].get<double>(), {1e-12, 0.0}));
  }
  for (const char* name : {"d_enc", "V_force"}) {
    const auto& g = got["outputs"][name];
    const auto& e = ref["outputs"][name];
    for (std::size_t k = 0; k < e["H"].size(); ++k) {
      ASSERT_TRUE(test::near(pair(g["H"][k]), pair(e["H"][k]), {1e-9, 0.0})) << name << " bin " << k;
      ASSERT_TRUE(test::near(g["coherence"][k].get<double>(), e["coherence"][k].get<double>(), {1e-9, 0.0}))
          << name << " bin " << k;
    }
  }
}

// `frf --json`: Welch's settings are dsp::FrfProvenance's results fields under their declared keys
// (the window as an object with its name and length); the rest is what the command names itself.
TEST(FrfCli, JsonKeysOfTheProvenanceComeFromItsDeclaration) {
  const std::string mat = test::fixture_path("io/scipy_two_outputs.mat").string();
  const test::CliRun r = run_cli("frf " + mat + " --input u_dac --output d_enc --nfft 512 --overlap 0.5 --detrend none --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  std::set<std::string> declared;
  core::for_each_field<dsp::FrfProvenance>([&](const auto& f) {
    if (f.in(core::kResults)) declared.insert(core::results_key(f));
  });
  EXPECT_EQ(declared, (std::set<std::string>{"estimator", "window", "nfft", "overlap", "detrend", "averages"}));
  std::set<std::string> keys;
  for (const auto& [k, v] : j.items()) keys.insert(k);
  std::set<std::string> own = {"source", "input", "freq_Hz", "effective_averages", "sample_rate_Hz", "outputs", "H_units", "warnings"};
  std::set<std::string> expected = declared;
  expected.insert(own.begin(), own.end());
  EXPECT_EQ(keys, expected);
  EXPECT_EQ(j["estimator"], "H1");
  EXPECT_EQ(j["nfft"], 512);
  EXPECT_EQ(j["overlap"], 0.5);
  EXPECT_EQ(j["detrend"], "none");
  EXPECT_EQ(j["averages"], 15);  // (4096 - 512) / 256 + 1
  EXPECT_EQ(j["window"]["name"], "hann-periodic");
  EXPECT_EQ(j["window"]["length"], 512);
  EXPECT_EQ(j["window"]["periodic"], true);
}

TEST(FrfCli, WritesTheFrfThatFitReadsBack) {
  test::TempDir dir;
  const std::string mat = test::fixture_path("io/scipy_two_outputs.mat").string();
  const std::string csv = (dir.path() / "frf.csv").string();
  const test::CliRun r = run_cli("frf " + mat + " --input u_dac --output d_enc --nfft 512 --out " + csv);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(test::read_text(csv).substr(0, 35), "freq_Hz,re_d_enc,im_d_enc,coh_d_enc");
  // The file's d_enc is a 95 Hz mode with 2 % damping: the fitted pole sits at 95 Hz within the
  // 3.9 Hz resolution of the estimate, and the Hann window's leakage at that resolution widens the
  // peak, so the damping comes out above the true 2 % but well below 5 %.
  const std::string model = (dir.path() / "model.json").string();
  const test::CliRun f = run_cli("fit " + csv + " --order 2 --fmin 20 --fmax 400 --out " + model + " --json");
  ASSERT_EQ(f.exit_code, 0) << f.err;
  const auto j = nlohmann::json::parse(f.out);
  ASSERT_EQ(j["poles_rad_per_s"].size(), 2U);
  const auto p = pair(j["poles_rad_per_s"][1]);
  EXPECT_NEAR(std::abs(p) / (2 * std::numbers::pi), 95.0, 2.0);
  EXPECT_GT(-p.real() / std::abs(p), 0.02);
  EXPECT_LT(-p.real() / std::abs(p), 0.05);
  // 15 averages of a 4096-sample record with leakage at the peak: the estimate itself is rough.
  EXPECT_LT(j["relative_rms_error"].get<double>(), 0.25);
  EXPECT_EQ(nlohmann::json::parse(test::read_text(model)), j);
}

TEST(FitCli, RecoversKnownPolesFromAnExactFrf) {
  // H(s) = sum of three lightly damped modes (0.4 %, 1 %, 5 %), written as an FRF CSV.
  test::TempDir dir;
  const std::complex<double> poles[] = {{-0.004 * 2 * M_PI * 40, 2 * M_PI * 40 * std::sqrt(1 - 0.004 * 0.004)},
                                        {-0.01 * 2 * M_PI * 95, 2 * M_PI * 95 * std::sqrt(1 - 1e-4)},
                                        {-0.05 * 2 * M_PI * 400, 2 * M_PI * 400 * std::sqrt(1 - 0.0025)}};
  const std::complex<double> residues[] = {{1.0, 2.0}, {-3.0, 0.5}, {10.0, -4.0}};
  std::ostringstream csv;
  csv.precision(17);
  csv << "freq_Hz,re_y,im_y\n";
  for (int k = 0; k < 400; ++k) {
    const double f = 10.0 * std::pow(100.0, k / 399.0);
    const std::complex<double> s(0.0, 2 * M_PI * f);
    std::complex<double> h = 0.0;
    for (int i = 0; i < 3; ++i) h += residues[i] / (s - poles[i]) + std::conj(residues[i]) / (s - std::conj(poles[i]));
    csv << f << "," << h.real() << "," << h.imag() << "\n";
  }
  const std::string file = test::write_text_file(dir, "exact.csv", csv.str());
  const test::CliRun r = run_cli("fit " + file + " --order 6 --asymptote none --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["poles_rad_per_s"].size(), 6U);
  for (const auto& expected : poles) {
    double best = 1e300;
    for (const auto& q : j["poles_rad_per_s"]) best = std::min(best, std::abs(pair(q) - expected) / std::abs(expected));
    EXPECT_LT(best, 1e-6) << expected;
  }
}

// Issue 33: UFF58 time histories in, scipy's H1 out; every file of the record in other units and
// time stamps gives the same FRF in SI (scripts/fixtures/make_io_units_fixtures.py).
TEST(FrfCli, UffTimeHistoriesAndFilesInOtherUnitsGiveScipysH1) {
  const auto ref = nlohmann::json::parse(test::read_text(test::fixture_path("io/units/expected.json")));
  for (const char* name : {"th_multi_ascii.uff", "th_multi_58b.uff", "v5_units_cell_pairs.mat", "h5_group_attr_map.mat",
                           "h5_root_attr_map.mat", "v73_units_cell_pairs.mat", "time_ms3.csv", "time_float32.csv"}) {
    SCOPED_TRACE(name);
    const std::string file = test::fixture_path(std::string("io/units/") + name).string();
    const test::CliRun r = run_cli("frf " + file + " --input u --output d_e,Vs --nfft 512 --overlap 0.5 --detrend none --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto got = nlohmann::json::parse(r.out);
    EXPECT_EQ(got["H_units"]["d_e"], "m/V");
    EXPECT_TRUE(got["warnings"].empty()) << got["warnings"];
    const bool csv = std::string(name).find(".csv") != std::string::npos;
    const auto& want = ref[csv ? "H_d_e_csv" : "H_d_e"];
    // Within 1e-12 of the peak |H| (ASCII UFF, 13 digits: 1e-9); the smallest bins lose relative digits.
    const bool ascii = std::string(name).find("ascii") != std::string::npos;
    double peak = 0.0;
    for (std::size_t k = 0; k < ref["freq_Hz"].size(); ++k) {
      peak = std::max(peak, std::abs(std::complex<double>(want["re"][k].get<double>(), want["im"][k].get<double>())));
    }
    for (std::size_t k = 1; k < ref["freq_Hz"].size(); ++k) {
      const std::complex<double> h(want["re"][k].get<double>(), want["im"][k].get<double>());
      ASSERT_TRUE(test::near(pair(got["outputs"]["d_e"]["H"][k]), h, {0.0, (ascii ? 1e-9 : 1e-12) * peak})) << "bin " << k;
    }
  }
  // --units overrides, --fs overrides the stamps: warnings on stderr and in --json.
  const std::string f6 = test::fixture_path("io/units/time_f6.csv").string();
  const test::CliRun r = run_cli("frf " + f6 + " --input u --output d_e --units d_e=mm --fs 2000 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto got = nlohmann::json::parse(r.out);
  ASSERT_EQ(got["warnings"].size(), 2u);
  EXPECT_NE(got["warnings"][0].get<std::string>().find("unit 'mm' from --units replaces 'um'"), std::string::npos);
  EXPECT_NE(got["warnings"][1].get<std::string>().find("--fs 2000 Hz overrides the time vector's 2048 Hz"), std::string::npos);
  EXPECT_NE(r.err.find("warning: " + f6 + ": --fs 2000 Hz"), std::string::npos) << r.err;
  EXPECT_EQ(run_cli("frf " + f6 + " --input u --output d_e --units de=mm").exit_code, 3);
  const test::CliRun jitter = run_cli("frf " + test::fixture_path("io/units/time_jitter_5.csv").string() + " --input u --output d_e");
  EXPECT_EQ(jitter.exit_code, 3);
  EXPECT_NE(jitter.err.find("time_jitter_5.csv: t: expected uniform sampling"), std::string::npos) << jitter.err;
}

TEST(FrfCli, BadInputNamesFileAndChannel) {
  test::TempDir dir;
  const std::string mat = test::fixture_path("io/scipy_two_outputs.mat").string();
  const test::CliRun unknown = run_cli("frf " + mat + " --input u_dac --output nope --json");
  EXPECT_EQ(unknown.exit_code, 3);
  EXPECT_NE(unknown.err.find("nope"), std::string::npos) << unknown.err;
  EXPECT_NE(unknown.err.find("scipy_two_outputs.mat"), std::string::npos) << unknown.err;
  EXPECT_TRUE(test::no_result(unknown));

  const std::string out = (dir.path() / "frf.csv").string();
  const test::CliRun too_short = run_cli("frf " + mat + " --input u_dac --output d_enc --nfft 100000 --out " + out);
  EXPECT_EQ(too_short.exit_code, 3) << too_short.err;
  EXPECT_FALSE(std::filesystem::exists(out));  // no partial output

  const std::string nan_csv = test::write_text_file(dir, "nan.csv", "t,u,y\n0,1,2\n0.001,nan,3\n0.002,1,2\n");
  const test::CliRun with_nan = run_cli("frf " + nan_csv + " --input u --output y --nfft 2");
  EXPECT_EQ(with_nan.exit_code, 3);
  EXPECT_NE(with_nan.err.find("u"), std::string::npos);

  const std::string flat = test::write_text_file(dir, "zero.csv", "t,u,y\n0,0,1\n0.001,0,2\n0.002,0,3\n0.003,0,1\n");
  const test::CliRun zero_power = run_cli("frf " + flat + " --input u --output y --nfft 2");
  EXPECT_EQ(zero_power.exit_code, 3) << zero_power.err;

}

// Issue 12: `fit --order 2` on both outputs of a lab's Welch FRF (d_e in m/V, Vs in V/V: 1e5 apart)
// finds the resonance within 1 %: each output is weighted by its own scale.
TEST(FitCli, BothOutputsOfAScipyWelchFrfGiveTheResonance) {
  const std::string f = test::fixture_path("ident/two_dof_welch_frf.csv").string();
  const auto truth = nlohmann::json::parse(test::read_text(test::fixture_path("ident/two_dof_welch_truth.json")));
  const test::CliRun r = run_cli("fit " + f + " --order 2 --fmin 20 --fmax 400 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["poles_rad_per_s"].size(), 2U);
  const auto p = pair(j["poles_rad_per_s"][1]);
  EXPECT_NEAR(std::abs(p) / (2 * std::numbers::pi) / truth["resonance_Hz"].get<double>(), 1.0, 0.01);
  EXPECT_EQ(j["quality"], "good");
  for (const char* name : {"de", "Vs"}) EXPECT_LT(j["per_output"][name]["relative_rms_error"].get<double>(), 0.2) << name;
  // At order 6 the model has the anti-resonance of Vs: a lightly damped zero pair at sqrt(k1 / m),
  // reported with a verdict on its phase.
  const test::CliRun six = run_cli("fit " + f + " --order 6 --fmin 20 --fmax 400 --json");
  const auto j6 = nlohmann::json::parse(six.out);
  bool found = false;
  for (const auto& z : j6["per_output"]["Vs"]["zeros"]) {
    if (!z["lightly_damped"].get<bool>() || std::abs(z["frequency_Hz"].get<double>() - 41.0) > 5.0) continue;
    found = true;
    EXPECT_NEAR(z["frequency_Hz"].get<double>() / truth["antiresonance_Hz"].get<double>(), 1.0, 0.01);
    EXPECT_TRUE(z["nonminimum_phase"].is_boolean());
    // Its standard errors (docs/uncertainty.md, section 5; no std_H in this file: the noise comes from
    // the residuals): 41.08 +- 0.55 Hz, and a damping of -0.022 +- 0.012 whose 95 % interval holds 0,
    // the truth's side being undecided by these data (equal weights gave +-0.0086, a confident wrong sign).
    const double se = z["frequency_se_Hz"].get<double>(), damping_se = z["damping_se"].get<double>();
    EXPECT_GT(se, 0.0);
    EXPECT_LT(std::abs(z["frequency_Hz"].get<double>() - truth["antiresonance_Hz"].get<double>()), 3.0 * se);
    const double damping = -z["zero"][0].get<double>() / (2.0 * std::numbers::pi * z["frequency_Hz"].get<double>());
    EXPECT_LT(damping - 1.96 * damping_se, 0.0);
    EXPECT_GT(damping + 1.96 * damping_se, 0.0);
  }
  EXPECT_EQ(j6["uncertainty_from_data_variance"], false);
  EXPECT_EQ(j6["pole_uncertainty"].size(), j6["poles_rad_per_s"].size());
  EXPECT_TRUE(found) << six.out;
  const test::CliRun text = run_cli("fit " + f + " --order 6 --fmin 20 --fmax 400");
  EXPECT_NE(text.out.find("minimum phase"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("standard errors from the residuals' noise"), std::string::npos) << text.out;
  // This file has no std columns: weighting by them is refused, naming the file and the output.
  const test::CliRun by_std = run_cli("fit " + f + " --order 6 --fmin 20 --fmax 400 --weighting inverse-std");
  EXPECT_EQ(by_std.exit_code, 3) << by_std.err;
  EXPECT_NE(by_std.err.find("two_dof_welch_frf.csv"), std::string::npos) << by_std.err;
  EXPECT_NE(by_std.err.find("std_H of de"), std::string::npos) << by_std.err;
}

// A fit over a band the input did not excite is poor: warning, "quality": "poor", exit 6.
TEST(FitCli, UnexcitedBandIsAPoorFit) {
  const std::string f = test::fixture_path("ident/two_dof_welch_frf.csv").string();
  const test::CliRun r = run_cli("fit " + f + " --output de --order 2 --fmin 700 --fmax 800 --json");
  EXPECT_EQ(r.exit_code, 6) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["quality"], "poor");
  EXPECT_NE(r.err.find("warning: the fit is poor"), std::string::npos) << r.err;
}

// `fit iff-plant` writes the TOML that `iff rlocus --plant` reads.
TEST(FitCli, IffPlantTomlFeedsTheRootLocus) {
  test::TempDir dir;
  const std::string f = test::fixture_path("ident/two_dof_welch_frf.csv").string();
  const auto truth = nlohmann::json::parse(test::read_text(test::fixture_path("ident/two_dof_welch_truth.json")));
  const std::string toml = (dir.path() / "plant.toml").string();
  const test::CliRun r = run_cli("fit iff-plant " + f + " --fmax 500 --out " + toml + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["quality"], "good");
  EXPECT_NEAR(j["plant"]["wp_Hz"].get<double>() / truth["resonance_Hz"].get<double>(), 1.0, 0.01);
  EXPECT_NEAR(j["plant"]["wz_Hz"].get<double>() / truth["antiresonance_Hz"].get<double>(), 1.0, 0.01);
  const test::CliRun rl = run_cli("iff rlocus --plant " + toml + " --json");
  ASSERT_EQ(rl.exit_code, 0) << rl.err;
  const auto l = nlohmann::json::parse(rl.out);
  EXPECT_NEAR(std::abs(pair(l["resonance_pole"])) / (2 * std::numbers::pi) / truth["resonance_Hz"].get<double>(), 1.0, 0.01);
  EXPECT_GT(l["max_damping"].get<double>(), 0.05);
}

// Issue 33: g0 is in the unit of H the file states (converted to SI), never V/V whatever the file:
// the same FRF with H_Vs in mV/V (values x 1000) gives the same g0, dimensionless; without units
// the summary says that SI was assumed.
TEST(FitCli, IffPlantG0InTheUnitTheFileStates) {
  test::TempDir dir;
  const std::string f = test::fixture_path("ident/two_dof_welch_frf.csv").string();
  std::istringstream in(test::read_text(f));
  std::ostringstream scaled;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (line.rfind("freq_Hz", 0) == 0) {
      scaled << "freq_Hz,re_de [m/V],im_de [m/V],coh_de,re_Vs [mV/V],im_Vs [mV/V],coh_Vs\n";
      continue;
    }
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string c; std::getline(row, c, ',');) cells.push_back(c);
    ASSERT_EQ(cells.size(), 7u) << line;
    for (const std::size_t k : {std::size_t{4}, std::size_t{5}}) {
      char buf[40];
      std::snprintf(buf, sizeof buf, "%.17g", 1e3 * std::stod(cells[k]));
      cells[k] = buf;
    }
    for (std::size_t k = 0; k < cells.size(); ++k) scaled << (k ? "," : "") << cells[k];
    scaled << "\n";
  }
  const std::string mv = test::write_text_file(dir, "mV_per_V.csv", scaled.str());
  const test::CliRun si = run_cli("fit iff-plant " + f + " --fmax 500 --json");
  const test::CliRun milli = run_cli("fit iff-plant " + mv + " --fmax 500 --json");
  ASSERT_EQ(si.exit_code, 0) << si.err;
  ASSERT_EQ(milli.exit_code, 0) << milli.err;
  const auto a = nlohmann::json::parse(si.out), b = nlohmann::json::parse(milli.out);
  EXPECT_TRUE(a["plant"]["g0_unit"].is_null());
  EXPECT_EQ(b["plant"]["g0_unit"], "1");
  EXPECT_NEAR(b["plant"]["g0"].get<double>() / a["plant"]["g0"].get<double>(), 1.0, 1e-6);
  const test::CliRun text = run_cli("fit iff-plant " + mv + " --fmax 500");
  EXPECT_NE(text.out.find(" (dimensionless: output and input in one unit), wz"), std::string::npos) << text.out;
  const test::CliRun bare = run_cli("fit iff-plant " + f + " --fmax 500");
  EXPECT_NE(bare.out.find(" (H's unit, not stated in the file: SI assumed), wz"), std::string::npos) << bare.out;
  EXPECT_EQ(bare.out.find("V/V"), std::string::npos) << bare.out;
}

// Other programs' window names are accepted; a bad option is exit 2 before any computation.
TEST(FrfCli, MatlabWindowNamesAndBadOptionsBeforeWork) {
  const std::string mat = test::fixture_path("io/scipy_two_outputs.mat").string();
  for (const char* w : {"hanning", "hann", "Hamming", "flattopwin"}) {
    EXPECT_EQ(run_cli("frf " + mat + " --input u_dac --output d_enc --window " + w + " --json").exit_code, 0) << w;
  }
  const test::CliRun xlsx = run_cli("frf " + mat + " --input u_dac --output d_enc --out x.xlsx");
  EXPECT_EQ(xlsx.exit_code, 2) << xlsx.err;
  EXPECT_NE(xlsx.err.find(".csv"), std::string::npos) << xlsx.err;
  EXPECT_EQ(xlsx.err.find("reading"), std::string::npos) << xlsx.err;  // refused before reading the file
  EXPECT_EQ(run_cli("frf " + mat + " --input u_dac --output d_enc --window triangle").exit_code, 2);
  EXPECT_EQ(run_cli("frf " + mat + " --input u_dac --output d_enc --detrend quadratic").exit_code, 2);
  EXPECT_EQ(run_cli("fit " + mat + " --order 2 --out model.txt").exit_code, 2);
  EXPECT_EQ(run_cli("fit iff-plant " + mat + " --out plant.json").exit_code, 2);
}

// `frf` without --nfft uses `run`'s settings: segments of 4 s at most a quarter of the record,
// mean removed (scipy's default detrending).
TEST(FrfCli, DefaultsAreTheCampaigns) {
  const std::string mat = test::fixture_path("io/scipy_two_outputs.mat").string();
  const test::CliRun r = run_cli("frf " + mat + " --input u_dac --output d_enc --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["nfft"], 1024);  // 4096 samples / 4 (4 s would be 8000)
  EXPECT_EQ(j["detrend"], "mean");
}

TEST(FitCli, TooHighAnOrderIsAClearError) {
  test::TempDir dir;
  const std::string file = test::write_text_file(dir, "few.csv", "freq_Hz,re_y,im_y\n1,1,0\n2,0.5,-0.5\n3,0.2,-0.4\n");
  const test::CliRun r = run_cli("fit " + file + " --order 6 --json");
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("poles"), std::string::npos) << r.err;
  EXPECT_TRUE(test::no_result(r));
}

// Issue 12: files as labs have them (scripts/fixtures/make_io_lab_fixtures.py: DAQ CSV in ms, um
// and mV with tabs and decimal commas, ';' CSV in mm, blank-separated CSV, v7.3 from MATLAB's
// layout, h5py and hdf5storage): `frf` gives scipy's H1 in SI units.
TEST(FrfCli, LabFilesGiveScipysH1InSi) {
  const auto ref = nlohmann::json::parse(test::read_text(test::fixture_path("io/lab/expected.json")));
  const std::pair<const char*, double> files[] = {
      {"daq_tab_decimal_comma.csv", 1e-5}, {"semicolon_mm.csv", 1e-5}, {"blanks_us.csv", 1e-5},  // 10 digits
      {"v73_matlab.mat", 1e-9},           {"v73_h5py.mat", 1e-9},     {"v73_hdf5storage.mat", 1e-9}};
  for (const auto& [name, tol] : files) {
    SCOPED_TRACE(name);
    const std::string file = test::fixture_path(std::string("io/lab/") + name).string();
    const test::CliRun r =
        run_cli("frf " + file + " --input u --output d_e,Vs --nfft 512 --overlap 0.5 --window hann --detrend none --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto got = nlohmann::json::parse(r.out);
    ASSERT_EQ(got["freq_Hz"].size(), ref["freq_Hz"].size());
    for (const char* out : {"d_e", "Vs"}) {
      const auto& g = got["outputs"][out];
      const auto& e = ref["outputs"][out];
      // Relative to the largest |H|: bins of tiny response carry the rounding of the files' 10 digits.
      double scale = 0.0;
      for (const auto& h : e["H"]) scale = std::max(scale, std::abs(pair(h)));
      for (std::size_t k = 0; k < e["H"].size(); ++k) {
        ASSERT_TRUE(test::near(pair(g["H"][k]), pair(e["H"][k]), {tol, tol * scale})) << out << " bin " << k;
      }
    }
  }
  const test::CliRun r = run_cli("frf " + test::fixture_path("io/lab/daq_tab_decimal_comma.csv").string() +
                                 " --input u --output d_e,Vs --nfft 512 --json --delimiter tab --decimal ,");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["H_units"]["d_e"], "m/V");
  // A wrong forced dialect is an input error that names it; an unknown spelling a usage error.
  const test::CliRun bad = run_cli("frf " + test::fixture_path("io/lab/semicolon_mm.csv").string() +
                                   " --input u --output d_e --fs 2000 --delimiter tab");
  EXPECT_EQ(bad.exit_code, 3);
  EXPECT_TRUE(test::contains(bad.err, "tab-separated")) << bad.err;
  EXPECT_EQ(run_cli("frf " + test::fixture_path("io/lab/semicolon_mm.csv").string() + " --input u --output d_e --delimiter pipe").exit_code, 2);
}

// Issue 35: a record whose input excited nothing (independent noise on u and y: coherence ~0)
// exited 3 without --json and 0 with it, and with --out the file was written before the exit 3.
// Now one outcome, one exit code, whatever the output flags; nothing is written.
TEST(FrfCli, TheExitCodeOfALowCoherenceRecordDoesNotDependOnTheOutputFlags) {
  test::TempDir dir;
  std::string csv = "t,u,y\n";
  std::uint64_t state = 12345;
  const auto noise = [&state] {  // a 64-bit LCG: two independent-looking sequences
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) * 0x1p-53 - 0.5;
  };
  for (int k = 0; k < 8192; ++k) {
    const double u = noise(), y = noise();
    csv += std::to_string(k * 1e-3) + "," + std::to_string(u) + "," + std::to_string(y) + "\n";
  }
  const std::string record = test::write_text_file(dir, "noise.csv", csv);
  const std::string out = (dir.path() / "frf.csv").string();
  for (const std::string& flags : std::vector<std::string>{"", " --json", " --out " + out, " --json --out " + out}) {
    const test::CliRun r = run_cli("frf " + record + " --input u --output y --nfft 256" + flags);
    EXPECT_EQ(r.exit_code, 3) << flags << ": " << r.err;
    EXPECT_TRUE(test::contains(r.err, "the input excites the outputs")) << flags << ": " << r.err;
    EXPECT_TRUE(test::no_result(r)) << flags << ": " << r.out;
    EXPECT_FALSE(std::filesystem::exists(out)) << flags;
  }
}

}  // namespace
}  // namespace piezobench
