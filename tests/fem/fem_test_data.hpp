#pragma once
// What several fem tests share: the folder of the external Ansys APA95ML export, the issue's
// accuracy of a reduced model against ccx on the full mesh, and a spring-mass chain.
#include <filesystem>
#include <vector>

#include "piezobench/fem/matrix_io.hpp"

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

}  // namespace piezobench::fem::test_data
