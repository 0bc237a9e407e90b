# Finds the C library of HDF5 (serial build, through pkg-config: FindHDF5 needs the C language
# enabled): the imported target Hdf5::headers (its headers only) and Hdf5Serial_SONAME. piezobench
# reads MAT v7.3 files with it; it does not link it but loads it on first use under that name
# (src/io/hdf5_stubs.cpp).
find_package(PkgConfig REQUIRED)
pkg_check_modules(PC_HDF5 QUIET hdf5-serial)
if(NOT PC_HDF5_FOUND)
  pkg_check_modules(PC_HDF5 QUIET hdf5)
endif()
find_path(HDF5_SERIAL_INCLUDE_DIR hdf5.h HINTS ${PC_HDF5_INCLUDE_DIRS} NO_DEFAULT_PATH)
find_path(HDF5_SERIAL_INCLUDE_DIR hdf5.h)
find_library(HDF5_SERIAL_LIBRARY NAMES hdf5 HINTS ${PC_HDF5_LIBRARY_DIRS} NO_DEFAULT_PATH)
find_library(HDF5_SERIAL_LIBRARY NAMES hdf5_serial hdf5)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(Hdf5Serial REQUIRED_VARS HDF5_SERIAL_LIBRARY HDF5_SERIAL_INCLUDE_DIR
                                  VERSION_VAR PC_HDF5_VERSION)
if(Hdf5Serial_FOUND AND NOT TARGET Hdf5::headers)
  include(PiezobenchSoname)
  piezobench_read_soname(Hdf5Serial_SONAME "${HDF5_SERIAL_LIBRARY}")
  add_library(Hdf5::headers INTERFACE IMPORTED)
  set_target_properties(Hdf5::headers PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${HDF5_SERIAL_INCLUDE_DIR}")
endif()
mark_as_advanced(HDF5_SERIAL_INCLUDE_DIR HDF5_SERIAL_LIBRARY)
