# Finds matio (MATLAB .mat v5/v7.3 through HDF5): the imported target Matio::headers (its header
# only) and Matio_SONAME. piezobench does not link matio: it loads it on first use under that
# name (src/io/matio_stubs.cpp).
find_package(PkgConfig REQUIRED)
pkg_check_modules(PC_MATIO QUIET matio)
find_path(MATIO_INCLUDE_DIR matio.h HINTS ${PC_MATIO_INCLUDE_DIRS})
find_library(MATIO_LIBRARY NAMES matio HINTS ${PC_MATIO_LIBRARY_DIRS})
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(Matio REQUIRED_VARS MATIO_LIBRARY MATIO_INCLUDE_DIR VERSION_VAR PC_MATIO_VERSION)
if(Matio_FOUND AND NOT TARGET Matio::headers)
  include(PiezobenchSoname)
  piezobench_read_soname(Matio_SONAME "${MATIO_LIBRARY}")
  add_library(Matio::headers INTERFACE IMPORTED)
  set_target_properties(Matio::headers PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${MATIO_INCLUDE_DIR}")
endif()
mark_as_advanced(MATIO_INCLUDE_DIR MATIO_LIBRARY)
