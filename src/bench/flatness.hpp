#pragma once
// The flatness measurement of the report's section 1.1: 4 probe points on each of the two
// interfaces, in one frame, and the flatness as the peak-to-valley of their residuals from the
// least-squares plane z = a + b x + c y (the report fits with fminsearch; the least-squares plane
// is the usual definition and has a closed form).
#include <Eigen/Dense>

#include "piezobench/bench/virtual_bench.hpp"

namespace piezobench::bench::detail {

// Probe positions (m): interface 1 centred at y = -25 mm, interface 2 at y = +25 mm, points at
// x = +-7 mm, y = centre +-4 mm. Rows: 8 points; columns x, y, interface (1 or 2).
Eigen::Matrix<double, 8, 3> probe_layout();

// Noise-free heights (m) of the 8 points for `unit`: interface 2 tilted by flatness_tilt about an
// axis of direction flatness_tilt_direction through its centre, both interfaces warped into a
// saddle of amplitude flatness_warp (sign(x) sign(y - centre) w). The APA's own seating in the
// clamp (a tilt and an offset of the whole part) is removed by the plane fit and not included.
Eigen::Matrix<double, 8, 1> probe_heights(const UnitTruth& unit);

// Peak-to-valley (m) of the residuals of z from the least-squares plane through (x, y, z).
double plane_flatness(const Eigen::VectorXd& x, const Eigen::VectorXd& y, const Eigen::VectorXd& z);

}  // namespace piezobench::bench::detail
