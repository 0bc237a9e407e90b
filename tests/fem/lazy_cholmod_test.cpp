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
  test_data::expect_exact_static_condensation(chain, r);
}

}  // namespace
}  // namespace piezobench::fem
