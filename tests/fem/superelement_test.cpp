// Super-element import: the Ansys APA95ML files against a small independent parser written here,
// the rigid-body precision warning, and bad files.
#include "piezobench/fem/superelement.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <sstream>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "test_util.hpp"
#include "fem_test_data.hpp"

namespace piezobench::fem {
namespace {

namespace fs = std::filesystem;

using test_data::kAnsysDir;
const fs::path kK = kAnsysDir / "piezo_amplified_K.txt";
const fs::path kM = kAnsysDir / "piezo_amplified_M.txt";
const fs::path kMasters = kAnsysDir / "piezo_amplified.txt";

// Independent reader: every '[' starts "[i, j]: value" (sscanf, not the library's parser).
Eigen::MatrixXd parse_ansys_independently(const fs::path& file, int n) {
  const std::string text = test::read_text(file);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  int count = 0;
  for (std::size_t p = text.find('['); p != std::string::npos; p = text.find('[', p + 1)) {
    int i = 0, j = 0;
    double v = 0.0;
    if (std::sscanf(text.c_str() + p, "[ %d , %d ] : %lf", &i, &j, &v) == 3) {
      A(i - 1, j - 1) = v;
      ++count;
    }
  }
  EXPECT_EQ(count, n * n);
  return A;
}

std::string replace_once(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  if (pos != std::string::npos) text.replace(pos, from.size(), to);
  return text;
}



TEST(SuperElement, EnumsRoundTrip) {
  for (Direction d : {Direction::kX, Direction::kY, Direction::kZ, Direction::kRx, Direction::kRy, Direction::kRz}) {
    EXPECT_EQ(direction_from_string(to_string(d)), d);
    EXPECT_EQ(direction_from_string(ansys_label(d)), d);
    EXPECT_EQ(direction_from_string(std::to_string(static_cast<int>(d))), d);
  }
  EXPECT_FALSE(direction_from_string("w").has_value());
  for (SuperElementFormat f : {SuperElementFormat::kAnsysText, SuperElementFormat::kCalculix, SuperElementFormat::kMatrixMarket}) {
    EXPECT_EQ(super_element_format_from_string(to_string(f)), f);
  }
  EXPECT_FALSE(super_element_format_from_string("nastran").has_value());
  EXPECT_EQ(detect_format("a/b.sti"), SuperElementFormat::kCalculix);
  EXPECT_EQ(detect_format("a/b.mtx"), SuperElementFormat::kMatrixMarket);
  EXPECT_EQ(detect_format(kK), SuperElementFormat::kAnsysText);
  EXPECT_EQ(DofLabel::nodal(76423, Direction::kRy).to_string(), "76423.ROTY");
  EXPECT_EQ(DofLabel::modal(3).to_string(), "mode 3");
}

TEST(SuperElement, ReadsTheAnsysApa95mlFilesExactly) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys");
  const SuperElement se = read_ansys_super_element(kK, kM, kMasters);
  ASSERT_EQ(se.size(), 108);
  EXPECT_EQ(se.nodal_dofs(), 78);
  EXPECT_EQ(se.modal_dofs(), 30);
  const std::vector<long> nodes = se.nodes();
  ASSERT_EQ(nodes.size(), 13U);
  EXPECT_EQ(nodes[0], 76423);
  EXPECT_EQ(nodes[1], 76429);
  EXPECT_EQ(nodes[2], 76430);
  EXPECT_EQ(nodes[12], 76440);
  EXPECT_EQ(se.find(76429, Direction::kX), 6);
  EXPECT_EQ(se.find(76440, Direction::kRz), 77);
  EXPECT_FALSE(se.find(76424, Direction::kX).has_value());  // in the node list, not a master
  // Coordinates from out_NLIST.txt beside the listing.
  ASSERT_EQ(se.coordinates.size(), 13U);
  EXPECT_TRUE(test::all_near(se.coordinates.at(76423), Eigen::Vector3d(0, 0.030, 0), {0, 1e-15}));
  EXPECT_TRUE(test::all_near(se.coordinates.at(76430), Eigen::Vector3d(-0.035, 0, 0), {0, 1e-15}));
  EXPECT_TRUE(test::all_near(se.coordinates.at(76440), Eigen::Vector3d(0.035, 0, 0), {0, 1e-15}));
  // Entries equal the independent parse (the file is already exactly symmetric).
  EXPECT_TRUE(test::all_near(se.K, parse_ansys_independently(kK, 108), {0, 0}));
  EXPECT_TRUE(test::all_near(se.M, parse_ansys_independently(kM, 108), {0, 0}));
}

TEST(SuperElement, WarnsThatFourDigitsSpoilTheRigidBodyModes) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys");
  const SuperElement se = read_ansys_super_element(kK, kM, kMasters);
  ASSERT_EQ(se.warnings.size(), 1U);
  EXPECT_NE(se.warnings[0].find("rigid-body modes"), std::string::npos) << se.warnings[0];
  EXPECT_NE(se.warnings[0].find("4 significant digits"), std::string::npos) << se.warnings[0];

  const RigidBodyCheck c = check_rigid_body_modes(se);
  ASSERT_TRUE(c.performed);
  EXPECT_TRUE(c.free_free);
  EXPECT_TRUE(c.spoiled);
  // Independent: the six lowest free-free modes of the dense problem, and the rigid-body content
  // measured against rigid motions built here about the origin (the subspace does not depend on
  // the reference point).
  const Eigen::MatrixXd K = parse_ansys_independently(kK, 108), M = parse_ansys_independently(kM, 108);
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(K, M);
  for (int k = 0; k < 7; ++k) {
    const double l = es.eigenvalues()(k);
    const double f = std::copysign(std::sqrt(std::abs(l)), l) / (2 * std::numbers::pi);
    if (k < 6) {
      EXPECT_TRUE(test::near(c.lowest_modes_Hz(k), f, 1e-9));
      EXPECT_GT(c.rigid_fraction(k), 0.9);
      EXPECT_LE(c.rigid_fraction(k), 1.0 + 1e-9);
    } else {
      EXPECT_TRUE(test::near(c.first_flexible_Hz, f, 1e-9));
    }
  }
  // The rigid-body modes are far from 0 Hz here (hundreds of Hz against ~3 kHz).
  EXPECT_GT(c.lowest_modes_Hz.cwiseAbs().maxCoeff(), 0.05 * c.first_flexible_Hz);
}

TEST(SuperElement, ExactRigidBodyModesDoNotWarn) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys");
  // Two nodes joined by an axial spring along x (6 DOF each, rotations carried by small
  // inertias and stiff torsion/bending between the nodes): a free-free element with an exact
  // null space of rigid motions -> performed, free-free, not spoiled.
  SuperElement se;
  se.source = "spring";
  const double k = 1e6, kr = 1e3;
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(12, 12);
  // Beam along x of length L between nodes at x = 0 and x = L (Euler-Bernoulli, unit EI, EA, GJ).
  const double L = 1.0, EA = k, EI = kr, GJ = kr;
  const auto add = [&](int a, int b, double v) { K(a, b) += v; };
  // axial
  add(0, 0, EA / L); add(6, 6, EA / L); add(0, 6, -EA / L); add(6, 0, -EA / L);
  // torsion
  add(3, 3, GJ / L); add(9, 9, GJ / L); add(3, 9, -GJ / L); add(9, 3, -GJ / L);
  // bending in x-y (v = y displacement, theta_z) and x-z (w, theta_y with sign flip)
  const double c1 = 12 * EI / (L * L * L), c2 = 6 * EI / (L * L), c3 = 4 * EI / L, c4 = 2 * EI / L;
  const int vy[4] = {1, 5, 7, 11};
  const double kb[4][4] = {{c1, c2, -c1, c2}, {c2, c3, -c2, c4}, {-c1, -c2, c1, -c2}, {c2, c4, -c2, c3}};
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) add(vy[a], vy[b], kb[a][b]);
  const int wz[4] = {2, 4, 8, 10};
  const double sgn[4] = {1, -1, 1, -1};
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) add(wz[a], wz[b], sgn[a] * sgn[b] * kb[a][b]);
  se.K = K;
  se.M = Eigen::MatrixXd::Identity(12, 12);
  for (int i : {3, 4, 5, 9, 10, 11}) se.M(i, i) = 1e-2;
  for (long node : {1L, 2L}) {
    for (int d = 1; d <= 6; ++d) se.dofs.push_back(DofLabel::nodal(node, static_cast<Direction>(d)));
  }
  se.coordinates[1] = Eigen::Vector3d(0, 0, 0);
  se.coordinates[2] = Eigen::Vector3d(L, 0, 0);
  se.validate();
  const RigidBodyCheck c = check_rigid_body_modes(se);
  ASSERT_TRUE(c.performed);
  EXPECT_TRUE(c.free_free);
  EXPECT_FALSE(c.spoiled) << c.message;
  EXPECT_LT(c.lowest_modes_Hz.cwiseAbs().maxCoeff(), 1e-4 * c.first_flexible_Hz);
  // Grounding node 1 with springs: no longer free-free, no warning either.
  for (int i = 0; i < 6; ++i) se.K(i, i) += 1e9;
  const RigidBodyCheck g = check_rigid_body_modes(se);
  EXPECT_FALSE(g.free_free);
  EXPECT_FALSE(g.spoiled);
}

// Variants of the Ansys export (skipped, like the other tests on it, when the external data are not
// there: the files are read in SetUp, after the check, not in the constructor).
class BadAnsysFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys");
    k = test::read_text(kK);
    m = test::read_text(kM);
    masters = test::read_text(kMasters);
  }
  test::TempDir dir;
  std::string k, m, masters;
  fs::path kf() const { return dir.path() / "K.txt"; }
  fs::path mf() const { return dir.path() / "M.txt"; }
  fs::path lf() const { return dir.path() / "masters.txt"; }
  void write_all() {
    test::write_text(kf(), k);
    test::write_text(mf(), m);
    test::write_text(lf(), masters);
  }
  SuperElement read() { return read_ansys_super_element(kf(), mf(), lf()); }
};

// Issue 21.5: the 26-byte file '[15000,15000]: 1.0' allocated the 15000 x 15000 matrix (1.77 GB)
// before finding the entries missing; the count is now checked first. Issue 21.6: a directory
// where a file is expected (out_NLIST.txt beside the listing) is an InputError, not exit 1.
TEST(SuperElementHostile, DeclaredSizeWithoutEntriesAndDirectories) {
  test::TempDir dir;
  const fs::path k = dir.path() / "K.txt", m = dir.path() / "M.txt", l = dir.path() / "masters.txt";
  test::write_text(k, "MAT_K:\n[15000,15000]: 1.0\n");
  test::write_text(m, "MAT_M:\n[15000,15000]: 1.0\n");
  test::write_text(l, "1 UX\n2 UX\n");
  test::expect_input_error([&] { (void)read_ansys_super_element(k, m, l); },
                           {k.string(), "225000000 entries of a full 15000 x 15000 matrix", "first missing: [1,1]"});
  test::write_text(k, "MAT_K:\n[1,1]: 1.0 [1,2]: 0.5 [1,2]: 0.5\n");
  test::expect_input_error([&] { (void)read_ansys_super_element(k, m, l); }, {k.string(), "[1,2]", "a repeated entry"});
  test::write_text(k, "MAT_K:\n[1,1]: 2.0 [1,2]: -1.0\n[2,1]: -1.0 [2,2]: 2.0\n");
  test::write_text(m, "MAT_M:\n[1,1]: 1.0 [1,2]: 0.0\n[2,1]: 0.0 [2,2]: 1.0\n");
  fs::create_directories(dir.path() / "out_NLIST.txt");
  test::expect_input_error([&] { (void)read_ansys_super_element(k, m, l); }, {"out_NLIST.txt", "a directory"});
  test::expect_input_error([&] { (void)read_ansys_super_element(dir.path(), m, l); }, {dir.path().string(), "a directory"});
}

TEST_F(BadAnsysFiles, CopiesReadFine) {
  write_all();
  const SuperElement se = read();
  EXPECT_EQ(se.size(), 108);
  // No out_NLIST.txt beside the copy: the coordinates come from the node list inside the listing.
  EXPECT_EQ(se.coordinates.size(), 13U);
}

TEST_F(BadAnsysFiles, TruncatedStiffness) {
  k = k.substr(0, k.size() / 2);
  k = k.substr(0, k.rfind('['));  // cut at an entry boundary: a whole-entry truncation
  write_all();
  test::expect_input_error([&] { (void)read(); }, {kf().string(), "entries", "truncated"});
}

TEST_F(BadAnsysFiles, TruncatedInsideAnEntry) {
  k = k.substr(0, k.rfind("[108,108]") + 5);
  write_all();
  test::expect_input_error([&] { (void)read(); }, {kf().string(), "line 110"});
}

TEST_F(BadAnsysFiles, MissingHeader) {
  k = replace_once(k, "MAT_K:", "");
  write_all();
  test::expect_input_error([&] { (void)read(); }, {kf().string(), "header", "MAT_K"});
}

TEST_F(BadAnsysFiles, AsymmetricStiffness) {
  k = replace_once(k, "[  2,  1]: 2.568e+04", "[  2,  1]: 2.600e+04");
  write_all();
  test::expect_input_error([&] { (void)read(); }, {kf().string(), "K[2,1]", "symmetric"});
}

TEST_F(BadAnsysFiles, NanEntry) {
  m = replace_once(m, "[  1,  1]: 3.913e-02", "[  1,  1]: nan");
  write_all();
  test::expect_input_error([&] { (void)read(); }, {mf().string(), "[1,1]", "finite"});
}

TEST_F(BadAnsysFiles, MassNotPositiveDefinite) {
  m = replace_once(m, "[  1,  1]: 3.913e-02", "[  1,  1]:-3.913e-02");
  write_all();
  test::expect_input_error([&] { (void)read(); }, {kf().string(), "M", "positive definite"});
}

TEST_F(BadAnsysFiles, ListingWithANodeMissingDoesNotMatchTheMatrices) {
  // Drop the six rows of node 76440: 72 master rows would leave 36 "modal" rows, but rows 73-78
  // of K are coupled to the interface.
  for (const char* label : {"UX  ", "UY  ", "UZ  ", "ROTX", "ROTY", "ROTZ"}) {
    masters = replace_once(masters, std::string("   76440 ") + label + "\n", "");
  }
  write_all();
  test::expect_input_error([&] { (void)read(); }, {lf().string(), "master DOF", "does not match"});
}

TEST_F(BadAnsysFiles, ListingLongerThanTheMatrices) {
  std::string extra;
  for (int node = 90000; node < 90006; ++node)
    for (const char* label : {"UX", "UY", "UZ", "ROTX", "ROTY", "ROTZ"}) extra += "   " + std::to_string(node) + " " + label + "\n";
  masters = replace_once(masters, "   76440 ROTZ\n", "   76440 ROTZ\n" + extra);
  write_all();
  test::expect_input_error([&] { (void)read(); }, {lf().string(), "master DOF", "at most 108 rows", "114 rows"});
}

TEST_F(BadAnsysFiles, NodeWithoutCoordinates) {
  PIEZOBENCH_SKIP_WITHOUT_SHARED_DATA("apa95ml-ansys");
  write_all();
  const fs::path nlist = dir.path() / "nlist.txt";
  std::string text = test::read_text(kAnsysDir / "out_NLIST.txt");
  text = replace_once(text, "    76440  0.35000E-001", "    76441  0.35000E-001");
  test::write_text(nlist, text);
  test::expect_input_error([&] { (void)read_ansys_super_element(kf(), mf(), lf(), nlist); }, {nlist.string(), "node 76440"});
}

TEST_F(BadAnsysFiles, SizesOfKAndMDiffer) {
  m = m.substr(0, m.find("[108,  1]"));
  write_all();
  test::expect_input_error([&] { (void)read(); }, {mf().string(), "entries"});
}

}  // namespace
}  // namespace piezobench::fem
