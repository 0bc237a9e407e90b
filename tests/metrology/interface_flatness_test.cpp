#include "piezobench/metrology/interface_flatness.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "piezobench/core/error.hpp"

namespace piezobench::metrology::interface_flatness_test {
namespace {

using Eigen::Matrix3Xd;
using Eigen::Vector3d;
using Eigen::VectorXd;

constexpr double kD = 2e-6;  // m, half the saddle's height

// Two interfaces, each a saddle of 4 points (x, y) = (+-1, +-1) mm with z = +d on one diagonal and
// -d on the other, the second shifted 4 mm in x: z is uncorrelated with x and y, so the
// least-squares plane is z = 0 and the flatness 2 d; the minimum zone of each saddle is the
// distance between its two diagonals, 2 d, so that of the whole set is 2 d too. Then tilted by a
// known rotation and moved: flatness does not change.
Matrix3Xd saddles(const Eigen::Matrix3d& rotation, const Vector3d& shift) {
  Matrix3Xd p(3, 8);
  const double a = 1e-3;
  for (int i = 0; i < 2; ++i) {
    const double x0 = 4e-3 * i;
    p.col(4 * i + 0) << x0 + a, a, kD;
    p.col(4 * i + 1) << x0 - a, -a, kD;
    p.col(4 * i + 2) << x0 + a, -a, -kD;
    p.col(4 * i + 3) << x0 - a, a, -kD;
  }
  return (rotation * p).colwise() + shift;
}

const Eigen::Matrix3d kTilt = (Eigen::AngleAxisd(0.3, Vector3d::UnitZ()) * Eigen::AngleAxisd(0.02, Vector3d::UnitY()) *
                               Eigen::AngleAxisd(-0.01, Vector3d::UnitX())).toRotationMatrix();

FlatnessAnalysisOptions options(FlatnessMethod method) {
  FlatnessAnalysisOptions o;
  o.method = method;
  o.source = "test";
  o.field = "points";
  return o;
}

TEST(InterfaceFlatness, TiltedSaddlesHaveTheirKnownFlatness) {
  const Matrix3Xd p = saddles(kTilt, Vector3d(0.1, -0.2, 0.05));
  const VectorXd ids = (VectorXd(8) << 1, 1, 1, 1, 2, 2, 2, 2).finished();
  const FlatnessAnalysisResult r = analyze_flatness(p, ids, options(FlatnessMethod::kMinimumZone));
  EXPECT_EQ(r.method, FlatnessMethod::kMinimumZone);
  EXPECT_EQ(r.points, 8);
  EXPECT_NEAR(r.least_squares_m, 2 * kD, 1e-12);
  ASSERT_TRUE(r.minimum_zone_m.has_value());
  EXPECT_NEAR(*r.minimum_zone_m, 2 * kD, 1e-12);
  EXPECT_DOUBLE_EQ(r.flatness_m, *r.minimum_zone_m);
  ASSERT_EQ(r.per_interface.size(), 2u);
  EXPECT_EQ(r.per_interface[0].id, 1.0);
  EXPECT_EQ(r.per_interface[0].points, 4);
  EXPECT_NEAR(r.per_interface[0].least_squares_m, 2 * kD, 1e-12);
  EXPECT_EQ(r.per_interface[1].id, 2.0);
  EXPECT_NEAR(r.per_interface[1].least_squares_m, 2 * kD, 1e-12);
  // The deviations from the zone's mid-plane: +d, +d, -d, -d per saddle (its normal oriented up).
  ASSERT_EQ(r.deviations_m.size(), 8);
  for (int k = 0; k < 8; ++k) EXPECT_NEAR(r.deviations_m(k), k % 4 < 2 ? kD : -kD, 1e-12) << k;
}

// A tilted 3 x 3 grid with its centre raised by h along the normal: z is uncorrelated with x and y,
// so the least-squares plane is the grid's raised by h / 9 (deviations 8h/9 at the centre, -h/9
// elsewhere); the minimum zone's mid-plane is h / 2 above the grid (deviations +-h/2). Both
// flatnesses are h; the deviations are the chosen method's. An interface of 3 collinear points has
// no flatness of its own and is left out, one of 2 points or 1 too.
TEST(InterfaceFlatness, MethodChoiceAndInterfacesWithoutAPlane) {
  const double h = 5e-6;
  Matrix3Xd p(3, 9);
  p << 0, 1, 2, 0, 1, 2, 0, 1, 2,
       0, 0, 0, 1, 1, 1, 2, 2, 2,
       0, 0, 0, 0, 0, 0, 0, 0, 0;
  p *= 1e-3;
  p(2, 4) = h;  // the centre point raised
  const Matrix3Xd q = kTilt * p;
  const VectorXd ids = (VectorXd(9) << 1, 1, 1, 2, 2, 2, 3, 3, 4).finished();
  const FlatnessAnalysisResult ls = analyze_flatness(q, ids, options(FlatnessMethod::kLeastSquares));
  const FlatnessAnalysisResult mz = analyze_flatness(q, ids, options(FlatnessMethod::kMinimumZone));
  EXPECT_NEAR(ls.flatness_m, h, 1e-12);
  EXPECT_NEAR(mz.flatness_m, h, 1e-12);
  for (int k = 0; k < 9; ++k) {
    EXPECT_NEAR(ls.deviations_m(k), k == 4 ? 8 * h / 9 : -h / 9, 1e-12) << k;
    EXPECT_NEAR(mz.deviations_m(k), k == 4 ? h / 2 : -h / 2, 1e-12) << k;
  }
  // Interface 1 (y = 0) is a line; interface 2 (y = 1, its middle point raised) is a plane of
  // flatness 0; 3 and 4 have too few points.
  ASSERT_EQ(ls.per_interface.size(), 1u);
  EXPECT_EQ(ls.per_interface[0].id, 2.0);
  EXPECT_EQ(ls.per_interface[0].points, 3);
  EXPECT_NEAR(ls.per_interface[0].least_squares_m, 0.0, 1e-12);
  EXPECT_TRUE(analyze_flatness(q, VectorXd(), options(FlatnessMethod::kLeastSquares)).per_interface.empty());
}

TEST(InterfaceFlatness, RefusesWhatItCannotMeasure) {
  Matrix3Xd many = Matrix3Xd::Random(3, 101);
  FlatnessAnalysisResult ls = analyze_flatness(many, VectorXd(), options(FlatnessMethod::kLeastSquares));
  EXPECT_FALSE(ls.minimum_zone_m.has_value());
  EXPECT_THROW(analyze_flatness(many, VectorXd(), options(FlatnessMethod::kMinimumZone)), InputError);
  EXPECT_THROW(analyze_flatness(many, VectorXd::Ones(100), options(FlatnessMethod::kLeastSquares)), InputError);
  EXPECT_THROW(analyze_flatness(many.leftCols(2), VectorXd(), options(FlatnessMethod::kLeastSquares)), InputError);
}

}  // namespace
}  // namespace piezobench::metrology::interface_flatness_test
