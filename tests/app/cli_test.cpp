// End-to-end tests of the piezobench command, run as a subprocess like a user or script would.
#include <gtest/gtest.h>

#include <complex>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "run_cli.hpp"
#include "test_util.hpp"

namespace piezobench {
namespace {

using test::run_cli;
using Outcome = test::CliRun;

TEST(Cli, VersionAndHelp) {
  const Outcome v = run_cli("--version");
  EXPECT_EQ(v.exit_code, 0);
  EXPECT_NE(v.out.find("piezobench 0."), std::string::npos) << v.out;
  const Outcome h = run_cli("--help");
  EXPECT_EQ(h.exit_code, 0);
  EXPECT_NE(h.out.find("iff"), std::string::npos);
  const Outcome hr = run_cli("iff rlocus --help");
  EXPECT_EQ(hr.exit_code, 0);
  EXPECT_NE(hr.out.find("--gains"), std::string::npos);
}

TEST(Cli, BadCommandLineExitsWithTwo) {
  EXPECT_EQ(run_cli("").exit_code, 2);
  EXPECT_EQ(run_cli("no-such-command").exit_code, 2);
  EXPECT_EQ(run_cli("iff rlocus --no-such-option").exit_code, 2);
  EXPECT_EQ(run_cli("iff rlocus --pade-order 0").exit_code, 2);
}

TEST(Cli, RlocusJsonHasTheContractKeys) {
  const Outcome r = run_cli("iff rlocus --gains 0,1000,10000,100000,1000000 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["gains"].size(), 5U);
  ASSERT_EQ(j["poles"].size(), 5U);
  EXPECT_EQ(j["poles"][0].size(), 6U);  // 3 plant states + 3 controller states
  EXPECT_NEAR(j["max_damping"].get<double>(), 0.40, 0.02);
  EXPECT_GT(j["optimal_gain"].get<double>(), 0.0);
  // At g = 0 the resonance branch sits on the plant's 95.2 Hz pole.
  const auto p0 = j["resonance_branch"][0];
  EXPECT_NEAR(std::abs(std::complex<double>(p0[0].get<double>(), p0[1].get<double>())) / (2 * M_PI), 95.2, 1e-9);
}

TEST(Cli, RlocusReadsPlantAndControllerFiles) {
  test::TempDir dir;
  // The report's plant written as a zpk is the default plant: the same optimum must come out.
  const double wz = 2 * M_PI * 42.7, wp = 2 * M_PI * 95.2, xz = 0.004, xp = 0.02, wh = 2 * M_PI * 0.4, g0 = 0.64;
  std::ostringstream tf;
  tf.precision(17);
  // G = g0 (s^2/wz^2 + 2 xz s/wz + 1) s / ((s^2/wp^2 + 2 xp s/wp + 1)(s + wh))
  tf << "num = [" << g0 / (wz * wz) << ", " << g0 * 2 * xz / wz << ", " << g0 << ", 0.0]\n"
     << "den = [" << 1 / (wp * wp) << ", " << 2 * xp / wp + wh / (wp * wp) << ", " << 1 + wh * 2 * xp / wp << ", " << wh << "]\n";
  const std::string tf_file = test::write_text_file(dir, "plant_tf.toml", tf.str());
  const std::string k_file = test::write_text_file(dir, "k.toml",
      "zeros = [0.0]\npoles = [-12.566370614359172, -125.66370614359172, -12566.370614359172]\ngain = -10.0\n");
  const Outcome a = run_cli("iff rlocus --json --gains 1e4");
  const Outcome b = run_cli("iff rlocus --json --gains 1e4 --plant " + tf_file + " --controller " + k_file);
  ASSERT_EQ(a.exit_code, 0) << a.err;
  ASSERT_EQ(b.exit_code, 0) << b.err;
  const auto ja = nlohmann::json::parse(a.out);
  const auto jb = nlohmann::json::parse(b.out);
  EXPECT_NEAR(jb["max_damping"].get<double>(), ja["max_damping"].get<double>(), 1e-8);
  EXPECT_NEAR(jb["optimal_gain"].get<double>() / ja["optimal_gain"].get<double>(), 1.0, 1e-6);
}

TEST(Cli, BadPlantFilesExitWithThreeAndNameTheField) {
  test::TempDir dir;
  const struct {
    const char* text;
    const char* needle;
  } cases[] = {
      {"num = [1.0\n", "line"},
      {"num = [1.0]\nden = [0.0, 1.0]\n", "den"},
      {"num = [1.0, 1.0, 1.0]\nden = [1.0, 1.0]\n", "num"},
      {"A = [[1.0, 0.0]]\nB = [[1.0]]\nC = [[1.0]]\n", "A"},
  };
  for (const auto& c : cases) {
    const std::string f = test::write_text_file(dir, "bad.toml", c.text);
    const Outcome r = run_cli("iff rlocus --json --plant " + f);
    EXPECT_EQ(r.exit_code, 3) << c.text << r.err;
    EXPECT_NE(r.err.find(f + ": " + c.needle), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
  const Outcome gains = run_cli("iff rlocus --gains 1,abc");
  EXPECT_EQ(gains.exit_code, 2);  // a bad command-line value is a usage error
  EXPECT_NE(gains.err.find("--gains"), std::string::npos);
}

}  // namespace
}  // namespace piezobench
