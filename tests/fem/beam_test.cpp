// Stack beams (issue 15): the 3D Euler-Bernoulli beam against closed-form results, and adding it
// to a super element.
#include "piezobench/fem/beam.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <numbers>

#include "piezobench/core/error.hpp"
#include "piezobench/fem/structural_model.hpp"
#include "test_util.hpp"

namespace piezobench::fem {
namespace {

const BeamSection kStack{48e9, 0.31, 7800.0, 1e-4};  // Table 4.1

TEST(Beam, AxialStiffnessIsCeAOverLAlongAnyDirection) {
  const Eigen::Vector3d a(0.01, -0.02, 0.003);
  const Eigen::Vector3d dir = Eigen::Vector3d(1.0, 2.0, -0.5).normalized();
  const BeamMatrices b = beam_matrices(a, a + 0.02 * dir, kStack);
  EXPECT_NEAR(b.length, 0.02, 1e-15);
  EXPECT_NEAR(b.axial_stiffness, 2.4e8, 1e-3);  // k = cE A / L = 48e9 x 1e-4 / 0.02 (report, eq. 4.1)
  // Pull the ends apart along the beam: the force is k times the extension, along the beam.
  Eigen::Matrix<double, 12, 1> u = Eigen::Matrix<double, 12, 1>::Zero();
  u.segment<3>(6) = 1e-6 * dir;
  const Eigen::Matrix<double, 12, 1> f = b.K * u;
  EXPECT_NEAR((f.segment<3>(6) - 2.4e8 * 1e-6 * dir).norm(), 0.0, 1e-6);
  EXPECT_NEAR((f.segment<3>(0) + 2.4e8 * 1e-6 * dir).norm(), 0.0, 1e-6);
}

TEST(Beam, RigidMotionsCostNothingAndCarryTheMass) {
  const Eigen::Vector3d a(0.0, 0.0, 0.0), b(0.012, 0.004, -0.009);
  const BeamMatrices m = beam_matrices(a, b, kStack);
  // Six rigid motions: translations and small rotations about a (u = theta x r).
  Eigen::Matrix<double, 12, 6> rigid = Eigen::Matrix<double, 12, 6>::Zero();
  for (int d = 0; d < 3; ++d) {
    rigid(d, d) = rigid(6 + d, d) = 1.0;
    const Eigen::Vector3d theta = Eigen::Vector3d::Unit(d);
    rigid.block<3, 1>(3, 3 + d) = theta;
    rigid.block<3, 1>(9, 3 + d) = theta;
    rigid.block<3, 1>(6, 3 + d) = theta.cross(b - a);
  }
  EXPECT_LT((m.K * rigid).norm(), 1e-6 * m.K.norm());
  // Total mass rho A L seen by each translation.
  const double mass = 7800.0 * 1e-4 * b.norm();
  for (int d = 0; d < 3; ++d) EXPECT_NEAR(rigid.col(d).dot(m.M * rigid.col(d)), mass, 1e-12 * mass);
  // Symmetric, K positive semi-definite with exactly 6 zero eigenvalues.
  EXPECT_LT((m.K - m.K.transpose()).norm(), 1e-9 * m.K.norm());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 12, 12>> es(m.K);
  EXPECT_LT(std::abs(es.eigenvalues()(5)), 1e-9 * es.eigenvalues()(11));
  EXPECT_GT(es.eigenvalues()(6), 1e-6 * es.eigenvalues()(11));
}

TEST(Beam, CantileverTipStiffnessAndFirstBendingMode) {
  // Clamped at a, loaded at b across the beam: k = 3 E I / L^3 (Euler-Bernoulli, exact for one element).
  const double L = 0.06, E = 48e9, A = 1e-4, I = A * A / 12.0;
  const BeamMatrices m = beam_matrices(Eigen::Vector3d::Zero(), Eigen::Vector3d(L, 0, 0), kStack);
  const Eigen::Matrix<double, 6, 6> kbb = m.K.bottomRightCorner<6, 6>();
  for (int d : {1, 2}) {
    Eigen::Matrix<double, 6, 1> f = Eigen::Matrix<double, 6, 1>::Zero();
    f(d) = 1.0;
    const Eigen::Matrix<double, 6, 1> u = kbb.ldlt().solve(f);
    EXPECT_NEAR(1.0 / u(d), 3.0 * E * I / (L * L * L), 1e-6 * 3.0 * E * I / (L * L * L));
  }
  // Axial mode of the clamped-free bar, one consistent element: w = sqrt(3 E / rho) / L (1.10 x the exact pi/2 sqrt(E/rho)/L).
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> es(kbb, m.M.bottomRightCorner<6, 6>());
  const double w_axial = std::sqrt(3.0 * E / 7800.0) / L;
  bool found = false;
  for (int k = 0; k < 6; ++k) found = found || std::abs(std::sqrt(es.eigenvalues()(k)) / w_axial - 1.0) < 1e-9;
  EXPECT_TRUE(found);
}

TEST(Beam, AddNodeAndBeamToASuperElement) {
  // A two-node element made of nothing, plus one modal DOF; then a beam between a new node and node 1.
  SuperElement se;
  se.K = Eigen::MatrixXd::Identity(13, 13);
  se.M = Eigen::MatrixXd::Identity(13, 13);
  for (long n : {1L, 2L}) {
    for (int d = 1; d <= 6; ++d) se.dofs.push_back(DofLabel::nodal(n, static_cast<Direction>(d)));
  }
  se.dofs.push_back(DofLabel::modal(1));
  se.coordinates[1] = Eigen::Vector3d(0, 0, 0);
  se.coordinates[2] = Eigen::Vector3d(0.06, 0, 0);
  se.K(12, 0) = se.K(0, 12) = 0.5;  // a coupling that must follow the modal DOF
  add_node(se, 7, Eigen::Vector3d(0.04, 0, 0));
  ASSERT_EQ(se.size(), 19);
  EXPECT_EQ(se.nodal_dofs(), 18);
  EXPECT_EQ(se.dofs[12], DofLabel::nodal(7, Direction::kX));
  EXPECT_TRUE(se.dofs[18].is_modal());
  EXPECT_EQ(se.K(18, 0), 0.5);
  EXPECT_EQ(se.K(12, 12), 0.0);
  const BeamMatrices b = add_beam(se, 1, 7, kStack, "stack");
  EXPECT_NEAR(b.axial_stiffness, 48e9 * 1e-4 / 0.04, 1e-3);
  EXPECT_NEAR(se.K(0, 0), 1.0 + b.axial_stiffness, 1e-3);
  EXPECT_NEAR(se.K(0, 12), -b.axial_stiffness, 1e-3);
  se.validate();
  EXPECT_THROW(add_node(se, 7, Eigen::Vector3d::Zero()), InputError);
  test::expect_input_error([&] { (void)add_beam(se, 1, 99, kStack, "stack"); }, {"stack"});
  test::expect_input_error([] { (void)BeamSection::parse("48e9,0.31,7800", "--stack"); }, {"--stack"});
  test::expect_input_error([] { (void)BeamSection::parse("48e9,0.31,7800,-1", "--stack"); }, {"AREA > 0"});
  const BeamSection s = BeamSection::parse("48e9, 0.31, 7800, 5.4e-5", "--stack");
  EXPECT_EQ(s.area, 5.4e-5);
}

}  // namespace
}  // namespace piezobench::fem
