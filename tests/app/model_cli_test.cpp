// End-to-end tests of `piezobench model 2dof`, `piezobench model tune` and `piezobench piezo`, run
// as a subprocess like a user or script would.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <complex>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "run_cli.hpp"
#include "test_util.hpp"
#include "piezobench/apa/piezo.hpp"
#include "piezobench/apa/two_dof.hpp"
#include "piezobench/core/fields.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench {
namespace {

using Complex = std::complex<double>;
using test::near;

using Outcome = test::CliRun;
using test::run_cli;

Complex cx(const nlohmann::json& j) { return {j[0].get<double>(), j[1].get<double>()}; }

TEST(ModelCli, Help) {
  const Outcome h = run_cli("--help");
  EXPECT_EQ(h.exit_code, 0);
  EXPECT_NE(h.out.find("model"), std::string::npos);
  EXPECT_NE(h.out.find("piezo"), std::string::npos);
  for (const char* cmd : {"model 2dof --help", "model tune --help", "piezo --help"}) {
    EXPECT_EQ(run_cli(cmd).exit_code, 0) << cmd;
  }
  EXPECT_EQ(run_cli("model").exit_code, 2);
  EXPECT_EQ(run_cli("model tune --json").exit_code, 2);  // --frf is required
}

TEST(ModelCli, TwoDofJsonHasTheReferenceNumbers) {
  const Outcome r = run_cli("model 2dof --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  // REFERENCE.md derived checks, within 0.5 % (issue 4).
  EXPECT_TRUE(near(j["static_gain_de_um_per_V"].get<double>(), -16.81, 0.005));
  EXPECT_TRUE(near(j["static_gain_Vs_V_per_V"].get<double>(), 0.588, 0.005));
  EXPECT_TRUE(near(j["resonance_Hz"].get<double>(), 95.37, 0.005));
  EXPECT_TRUE(near(j["antiresonance_Hz"].get<double>(), 41.09, 0.005));
  EXPECT_EQ(j["poles"].size(), 3U);
  EXPECT_EQ(j["zeros_Vs"].size(), 2U);
  // The zeros of u -> Vs are those of m s^2 + c1 s + k1 (Table 3.1).
  EXPECT_TRUE(near(std::abs(cx(j["zeros_Vs"][0])), std::sqrt(0.38e6 / 5.7), 1e-9));
  const auto& f = j["freq_Hz"];
  ASSERT_EQ(f.size(), 500U);
  ASSERT_EQ(j["H_de"].size(), 500U);
  ASSERT_EQ(j["H_Vs"].size(), 500U);
  EXPECT_TRUE(near(f[0].get<double>(), 1.0, 1e-12));
  EXPECT_TRUE(near(f[499].get<double>(), 1e4, 1e-12));
  // At 1 Hz the response is the static gain to within (1 Hz / 95 Hz)^2 ~ 1e-4.
  EXPECT_TRUE(near(cx(j["H_de"][0]).real() * 1e6, j["static_gain_de_um_per_V"].get<double>(), 1e-3));
  EXPECT_TRUE(near(cx(j["H_Vs"][0]).real(), j["static_gain_Vs_V_per_V"].get<double>(), 1e-3));
}

TEST(ModelCli, TwoDofOptionsAndParamsFile) {
  test::TempDir dir;
  const std::string params = test::write_text_file(dir, "p.toml", "m = 5.7\nk1 = 0.5e6\nga = -3\n");
  const Outcome r = run_cli("model 2dof --json --params " + params + " --fmin 10 --fmax 1000 --points 11 --amplifier-gain 10");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(near(j["antiresonance_Hz"].get<double>(), std::sqrt(0.5e6 / 5.7) / kTwoPi, 1e-9));
  const double ktot = 0.5e6 + 5e6 * 2.5e6 / 7.5e6;
  EXPECT_TRUE(near(j["static_gain_de_um_per_V"].get<double>(), 1e6 * 10 * -3.0 * (2.0 / 3.0) / ktot, 1e-9));
  EXPECT_EQ(j["freq_Hz"].size(), 11U);
  EXPECT_EQ(j["params"]["k1"].get<double>(), 0.5e6);

  // High-pass and delay: one more pole at -1/(R C), Vs blocked at DC, |H| unchanged by the delay.
  const Outcome h = run_cli("model 2dof --json --hpf-r 80.6e3 --hpf-c 5e-6 --delay 200e-6 --points 5");
  ASSERT_EQ(h.exit_code, 0) << h.err;
  const auto jh = nlohmann::json::parse(h.out);
  EXPECT_EQ(jh["poles"].size(), 4U);
  EXPECT_EQ(jh["static_gain_Vs_V_per_V"].get<double>(), 0.0);
  EXPECT_TRUE(near(jh["static_gain_Vs_before_hpf_V_per_V"].get<double>(), 0.588, 0.005));
  EXPECT_TRUE(near(jh["bench"]["hpf_corner_Hz"].get<double>(), 0.395, 0.002));
  const Outcome plain = run_cli("model 2dof --json --points 5");
  const auto jp = nlohmann::json::parse(plain.out);
  for (std::size_t k = 0; k < 5; ++k) {
    EXPECT_TRUE(near(std::abs(cx(jh["H_de"][k])), std::abs(cx(jp["H_de"][k])), 1e-12));
  }

  const Outcome text = run_cli("model 2dof");
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("resonance"), std::string::npos);
  EXPECT_NE(text.out.find("-16.81"), std::string::npos) << text.out;
}

TEST(ModelCli, BadParamsExitWithThreeAndNameTheKey) {
  test::TempDir dir;
  const struct {
    const char* text;
    const char* needle;
  } cases[] = {
      {"m = 5.7\nkk = 1.0\n", "line 2: kk"},
      {"k1 = \"stiff\"\n", "line 1: k1"},
      {"m = -1.0\n", "m"},
      {"m = [1.0\n", "line"},
  };
  for (const auto& c : cases) {
    const std::string f = test::write_text_file(dir, "bad.toml", c.text);
    const Outcome r = run_cli("model 2dof --json --params " + f);
    EXPECT_EQ(r.exit_code, 3) << c.text << r.err;
    EXPECT_NE(r.err.find(f + ": " + c.needle), std::string::npos) << r.err;
    EXPECT_TRUE(test::no_result(r)) << r.out;
  }
  EXPECT_EQ(run_cli("model 2dof --fmin 0").exit_code, 2);  // the command line is at fault
  EXPECT_EQ(run_cli("model 2dof --fmin 100 --fmax 10").exit_code, 2);
  EXPECT_EQ(run_cli("model 2dof --hpf-r 1e3").exit_code, 3);
  EXPECT_EQ(run_cli("model 2dof --amplifier-gain 0").exit_code, 3);
  EXPECT_EQ(run_cli("model 2dof --points 1").exit_code, 2);
}

// FRF CSV of a 2-DoF actuator (direct solve of the dynamic stiffness), input u through 20 V/V,
// 1 % complex noise.
std::string frf_csv(double k1, double ke, double ka, double ce, double ca, double ga, double gs, double noise) {
  const double m = 5.7, c1 = 6.0, G = 20.0;
  std::mt19937 rng(5);
  std::normal_distribution<double> gauss(0.0, noise / std::sqrt(2.0));
  std::ostringstream os;
  os.precision(17);
  os << "freq_Hz,re_de,im_de,re_Vs,im_Vs\n";
  const int n = 500;
  for (int k = 0; k < n; ++k) {
    const double f = std::pow(10.0, std::log10(2000.0) * k / (n - 1));
    const Complex s(0.0, kTwoPi * f);
    const Complex z1 = k1 + c1 * s, ze = ke + ce * s, za = ka + ca * s;
    // [m s^2 + Z1 + Ze, -Ze; -Ze, Ze + Za] [x; xn] = [0; ga G]
    const Complex a = m * s * s + z1 + ze, det = a * (ze + za) - ze * ze;
    const Complex x = ze * ga * G / det, xn = a * ga * G / det;
    const Complex de = x * Complex(1.0 + gauss(rng), gauss(rng));
    const Complex vs = gs * (x - xn) * Complex(1.0 + gauss(rng), gauss(rng));
    os << f << ',' << de.real() << ',' << de.imag() << ',' << vs.real() << ',' << vs.imag() << '\n';
  }
  return os.str();
}

TEST(ModelCli, TuneRecoversTheParameters) {
  test::TempDir dir;
  const double k1 = 0.42e6, ke = 5.6e6, ka = 2.8e6, ce = 90.0, ca = 55.0, ga = -2.9, gs = 0.5e6;
  const std::string f = test::write_text_file(dir, "frf.csv", frf_csv(k1, ke, ka, ce, ca, ga, gs, 0.01));
  const Outcome r = run_cli("model tune --frf " + f + " --mass 5.7 --json");
  const auto j = nlohmann::json::parse(r.out);
  const auto& p = j["model_2dof"];
  for (const char* key : {"m", "k1", "c1", "ke", "ce", "ka", "ca", "ga", "gs"}) ASSERT_TRUE(p.contains(key)) << key;
  // Issue 4: stiffnesses and gains within 2 %. With `run`'s procedure (issue 12: the delays from
  // the plant fits, the IFF plant's delay also absorbing the node relaxation that eq. 2.3 lacks)
  // the dampings are not recovered on these chain-free data (ce / ca = 1.6, not the imposed 2):
  // issue 30 reports them undetermined, and the verdict is then poor (exit 6), never a confident
  // wrong value.
  (void)ce;
  (void)ca;
  for (const auto& name : j["undetermined"]) {
    EXPECT_TRUE(name == "c1" || name == "ce" || name == "ca") << name;
  }
  EXPECT_EQ(r.exit_code, j["undetermined"].empty() ? 0 : 6) << r.err;
  EXPECT_TRUE(j["uncertainty"].contains("standard_errors"));
  EXPECT_TRUE(near(p["k1"].get<double>(), k1, 0.02));
  EXPECT_TRUE(near(p["ke"].get<double>(), ke, 0.02));
  EXPECT_TRUE(near(p["ka"].get<double>(), ka, 0.02));
  EXPECT_TRUE(near(p["ga"].get<double>(), ga, 0.02));
  EXPECT_TRUE(near(p["gs"].get<double>(), gs, 0.02));
  EXPECT_EQ(p["m"].get<double>(), 5.7);
  EXPECT_LT(j["fit_error_de"].get<double>(), 0.03);
  EXPECT_LT(j["fit_error_vs"].get<double>(), 0.03);
  // The declared keys (results.json's model_2dof_fit spelling), not a hand list.
  EXPECT_TRUE(j["features"].contains("static_gain_vs_V_per_V"));
  EXPECT_FALSE(j["features"].contains("static_gain_Vs_V_per_V"));
  EXPECT_TRUE(j["initial"].contains("k1_N_per_um"));
  EXPECT_EQ(j["status"].get<std::string>(), "converged");
  EXPECT_EQ(j["quality"], j["undetermined"].empty() ? "good" : "poor");

  // The amplifier gain scales ga: data through 20 V/V read as 10 V/V give twice the force per volt.
  const Outcome half = run_cli("model tune --frf " + f + " --amplifier-gain 10 --json");
  ASSERT_NE(half.exit_code, 3) << half.err;
  EXPECT_TRUE(near(nlohmann::json::parse(half.out)["model_2dof"]["ga"].get<double>(), 2.0 * ga, 0.02));

  const Outcome text = run_cli("model tune --frf " + f);
  EXPECT_EQ(text.exit_code, r.exit_code) << text.err;
  EXPECT_NE(text.out.find("converged"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("relative standard errors"), std::string::npos) << text.out;
}

// Issue 33: an FRF in um/V (stated in the header, or given by --units) gives the same ga as in
// SI; a file that says nothing is read as SI with a warning.
TEST(ModelCli, TuneHonoursTheUnitsOfTheFrf) {
  test::TempDir dir;
  const double k1 = 0.42e6, ke = 5.6e6, ka = 2.8e6, ce = 90.0, ca = 55.0, ga = -2.9, gs = 0.5e6;
  std::istringstream si(frf_csv(k1, ke, ka, ce, ca, ga, gs, 0.01));
  std::ostringstream um;
  um.precision(17);
  std::string line;
  std::getline(si, line);
  um << "freq_Hz,re_de [um/V],im_de [um/V],re_Vs [V/V],im_Vs [V/V]\n";
  std::ostringstream bare;
  bare.precision(17);
  bare << "freq_Hz,re_de,im_de,re_Vs,im_Vs\n";
  while (std::getline(si, line)) {
    std::vector<double> v;
    std::istringstream cells(line);
    for (std::string c; std::getline(cells, c, ',');) v.push_back(std::stod(c));
    um << v[0] << ',' << v[1] * 1e6 << ',' << v[2] * 1e6 << ',' << v[3] << ',' << v[4] << '\n';
    bare << v[0] << ',' << v[1] * 1e6 << ',' << v[2] * 1e6 << ',' << v[3] << ',' << v[4] << '\n';
  }
  const std::string stated = test::write_text_file(dir, "frf_um.csv", um.str());
  const std::string unstated = test::write_text_file(dir, "frf_bare.csv", bare.str());
  for (const std::string& args : {"--frf " + stated, "--frf " + unstated + " --units de=um"}) {
    const Outcome r = run_cli("model tune " + args + " --mass 5.7 --json");
    ASSERT_EQ(r.exit_code, 0) << args << r.err;
    EXPECT_TRUE(near(nlohmann::json::parse(r.out)["model_2dof"]["ga"].get<double>(), ga, 0.02)) << args << r.out;
  }
  const Outcome warned = run_cli("model tune --frf " + unstated + " --mass 5.7 --json");
  EXPECT_NE(warned.err.find("warning: " + unstated + ": output de has no unit: H taken as SI"), std::string::npos) << warned.err;
  EXPECT_EQ(nlohmann::json::parse(warned.out)["warnings"].size(), 2u);  // de and Vs
  EXPECT_EQ(run_cli("model tune --frf " + unstated + " --units d=um").exit_code, 3);   // names no channel
  const test::CliRun furlong = run_cli("model tune --frf " + unstated + " --units de=furlong");
  EXPECT_EQ(furlong.exit_code, 2);
  // The option is named once ("--units: expected ..."), not twice.
  EXPECT_NE(furlong.err.find("--units: expected a unit of the table"), std::string::npos) << furlong.err;
  EXPECT_EQ(furlong.err.find("--units: --units"), std::string::npos) << furlong.err;
}

TEST(ModelCli, TuneBadInputExitsWithThree) {
  test::TempDir dir;
  const std::string no_vs = test::write_text_file(dir, "novs.csv", "freq_Hz,re_de,im_de\n1,1,0\n2,1,0\n");
  const Outcome r = run_cli("model tune --frf " + no_vs + " --json");
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("Vs"), std::string::npos) << r.err;
  EXPECT_TRUE(test::no_result(r));
  const std::string good = test::write_text_file(dir, "frf.csv", frf_csv(0.4e6, 5e6, 2.5e6, 100, 50, -2.5, 0.46e6, 0.0));
  EXPECT_EQ(run_cli("model tune --frf " + good + " --mass -1").exit_code, 3);
  EXPECT_EQ(run_cli("model tune --frf " + good + " --fmin 500 --fmax 501").exit_code, 3);
}

// Issue 12: a Welch FRF made by a lab's scipy script (coherence columns, whole band, the bench's
// high-pass and 200 us delay in the data): with only --mass, the campaign's procedure (band from
// the coherence, delay and high-pass from the plant fits) finds the parameters of the simulation.
TEST(ModelCli, TuneOnAScipyWelchFrfWithOnlyTheMass) {
  const std::string f = test::fixture_path("ident/two_dof_welch_frf.csv").string();
  const auto truth = nlohmann::json::parse(test::read_text(test::fixture_path("ident/two_dof_welch_truth.json")));
  const Outcome r = run_cli("model tune --frf " + f + " --mass 5.7 --json");
  const auto j = nlohmann::json::parse(r.out);
  const auto& p = j["model_2dof"];
  for (const char* key : {"k1", "ke", "ka", "ga", "gs"}) {
    EXPECT_TRUE(near(p[key].get<double>(), truth[key].get<double>(), 0.03)) << key << " " << p[key] << " vs " << truth[key];
  }
  // The shell's damping c1 does not show in this FRF: the refinement drives it towards 0, and it is
  // reported undetermined (issue 30), so the verdict is poor and the exit code 6.
  EXPECT_EQ(j["undetermined"], nlohmann::json::array({"c1"}));
  EXPECT_EQ(j["quality"], "poor");
  EXPECT_EQ(r.exit_code, 6) << r.err;
  EXPECT_TRUE(near(j["chain"]["delay_s"].get<double>(), truth["effective_delay_s"].get<double>(), 0.05));
  EXPECT_TRUE(near(j["chain"]["hpf_corner_Hz"].get<double>(), 0.39, 0.1));
}

// A tuning whose result is not physical or does not fit is never reported as a plain success.
TEST(ModelCli, PoorTuningWarnsAndExitsWithSix) {
  const std::string f = test::fixture_path("ident/two_dof_welch_frf.csv").string();
  // A delay given on the command line replaces the fitted one: 2 ms instead of 0.25 ms leaves no
  // model that fits.
  const Outcome r = run_cli("model tune --frf " + f + " --mass 5.7 --delay 0.002 --json");
  EXPECT_EQ(r.exit_code, 6) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["quality"], "poor");
  EXPECT_FALSE(j["quality_problems"].empty());
  EXPECT_NE(r.err.find("warning: the fit is poor"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("Try:"), std::string::npos) << r.err;
}

TEST(ModelCli, PiezoTable41) {
  const Outcome r = run_cli("piezo --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(near(j["ga_N_per_V"].get<double>(), 26.11, 0.002));
  EXPECT_TRUE(near(j["gs_V_per_m"].get<double>(), 5.06e6, 0.002));
  EXPECT_TRUE(near(j["ka_N_per_m"].get<double>(), 2.4e8, 1e-12));
  // Explicit values: the same Table 4.1 spelled out.
  const Outcome e = run_cli("piezo --json --d33 680e-12 --eps-t 4.0e-8 --s-d 21e-12 --c-e 48e9 --length 0.02 --area 1e-4 --layers 160");
  ASSERT_EQ(e.exit_code, 0) << e.err;
  EXPECT_EQ(nlohmann::json::parse(e.out)["ga_N_per_V"].get<double>(), j["ga_N_per_V"].get<double>());
  const Outcome text = run_cli("piezo");
  ASSERT_EQ(text.exit_code, 0);
  EXPECT_NE(text.out.find("26.11"), std::string::npos) << text.out;

  for (const char* bad : {"--layers 0", "--layers 160.5", "--d33 -1", "--area 0"}) {
    const Outcome b = run_cli(std::string("piezo --json ") + bad);
    EXPECT_EQ(b.exit_code, 3) << bad << b.err;
    EXPECT_TRUE(test::no_result(b));
  }
  EXPECT_NE(run_cli("piezo --layers 160.5").err.find("layers"), std::string::npos);
}

// The commands' numbers are their structs' declared fields (issue 32): every field of
// apa::TwoDofCharacteristics and apa::PiezoSensitivities is in the JSON under its results key, in its
// shown unit, equal to the library's value.
TEST(ModelCli, JsonKeysComeFromTheDeclarations) {
  const Outcome r = run_cli("model 2dof --json --points 3");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const apa::TwoDofCharacteristics c = apa::characterize(apa::TwoDofParams{}, apa::TwoDofBench{});
  int numbers = 0;
  core::for_each_field<apa::TwoDofCharacteristics>([&](const auto& f) {
    const std::string key = core::results_key(f);
    ASSERT_TRUE(j.contains(key)) << key;
    if constexpr (std::is_same_v<std::remove_cvref_t<decltype(f.of(c))>, double>) {
      EXPECT_NEAR(j[key].get<double>(), f.of(c) * f.shown.per_si, 1e-12 * std::abs(f.of(c) * f.shown.per_si)) << key;
      ++numbers;
    } else {
      EXPECT_EQ(j[key].size(), static_cast<std::size_t>(f.of(c).size())) << key;
    }
  });
  EXPECT_EQ(numbers, 7);
  EXPECT_TRUE(near(j["resonance_Hz"].get<double>(), 95.37, 1e-3));  // report Table 3.1's model

  const Outcome p = run_cli("piezo --json");
  ASSERT_EQ(p.exit_code, 0) << p.err;
  const auto jp = nlohmann::json::parse(p.out);
  const apa::PiezoSensitivities s = apa::piezo_sensitivities(apa::PiezoConstants{});
  core::for_each_field<apa::PiezoSensitivities>([&](const auto& f) {
    const std::string key = core::results_key(f);
    ASSERT_TRUE(jp.contains(key)) << key;
    EXPECT_DOUBLE_EQ(jp[key].get<double>(), f.of(s)) << key;
  });
  EXPECT_TRUE(jp.contains("ka_N_per_m") && jp.contains("ga_N_per_V") && jp.contains("gs_V_per_m"));
}

}  // namespace
}  // namespace piezobench
