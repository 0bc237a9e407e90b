#include "piezobench/metrology/flatness.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "check.hpp"
#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"

namespace piezobench::metrology {

std::string to_string(FlatnessMethod method) {
  switch (method) {
    case FlatnessMethod::kLeastSquares: return "least-squares";
    case FlatnessMethod::kMinimumZone: return "minimum-zone";
  }
  return "unknown";
}

FlatnessMethod flatness_method_from_string(const std::string& name, const std::string& source) {
  for (const FlatnessMethod m : {FlatnessMethod::kLeastSquares, FlatnessMethod::kMinimumZone}) {
    if (to_string(m) == name) return m;
  }
  throw InputError(source, "method", "least-squares or minimum-zone", "'" + name + "'");
}

void FlatnessOptions::validate() const {
  if (max_minimum_zone_points < 4) {
    throw InputError("flatness options", "max_minimum_zone_points", "at least 4",
                     std::to_string(max_minimum_zone_points));
  }
}

namespace {

using Eigen::Index;
using Eigen::Vector3d;

// Orients a unit normal so that its largest component is positive (a deterministic sign).
Vector3d oriented(Vector3d n) {
  Index k = 0;
  n.cwiseAbs().maxCoeff(&k);
  return n(k) < 0.0 ? Vector3d(-n) : n;
}

// Fills deviations, flatness and contacts for a reference plane given by its normal; the offset is
// put in the middle of the zone for the minimum zone and at the centroid for least squares.
FlatnessResult finish(const Eigen::Matrix3Xd& points, const Vector3d& normal, FlatnessMethod method,
                      double ls_offset) {
  FlatnessResult r;
  r.method = method;
  r.plane.normal = oriented(normal);
  const Eigen::VectorXd proj = points.transpose() * r.plane.normal;
  const double hi = proj.maxCoeff();
  const double lo = proj.minCoeff();
  r.plane.offset = method == FlatnessMethod::kMinimumZone ? 0.5 * (hi + lo) : ls_offset;
  r.deviations = proj.array() - r.plane.offset;
  r.flatness = hi - lo;
  const double scale = std::max({r.flatness, points.cwiseAbs().maxCoeff() * 1e-12, std::numeric_limits<double>::min()});
  const double tol = method == FlatnessMethod::kMinimumZone ? 1e-9 * scale : 0.0;
  for (Index i = 0; i < proj.size(); ++i) {
    if (proj(i) >= hi - tol || proj(i) <= lo + tol) r.contacts.push_back(i);
  }
  return r;
}

// Width of the zone with normal n (not necessarily unit length: the width is divided by |n|);
// returns +inf as soon as it exceeds `bound` (points are visited in `order`).
double zone_width(const Eigen::Matrix3Xd& p, const std::vector<Index>& order, const Vector3d& n, double bound) {
  const double norm = n.norm();
  const double limit = bound * norm;
  double hi = -std::numeric_limits<double>::infinity();
  double lo = std::numeric_limits<double>::infinity();
  for (const Index i : order) {
    const double d = n.dot(p.col(i));
    hi = std::max(hi, d);
    lo = std::min(lo, d);
    if (hi - lo >= limit) return std::numeric_limits<double>::infinity();
  }
  return (hi - lo) / norm;
}

}  // namespace

FlatnessResult flatness(const Eigen::Matrix3Xd& points, const FlatnessOptions& options, const std::string& source) {
  options.validate();
  const Index n = points.cols();
  if (n < 3) throw InputError(source, "points", "at least 3 points", std::to_string(n));
  for (Index j = 0; j < n; ++j) {
    if (!points.col(j).allFinite()) {
      throw InputError(source, "points", "finite coordinates", fmt::format("a non-finite value at point {}", j));
    }
  }
  if (options.method == FlatnessMethod::kMinimumZone && n > options.max_minimum_zone_points) {
    throw InputError(source, "points",
                     fmt::format("at most {} points for the minimum zone (or the least-squares method)",
                                 options.max_minimum_zone_points),
                     std::to_string(n));
  }
  // Work on centred coordinates: the candidate normals and widths do not depend on a translation,
  // and centring keeps the dot products free of cancellation.
  const Vector3d centroid = points.rowwise().mean();
  const Eigen::Matrix3Xd c = points.colwise() - centroid;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(c.transpose(), Eigen::ComputeThinV);
  const Eigen::Vector3d sv = svd.singularValues();
  if (sv(1) <= 1e-12 * sv(0) || sv(0) == 0.0) {
    throw InputError(source, "points", "points that span a plane", "all points on one line");
  }
  const Vector3d ls_normal = oriented(svd.matrixV().col(2));
  const FlatnessResult ls = finish(points, ls_normal, FlatnessMethod::kLeastSquares, ls_normal.dot(centroid));
  if (options.method == FlatnessMethod::kLeastSquares) return ls;

  // Visit the points from the most extreme (for the least-squares plane) inwards, alternating
  // above and below, so that a candidate wider than the best one is abandoned after few points.
  std::vector<Index> by_dev(static_cast<std::size_t>(n));
  std::iota(by_dev.begin(), by_dev.end(), Index{0});
  std::sort(by_dev.begin(), by_dev.end(), [&](Index a, Index b) { return ls.deviations(a) > ls.deviations(b); });
  std::vector<Index> order;
  for (std::size_t lo = 0, hi = by_dev.size(); lo < hi;) {
    order.push_back(by_dev[lo++]);
    if (lo < hi) order.push_back(by_dev[--hi]);
  }

  double best = ls.flatness;
  Vector3d best_normal = ls_normal;
  const double scale = c.colwise().norm().maxCoeff();
  // Cross products below this (relative to the squared size) come from (nearly) collinear points
  // or parallel pairs and give no direction.
  const double tiny = 1e-14 * scale * scale;
  auto consider = [&](const Vector3d& normal) {
    if (normal.norm() <= tiny) return;
    const double w = zone_width(c, order, normal, best);
    if (w < best) {
      best = w;
      best_normal = normal.normalized();
    }
  };
  // 3-1 configurations: the plane through three points.
  for (Index i = 0; i < n; ++i) {
    for (Index j = i + 1; j < n; ++j) {
      const Vector3d a = c.col(j) - c.col(i);
      for (Index k = j + 1; k < n; ++k) consider(a.cross(c.col(k) - c.col(i)));
    }
  }
  // 2-2 configurations: one pair of points on each plane, the normal perpendicular to both pairs.
  std::vector<std::pair<Index, Index>> pairs;
  for (Index i = 0; i < n; ++i) {
    for (Index j = i + 1; j < n; ++j) pairs.emplace_back(i, j);
  }
  for (std::size_t a = 0; a < pairs.size(); ++a) {
    const auto [i, j] = pairs[a];
    const Vector3d u = c.col(j) - c.col(i);
    for (std::size_t b = a + 1; b < pairs.size(); ++b) {
      const auto [k, l] = pairs[b];
      if (k == i || k == j || l == i || l == j) continue;
      consider(u.cross(c.col(l) - c.col(k)));
    }
  }
  return finish(points, best_normal, FlatnessMethod::kMinimumZone, 0.0);
}

}  // namespace piezobench::metrology
