#pragma once
// What several fem tests share: the folder of the external Ansys APA95ML export, the issue's
// accuracy of a reduced model against ccx on the full mesh, a spring-mass chain and the check that
// its Craig-Bampton reduction condenses the statics exactly.
#include <gtest/gtest.h>

#include <filesystem>
#include <vector>

#include "piezobench/fem/craig_bampton.hpp"
#include "piezobench/fem/matrix_io.hpp"
#include "test_util.hpp"

namespace piezobench::fem::test_data {

inline const std::filesystem::path kAnsysDir = std::filesystem::path(PIEZOBENCH_SHARED_DATA_DIR) / "apa95ml-ansys";
inline constexpr double kAgainstCcx = 2e-3;  // 0.2 %

// A chain of n masses (1 + 0.01 i) joined by springs (1000 + 10 i), grounded at both ends through
// the end springs; node i + 1 has one DOF, x.
inline SparseModel spring_chain(int n) {
  SparseModel chain;
  std::vector<Eigen::Triplet<double, int>> tk, tm;
  for (int i = 0; i < n; ++i) {
    const double k = 1000.0 + 10.0 * i;
    tk.emplace_back(i, i, 2 * k);
    if (i + 1 < n) {
      tk.emplace_back(i, i + 1, -k);
      tk.emplace_back(i + 1, i, -k);
    }
    tm.emplace_back(i, i, 1.0 + 0.01 * i);
    chain.dofs.push_back(DofLabel::nodal(i + 1, Direction::kX));
  }
  chain.K.resize(n, n);
  chain.M.resize(n, n);
  chain.K.setFromTriplets(tk.begin(), tk.end());
  chain.M.setFromTriplets(tm.begin(), tm.end());
  return chain;
}

// The static part of a Craig-Bampton reduction is exact whatever the number of modes: for a chain of
// n nodes reduced to nodes 1 and n, the reduced model's static response to interface forces
// (1, -0.5) equals the full model's (dense solve).
inline void expect_exact_static_condensation(const SparseModel& chain, const CraigBamptonResult& r) {
  const auto n = static_cast<Eigen::Index>(chain.K.rows());
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
  f(0) = 1.0;
  f(n - 1) = -0.5;
  const Eigen::VectorXd u_full = Eigen::MatrixXd(chain.K).ldlt().solve(f);
  Eigen::VectorXd fr = Eigen::VectorXd::Zero(r.reduced.size());
  fr(0) = 1.0;
  fr(1) = -0.5;
  const Eigen::VectorXd u_red = r.reduced.K.ldlt().solve(fr);
  EXPECT_TRUE(test::near(u_red(0), u_full(0), 1e-10));
  EXPECT_TRUE(test::near(u_red(1), u_full(n - 1), 1e-10));
}

}  // namespace piezobench::fem::test_data
