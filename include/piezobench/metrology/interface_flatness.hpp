#pragma once
// The flatness analysis of a unit's probe points (report section 1.1): the least-squares flatness
// always, the minimum-zone flatness when there are few enough points for its exact O(n^4) search
// (flatness.hpp), the one of the specification's method reported; and, when the points carry an
// interface id, the least-squares flatness of each interface on its own.
//
// Units: the caller's (SI m in piezobench): every flatness and deviation is in the points' unit.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "piezobench/metrology/flatness.hpp"

namespace piezobench::metrology {

struct FlatnessAnalysisOptions {
  FlatnessMethod method = FlatnessMethod::kLeastSquares;  // the specification's: the reported flatness
  // The minimum zone is computed up to this many points (FlatnessOptions::max_minimum_zone_points);
  // above it, only when `method` asks for it, an InputError.
  Eigen::Index max_minimum_zone_points = 100;
  // Errors: InputError(source, field, ...); flatness()'s messages name "source: field".
  std::string source, field;
};

struct InterfaceFlatness {
  double id = 0.0;               // the interface's value of the id channel
  long points = 0;               // its points (at least 3)
  double least_squares_m = 0.0;  // least-squares flatness of its points
};

struct FlatnessAnalysisResult {
  FlatnessMethod method = FlatnessMethod::kLeastSquares;  // of flatness_m
  double flatness_m = 0.0;                 // by `method`
  double least_squares_m = 0.0;
  std::optional<double> minimum_zone_m;    // nullopt: more than max_minimum_zone_points points
  long points = 0;
  // Interfaces with 3 non-collinear points or more, by increasing id (empty without ids).
  std::vector<InterfaceFlatness> per_interface;
  Eigen::VectorXd deviations_m;            // signed distance of every point to `method`'s plane
};

// points: 3 x n (x, y, z per column); interface_ids: one id per point, or empty (no interfaces).
// InputError (source, field) as flatness() for the whole set (fewer than 3 points, non-finite,
// collinear), ids of another length than the points, or method = minimum zone with more points
// than max_minimum_zone_points. An interface whose points are collinear has no flatness of its own
// and is left out.
FlatnessAnalysisResult analyze_flatness(const Eigen::Matrix3Xd& points, const Eigen::VectorXd& interface_ids,
                                        const FlatnessAnalysisOptions& options);

}  // namespace piezobench::metrology
