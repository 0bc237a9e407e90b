#include "piezobench/metrology/interface_flatness.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "piezobench/core/error.hpp"

namespace piezobench::metrology {

namespace {

using Eigen::Index;

// The least-squares flatness of each interface's points, by increasing id.
std::vector<InterfaceFlatness> per_interface(const Eigen::Matrix3Xd& p, const Eigen::VectorXd& ids, const std::string& source) {
  std::vector<double> distinct(ids.data(), ids.data() + ids.size());
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  std::vector<InterfaceFlatness> out;
  for (const double id : distinct) {
    std::vector<Index> cols;
    for (Index k = 0; k < ids.size(); ++k) {
      if (ids(k) == id) cols.push_back(k);
    }
    if (cols.size() < 3) continue;
    Eigen::Matrix3Xd q(3, static_cast<Index>(cols.size()));
    for (std::size_t i = 0; i < cols.size(); ++i) q.col(static_cast<Index>(i)) = p.col(cols[i]);
    try {
      out.push_back({id, static_cast<long>(cols.size()), flatness(q, {}, source).flatness});
    } catch (const InputError&) {
      // an interface whose points are collinear has no flatness of its own; the whole set still does
    }
  }
  return out;
}

}  // namespace

FlatnessAnalysisResult analyze_flatness(const Eigen::Matrix3Xd& p, const Eigen::VectorXd& interface_ids,
                                        const FlatnessAnalysisOptions& o) {
  const std::string source = o.field.empty() ? o.source : o.source + ": " + o.field;
  if (interface_ids.size() != 0 && interface_ids.size() != p.cols()) {
    throw InputError(o.source, o.field, fmt::format("one interface id per point ({})", p.cols()), fmt::format("{}", interface_ids.size()));
  }
  const FlatnessResult ls = flatness(p, {FlatnessMethod::kLeastSquares}, source);
  std::optional<FlatnessResult> mz;
  if (p.cols() <= o.max_minimum_zone_points) {
    mz = flatness(p, {FlatnessMethod::kMinimumZone, o.max_minimum_zone_points}, source);
  } else if (o.method == FlatnessMethod::kMinimumZone) {
    throw InputError(o.source, o.field, fmt::format("at most {} points for the minimum-zone flatness of the specification", o.max_minimum_zone_points),
                     fmt::format("{}", p.cols()));
  }
  const FlatnessResult& chosen = o.method == FlatnessMethod::kMinimumZone ? *mz : ls;
  FlatnessAnalysisResult out;
  out.method = o.method;
  out.flatness_m = chosen.flatness;
  out.least_squares_m = ls.flatness;
  if (mz) out.minimum_zone_m = mz->flatness;
  out.points = static_cast<long>(p.cols());
  out.deviations_m = chosen.deviations;
  if (interface_ids.size() != 0) out.per_interface = per_interface(p, interface_ids, source);
  return out;
}

}  // namespace piezobench::metrology
