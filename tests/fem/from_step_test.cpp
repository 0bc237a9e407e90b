// From STEP to super element (issue 8): the parsers and file helpers on small inputs, the error
// paths (missing tools, a STEP that does not load, selectors that select nothing), and the whole
// chain once on APA95ML.step at 4 mm (gmsh + ccx + Craig-Bampton, about 35,000 DOF), checked
// against ccx's own *FREQUENCY on the full mesh (the issue: the first five clamped modes within
// 0.2 %), against the mass integrated independently from the mesh, and against analytic
// geometry (the stack end faces are 20 x 22.5 mm rectangles at x = +-34.7793 mm).
#include "piezobench/fem/from_step.hpp"

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>

#include "from_step_files.hpp"
#include "from_step_process.hpp"
#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/usage_error.hpp"
#include "piezobench/fem/superelement.hpp"
#include "test_util.hpp"
#include "fem_test_data.hpp"

namespace piezobench::fem {
namespace {

namespace fs = std::filesystem;

const fs::path kStep = fs::path(PIEZOBENCH_SHARED_DATA_DIR) / "apa95ml-ansys" / "APA95ML.step";
// The acceptance for the reduced model against ccx on the full mesh.
using test_data::kAgainstCcx;

// Sets an environment variable for the scope and restores it.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    const char* old = std::getenv(name);
    had_ = old != nullptr;
    if (had_) old_ = old;
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (had_) {
      ::setenv(name_, old_.c_str(), 1);
    } else {
      ::unsetenv(name_);
    }
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::string old_;
  bool had_ = false;
};

FromStepOptions quiet_apa95ml(const fs::path& out) {
  FromStepOptions o = FromStepOptions::apa95ml();
  o.out = out;
  return o;
}

// ---- parsers ----------------------------------------------------------------------------------

TEST(FromStep, ParsesSelectorsRegionsMaterialsAndRemotePoints) {
  FaceSelector s = FaceSelector::parse("y=max", "f");
  EXPECT_EQ(s.kind, FaceSelector::Kind::kPlane);
  EXPECT_EQ(s.axis, 1);
  EXPECT_EQ(s.at, FaceSelector::At::kMax);
  EXPECT_EQ(s.to_string(), "y=max");
  s = FaceSelector::parse("X=-34.7793", "f");
  EXPECT_EQ(s.axis, 0);
  EXPECT_EQ(s.at, FaceSelector::At::kValue);
  EXPECT_DOUBLE_EQ(s.value, -34.7793);
  EXPECT_EQ(s.to_string(), "x=-34.7793");
  s = FaceSelector::parse("box:1,2,3,-1,-2,-3", "f");
  EXPECT_EQ(s.kind, FaceSelector::Kind::kBox);
  EXPECT_EQ(s.box.lo, Eigen::Vector3d(-1, -2, -3));
  EXPECT_EQ(s.box.hi, Eigen::Vector3d(1, 2, 3));
  s = FaceSelector::parse("surface:12,5", "f");
  EXPECT_EQ(s.surfaces, (std::vector<int>{12, 5}));
  EXPECT_EQ(s.to_string(), "surface:12,5");
  for (const char* bad : {"", "y", "w=max", "y=top", "y=nan", "box:1,2,3", "box:0,0,0,1,1,0", "surface:", "surface:0", "surface:a"}) {
    (void)test::input_error([&] { (void)FaceSelector::parse(bad, "--remote-point"); }, "--remote-point");
  }

  const RemotePointSpec p = RemotePointSpec::parse("top:y=max", "--remote-point");
  EXPECT_EQ(p.name, "top");
  for (const char* bad : {"top", ":y=max", "t op:y=max", "top:y=up"}) {
    EXPECT_THROW((void)RemotePointSpec::parse(bad, "--remote-point"), InputError) << bad;
  }
  const RegionSpec r = RegionSpec::parse("stack:box:-1,-1,-1,1,1,1", "--region");
  EXPECT_EQ(r.name, "stack");
  EXPECT_EQ(r.box.hi, Eigen::Vector3d(1, 1, 1));
  for (const char* bad : {"stack", "stack:1,2,3,4,5,6", "body:box:0,0,0,1,1,1", "st-ack:box:0,0,0,1,1,1"}) {
    EXPECT_THROW((void)RegionSpec::parse(bad, "--region"), InputError) << bad;
  }
  const Material m = Material::parse("190e9,0.3,7800", "--material");
  EXPECT_EQ(m.youngs_modulus, 190e9);
  EXPECT_EQ(m.poisson_ratio, 0.3);
  EXPECT_EQ(m.density, 7800.0);
  for (const char* bad : {"190e9,0.3", "190e9,0.5,7800", "-1,0.3,7800", "190e9,0.3,0", "1,2,x", "inf,0.3,7800"}) {
    EXPECT_THROW((void)Material::parse(bad, "--material"), InputError) << bad;
  }
}

TEST(FromStep, ValidatesOptions) {
  FromStepOptions o = FromStepOptions::apa95ml();
  EXPECT_NO_THROW(o.validate());
  EXPECT_EQ(o.remote_points.size(), 4U);
  EXPECT_EQ(o.clamp, "bottom");
  const auto expect_bad = [](FromStepOptions bad, const std::string& field) { (void)test::input_error([&] { bad.validate(); }, field); };
  FromStepOptions b = o;
  b.mesh_size_mm = 0.0;
  expect_bad(b, "--mesh-size");
  b = o;
  b.element_order = 3;
  expect_bad(b, "--order");
  b = o;
  b.clamp = "nowhere";
  expect_bad(b, "--clamp");
  b = o;
  b.remote_points.push_back(b.remote_points.front());
  expect_bad(b, "--remote-point");
  b = o;
  b.remote_points.clear();
  expect_bad(b, "--remote-point");
  b = o;
  b.materials.erase("stack");
  expect_bad(b, "--material");
  b = o;
  b.materials["shell"] = b.materials["body"];  // no such region
  expect_bad(b, "--material");
}

TEST(FromStep, VersionsAndLogLines) {
  EXPECT_EQ(detail::parse_version("4.8.4\n"), "4.8.4");
  EXPECT_EQ(detail::parse_version("\nThis is Version 2.20\n\n"), "2.20");
  EXPECT_EQ(detail::parse_version("gmsh 4.11.1-git-abc"), "4.11.1");
  EXPECT_FALSE(detail::parse_version("no version here 4 x"));
  EXPECT_EQ(detail::compare_versions("4.8.4", "4.0"), 1);
  EXPECT_EQ(detail::compare_versions("2.20", "2.15"), 1);
  EXPECT_EQ(detail::compare_versions("2.9", "2.15"), -1);
  EXPECT_EQ(detail::compare_versions("2.15", "2.15.0"), 0);
  EXPECT_EQ(detail::last_lines("a Err 1\nb\nc Err 2\nd Err 3\n", "Err", 2), "c Err 2\nd Err 3");
}

TEST(FromStep, FindsExecutablesInPathAndRunsThemWithoutAShell) {
  test::TempDir dir;
  const fs::path script = dir.path() / "tool.sh";
  // Arguments arrive as they are: no word splitting, no globbing, no expansion.
  test::write_text(script, "#!/bin/sh\necho \"argc=$# 1=[$1] 2=[$2]\"\necho line2 >&2\nexit 7\n");
  fs::permissions(script, fs::perms::owner_all);
  {
    ScopedEnv path("PATH", dir.path().string() + ":/usr/bin:/bin");
    const auto found = detail::find_executable("tool.sh");
    ASSERT_TRUE(found);
    EXPECT_EQ(*found, script);
  }
  {
    ScopedEnv path("PATH", "/nonexistent");
    EXPECT_FALSE(detail::find_executable("tool.sh"));
    EXPECT_FALSE(detail::find_executable("sh"));
  }
  EXPECT_FALSE(detail::find_executable((dir.path() / "missing").string()));
  EXPECT_FALSE(detail::find_executable(dir.path().string()));  // a folder
  std::vector<std::string> lines;
  const auto r = detail::run_process(script, {"a b; rm -rf *", "$HOME"}, dir.path(), dir.path() / "log.txt",
                                     [&](std::string_view l) { lines.emplace_back(l); });
  EXPECT_EQ(r.exit_code, 7);
  EXPECT_FALSE(r.signaled);
  ASSERT_EQ(lines.size(), 2U);
  EXPECT_EQ(lines[0], "argc=2 1=[a b; rm -rf *] 2=[$HOME]");
  EXPECT_EQ(lines[1], "line2");
  EXPECT_TRUE(fs::exists(script));
}

// ---- gmsh and ccx files -------------------------------------------------------------------------

detail::GeometryReport small_report() {
  // A 10 x 20 x 30 mm block (faces at x = 0, 10; y = 0, 20; z = 0, 30) and a second volume.
  return detail::parse_geometry_report(
      "# gmsh entities\n"
      "V 1 0 0 0 10 20 30\n"
      "V 2 0 0 0 10 20 5\n"
      "S 1 0 0 0 1e-7 20 30\n"
      "S 2 10 0 0 10 20 30\n"
      "S 3 0 0 0 10 1e-7 30\n"
      "S 4 0 20 0 10 20 30\n"
      "S 5 0 0 0 10 20 0\n"
      "S 6 0 0 30 10 20 30\n"
      "S 7 2 2 10 8 18 12\n"  // not planar
      "END\n",
      "report");
}

TEST(FromStep, ReadsTheGeometryReportAndSelectsFaces) {
  const detail::GeometryReport g = small_report();
  ASSERT_EQ(g.volumes.size(), 2U);
  ASSERT_EQ(g.surfaces.size(), 7U);
  EXPECT_EQ(g.bounds.hi, Eigen::Vector3d(10, 20, 30));
  const auto sel = [&](const char* text) { return detail::select_faces(FaceSelector::parse(text, "f"), g, 1e-3); };
  EXPECT_EQ(sel("x=min"), std::vector<int>{1});
  EXPECT_EQ(sel("x=max"), std::vector<int>{2});
  EXPECT_EQ(sel("y=20"), std::vector<int>{4});
  EXPECT_EQ(sel("y=20.003"), std::vector<int>{4});  // within 1e-4 of the model's size (37 mm)
  EXPECT_TRUE(sel("y=20.1").empty());
  EXPECT_EQ(sel("z=max"), std::vector<int>{6});
  EXPECT_EQ(sel("box:1,1,5,9,19,15"), std::vector<int>{7});
  EXPECT_EQ(sel("surface:6,2"), (std::vector<int>{2, 6}));
  EXPECT_TRUE(sel("surface:6,99").empty());  // all of them or nothing
  const std::string planes = detail::describe_planar_faces(g, 1e-3);
  EXPECT_TRUE(test::contains(planes, "normal to x at x = 0, 10")) << planes;
  EXPECT_TRUE(test::contains(planes, "normal to z at z = 0, 30")) << planes;

  RegionSpec low = RegionSpec::parse("low:box:-1,-1,-1,11,21,6", "--region");
  const auto regions = detail::assign_regions(g, {low}, 1e-3);
  EXPECT_EQ(regions.at("low"), std::vector<int>{2});
  EXPECT_EQ(regions.at("body"), std::vector<int>{1});
  const RegionSpec far = RegionSpec::parse("far:box:100,100,100,101,101,101", "--region");
  (void)test::input_error([&] { (void)detail::assign_regions(g, {far}, 1e-3); }, "box");

  for (const char* bad : {"V 1 0 0 0 1 1\nEND\n", "X 1 0 0 0 1 1 1\nEND\n", "V 1 0 0 0 1 1 nan\nEND\n", "V 1 0 0 0 1 1 1\n"}) {
    EXPECT_THROW((void)detail::parse_geometry_report(bad, "report"), InputError) << bad;
  }
}

TEST(FromStep, ReadsGmshMeshesAndWritesCalculixDecks) {
  test::TempDir dir;
  // One C3D4 tetrahedron on the unit corner (mm) and its face z = 0 as a surface element.
  test::write_text(dir.path() / "gmsh.inp",
                   "*Heading\n gmsh.inp\n*NODE\n1, 0, 0, 0\n2, 10, 0, 0\n3, 0, 10, 0\n4, 0, 0, 10\n"
                   "******* E L E M E N T S *************\n"
                   "*ELEMENT, type=CPS3, ELSET=Surface5\n1, 1, 2, 3\n"
                   "*ELEMENT, type=C3D4, ELSET=Volume1\n2, 1, 2, 3, 4\n"
                   "*ELSET,ELSET=E_BODY\n2,\n*NSET,NSET=F_BASE\n1, 2, 3,\n");
  const detail::GmshMesh mesh = detail::read_gmsh_inp(dir.path() / "gmsh.inp");
  EXPECT_EQ(mesh.volume_type, "C3D4");
  ASSERT_EQ(mesh.volume_elements.at(1).size(), 1U);
  ASSERT_EQ(mesh.surface_elements.at(5).size(), 1U);
  const detail::FacePatch patch = detail::face_patch(mesh, {5});
  EXPECT_DOUBLE_EQ(patch.area, 50.0);  // mm^2
  EXPECT_TRUE(test::all_near(patch.centroid, Eigen::Vector3d(10.0 / 3, 10.0 / 3, 0), {1e-14, 1e-14}));
  EXPECT_EQ(patch.nodes, (std::vector<long>{1, 2, 3}));

  detail::DeckPoint base;
  base.name = "base";
  base.ref = 5;
  base.rot = 6;
  base.position_m = 1e-3 * patch.centroid;
  base.nodes = patch.nodes;
  detail::write_mesh_inp(dir.path() / "mesh.inp", mesh, {{"body", {1}}}, {base});
  const std::string inp = test::read_text(dir.path() / "mesh.inp");
  EXPECT_TRUE(test::contains(inp, "2, 0.01, 0, 0\n")) << inp;  // metres
  EXPECT_TRUE(test::contains(inp, "*ELEMENT, TYPE=C3D4, ELSET=E_BODY\n2, 1, 2, 3, 4\n")) << inp;
  EXPECT_TRUE(test::contains(inp, "*NSET, NSET=F_BASE\n1, 2, 3\n")) << inp;
  EXPECT_TRUE(test::contains(inp, "5, 0.00333333333333, 0.00333333333333, 0\n6, ")) << inp;
  // read_inp_nodes (matrix_io) reads it back.
  EXPECT_EQ(read_inp_nodes(dir.path() / "mesh.inp").size(), 6U);

  const std::map<std::string, Material> materials{{"body", {190e9, 0.3, 7800}}};
  const std::string dump = detail::ccx_deck("mesh.inp", materials, {"body"}, {base}, nullptr, 0, "t");
  EXPECT_TRUE(test::contains(dump, "*ELASTIC\n190000000000, 0.29999999999999999\n*DENSITY\n7800\n")) << dump;
  EXPECT_TRUE(test::contains(dump, "*RIGID BODY, NSET=F_BASE, REF NODE=5, ROT NODE=6\n")) << dump;
  EXPECT_TRUE(test::contains(dump, "*FREQUENCY, SOLVER=MATRIXSTORAGE\n*END STEP")) << dump;
  const std::string ref = detail::ccx_deck("mesh.inp", materials, {"body"}, {base}, &base, 7, "t");
  EXPECT_TRUE(test::contains(ref, "*BOUNDARY\n5, 1, 3\n6, 1, 3\n*STEP\n*FREQUENCY\n7\n")) << ref;

  for (const char* bad : {"*NODE\n1, 0, 0\n*ELEMENT, type=C3D4, ELSET=Volume1\n2, 1, 1, 1, 1\n",
                          "*NODE\n1, 0, 0, 0\n*ELEMENT, type=C3D4, ELSET=Volume1\n2, 1, 1, 1\n",
                          "*NODE\n1, 0, 0, 0\n*ELEMENT, type=C3D4, ELSET=Volume1\n2, 1, 1, 1, 9\n",
                          "*NODE\n1, 0, 0, 0\n*ELEMENT, type=C3D4, ELSET=Part1\n2, 1, 1, 1, 1\n", "*NODE\n1, 0, 0, 0\n"}) {
    test::write_text(dir.path() / "bad.inp", bad);
    EXPECT_THROW((void)detail::read_gmsh_inp(dir.path() / "bad.inp"), InputError) << bad;
  }
}

TEST(FromStep, ReadsTheEigenvalueTableOfCcx) {
  test::TempDir dir;
  test::write_text(dir.path() / "r.dat",
                   "\n     E I G E N V A L U E   O U T P U T\n\n MODE NO    EIGENVALUE                       FREQUENCY\n"
                   "                                     REAL PART            IMAGINARY PART\n"
                   "                           (RAD/TIME)      (CYCLES/TIME     (RAD/TIME)\n\n"
                   "      1   0.6728710E+07   0.2593976E+04   0.4128440E+03   0.0000000E+00\n"
                   "      2   0.3022846E+08   0.5498042E+04   0.8750405E+03   0.0000000E+00\n\n"
                   "     P A R T I C I P A T I O N   F A C T O R S\n"
                   "      1   0.1E+00   0.2E+00   0.3E+00   0.4E+00   0.5E+00   0.6E+00\n");
  EXPECT_EQ(detail::read_ccx_frequencies(dir.path() / "r.dat"), (std::vector<double>{412.844, 875.0405}));
  test::write_text(dir.path() / "empty.dat", "\n");
  EXPECT_THROW((void)detail::read_ccx_frequencies(dir.path() / "empty.dat"), InputError);
}

// ---- error paths of the chain ------------------------------------------------------------------

TEST(FromStep, MissingOrWrongToolsAreInputErrors) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys/APA95ML.step");
  test::TempDir dir;
  FromStepOptions o = quiet_apa95ml(dir.path() / "out");
  {
    ScopedEnv path("PATH", "/nonexistent");
    const std::string what = test::input_error([&] { (void)superelement_from_step(kStep, o); }, "executable");
    EXPECT_TRUE(test::contains(what, "gmsh")) << what;
    EXPECT_TRUE(test::contains(what, "Debian package gmsh")) << what;
  }
  o.gmsh = "/usr/bin/gmsh";
  o.ccx = (dir.path() / "no" / "ccx").string();
  std::string what = test::input_error([&] { (void)superelement_from_step(kStep, o); }, "executable");
  EXPECT_TRUE(test::contains(what, "--ccx")) << what;
  EXPECT_TRUE(test::contains(what, "calculix-ccx")) << what;
  o.ccx = "/bin/true";  // starts, prints no version
  what = test::input_error([&] { (void)superelement_from_step(kStep, o); }, "version");
  EXPECT_TRUE(test::contains(what, "ccx")) << what;
  EXPECT_FALSE(fs::exists(dir.path() / "out" / "from_step_work"));
}

TEST(FromStep, AStepThatDoesNotLoadIsAnInputError) {
  test::TempDir dir;
  const FromStepOptions o = quiet_apa95ml(dir.path() / "out");
  test::write_text(dir.path() / "bad.step", "ISO-10303-21;\nthis is not STEP\n");
  const std::string what = test::input_error([&] { (void)superelement_from_step(dir.path() / "bad.step", o); }, "STEP");
  EXPECT_TRUE(test::contains(what, "gmsh")) << what;
  EXPECT_TRUE(fs::exists(dir.path() / "out" / "gmsh_geometry.log"));  // the log stays
  EXPECT_FALSE(fs::exists(dir.path() / "out" / "from_step_work"));     // the temporary files do not
  (void)test::input_error([&] { (void)superelement_from_step(dir.path() / "missing.step", o); }, "file");
}

TEST(FromStep, SelectorsAndRegionsThatSelectNothingAreInputErrors) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys/APA95ML.step");
  test::TempDir dir;
  FromStepOptions o = quiet_apa95ml(dir.path() / "out");
  o.remote_points.push_back(RemotePointSpec::parse("nothing:z=100", "--remote-point"));
  o.keep_temp = true;
  std::string what = test::input_error([&] { (void)superelement_from_step(kStep, o); }, "selector");
  EXPECT_TRUE(test::contains(what, "nothing")) << what;
  EXPECT_TRUE(test::contains(what, "z=100")) << what;
  // The message lists where the planar faces are: the interfaces at y = +-29.9975 mm.
  EXPECT_TRUE(test::contains(what, "-29.9975")) << what;
  EXPECT_TRUE(fs::exists(dir.path() / "out" / "from_step_work" / "geometry.txt"));  // kept on request
  EXPECT_TRUE(fs::exists(dir.path() / "out" / "geometry.txt"));

  o = quiet_apa95ml(dir.path() / "out2");
  o.regions.push_back(RegionSpec::parse("far:box:100,100,100,101,101,101", "--region"));
  o.materials["far"] = o.materials["body"];
  what = test::input_error([&] { (void)superelement_from_step(kStep, o); }, "box");
  EXPECT_TRUE(test::contains(what, "far")) << what;
  EXPECT_FALSE(fs::exists(dir.path() / "out2" / "from_step_work"));
}

// ---- the whole chain ---------------------------------------------------------------------------

// Total mass of the mesh in mesh.inp (metres), integrated as ccx integrates C3D10 masses: the
// 4-point rule on the quadratic tetrahedron.
double mesh_mass(const fs::path& mesh_inp, const std::map<std::string, double>& density_by_elset) {
  std::map<long, Eigen::Vector3d> nodes = read_inp_nodes(mesh_inp);
  std::ifstream in(mesh_inp);
  std::string line;
  double rho = -1.0, mass = 0.0;
  const double a = 0.5854101966249685, b = 0.1381966011250105;
  const std::array<Eigen::Vector3d, 4> gauss = {Eigen::Vector3d(b, b, b), Eigen::Vector3d(a, b, b), Eigen::Vector3d(b, a, b),
                                                Eigen::Vector3d(b, b, a)};
  while (std::getline(in, line)) {
    if (line.rfind("*", 0) == 0) {
      rho = -1.0;
      const auto at = line.find("ELSET=");
      if (line.rfind("*ELEMENT", 0) == 0 && at != std::string::npos) rho = density_by_elset.at(line.substr(at + 6));
      continue;
    }
    if (rho < 0.0) continue;
    std::vector<long> ids;
    std::stringstream ss(line);
    for (std::string tok; std::getline(ss, tok, ',');) ids.push_back(std::stol(tok));
    EXPECT_EQ(ids.size(), 11U);
    Eigen::Matrix<double, 3, 10> x;
    for (int k = 0; k < 10; ++k) x.col(k) = nodes.at(ids[static_cast<std::size_t>(k + 1)]);
    for (const Eigen::Vector3d& p : gauss) {
      const double L[4] = {1.0 - p.sum(), p(0), p(1), p(2)};
      // dL/d(xi, eta, zeta)
      const Eigen::Matrix<double, 4, 3> dL = (Eigen::Matrix<double, 4, 3>() << -1, -1, -1, 1, 0, 0, 0, 1, 0, 0, 0, 1).finished();
      Eigen::Matrix<double, 10, 3> dN;
      for (int i = 0; i < 4; ++i) dN.row(i) = (4.0 * L[i] - 1.0) * dL.row(i);
      const int edges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};  // Abaqus order of nodes 5..10
      for (int e = 0; e < 6; ++e) {
        const int i = edges[e][0], j = edges[e][1];
        dN.row(4 + e) = 4.0 * (L[i] * dL.row(j) + L[j] * dL.row(i));
      }
      mass += rho * (x * dN).determinant() / 24.0;
    }
  }
  return mass;
}

TEST(FromStep, Apa95mlAt4mmMatchesCalculixOnTheFullMesh) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys/APA95ML.step");
  test::TempDir dir;
  FromStepOptions o = quiet_apa95ml(dir.path() / "out");
  o.mesh_size_mm = 4.0;
  o.modes = 30;
  o.verify = true;
  std::vector<std::string> log;
  o.log = [&](const std::string& line) { log.push_back(line); };
  const FromStepResult r = superelement_from_step(kStep, o);

  // ccx on the full mesh against the reduced model, same boundary condition (bottom clamped).
  ASSERT_TRUE(r.reference_modes_Hz);
  ASSERT_EQ(r.reference_modes_Hz->size(), 10);
  ASSERT_EQ(r.modes_clamped_Hz.size(), 10);
  EXPECT_EQ(r.clamp, "bottom");
  for (Index k = 0; k < 10; ++k) {
    std::printf("clamped mode %lld: reduced %.7g Hz, ccx %.7g Hz, difference %+.2e\n", static_cast<long long>(k + 1),
                r.modes_clamped_Hz(k), (*r.reference_modes_Hz)(k), r.modes_clamped_Hz(k) / (*r.reference_modes_Hz)(k) - 1.0);
    if (k < 5) {
      EXPECT_TRUE(test::near(r.modes_clamped_Hz(k), (*r.reference_modes_Hz)(k), kAgainstCcx)) << "mode " << k + 1;
    }
    // Craig-Bampton only adds constraints to the full model: its modes are upper bounds.
    EXPECT_GE(r.modes_clamped_Hz(k), (*r.reference_modes_Hz)(k) * (1.0 - 1e-6)) << "mode " << k + 1;
  }

  // The model: C3D10, the stack region cut out, four remote points of 6 DOF.
  EXPECT_EQ(r.element_type, "C3D10");
  EXPECT_GT(r.mesh_nodes, 8000);
  EXPECT_GT(r.region_elements.at("stack"), 0);
  EXPECT_GT(r.region_elements.at("body"), 0);
  EXPECT_EQ(r.region_elements.at("stack") + r.region_elements.at("body"), r.mesh_elements);
  EXPECT_EQ(r.reduction.interface_dofs, 24);
  EXPECT_EQ(r.reduced.size(), 24 + 30);
  EXPECT_EQ(r.reduced.modal_dofs(), 30);
  ASSERT_EQ(r.remote_points.size(), 4U);
  const RemotePointResult& top = r.remote_points[0];
  const RemotePointResult& stack_a = r.remote_points[2];
  const RemotePointResult& stack_b = r.remote_points[3];
  EXPECT_EQ(top.name, "top");
  EXPECT_TRUE(test::all_near(top.position_m, Eigen::Vector3d(0, 0.0299975, 0), {0.0, 1e-9}));
  EXPECT_TRUE(test::all_near(r.remote_points[1].position_m, Eigen::Vector3d(0, -0.0299975, 0), {0.0, 1e-9}));
  // The stack ends: the 20 x 22.5 mm cross-section of the block at x = -+34.7793 mm.
  EXPECT_TRUE(test::near(stack_a.area_m2, 20e-3 * 22.5e-3, 1e-9));
  EXPECT_TRUE(test::near(stack_b.area_m2, 20e-3 * 22.5e-3, 1e-9));
  EXPECT_TRUE(test::all_near(stack_a.position_m, Eigen::Vector3d(-0.0347793, 0, 0), {0.0, 1e-9}));
  EXPECT_TRUE(test::all_near(stack_b.position_m, Eigen::Vector3d(0.0347793, 0, 0), {0.0, 1e-9}));
  for (const RemotePointResult& p : r.remote_points) {
    EXPECT_EQ(p.rot_node, p.node + 1);
    EXPECT_GT(p.face_nodes, 50);
    EXPECT_TRUE(r.reduced.find(p.node, Direction::kRz).has_value()) << p.name;
  }

  // Free-free, the reduced model keeps six rigid-body modes at 0 Hz.
  EXPECT_TRUE(r.reduced.warnings.empty());
  ASSERT_GE(r.free_modes_Hz.size(), 7);
  EXPECT_LT(r.free_modes_Hz.head(6).cwiseAbs().maxCoeff(), 1e-3 * r.free_modes_Hz(6));

  // Its rigid translation mass equals the mass integrated from the mesh (steel body, PZT stack).
  Eigen::VectorXd ux = Eigen::VectorXd::Zero(r.reduced.size());
  for (const RemotePointResult& p : r.remote_points) ux(*r.reduced.find(p.node, Direction::kX)) = 1.0;
  const double mass = ux.dot(r.reduced.M * ux);
  const double expected = mesh_mass(o.out / "mesh.inp", {{"E_BODY", 7800.0}, {"E_STACK", 7800.0}});
  std::printf("mass: reduced model %.12g kg, integrated from the mesh %.12g kg\n", mass, expected);
  EXPECT_TRUE(test::near(mass, expected, 1e-9));
  // The block alone is 69.5586 x 20 x 22.5 mm of PZT (7800 kg/m^3): a lower bound.
  EXPECT_GT(mass, 7800.0 * 69.5586e-3 * 20e-3 * 22.5e-3);

  // The output folder: the super element readable by the importer, the decks, the logs; no work
  // folder (no --keep-temp).
  const fs::path out = o.out;
  const SuperElement back = read_super_element(SuperElementFormat::kMatrixMarket, out / "APA95ML_K.mtx", out / "APA95ML_M.mtx",
                                               out / "APA95ML_dofs.txt");
  ASSERT_EQ(back.size(), r.reduced.size());
  EXPECT_EQ(back.dofs, r.reduced.dofs);
  EXPECT_TRUE(test::all_near(back.K, r.reduced.K, {1e-14, 1e-12 * r.reduced.K.cwiseAbs().maxCoeff()}));
  EXPECT_TRUE(test::all_near(back.M, r.reduced.M, {1e-14, 1e-14 * r.reduced.M.cwiseAbs().maxCoeff()}));
  EXPECT_TRUE(test::all_near(back.coordinates.at(top.node), top.position_m, {0.0, 1e-15}));
  for (const char* f : {"APA95ML_simscape.m", "mesh.inp", "mesh.geo", "matrices.inp", "reference.inp", "reference.dat",
                        "geometry.txt", "gmsh_geometry.log", "gmsh_mesh.log", "ccx_matrices.log", "ccx_reference.log"}) {
    EXPECT_TRUE(fs::exists(out / f)) << f;
  }
  EXPECT_FALSE(fs::exists(out / "from_step_work"));
  EXPECT_TRUE(test::contains(test::read_text(out / "matrices.inp"), "*FREQUENCY, SOLVER=MATRIXSTORAGE"));
  EXPECT_TRUE(test::contains(test::read_text(out / "reference.inp"),
                             "*BOUNDARY\n" + std::to_string(r.remote_points[1].node) + ", 1, 3\n"));
  EXPECT_TRUE(test::contains(test::read_text(out / "APA95ML_simscape.m"), "frame_nodes"));

  // Progress: every stage, with gmsh's and ccx's own stage lines.
  std::string all;
  for (const std::string& l : log) all += l + "\n";
  for (const char* stage : {"[1/6]", "[2/6]", "[3/6]", "[4/6]", "[5/6]", "[6/6]", "[verify]", "gmsh: Meshing 3D",
                            "ccx: Factoring", "factorizing K_ii"}) {
    EXPECT_TRUE(test::contains(all, stage)) << stage << " not in\n" << all;
  }
  EXPECT_FALSE(test::contains(all, "Meshing curve")) << "gmsh's per-curve lines are not forwarded";
}

// ---- issue 15: the APA300ML geometry of the repository, stacks as beams, the size guard ---------

namespace apa300ml {
const fs::path kGeo = fs::path(PIEZOBENCH_SOURCE_DIR) / "data/geometry/apa300ml.geo";
bool tools() { return detail::find_executable("gmsh") && detail::find_executable("ccx"); }
}  // namespace apa300ml

TEST(FromStep, EstimatesTheMeshFromTheGeometry) {
  // The fit of elements ~ 3 V / h^3 + 4 S / h^2 against APA95ML.step at 2 mm (30,200 C3D10).
  const MeshEstimate e = estimate_mesh(44907.0, 13986.0, 2.0, 2);
  EXPECT_NEAR(e.elements, 30827.0, 1.0);
  EXPECT_NEAR(e.elements / 30200.0, 1.0, 0.05);
  EXPECT_NEAR(e.nodes, 1.65 * e.elements, 1e-6);
  EXPECT_NEAR(e.memory_GB, 0.2 + 1.3 * std::pow(3.0 * e.nodes / 144000.0, 1.2), 1e-9);
  // A user thinking in metres: 4 mm written 0.004.
  const MeshEstimate m = estimate_mesh(44907.0, 13986.0, 0.004, 2);
  EXPECT_GT(m.elements, 1e12);
  EXPECT_GT(m.memory_GB, 1e6);
  EXPECT_GT(default_max_memory_GB(), 0.0);
  EXPECT_LE(default_max_memory_GB(), 8.0);
}

TEST(FromStep, RefusesAMeshTooLargeBeforeGmshMeshes) {
  if (!apa300ml::tools()) GTEST_SKIP() << "gmsh or ccx not installed";
  test::TempDir dir;
  FromStepOptions o = FromStepOptions::apa300ml();
  o.out = dir.path() / "out";
  o.mesh_size_mm = 0.004;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    (void)superelement_from_step(apa300ml::kGeo, o);
    ADD_FAILURE() << "expected a UsageError";
  } catch (const UsageError& e) {
    const std::string what = e.what();
    EXPECT_TRUE(test::contains(what, "--mesh-size 0.004")) << what;
    EXPECT_TRUE(test::contains(what, "--max-memory")) << what;
    EXPECT_TRUE(test::contains(what, "elements")) << what;
    EXPECT_EQ(e.exit_code(), ExitCode::kUsage);
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 30.0);
  EXPECT_FALSE(fs::exists(dir.path() / "out" / "gmsh_mesh.log"));  // gmsh never meshed
}

// The repository's geometry at a coarse 4 mm (a few seconds): stacks as beams with k = c^E A / L,
// the joint between actuator and sensor stacks, the reduction against ccx before the stacks.
TEST(FromStep, Apa300mlGeometryWithStackBeamsAt4mm) {
  if (!apa300ml::tools()) GTEST_SKIP() << "gmsh or ccx not installed";
  test::TempDir dir;
  FromStepOptions o = FromStepOptions::apa300ml();
  o.out = dir.path() / "out";
  o.mesh_size_mm = 4.0;
  o.modes = 12;
  o.clamped_modes = 4;
  o.verify = true;
  o.tool_timeout_s = 120.0;
  const FromStepResult r = superelement_from_step(apa300ml::kGeo, o);
  ASSERT_EQ(r.stacks.size(), 2u);
  EXPECT_NEAR(r.stacks[0].length_m, 0.040, 1e-9);  // the two actuator stacks, remote points 3 -> 4
  EXPECT_NEAR(r.stacks[0].axial_stiffness, 1.2e8, 1.0);
  EXPECT_NEAR(r.stacks[1].axial_stiffness, 2.4e8, 1.0);  // the sensor stack, 4 -> 5: 48e9 x 1e-4 / 0.02
  ASSERT_EQ(r.joints.size(), 1u);
  EXPECT_NEAR(r.joints[0].position_m.x(), 0.010, 1e-9);
  EXPECT_EQ(r.reduced.nodal_dofs(), 30);  // 4 remote points and the joint
  ASSERT_TRUE(r.reference_modes_Hz);
  for (Index k = 0; k < 3; ++k) {
    EXPECT_TRUE(test::near(r.shell_modes_clamped_Hz(k), (*r.reference_modes_Hz)(k), kAgainstCcx)) << "mode " << k + 1;
  }
  // The figures of docs/apa300ml.md, loosely (4 mm is coarse): shell 0.38 N/um, about 2.7 N/um with
  // the stacks, first modes near 300 and 410 Hz; the stacks stiffen the model.
  EXPECT_NEAR(r.shell_axial_stiffness * 1e-6, 0.38, 0.05);
  EXPECT_NEAR(r.axial_stiffness * 1e-6, 2.7, 0.3);
  EXPECT_NEAR(r.modes_clamped_Hz(0), 300.0, 25.0);
  EXPECT_NEAR(r.modes_clamped_Hz(1), 412.0, 30.0);
  EXPECT_GT(r.modes_clamped_Hz(0), r.shell_modes_clamped_Hz(0));
  EXPECT_GT(r.estimate.elements, 0.5 * static_cast<double>(r.mesh_elements));
  EXPECT_LT(r.estimate.elements, 2.0 * static_cast<double>(r.mesh_elements));
}

}  // namespace
}  // namespace piezobench::fem
