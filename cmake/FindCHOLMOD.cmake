# Finds CHOLMOD from SuiteSparse: the imported target SuiteSparse::CHOLMOD_headers (its headers
# only) and CHOLMOD_SONAME. piezobench does not link CHOLMOD (it brings BLAS, LAPACK and the Fortran
# runtime): it loads it on first use under that name (src/fem/cholmod_stubs.cpp).
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
find_library(CHOLMOD_LIBRARY NAMES cholmod)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(CHOLMOD REQUIRED_VARS CHOLMOD_LIBRARY CHOLMOD_INCLUDE_DIR)
if(CHOLMOD_FOUND AND NOT TARGET SuiteSparse::CHOLMOD_headers)
  include(PiezobenchSoname)
  piezobench_read_soname(CHOLMOD_SONAME "${CHOLMOD_LIBRARY}")
  add_library(SuiteSparse::CHOLMOD_headers INTERFACE IMPORTED)
  set_target_properties(SuiteSparse::CHOLMOD_headers PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${CHOLMOD_INCLUDE_DIR}")
endif()
mark_as_advanced(CHOLMOD_INCLUDE_DIR CHOLMOD_LIBRARY)
