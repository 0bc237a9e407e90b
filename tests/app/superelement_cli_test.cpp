// End-to-end tests of `piezobench superelement` on the Ansys APA95ML files (run as a subprocess).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <Eigen/Dense>
#include <algorithm>
#include <complex>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <set>
#include <unistd.h>

#include "run_cli.hpp"
#include "test_util.hpp"

#include "piezobench/core/eigen_solvers.hpp"

namespace piezobench {
namespace {

namespace fs = std::filesystem;
const fs::path kDir = fs::path(PIEZOBENCH_SHARED_DATA_DIR) / "apa95ml-ansys";
const std::string kFiles = (kDir / "piezo_amplified_K.txt").string() + " " + (kDir / "piezo_amplified_M.txt").string() + " " +
                           (kDir / "piezo_amplified.txt").string();
const std::string kCheck = " --fix 76429 --force 76430:76440:x --output 76423:y";

using Outcome = test::CliRun;
using test::run_cli;

std::vector<std::complex<double>> channel(const nlohmann::json& j, std::size_t index) {
  std::vector<std::complex<double>> h;
  for (const auto& v : j["H"][index]) h.emplace_back(v[0].get<double>(), v[1].get<double>());
  return h;
}

// Independent dense solution (own parsing, rows/columns deleted for the clamped node, FullPivLU).
std::vector<std::complex<double>> independent(const std::vector<double>& hz, double mass, std::vector<double>* modes) {
  const auto parse = [](const fs::path& file) {
    const std::string text = test::read_text(file);
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(108, 108);
    for (std::size_t p = text.find('['); p != std::string::npos; p = text.find('[', p + 1)) {
      int i = 0, j = 0;
      double v = 0;
      if (std::sscanf(text.c_str() + p, "[ %d , %d ] : %lf", &i, &j, &v) == 3) A(i - 1, j - 1) = v;
    }
    return A;
  };
  const Eigen::MatrixXd K0 = parse(kDir / "piezo_amplified_K.txt");
  Eigen::MatrixXd M0 = parse(kDir / "piezo_amplified_M.txt");
  std::map<std::pair<long, std::string>, int> index;
  std::ifstream in(kDir / "piezo_amplified.txt");
  std::string line;
  int row = 0;
  while (std::getline(in, line)) {
    long node = 0;
    char label[16], extra[16];
    if (std::sscanf(line.c_str(), "%ld %15s %15s", &node, label, extra) == 2) index[{node, label}] = row++;
  }
  for (const char* l : {"UX", "UY", "UZ"}) M0(index.at({76423, l}), index.at({76423, l})) += mass;
  std::set<int> fixed;
  for (const char* l : {"UX", "UY", "UZ", "ROTX", "ROTY", "ROTZ"}) fixed.insert(index.at({76429, l}));
  std::vector<int> keep;
  for (int i = 0; i < 108; ++i)
    if (!fixed.count(i)) keep.push_back(i);
  const int n = static_cast<int>(keep.size());
  Eigen::MatrixXd K(n, n), M(n, n);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) K(a, b) = K0(keep[a], keep[b]), M(a, b) = M0(keep[a], keep[b]);
  const auto pos = [&](long node, const char* l) {
    return static_cast<int>(std::find(keep.begin(), keep.end(), index.at({node, l})) - keep.begin());
  };
  Eigen::VectorXcd F = Eigen::VectorXcd::Zero(n);
  F(pos(76440, "UX")) = 1.0;
  F(pos(76430, "UX")) = -1.0;
  std::vector<std::complex<double>> h;
  for (double f : hz) {
    const double w = 2 * std::numbers::pi * f;
    h.push_back(Eigen::FullPivLU<Eigen::MatrixXcd>((K - w * w * M).cast<std::complex<double>>()).solve(F)(pos(76423, "UY")));
  }
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(K, M, Eigen::EigenvaluesOnly);
  for (Eigen::Index i = 0; i < es.eigenvalues().size(); ++i) modes->push_back(std::sqrt(std::abs(es.eigenvalues()(i))) / (2 * std::numbers::pi));
  return h;
}

TEST(SuperElementCli, TenKilogramsMatchAnIndependentDenseSolution) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys");
  const Outcome r = run_cli("superelement " + kFiles + kCheck + " --mass 76423:10 --fmin 10 --fmax 10000 --points 120 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* key : {"modes_Hz", "freq_Hz", "H", "warnings", "channels"}) EXPECT_TRUE(j.contains(key)) << key;
  const auto hz = j["freq_Hz"].get<std::vector<double>>();
  ASSERT_EQ(hz.size(), 120U);
  ASSERT_EQ(j["H"].size(), 1U);
  EXPECT_EQ(j["channels"][0]["output"], "76423:y");
  const auto h = channel(j, 0);
  std::vector<double> modes;
  const auto expected = independent(hz, 10.0, &modes);
  int compared = 0;
  for (std::size_t k = 0; k < hz.size(); ++k) {
    double nearest = 1e300;
    for (double m : modes) nearest = std::min(nearest, std::abs(m - hz[k]));
    if (nearest < 0.02 * hz[k]) continue;
    ++compared;
    EXPECT_TRUE(test::near<std::complex<double>>(h[k], expected[k], {1e-6, 0})) << hz[k] << " Hz";
  }
  EXPECT_GT(compared, 90);
  const auto m = j["modes_Hz"].get<std::vector<double>>();
  ASSERT_EQ(m.size(), 102U);
  for (std::size_t i = 0; i < 10; ++i) EXPECT_TRUE(test::near(m[i], modes[i], 1e-9)) << i;
  // The precision warning of the Ansys file.
  ASSERT_FALSE(j["warnings"].empty());
  EXPECT_NE(j["warnings"][0].get<std::string>().find("rigid-body"), std::string::npos);
}

TEST(SuperElementCli, MedianErrorAgainstAnsysIsUnderOneDecibel) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys");
  const Outcome r = run_cli("superelement " + kFiles + kCheck + " --fmin 1009 --fmax 10000 --points 1000 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const auto hz = j["freq_Hz"].get<std::vector<double>>();
  const auto h = channel(j, 0);
  // Ansys's response, linearly interpolated in frequency onto our log grid.
  std::vector<double> f, a;
  std::ifstream in(kDir / "FEA-Response-Top.txt");
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    int i = 0;
    double fr = 0, am = 0, ph = 0;
    if (std::sscanf(line.c_str(), "%d,%lf,%lf,%lf", &i, &fr, &am, &ph) == 4) f.push_back(fr), a.push_back(am);
  }
  ASSERT_EQ(f.size(), 1000U);
  std::vector<double> err;
  for (std::size_t k = 0; k < hz.size(); ++k) {
    const auto it = std::upper_bound(f.begin(), f.end(), hz[k]);
    if (it == f.begin() || it == f.end()) continue;
    const std::size_t i = static_cast<std::size_t>(it - f.begin());
    const double t = (hz[k] - f[i - 1]) / (f[i] - f[i - 1]);
    const double ansys = a[i - 1] + t * (a[i] - a[i - 1]);
    err.push_back(std::abs(20 * std::log10(std::abs(h[k]) / ansys)));
  }
  ASSERT_GT(err.size(), 900U);
  std::nth_element(err.begin(), err.begin() + static_cast<std::ptrdiff_t>(err.size() / 2), err.end());
  EXPECT_LT(err[err.size() / 2], 1.0);
}

TEST(SuperElementCli, TextOutputAndHelp) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys");
  const Outcome r = run_cli("superelement " + kFiles + kCheck + " --points 20");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("modes [Hz]"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
  const Outcome h = run_cli("superelement --help");
  EXPECT_EQ(h.exit_code, 0);
  EXPECT_NE(h.out.find("--force"), std::string::npos);
  EXPECT_EQ(run_cli("superelement").exit_code, 2);  // positional files missing
}

TEST(SuperElementCli, BadInputExitsWithThreeAndSaysWhat) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys");
  test::TempDir dir;
  const std::string k = test::read_text(kDir / "piezo_amplified_K.txt");
  const std::string m_file = (kDir / "piezo_amplified_M.txt").string();
  const std::string l_file = (kDir / "piezo_amplified.txt").string();
  const auto write = [&](const std::string& name, const std::string& text) {
    const auto p = dir.path() / name;
    std::ofstream(p) << text;
    return p.string();
  };
  struct Case {
    std::string args;
    std::vector<std::string> needles;
  };
  std::string asym = k;
  asym.replace(asym.find("[  2,  1]: 2.568e+04"), 20, "[  2,  1]: 9.999e+04");
  const std::string truncated = write("truncated_K.txt", k.substr(0, k.size() / 3));
  const std::string asymmetric = write("asymmetric_K.txt", asym);
  std::string listing = test::read_text(kDir / "piezo_amplified.txt");
  listing.replace(listing.find("   76440 UX  \n"), 14, "");
  const std::string short_listing = write("listing.txt", listing);
  const std::vector<Case> cases = {
      {truncated + " " + m_file + " " + l_file + kCheck, {truncated, "entries", "truncated"}},
      {asymmetric + " " + m_file + " " + l_file + kCheck, {asymmetric, "K[2,1]", "symmetric"}},
      {(kDir / "piezo_amplified_K.txt").string() + " " + m_file + " " + short_listing + kCheck, {short_listing, "master DOF"}},
      {kFiles + " --fix 12345", {"--fix", "12345", "76423"}},
      {kFiles + " --force 76430:99999:x", {"--force", "99999"}},
      {kFiles + " --force 76430:76440:w", {"--force", "DIR"}},
      {kFiles + " --output 76423", {"--output"}},
      {kFiles + " --mass 76423:-1", {"--mass"}},
      {kFiles + " --damping modal", {"--damping"}},
  };
  for (const Case& c : cases) {
    const Outcome r = run_cli("superelement " + c.args + " --json");
    EXPECT_EQ(r.exit_code, 3) << c.args << "\n" << r.err;
    EXPECT_TRUE(test::no_result(r)) << r.out;
    for (const auto& needle : c.needles) EXPECT_NE(r.err.find(needle), std::string::npos) << c.args << "\n" << r.err;
  }
}

}  // namespace
}  // namespace piezobench
