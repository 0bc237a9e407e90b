// Matrix files: CalculiX dumps, Matrix Market, DOF lists, *NODE decks and the writers.
#include "piezobench/fem/matrix_io.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "piezobench/core/error.hpp"
#include "test_util.hpp"

namespace piezobench::fem {
namespace {

namespace fs = std::filesystem;



TEST(MatrixIo, ReadsACalculixUpperTriangle) {
  test::TempDir dir;
  // 3 x 3: [[4, -1, 0], [-1, 4, -2], [0, -2, 5]] written as ccx does (column by column, upper).
  test::write_text(dir.path() / "a.sti", "1 1  4.0000000000000e+00\n1 2 -1.0000000000000e+00\n2 2  4.0e+00\n2 3 -2.0e+00\n3 3  5.0e+00\n");
  test::write_text(dir.path() / "a.mas", "1 1 2.0\n2 2 2.0\n3 3 2.0\n1 2 0.5\n");
  test::write_text(dir.path() / "a.dof", "1.1\n1.2\n7.3\n");
  const SparseMatrix K = read_calculix_matrix(dir.path() / "a.sti", 3);
  const Eigen::MatrixXd expected = (Eigen::MatrixXd(3, 3) << 4, -1, 0, -1, 4, -2, 0, -2, 5).finished();
  EXPECT_TRUE(test::all_near(Eigen::MatrixXd(K), expected, {0, 0}));
  const std::vector<DofLabel> dofs = read_calculix_dofs(dir.path() / "a.dof");
  ASSERT_EQ(dofs.size(), 3U);
  EXPECT_EQ(dofs[2], DofLabel::nodal(7, Direction::kZ));
  const SparseModel model = read_calculix_model(dir.path() / "a.sti", dir.path() / "a.mas", dir.path() / "a.dof");
  EXPECT_EQ(model.size(), 3);
  EXPECT_EQ(Eigen::MatrixXd(model.M)(1, 0), 0.5);
}

TEST(MatrixIo, BadCalculixFiles) {
  test::TempDir dir;
  const auto f = dir.path() / "bad.sti";
  test::write_text(f, "1 1 4.0\n2 2 4.0\n1 2 1.0\n2 1 1.0\n");  // both triangles: a repeated entry
  test::expect_input_error([&] { (void)read_calculix_matrix(f, 2); }, {f.string(), "repeated"});
  test::write_text(f, "1 1 4.0\n1 2 1.0\n");  // truncated: no diagonal for row 2
  test::expect_input_error([&] { (void)read_calculix_matrix(f, 2); }, {f.string(), "row 2", "truncated"});
  test::write_text(f, "1 1 4.0\n2 2 4.0\n1 3 1.0\n");
  test::expect_input_error([&] { (void)read_calculix_matrix(f, 2); }, {f.string(), "line 3"});
  test::write_text(f, "1 1 4.0\n2 2 nan\n");
  test::expect_input_error([&] { (void)read_calculix_matrix(f, 2); }, {f.string(), "line 2", "finite"});
  test::write_text(f, "1 1 4.0\n2 2 4.0 x\n");
  test::expect_input_error([&] { (void)read_calculix_matrix(f, 2); }, {f.string(), "line 2"});
  const auto d = dir.path() / "bad.dof";
  test::write_text(d, "1.1\n1.7\n");
  test::expect_input_error([&] { (void)read_calculix_dofs(d); }, {d.string(), "line 2"});
  test::write_text(d, "1.1\n1.1\n");
  test::expect_input_error([&] { (void)read_calculix_dofs(d); }, {d.string(), "line 2", "once"});
  // .sti larger than the .dof list.
  test::write_text(d, "1.1\n");
  test::write_text(f, "1 1 4.0\n2 2 4.0\n");
  test::expect_input_error([&] { (void)read_calculix_model(f, f, d); }, {f.string(), "line 2", "1..1"});
}

TEST(MatrixIo, MatrixMarketRoundTripAndKinds) {
  test::TempDir dir;
  const Eigen::MatrixXd A = (Eigen::MatrixXd(3, 3) << 1.0 / 3, 0, 2e-9, 0, 5, -1, 2e-9, -1, 7).finished();
  const auto f = dir.path() / "a.mtx";
  write_matrix_market(f, A, "a test\nwith two lines");
  EXPECT_TRUE(test::all_near(Eigen::MatrixXd(read_matrix_market(f)), A, {0, 0}));  // 17 digits: exact
  // General storage and the upper triangle of a symmetric file are accepted too.
  test::write_text(f, "%%MatrixMarket matrix coordinate real general\n% c\n2 2 4\n1 1 1\n1 2 2\n2 1 2\n2 2 3\n");
  EXPECT_TRUE(test::all_near(Eigen::MatrixXd(read_matrix_market(f)), (Eigen::MatrixXd(2, 2) << 1, 2, 2, 3).finished(), {0, 0}));
  test::write_text(f, "%%MatrixMarket matrix coordinate integer symmetric\n2 2 3\n1 1 1\n1 2 2\n2 2 3\n");
  EXPECT_TRUE(test::all_near(Eigen::MatrixXd(read_matrix_market(f)), (Eigen::MatrixXd(2, 2) << 1, 2, 2, 3).finished(), {0, 0}));
}

TEST(MatrixIo, BadMatrixMarketFiles) {
  test::TempDir dir;
  const auto f = dir.path() / "bad.mtx";
  test::write_text(f, "%%MatrixMarket matrix coordinate real symmetric\n2 2 3\n1 1 1\n2 1 2\n");
  test::expect_input_error([&] { (void)read_matrix_market(f); }, {f.string(), "entries", "3 entries", "truncated"});
  test::write_text(f, "%%MatrixMarket matrix array real general\n2 2\n1\n2\n3\n4\n");
  test::expect_input_error([&] { (void)read_matrix_market(f); }, {f.string(), "header", "coordinate"});
  test::write_text(f, "%%MatrixMarket matrix coordinate complex general\n1 1 1\n1 1 1 0\n");
  test::expect_input_error([&] { (void)read_matrix_market(f); }, {f.string(), "header", "real"});
  test::write_text(f, "%%MatrixMarket matrix coordinate real general\n2 2 1\n3 1 1\n");
  test::expect_input_error([&] { (void)read_matrix_market(f); }, {f.string(), "line 3", "indices"});
  test::write_text(f, "%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n2 1 1\n1 2 1\n");
  test::expect_input_error([&] { (void)read_matrix_market(f); }, {f.string(), "repeated"});
  test::write_text(f, "1 2 3\n");
  test::expect_input_error([&] { (void)read_matrix_market(f); }, {f.string(), "header"});
}

TEST(MatrixIo, DofListRoundTrip) {
  test::TempDir dir;
  SuperElement se;
  se.dofs = {DofLabel::nodal(10, Direction::kX), DofLabel::nodal(10, Direction::kRz), DofLabel::nodal(11, Direction::kY),
             DofLabel::modal(1), DofLabel::modal(2)};
  se.coordinates[10] = Eigen::Vector3d(0.1, -0.2, 1.0 / 3);
  const auto f = dir.path() / "dofs.txt";
  write_dof_list(f, se);
  const DofList back = read_dof_list(f);
  ASSERT_EQ(back.dofs.size(), 5U);
  for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(back.dofs[i], se.dofs[i]) << i;
  ASSERT_EQ(back.coordinates.size(), 1U);  // node 11 has no coordinates
  EXPECT_TRUE(test::all_near(back.coordinates.at(10), se.coordinates.at(10), {0, 0}));
  test::write_text(f, "1 UX\nMODE 1\n1 UY\n");
  test::expect_input_error([&] { (void)read_dof_list(f); }, {f.string(), "line 3", "before the modal"});
  test::write_text(f, "1 UX\nMODE 2\n");
  test::expect_input_error([&] { (void)read_dof_list(f); }, {f.string(), "line 2", "MODE 1"});
  test::write_text(f, "1 UW 0 0 0\n");
  test::expect_input_error([&] { (void)read_dof_list(f); }, {f.string(), "line 1"});
}

TEST(MatrixIo, InpNodesFollowIncludes) {
  test::TempDir dir;
  test::write_text(dir.path() / "mesh.inp", "*NODE, NSET=ALL\n1, 0.0, 0.0, 0.0\n2, 1.0, 2.0, 3.0\n*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n");
  test::write_text(dir.path() / "deck.inp", "** comment\n*INCLUDE, INPUT=mesh.inp\n*NODE\n3, 4.5, 0, -1e-3\n*NODE PRINT, NSET=ALL\nU\n");
  const auto nodes = read_inp_nodes(dir.path() / "deck.inp");
  ASSERT_EQ(nodes.size(), 3U);
  EXPECT_TRUE(test::all_near(nodes.at(2), Eigen::Vector3d(1, 2, 3), {0, 0}));
  EXPECT_TRUE(test::all_near(nodes.at(3), Eigen::Vector3d(4.5, 0, -1e-3), {0, 0}));
  test::write_text(dir.path() / "bad.inp", "*NODE\n1, 0.0, abc, 0.0\n");
  test::expect_input_error([&] { (void)read_inp_nodes(dir.path() / "bad.inp"); }, {"bad.inp", "line 2"});
}

TEST(MatrixIo, SuperElementAndSimscapeWriters) {
  test::TempDir dir;
  SuperElement se;
  se.K = Eigen::MatrixXd::Identity(7, 7) * 3.0;
  se.K(0, 1) = se.K(1, 0) = 0.5;
  se.M = Eigen::MatrixXd::Identity(7, 7);
  for (int d = 1; d <= 6; ++d) se.dofs.push_back(DofLabel::nodal(5, static_cast<Direction>(d)));
  se.dofs.push_back(DofLabel::modal(1));
  se.coordinates[5] = Eigen::Vector3d(1, 2, 3);
  se.source = "test";
  const auto files = write_super_element(dir.path(), "se", se);
  ASSERT_EQ(files.size(), 3U);
  const SuperElement back = read_matrix_market_super_element(files[0], files[1], files[2]);
  EXPECT_TRUE(test::all_near(back.K, se.K, {0, 0}));
  EXPECT_TRUE(test::all_near(back.M, se.M, {0, 0}));
  EXPECT_EQ(back.dofs, se.dofs);
  const auto m = write_simscape(dir.path(), "se", se);
  const std::string text = test::read_text(m);
  EXPECT_NE(text.find("frame_nodes = [5];"), std::string::npos) << text;
  EXPECT_NE(text.find("origins = [\n  1 2 3\n];"), std::string::npos) << text;
  EXPECT_NE(text.find("K = [\n  3 0.5 0 0 0 0 0\n"), std::string::npos) << text;
  // A node with only translations cannot be a Simscape frame.
  se.dofs[3] = DofLabel::nodal(6, Direction::kX);
  test::expect_input_error([&] { (void)write_simscape(dir.path(), "se", se); }, {"dofs", "node 5"});
}

}  // namespace
}  // namespace piezobench::fem
