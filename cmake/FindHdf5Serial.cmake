# Finds the C library of HDF5 (serial build, through pkg-config: FindHDF5 needs the C language
# enabled) and defines the imported target Hdf5::hdf5. piezobench reads MAT v7.3 files with it.
find_package(PkgConfig REQUIRED)
pkg_check_modules(PC_HDF5 QUIET IMPORTED_TARGET hdf5-serial)
if(NOT PC_HDF5_FOUND)
  pkg_check_modules(PC_HDF5 QUIET IMPORTED_TARGET hdf5)
endif()
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(Hdf5Serial REQUIRED_VARS PC_HDF5_FOUND VERSION_VAR PC_HDF5_VERSION)
if(Hdf5Serial_FOUND AND NOT TARGET Hdf5::hdf5)
  add_library(Hdf5::hdf5 INTERFACE IMPORTED)
  set_target_properties(Hdf5::hdf5 PROPERTIES INTERFACE_LINK_LIBRARIES PkgConfig::PC_HDF5)
endif()
