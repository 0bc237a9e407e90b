#include "flatness.hpp"

#include <cmath>

namespace piezobench::bench::detail {

Eigen::Matrix<double, 8, 3> probe_layout() {
  Eigen::Matrix<double, 8, 3> p;
  int row = 0;
  for (int interface = 1; interface <= 2; ++interface) {
    const double centre = interface == 1 ? -0.025 : 0.025;
    for (const double dx : {-0.007, 0.007}) {
      for (const double dy : {-0.004, 0.004}) {
        p(row, 0) = dx;
        p(row, 1) = centre + dy;
        p(row, 2) = interface;
        ++row;
      }
    }
  }
  return p;
}

Eigen::Matrix<double, 8, 1> probe_heights(const UnitTruth& unit) {
  const Eigen::Matrix<double, 8, 3> p = probe_layout();
  Eigen::Matrix<double, 8, 1> z;
  const double c = std::cos(unit.flatness_tilt_direction), s = std::sin(unit.flatness_tilt_direction);
  for (int i = 0; i < 8; ++i) {
    const double centre = p(i, 2) == 1.0 ? -0.025 : 0.025;
    const double dx = p(i, 0), dy = p(i, 1) - centre;
    const double saddle = (dx > 0 ? 1.0 : -1.0) * (dy > 0 ? 1.0 : -1.0);
    // Height change of a plane tilted by theta about the axis (c, s) through the centre: the
    // distance from that axis times tan(theta).
    const double tilt = p(i, 2) == 2.0 ? std::tan(unit.flatness_tilt) * (-s * dx + c * dy) : 0.0;
    z(i) = tilt + unit.flatness_warp * saddle;
  }
  return z;
}

double plane_flatness(const Eigen::VectorXd& x, const Eigen::VectorXd& y, const Eigen::VectorXd& z) {
  Eigen::MatrixXd a(x.size(), 3);
  a.col(0).setOnes();
  a.col(1) = x;
  a.col(2) = y;
  const Eigen::Vector3d coef = a.colPivHouseholderQr().solve(z);
  const Eigen::VectorXd r = z - a * coef;
  return r.maxCoeff() - r.minCoeff();
}

}  // namespace piezobench::bench::detail
