#pragma once
// Flatness of measured interface points (report section 1.1: 8 probe points per unit, 4 on each
// interface, one plane through all of them), by the two reference planes of ISO 1101 / ISO 12781:
//
//  - least squares ("least-squares", LSPL): the plane minimizing the sum of squared orthogonal
//    distances (through the centroid, normal = right singular vector of the smallest singular
//    value of the centred points); flatness = max - min of the signed distances to it.
//  - minimum zone ("minimum-zone", MZPL, the ISO 1101 definition of a flatness tolerance): the
//    smallest distance between two parallel planes that enclose every point. Computed exactly:
//    the optimal zone touches the points in a 3-1 configuration (a plane through three points and
//    its parallel through a fourth) or a 2-2 configuration (each plane through two points, the
//    normal perpendicular to both point pairs) (M. E. Houle, G. T. Toussaint, "Computing the width
//    of a set", IEEE PAMI 10(5), 1988), so every candidate normal from three points and from two
//    pairs of points is tried and the narrowest enclosing zone kept. O(n^4) candidates, each
//    abandoned as soon as it is wider than the best so far; hence the point limit below.
//  The minimum zone is never wider than the least-squares flatness.
//
// Units: the caller's (SI m in piezobench); the flatness is in the same unit.
#include <Eigen/Dense>
#include <string>
#include <vector>

namespace piezobench::metrology {

enum class FlatnessMethod { kLeastSquares, kMinimumZone };
std::string to_string(FlatnessMethod method);  // "least-squares", "minimum-zone"
// InputError (source, field "method") listing the two names.
FlatnessMethod flatness_method_from_string(const std::string& name, const std::string& source = "");

// The plane {p : normal . p = offset}, |normal| = 1, oriented with its largest component of the
// normal positive (z up for a horizontal interface).
struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;
  [[nodiscard]] double distance(const Eigen::Vector3d& p) const { return normal.dot(p) - offset; }
};

struct FlatnessOptions {
  FlatnessMethod method = FlatnessMethod::kLeastSquares;
  // The minimum zone refuses more points than this (InputError field "points"): its cost grows
  // as n^4 (100 points: ~0.1 s).
  Eigen::Index max_minimum_zone_points = 100;
  void validate() const;  // InputError (source "flatness options") naming the field
};

struct FlatnessResult {
  FlatnessMethod method = FlatnessMethod::kLeastSquares;
  double flatness = 0.0;        // width of the zone, same unit as the points
  Plane plane;                  // least squares: the fitted plane; minimum zone: the zone's mid-plane
  Eigen::VectorXd deviations;   // signed distance of every point to `plane`
  // Points on the two planes bounding the zone (minimum zone: at least 4 in a 3-1 or 2-2
  // configuration, within 1e-9 of the flatness; least squares: the highest and the lowest point).
  std::vector<Eigen::Index> contacts;
};

// points: 3 x n (x, y, z per column). InputError (source, field "points") for fewer than 3 points,
// a non-finite coordinate (the column is named), all points on one line (no plane), or more
// points than the minimum-zone limit; bad options as FlatnessOptions::validate.
FlatnessResult flatness(const Eigen::Matrix3Xd& points, const FlatnessOptions& options = {},
                        const std::string& source = "");

}  // namespace piezobench::metrology
