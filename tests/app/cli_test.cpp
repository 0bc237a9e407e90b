// End-to-end tests of the piezobench command, run as a subprocess like a user or script would.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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
    // --json: stdout holds one document, the error's.
    const auto e = nlohmann::json::parse(r.out);
    EXPECT_EQ(e["error"]["kind"], "input") << r.out;
    EXPECT_EQ(e["error"]["exit_code"], 3);
    EXPECT_EQ(e["error"]["source"], f);
    EXPECT_EQ(e["error"]["field"].get<std::string>().rfind(c.needle, 0), 0u) << r.out;
  }
  const Outcome gains = run_cli("iff rlocus --gains 1,abc");
  EXPECT_EQ(gains.exit_code, 2);  // a bad command-line value is a usage error
  EXPECT_NE(gains.err.find("--gains"), std::string::npos);
}

// Issue 33: an unknown option names the nearest one; limits print as people write them.
TEST(Cli, UnknownOptionSuggestsTheNearestAndRangesAreReadable) {
  const Outcome typo = run_cli("iff rlocus --gain 1,2");
  EXPECT_EQ(typo.exit_code, 2);
  EXPECT_NE(typo.err.find("did you mean --gains (instead of --gain)?"), std::string::npos) << typo.err;
  const Outcome far = run_cli("iff rlocus --zzzzzzzz");
  EXPECT_EQ(far.exit_code, 2);
  EXPECT_EQ(far.err.find("did you mean"), std::string::npos) << far.err;
  test::TempDir dir;
  const std::string csv = test::write_text_file(dir, "x.csv", "t,u,y\n0,0,0\n1,1,1\n");
  const Outcome negative = run_cli("frf " + csv + " --input u --output y --nfft -1");
  EXPECT_EQ(negative.exit_code, 2);
  EXPECT_NE(negative.err.find("expected a number >= 0, found '-1'"), std::string::npos) << negative.err;
  EXPECT_LT(negative.err.size(), 400u) << negative.err;  // no 309-digit limit
  const Outcome work = run_cli("iff rlocus --max-work 5");
  EXPECT_NE(work.err.find("expected a number in [1000, 1e+15], found '5'"), std::string::npos) << work.err;
}

// A missing input file is exit 3 in every command, named with the same message.
TEST(Cli, MissingInputFileIsExitThreeEverywhere) {
  test::TempDir dir;
  const std::string none = (dir.path() / "none.file").string();
  for (const std::string& command :
       {"frf " + none + " --input u --output y", "fit " + none + " --order 2", "fit iff-plant " + none, "iff rlocus --plant " + none,
        "model tune --frf " + none, "model 2dof --params " + none, "superelement " + none + " " + none + " " + none,
        "run " + none, "hysteresis fit " + none}) {
    const Outcome r = run_cli(command + " --json");
    EXPECT_EQ(r.exit_code, 3) << command << ": " << r.err;
    EXPECT_NE(r.err.find(none), std::string::npos) << command << ": " << r.err;
    const auto e = nlohmann::json::parse(r.out.empty() ? "{}" : r.out);
    EXPECT_EQ(e["error"]["exit_code"], 3) << command << ": " << r.out;
  }
}

// `iff rlocus` prints a summary with units: the gain of maximum damping and where the loop goes
// unstable; the table only in the JSON document (--json, --out).
TEST(Cli, RlocusSummaryAndTableOnlyInJson) {
  test::TempDir dir;
  const Outcome text = run_cli("iff rlocus --gains 0,1e4,1e5,1e6,1e7,1e8");
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("maximum damping: gain g = "), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("rad/s"), std::string::npos) << text.out;
  EXPECT_TRUE(text.out.find("unstable from gain g = ") != std::string::npos ||
              text.out.find("stable at every gain computed (g = 0 to 1e+08)") != std::string::npos)
      << text.out;
  EXPECT_LT(std::count(text.out.begin(), text.out.end(), '\n'), 8) << text.out;
  const std::string out = (dir.path() / "locus.json").string();
  const Outcome file = run_cli("iff rlocus --gains 0,1e4,1e5,1e6,1e7,1e8 --out " + out);
  ASSERT_EQ(file.exit_code, 0) << file.err;
  std::ifstream in(out);
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["gains"].size(), 6u);
  EXPECT_EQ(j["poles"].size(), 6u);
  // The loop's poles at the reported unstable gain have one in the right half plane, none before.
  if (!j["unstable_from_gain"].is_null()) {
    const double g = j["unstable_from_gain"].get<double>();
    for (std::size_t i = 0; i < j["gains"].size(); ++i) {
      bool rhp = false;
      for (const auto& p : j["poles"][i]) rhp = rhp || p[0].get<double>() > 1e-9 * std::max(1.0, std::hypot(p[0].get<double>(), p[1].get<double>()));
      EXPECT_EQ(rhp, j["gains"][i].get<double>() >= g) << i;
    }
  }
}

}  // namespace
}  // namespace piezobench
