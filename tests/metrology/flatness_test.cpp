#include "piezobench/metrology/flatness.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "test_util.hpp"

#include "piezobench/core/eigen_solvers.hpp"

namespace piezobench::metrology {
namespace {

using Eigen::Matrix3Xd;
using Eigen::Vector3d;
using test::near;

Eigen::Matrix3d rotation(double a, double b, double c) {
  return (Eigen::AngleAxisd(a, Vector3d::UnitZ()) * Eigen::AngleAxisd(b, Vector3d::UnitY()) *
          Eigen::AngleAxisd(c, Vector3d::UnitX()))
      .toRotationMatrix();
}

Matrix3Xd moved(const Matrix3Xd& p, const Eigen::Matrix3d& r, const Vector3d& shift) {
  return (r * p).colwise() + shift;
}

FlatnessResult mz(const Matrix3Xd& p) { return flatness(p, {FlatnessMethod::kMinimumZone}); }
FlatnessResult ls(const Matrix3Xd& p) { return flatness(p, {FlatnessMethod::kLeastSquares}); }

// Width of the zone with unit normal n.
double width(const Matrix3Xd& p, const Vector3d& n) {
  const Eigen::VectorXd d = p.transpose() * n;
  return d.maxCoeff() - d.minCoeff();
}

// Independent brute force: the narrowest zone over a grid of normals on the half sphere, then, from
// each of the 20 best grid normals, local grids of 11 x 11 normals n0 + a e1 + b e2 (e1, e2 tangent
// at n0) recentred on the best one and shrunk by half, 60 times. Only widths of real zones are
// evaluated, so the result is >= the true minimum, and it converges to it.
double brute_force_minimum_zone(const Matrix3Xd& p) {
  std::vector<std::pair<double, Vector3d>> grid;
  const int nt = 90, np = 180;
  for (int i = 0; i <= nt; ++i) {
    for (int j = 0; j < np; ++j) {
      const double th = M_PI / 2 * i / nt, ph = 2 * M_PI * j / np;
      const Vector3d n(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
      grid.push_back({width(p, n), n});
    }
  }
  std::partial_sort(grid.begin(), grid.begin() + 20, grid.end(),
                    [](const auto& a, const auto& b) { return a.first < b.first; });
  double best = std::numeric_limits<double>::infinity();
  for (int s = 0; s < 20; ++s) {
    Vector3d n0 = grid[static_cast<std::size_t>(s)].second;
    double w0 = grid[static_cast<std::size_t>(s)].first;
    double half = 2.0 * M_PI / np;
    for (int it = 0; it < 60; ++it) {
      const Vector3d e1 = n0.unitOrthogonal();
      const Vector3d e2 = n0.cross(e1);
      Vector3d next = n0;
      for (int a = -5; a <= 5; ++a) {
        for (int b = -5; b <= 5; ++b) {
          const Vector3d n = (n0 + half * (a / 5.0) * e1 + half * (b / 5.0) * e2).normalized();
          const double w = width(p, n);
          if (w < w0) {
            w0 = w;
            next = n;
          }
        }
      }
      n0 = next;
      half *= 0.5;
    }
    best = std::min(best, w0);
  }
  return best;
}

TEST(Flatness, MethodNamesRoundTrip) {
  for (const auto m : {FlatnessMethod::kLeastSquares, FlatnessMethod::kMinimumZone}) {
    EXPECT_EQ(flatness_method_from_string(to_string(m)), m);
  }
  const std::string msg = test::input_error([] { (void)flatness_method_from_string("best-fit", "campaign.toml"); }, "method");
  EXPECT_TRUE(test::contains(msg, "campaign.toml")) << msg;
  EXPECT_TRUE(test::contains(msg, "minimum-zone")) << msg;
}

// Two interfaces of 4 probe points each, on two parallel planes h apart, moved anywhere in space:
// both methods give h.
TEST(Flatness, TwoParallelInterfacesGiveTheirDistance) {
  const double h = 7e-6;
  Matrix3Xd p(3, 8);
  p << 0, 0.03, 0.03, 0, 0, 0.03, 0.03, 0,  //
      0, 0, 0.02, 0.02, 0, 0, 0.02, 0.02,   //
      0, 0, 0, 0, h, h, h, h;
  const Matrix3Xd q = moved(p, rotation(0.3, -1.1, 0.7), Vector3d(0.1, -2.0, 5.0));
  const FlatnessResult a = ls(q);
  const FlatnessResult b = mz(q);
  EXPECT_TRUE(near(a.flatness, h, 1e-7));
  EXPECT_TRUE(near(b.flatness, h, 1e-7));
  // The reference plane is parallel to the interfaces.
  const Vector3d n = rotation(0.3, -1.1, 0.7) * Vector3d::UnitZ();
  EXPECT_NEAR(std::abs(a.plane.normal.dot(n)), 1.0, 1e-12);
  EXPECT_NEAR(std::abs(b.plane.normal.dot(n)), 1.0, 1e-12);
  EXPECT_EQ(b.contacts.size(), 8u);
  // Mid-plane: deviations +-h/2.
  EXPECT_NEAR(b.deviations.cwiseAbs().maxCoeff(), h / 2, 1e-15);
}

// A saddle of four points (+d, -d, -d, +d at the corners of a square): the least-squares plane is the
// square's plane and the minimum zone is the 2-2 configuration through the diagonals; both 2 d.
TEST(Flatness, SaddleIsTwoTwoConfiguration) {
  const double d = 3e-6;
  Matrix3Xd p(3, 4);
  p << 1, -1, -1, 1,  //
      1, 1, -1, -1,   //
      d, -d, d, -d;
  p.topRows(2) *= 0.01;
  const Matrix3Xd q = moved(p, rotation(-0.4, 0.2, 2.0), Vector3d(1, 2, 3));
  EXPECT_TRUE(near(ls(q).flatness, 2 * d, 1e-7));
  const FlatnessResult z = mz(q);
  EXPECT_TRUE(near(z.flatness, 2 * d, 1e-7));
  EXPECT_EQ(z.contacts.size(), 4u);
}

// Regular tetrahedron of edge 2 sqrt(2): its width is the distance between opposite edges, 2
// (2-2); the cube of side 2: width 2 (3-1, a face).
TEST(Flatness, TetrahedronAndCubeWidths) {
  Matrix3Xd tet(3, 4);
  tet << 1, 1, -1, -1,  //
      1, -1, 1, -1,     //
      1, -1, -1, 1;
  EXPECT_TRUE(near(mz(moved(tet, rotation(0.1, 0.2, 0.3), Vector3d(4, 5, 6))).flatness, 2.0, 1e-12));
  Matrix3Xd cube(3, 8);
  int k = 0;
  for (int i : {-1, 1})
    for (int j : {-1, 1})
      for (int l : {-1, 1}) cube.col(k++) = Vector3d(i, j, l);
  EXPECT_TRUE(near(mz(moved(cube, rotation(1.0, 0.5, -0.2), Vector3d::Zero())).flatness, 2.0, 1e-12));
}

// 3-1: a triangle and one point at height h above its inside.
TEST(Flatness, TriangleAndApexIsThreeOneConfiguration) {
  const double h = 1e-3;
  Matrix3Xd p(3, 4);
  p << 0, 4, 0, 1,  //
      0, 0, 4, 1,   //
      0, 0, 0, h;
  const FlatnessResult z = mz(moved(p, rotation(0.7, 0.7, 0.7), Vector3d(-1, 0, 1)));
  EXPECT_TRUE(near(z.flatness, h, 1e-10));
  EXPECT_EQ(z.contacts.size(), 4u);
}

// The least-squares plane with orthogonal distances agrees with the ordinary z = a x + b y + c
// regression for a nearly horizontal interface (they differ by the square of the tilt).
TEST(Flatness, LeastSquaresMatchesRegressionForSmallTilt) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 2e-6);
  std::uniform_real_distribution<double> pos(-0.02, 0.02);
  Matrix3Xd p(3, 8);
  for (int i = 0; i < 8; ++i) {
    const double x = pos(rng), y = pos(rng);
    p.col(i) = Vector3d(x, y, 1e-4 * x - 2e-4 * y + 0.05 + noise(rng));
  }
  Eigen::MatrixXd a(8, 3);
  a << p.row(0).transpose(), p.row(1).transpose(), Eigen::VectorXd::Ones(8);
  const Eigen::Vector3d coef = a.colPivHouseholderQr().solve(p.row(2).transpose());
  const Eigen::VectorXd vertical = p.row(2).transpose() - a * coef;
  const double expected = (vertical.maxCoeff() - vertical.minCoeff()) / std::sqrt(1 + coef(0) * coef(0) + coef(1) * coef(1));
  EXPECT_TRUE(near(ls(p).flatness, expected, 1e-6));
  EXPECT_LE(mz(p).flatness, ls(p).flatness * (1 + 1e-12));
}

// Minimum zone against the independent brute force on random point sets (generic positions, and
// flat probe-like sets).
TEST(Flatness, MinimumZoneEqualsBruteForce) {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 8; ++trial) {
    const int n = 5 + trial;
    const double thickness = trial % 2 == 0 ? 0.3 : 0.01;
    Matrix3Xd p(3, n);
    for (int i = 0; i < n; ++i) p.col(i) = Vector3d(u(rng), u(rng), thickness * u(rng));
    p = moved(p, rotation(u(rng), u(rng), u(rng)), Vector3d(u(rng), u(rng), u(rng)));
    const FlatnessResult z = mz(p);
    const double brute = brute_force_minimum_zone(p);
    EXPECT_LE(z.flatness, brute * (1 + 1e-12)) << "trial " << trial;
    EXPECT_TRUE(near(brute, z.flatness, 1e-7)) << "trial " << trial;
    EXPECT_LE(z.flatness, ls(p).flatness * (1 + 1e-12));
    // The reported zone holds every point.
    EXPECT_LE(z.deviations.cwiseAbs().maxCoeff(), z.flatness / 2 * (1 + 1e-12));
    EXPECT_GE(z.contacts.size(), 4u);
  }
}

TEST(Flatness, BadInputNamesThePoints) {
  Matrix3Xd two(3, 2);
  two.setZero();
  EXPECT_TRUE(test::contains(test::input_error([&] { (void)flatness(two, {}, "apa1.mat"); }, "points"), "apa1.mat"));
  Matrix3Xd nan = Matrix3Xd::Random(3, 5);
  nan(2, 3) = std::nan("");
  EXPECT_TRUE(test::contains(test::input_error([&] { (void)flatness(nan); }, "points"), "point 3"));
  Matrix3Xd line(3, 4);
  line << 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3;
  EXPECT_TRUE(test::contains(test::input_error([&] { (void)flatness(line); }, "points"), "one line"));
  const Matrix3Xd many = Matrix3Xd::Random(3, 101);
  EXPECT_TRUE(test::contains(test::input_error([&] { (void)mz(many); }, "points"), "at most 100"));
  EXPECT_NO_THROW((void)ls(many));
  FlatnessOptions bad;
  bad.max_minimum_zone_points = 2;
  test::input_error([&] { (void)flatness(Matrix3Xd::Random(3, 5), bad); }, "max_minimum_zone_points");
}

}  // namespace
}  // namespace piezobench::metrology
