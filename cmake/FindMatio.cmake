# Finds matio (MATLAB .mat v5/v7.3 through HDF5) and defines the imported target Matio::matio.
find_package(PkgConfig REQUIRED)
pkg_check_modules(PC_MATIO QUIET IMPORTED_TARGET matio)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(Matio REQUIRED_VARS PC_MATIO_FOUND VERSION_VAR PC_MATIO_VERSION)
if(Matio_FOUND AND NOT TARGET Matio::matio)
  add_library(Matio::matio INTERFACE IMPORTED)
  set_target_properties(Matio::matio PROPERTIES INTERFACE_LINK_LIBRARIES PkgConfig::PC_MATIO)
endif()
