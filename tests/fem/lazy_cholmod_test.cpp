// CHOLMOD is loaded on first use (src/fem/cholmod_stubs.cpp): building and checking a model does
// not map it (nor BLAS, LAPACK, OpenBLAS and the Fortran runtime it brings), and the first
// Craig-Bampton reduction loads it and gives the exact static condensation. One test in its own
// program, so that nothing has loaded the library before it looks.
#include <gtest/gtest.h>

#include "piezobench/core/shared_library.hpp"
#include "piezobench/fem/craig_bampton.hpp"
#include "piezobench/fem/structural_model.hpp"
#include "test_util.hpp"

namespace piezobench::fem {
namespace {

using core::is_shared_object_loaded;

TEST(LazyCholmod, LoadedByTheFirstReductionOnly) {
  ASSERT_TRUE(is_shared_object_loaded("libc.so"));  // the search itself works
  EXPECT_FALSE(is_shared_object_loaded("libcholmod"));
  EXPECT_FALSE(is_shared_object_loaded("libopenblas"));
  EXPECT_FALSE(is_shared_object_loaded("libgfortran"));

  // A chain of n springs and masses (grounded at both ends), nodes 1 and n retained.
  const int n = 30;
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
  EXPECT_FALSE(is_shared_object_loaded("libcholmod"));

  CraigBamptonOptions o;
  o.modes = 4;
  const CraigBamptonResult r = craig_bampton(chain, {{1, -1}, {n, -1}}, o);
  EXPECT_TRUE(is_shared_object_loaded("libcholmod"));
  // The static part is exact whatever the number of modes: the reduced model's response to
  // interface forces equals the full model's (dense solve).
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

}  // namespace
}  // namespace piezobench::fem
