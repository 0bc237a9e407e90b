// Flatness geometry of the virtual units (src/bench/flatness.hpp): the least-squares plane and
// the heights made by a tilt and a warp, against closed forms.
#include "flatness.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "test_util.hpp"

namespace piezobench::bench::detail {
namespace {

using test::near;

TEST(PlaneFlatness, PointsOnAPlaneAreFlat) {
  const Eigen::Matrix<double, 8, 3> p = probe_layout();
  const Eigen::VectorXd z = 1e-3 + 2e-4 * p.col(0).array() - 3e-4 * p.col(1).array();
  EXPECT_NEAR(plane_flatness(p.col(0), p.col(1), z), 0.0, 1e-15);
}

TEST(PlaneFlatness, ResidualsOfAKnownPattern) {
  // Four points at the corners of a square, heights +h, -h, -h, +h (a saddle): the best plane is
  // z = 0 (the pattern is orthogonal to 1, x and y), so the peak-to-valley is 2 h.
  Eigen::VectorXd x(4), y(4), z(4);
  x << -1, 1, -1, 1;
  y << -1, -1, 1, 1;
  z << 1e-6, -1e-6, -1e-6, 1e-6;
  EXPECT_TRUE(near(plane_flatness(x, y, z), 2e-6, 1e-12));
}

TEST(ProbeLayout, FourPointsOnEachInterface) {
  const Eigen::Matrix<double, 8, 3> p = probe_layout();
  EXPECT_EQ((p.col(2).array() == 1.0).count(), 4);
  EXPECT_EQ((p.col(2).array() == 2.0).count(), 4);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(p(i, 1) < 0.0, p(i, 2) == 1.0);
}

TEST(ProbeHeights, WarpIsASaddleOfItsAmplitude) {
  UnitTruth u;
  u.flatness_warp = 3e-6;
  const Eigen::Matrix<double, 8, 1> z = probe_heights(u);
  for (int i = 0; i < 8; ++i) EXPECT_NEAR(std::abs(z(i)), 3e-6, 1e-18);
  const Eigen::Matrix<double, 8, 3> p = probe_layout();
  // Both interfaces carry the same saddle: the best plane is flat, the peak-to-valley 2 w.
  EXPECT_TRUE(near(plane_flatness(p.col(0), p.col(1), z), 6e-6, 1e-12));
}

TEST(ProbeHeights, TiltOfInterfaceTwoAboutItsCentre) {
  UnitTruth u;
  u.flatness_tilt = 1e-4;
  u.flatness_tilt_direction = 0.0;  // axis along x: heights change with y across interface 2
  const Eigen::Matrix<double, 8, 1> z = probe_heights(u);
  const Eigen::Matrix<double, 8, 3> p = probe_layout();
  for (int i = 0; i < 8; ++i) {
    const double expected = p(i, 2) == 2.0 ? std::tan(1e-4) * (p(i, 1) - 0.025) : 0.0;
    EXPECT_NEAR(z(i), expected, 1e-18);
  }
  // Interface 1 flat at 0, interface 2 at +-0.4 um: the plane cannot follow a tilt of one interface
  // only, so the flatness is of the order of the tilt's height change (0.8 um here).
  const double f = plane_flatness(p.col(0), p.col(1), z);
  EXPECT_GT(f, 0.3e-6);
  EXPECT_LT(f, 0.9e-6);
}

}  // namespace
}  // namespace piezobench::bench::detail
