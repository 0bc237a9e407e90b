// CHOLMOD is loaded on first use (src/fem/cholmod_stubs.cpp): building and checking a model does
// not map it (nor BLAS, LAPACK, OpenBLAS and the Fortran runtime it brings), and the first
// Craig-Bampton reduction loads it and gives the exact static condensation. One test in its own
// program, so that nothing has loaded the library before it looks.
#include <gtest/gtest.h>

#include "piezobench/core/shared_library.hpp"
#include "piezobench/fem/craig_bampton.hpp"
#include "piezobench/fem/structural_model.hpp"
#include "fem_test_data.hpp"
#include "test_util.hpp"

namespace piezobench::fem {
namespace {

using core::is_shared_object_loaded;

TEST(LazyCholmod, LoadedByTheFirstReductionOnly) {
  ASSERT_TRUE(is_shared_object_loaded("libc.so"));  // the search itself works
  EXPECT_FALSE(is_shared_object_loaded("libcholmod"));
  EXPECT_FALSE(is_shared_object_loaded("libopenblas"));
  EXPECT_FALSE(is_shared_object_loaded("libgfortran"));

  // A spring-mass chain, nodes 1 and n retained.
  const int n = 30;
  const SparseModel chain = test_data::spring_chain(n);
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
