// HDF5, loaded on first use (core/shared_library.hpp): the functions of <hdf5.h> that the MAT v7.3
// reader (mat_reader.cpp) calls, each forwarding to libhdf5's own. A function used for the first
// time needs its line in the list below, with its signature as hdf5.h declares it (the compiler
// checks the two agree; `nm -u` on the object lists what is used).
//
// HDF5's predefined types are global variables (H5T_NATIVE_DOUBLE is `(H5open(), H5T_NATIVE_DOUBLE_g)`):
// this file defines the ones piezobench uses and, when the library is loaded, runs the real H5open
// and copies their values (they do not change until H5close, which piezobench never calls).
// The soname is the one the build found (PIEZOBENCH_HDF5_SONAME, src/io/CMakeLists.txt).
#include <hdf5.h>

#include "isolated.hpp"
#include "piezobench/core/shared_library.hpp"

#define PIEZOBENCH_HDF5_FUNCTIONS(X)                                                                             \
  X(herr_t, H5open, (void), ())                                                                                  \
  X(herr_t, H5check_version, (unsigned majnum, unsigned minnum, unsigned relnum), (majnum, minnum, relnum))      \
  X(H5I_type_t, H5Iget_type, (hid_t id), (id))                                                                   \
  X(herr_t, H5Eset_auto2, (hid_t estack_id, H5E_auto2_t func, void* client_data), (estack_id, func, client_data)) \
  X(hid_t, H5Fopen, (const char* filename, unsigned flags, hid_t fapl_id), (filename, flags, fapl_id))          \
  X(herr_t, H5Fclose, (hid_t file_id), (file_id))                                                                \
  X(htri_t, H5Lexists, (hid_t loc_id, const char* name, hid_t lapl_id), (loc_id, name, lapl_id))                 \
  X(herr_t, H5Literate,                                                                                          \
    (hid_t grp_id, H5_index_t idx_type, H5_iter_order_t order, hsize_t* idx, H5L_iterate_t op, void* op_data),   \
    (grp_id, idx_type, order, idx, op, op_data))                                                                 \
  X(hid_t, H5Oopen, (hid_t loc_id, const char* name, hid_t lapl_id), (loc_id, name, lapl_id))                    \
  X(herr_t, H5Oclose, (hid_t object_id), (object_id))                                                            \
  X(htri_t, H5Aexists, (hid_t obj_id, const char* attr_name), (obj_id, attr_name))                               \
  X(herr_t, H5Aiterate2, (hid_t loc_id, H5_index_t idx_type, H5_iter_order_t order, hsize_t* idx, H5A_operator2_t op, void* op_data), \
    (loc_id, idx_type, order, idx, op, op_data))                                                                 \
  X(hid_t, H5Aopen, (hid_t obj_id, const char* attr_name, hid_t aapl_id), (obj_id, attr_name, aapl_id))          \
  X(hid_t, H5Aget_space, (hid_t attr_id), (attr_id))                                                             \
  X(hid_t, H5Aget_type, (hid_t attr_id), (attr_id))                                                              \
  X(herr_t, H5Aread, (hid_t attr_id, hid_t type_id, void* buf), (attr_id, type_id, buf))                         \
  X(herr_t, H5Aclose, (hid_t attr_id), (attr_id))                                                                \
  X(hid_t, H5Dget_space, (hid_t dset_id), (dset_id))                                                             \
  X(hid_t, H5Dget_type, (hid_t dset_id), (dset_id))                                                              \
  X(hid_t, H5Dget_create_plist, (hid_t dset_id), (dset_id))                                                      \
  X(hsize_t, H5Dget_storage_size, (hid_t dset_id), (dset_id))                                                    \
  X(herr_t, H5Dread, (hid_t dset_id, hid_t mem_type_id, hid_t mem_space_id, hid_t file_space_id, hid_t dxpl_id, void* buf), \
    (dset_id, mem_type_id, mem_space_id, file_space_id, dxpl_id, buf))                                           \
  X(int, H5Pget_nfilters, (hid_t plist_id), (plist_id))                                                          \
  X(hid_t, H5Rdereference2, (hid_t obj_id, hid_t oapl_id, H5R_type_t ref_type, const void* ref),                 \
    (obj_id, oapl_id, ref_type, ref))                                                                            \
  X(herr_t, H5Pclose, (hid_t plist_id), (plist_id))                                                              \
  X(hid_t, H5Screate_simple, (int rank, const hsize_t dims[], const hsize_t maxdims[]), (rank, dims, maxdims))   \
  X(int, H5Sget_simple_extent_dims, (hid_t space_id, hsize_t dims[], hsize_t maxdims[]), (space_id, dims, maxdims)) \
  X(int, H5Sget_simple_extent_ndims, (hid_t space_id), (space_id))                                               \
  X(hssize_t, H5Sget_simple_extent_npoints, (hid_t space_id), (space_id))                                        \
  X(herr_t, H5Sselect_hyperslab,                                                                                 \
    (hid_t space_id, H5S_seloper_t op, const hsize_t start[], const hsize_t stride[], const hsize_t count[],     \
     const hsize_t block[]),                                                                                     \
    (space_id, op, start, stride, count, block))                                                                 \
  X(herr_t, H5Sclose, (hid_t space_id), (space_id))                                                              \
  X(hid_t, H5Tcreate, (H5T_class_t type, size_t size), (type, size))                                             \
  X(hid_t, H5Tcopy, (hid_t type_id), (type_id))                                                                  \
  X(herr_t, H5Tinsert, (hid_t parent_id, const char* name, size_t offset, hid_t member_id),                      \
    (parent_id, name, offset, member_id))                                                                        \
  X(H5T_class_t, H5Tget_class, (hid_t type_id), (type_id))                                                       \
  X(size_t, H5Tget_size, (hid_t type_id), (type_id))                                                             \
  X(int, H5Tget_nmembers, (hid_t type_id), (type_id))                                                            \
  X(int, H5Tget_member_index, (hid_t type_id, const char* name), (type_id, name))                                \
  X(H5T_cset_t, H5Tget_cset, (hid_t type_id), (type_id))                                                         \
  X(htri_t, H5Tis_variable_str, (hid_t type_id), (type_id))                                                      \
  X(herr_t, H5Tset_size, (hid_t type_id, size_t size), (type_id, size))                                          \
  X(herr_t, H5Tset_cset, (hid_t type_id, H5T_cset_t cset), (type_id, cset))                                      \
  X(herr_t, H5Tclose, (hid_t type_id), (type_id))

// The predefined types piezobench uses (the H5T_... macros of H5Tpublic.h read these).
#define PIEZOBENCH_HDF5_VARIABLES(X) \
  X(H5T_C_S1_g)                      \
  X(H5T_NATIVE_DOUBLE_g)             \
  X(H5T_NATIVE_LLONG_g)              \
  X(H5T_NATIVE_UINT16_g)             \
  X(H5T_NATIVE_ULLONG_g)             \
  X(H5T_STD_REF_OBJ_g)

#define PIEZOBENCH_HDF5_DEFINE_VARIABLE(name) \
  extern "C" {                                \
  __attribute__((visibility("hidden"))) hid_t name = H5I_INVALID_HID; \
  }
#define PIEZOBENCH_HDF5_COPY_VARIABLE(name) name = *static_cast<const hid_t*>(library().symbol(#name));

PIEZOBENCH_HDF5_VARIABLES(PIEZOBENCH_HDF5_DEFINE_VARIABLE)

namespace {

piezobench::core::SharedLibrary& library() {
  static piezobench::core::SharedLibrary hdf5(PIEZOBENCH_HDF5_SONAME, "reading and writing MAT v7.3 files (HDF5)");
  return hdf5;
}

struct Functions {
  PIEZOBENCH_HDF5_FUNCTIONS(PIEZOBENCH_STUB_MEMBER)
};

const Functions& functions() {
  static const Functions resolved = [] {
    Functions table;
    PIEZOBENCH_HDF5_FUNCTIONS(PIEZOBENCH_STUB_RESOLVE)
    if (table.H5open() < 0) throw piezobench::core::SharedLibraryError(library().soname() + ": H5open failed");
    PIEZOBENCH_HDF5_VARIABLES(PIEZOBENCH_HDF5_COPY_VARIABLE)
    return table;
  }();
  return resolved;
}

}  // namespace

PIEZOBENCH_HDF5_FUNCTIONS(PIEZOBENCH_STUB_DEFINE)

void piezobench::io::detail::map_hdf5_library() { (void)library().symbol("H5open"); }
