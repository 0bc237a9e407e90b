// CHOLMOD, loaded on first use (core/shared_library.hpp): the functions of <cholmod.h> that
// Eigen's CholmodSupport calls for craig_bampton.cpp, each forwarding to libcholmod's own (which
// brings BLAS, LAPACK, OpenBLAS, METIS and the Fortran runtime: 13,000 relocations at start-up when
// linked). A function used for the first time needs its line in the list below, with its signature
// as cholmod.h declares it (the compiler checks the two agree; `nm -u` on the object lists them).
// The soname is the one the build found (PIEZOBENCH_CHOLMOD_SONAME, src/fem/CMakeLists.txt).
#include <cholmod.h>

#include "piezobench/core/shared_library.hpp"

#define PIEZOBENCH_CHOLMOD_FUNCTIONS(X)                                                                         \
  X(int, cholmod_start, (cholmod_common * Common), (Common))                                                    \
  X(int, cholmod_finish, (cholmod_common * Common), (Common))                                                   \
  X(cholmod_factor*, cholmod_analyze, (cholmod_sparse * A, cholmod_common * Common), (A, Common))               \
  X(int, cholmod_factorize_p,                                                                                   \
    (cholmod_sparse * A, double beta[2], int* fset, size_t fsize, cholmod_factor* L, cholmod_common* Common),   \
    (A, beta, fset, fsize, L, Common))                                                                          \
  X(cholmod_dense*, cholmod_solve, (int sys, cholmod_factor* L, cholmod_dense* B, cholmod_common* Common),     \
    (sys, L, B, Common))                                                                                        \
  X(int, cholmod_free_factor, (cholmod_factor * *L, cholmod_common * Common), (L, Common))                      \
  X(int, cholmod_free_dense, (cholmod_dense * *dense, cholmod_common * Common), (dense, Common))

namespace {

piezobench::core::SharedLibrary& library() {
  static piezobench::core::SharedLibrary loaded(PIEZOBENCH_CHOLMOD_SONAME,
                                                "the sparse Cholesky factorization of Craig-Bampton (CHOLMOD)");
  return loaded;
}

struct Functions {
  PIEZOBENCH_CHOLMOD_FUNCTIONS(PIEZOBENCH_STUB_MEMBER)
};

const Functions& functions() {
  static const Functions resolved = [] {
    Functions table;
    PIEZOBENCH_CHOLMOD_FUNCTIONS(PIEZOBENCH_STUB_RESOLVE)
    return table;
  }();
  return resolved;
}

}  // namespace

PIEZOBENCH_CHOLMOD_FUNCTIONS(PIEZOBENCH_STUB_DEFINE)
