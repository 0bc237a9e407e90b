// End-to-end tests of `piezobench superelement from-step` (run as a subprocess): one coarse run on
// APA95ML.step (8 mm, C3D4, so that it takes a few seconds) whose output is read back by
// `piezobench superelement`, and the error exits (exit code 3, the message says what).
#include <gtest/gtest.h>

#include <complex>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "run_cli.hpp"
#include "test_util.hpp"

namespace piezobench {
namespace {

namespace fs = std::filesystem;
const std::string kStep = (fs::path(PIEZOBENCH_SHARED_DATA_DIR) / "apa95ml-ansys" / "APA95ML.step").string();
// The acceptance for the reduced model against ccx on the full mesh.
constexpr double kAgainstCcx = 2e-3;

using test::run_cli;

long node_of(const nlohmann::json& doc, const std::string& name) {
  for (const auto& p : doc["remote_points"]) {
    if (p["name"] == name) return p["node"].get<long>();
  }
  ADD_FAILURE() << "no remote point " << name;
  return -1;
}

TEST(FromStepCli, CoarseChainWritesASuperElementThatTheImporterReads) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys/APA95ML.step");
  test::TempDir dir;
  const fs::path out = dir.path() / "apa";
  const test::CliRun r = run_cli("superelement from-step " + kStep + " --mesh-size 8 --order 1 --modes 10 --verify --json --out " +
                             out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json doc = nlohmann::json::parse(r.out);  // exactly one JSON document
  // Progress went to stderr.
  EXPECT_TRUE(test::contains(r.err, "[2/6] meshing")) << r.err;
  EXPECT_TRUE(test::contains(r.err, "gmsh: Meshing 3D")) << r.err;
  EXPECT_TRUE(test::contains(r.err, "Craig-Bampton")) << r.err;

  const std::vector<double> reduced = doc["modes_clamped_Hz"].get<std::vector<double>>();
  const std::vector<double> reference = doc["reference_modes_Hz"].get<std::vector<double>>();
  ASSERT_EQ(reduced.size(), 10U);
  ASSERT_EQ(reference.size(), 10U);
  // 10 modes only on this coarse model: the first three within the 0.2 %.
  for (std::size_t k = 0; k < 3; ++k) EXPECT_TRUE(test::near(reduced[k], reference[k], kAgainstCcx)) << k;
  for (std::size_t k = 0; k < 10; ++k) EXPECT_GE(reduced[k], reference[k] * (1 - 1e-6)) << k;
  EXPECT_EQ(doc["clamp"], "bottom");
  EXPECT_EQ(doc["mesh"]["element"], "C3D4");
  EXPECT_EQ(doc["super_element"]["dofs"], 4 * 6 + 10);
  EXPECT_EQ(doc["remote_points"].size(), 4U);
  EXPECT_TRUE(doc["warnings"].empty());
  EXPECT_FALSE(doc["gmsh"]["version"].get<std::string>().empty());
  EXPECT_FALSE(doc["ccx"]["version"].get<std::string>().empty());
  EXPECT_EQ(nlohmann::json::parse(test::read_text(out / "from_step.json"))["modes_clamped_Hz"], doc["modes_clamped_Hz"]);
  EXPECT_FALSE(fs::exists(out / "from_step_work"));

  // `piezobench superelement` on the files: the same clamped modes, and the stack pushing its
  // ends apart (+x on stack_b, -x on stack_a) lowers the top interface (the report's sign).
  const std::string files = doc["super_element"]["K"].get<std::string>() + " " + doc["super_element"]["M"].get<std::string>() + " " +
                            doc["super_element"]["dof_list"].get<std::string>();
  const long bottom = node_of(doc, "bottom"), top = node_of(doc, "top");
  const long a = node_of(doc, "stack_a"), b = node_of(doc, "stack_b");
  const test::CliRun se = run_cli("superelement " + files + " --fix " + std::to_string(bottom) + " --force " + std::to_string(a) + ":" +
                              std::to_string(b) + ":x --output " + std::to_string(top) + ":y --fmin 1 --fmax 100 --points 3 --json");
  ASSERT_EQ(se.exit_code, 0) << se.err;
  const nlohmann::json sj = nlohmann::json::parse(se.out);
  const std::vector<double> read_back = sj["modes_Hz"].get<std::vector<double>>();
  ASSERT_GE(read_back.size(), 10U);
  for (std::size_t k = 0; k < 10; ++k) EXPECT_TRUE(test::near(read_back[k], reduced[k], 1e-9)) << k;
  const std::complex<double> h(sj["H"][0][0][0].get<double>(), sj["H"][0][0][1].get<double>());
  EXPECT_LT(h.real(), 0.0) << "top displacement per newton of stack force";
  EXPECT_LT(std::abs(h.imag()), 1e-9 * std::abs(h.real()));  // no damping asked

  // The decks stay so that anyone can rerun ccx.
  for (const char* f : {"mesh.inp", "matrices.inp", "reference.inp", "ccx_matrices.log", "ccx_reference.log", "gmsh_mesh.log"}) {
    EXPECT_TRUE(fs::exists(out / f)) << f;
  }
}

TEST(FromStepCli, TextOutputHelpAndUsage) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys/APA95ML.step");
  const test::CliRun h = run_cli("superelement from-step --help");
  EXPECT_EQ(h.exit_code, 0);
  for (const char* option : {"--mesh-size", "--modes", "--material", "--remote-point", "--verify", "--keep-temp", "--out"}) {
    EXPECT_TRUE(test::contains(h.out, option)) << option;
  }
  EXPECT_EQ(run_cli("superelement from-step").exit_code, 2);  // STEP_FILE missing
  EXPECT_EQ(run_cli("superelement").exit_code, 2);            // the importer's files missing

  test::TempDir dir;
  const test::CliRun r = run_cli("superelement from-step " + kStep + " --mesh-size 8 --order 1 --modes 6 --remote-point top:y=max " +
                             "--remote-point bottom:y=min --out " + (dir.path() / "o").string() + " --keep-temp --stem apa");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(test::contains(r.out, "modes with bottom clamped [Hz]:")) << r.out;
  EXPECT_TRUE(test::contains(r.out, "use it: piezobench superelement")) << r.out;
  EXPECT_TRUE(fs::exists(dir.path() / "o" / "apa_K.mtx"));
  EXPECT_TRUE(fs::exists(dir.path() / "o" / "from_step_work" / "matrices.dof"));  // --keep-temp
}

TEST(FromStepCli, BadInputExitsWithThreeAndSaysWhat) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys/APA95ML.step");
  test::TempDir dir;
  const std::string bad_step = test::write_text_file(dir, "bad.step", "ISO-10303-21;\nnot a STEP file\n");
  const std::string out = " --out " + (dir.path() / "out").string() + " --mesh-size 8 --order 1";
  struct Case {
    std::string args;
    std::vector<std::string> needles;
    int exit_code = 3;  // 2: a value the option cannot take
  };
  const std::vector<Case> cases = {
      {kStep + out + " --ccx " + (dir.path() / "none" / "ccx").string(), {"--ccx", "calculix-ccx"}},
      {kStep + out + " --ccx /bin/true", {"--ccx", "version"}},         // prints no version
      {kStep + out + " --gmsh /bin/true", {"--gmsh", "geometry.txt"}},  // `true --version` prints one, runs nothing
      {bad_step + out, {bad_step, "gmsh"}},
      {(dir.path() / "missing.step").string() + out, {"missing.step", "no such file"}},
      {kStep + out + " --remote-point top:y=max --remote-point side:z=99", {"--remote-point side", "z=99", "planar faces"}},
      {kStep + out + " --region far:box:100,100,100,101,101,101 --material far:1e9,0.3,1000", {"--region far", "no volume"}},
      {kStep + out + " --material shell:190e9,0.3,7800", {"--material", "shell"}},
      {kStep + out + " --material body:190e9,0.6,7800", {"--material body", "nu"}},
      {kStep + out + " --preset apa200ml", {"--preset", "apa300ml"}, 2},  // unknown; the message lists the presets
      {kStep + out + " --clamp middle", {"--clamp", "middle"}},
  };
  for (const Case& c : cases) {
    const test::CliRun r = run_cli("superelement from-step " + c.args + " --json");
    EXPECT_EQ(r.exit_code, c.exit_code) << c.args << "\n" << r.err;
    EXPECT_TRUE(test::no_result(r)) << r.out;
    for (const auto& needle : c.needles) EXPECT_TRUE(test::contains(r.err, needle)) << c.args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(dir.path() / "out" / "from_step_work")) << c.args;
  }
}

}  // namespace
}  // namespace piezobench
