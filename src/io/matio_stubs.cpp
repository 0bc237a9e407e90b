// matio, loaded on first use (core/shared_library.hpp): the functions of <matio.h> piezobench
// calls, each forwarding to libmatio's own. A function used for the first time needs its line in
// the list below, with its signature as matio.h declares it (the compiler checks the two agree).
// The soname is the one the build found (PIEZOBENCH_MATIO_SONAME, src/io/CMakeLists.txt).
#include <matio.h>

#include "piezobench/core/shared_library.hpp"

#define PIEZOBENCH_MATIO_FUNCTIONS(X)                                                                              \
  X(int, Mat_LogInitFunc, (const char* prog_name, void (*log_func)(int log_level, char* message)),                  \
    (prog_name, log_func))                                                                                         \
  X(mat_t*, Mat_CreateVer, (const char* matname, const char* hdr_str, enum mat_ft mat_file_ver),                    \
    (matname, hdr_str, mat_file_ver))                                                                              \
  X(mat_t*, Mat_Open, (const char* matname, int mode), (matname, mode))                                             \
  X(int, Mat_Close, (mat_t * mat), (mat))                                                                          \
  X(int, Mat_Rewind, (mat_t * mat), (mat))                                                                         \
  X(size_t, Mat_SizeOf, (enum matio_types data_type), (data_type))                                                 \
  X(matvar_t*, Mat_VarCreate,                                                                                      \
    (const char* name, enum matio_classes class_type, enum matio_types data_type, int rank, size_t* dims,          \
     void* data, int opt),                                                                                         \
    (name, class_type, data_type, rank, dims, data, opt))                                                          \
  X(matvar_t*, Mat_VarCreateStruct2, (const char* name, int rank, const size_t* dims, const char* const* fields),   \
    (name, rank, dims, fields))                                                                                    \
  X(void, Mat_VarFree, (matvar_t * matvar), (matvar))                                                              \
  X(matvar_t*, Mat_VarGetCell, (matvar_t * matvar, int index), (matvar, index))                                    \
  X(unsigned, Mat_VarGetNumberOfFields, (matvar_t * matvar), (matvar))                                             \
  X(char* const*, Mat_VarGetStructFieldnames, (const matvar_t* matvar), (matvar))                                  \
  X(matvar_t*, Mat_VarGetStructFieldByIndex, (matvar_t * matvar, size_t field_index, size_t index),                \
    (matvar, field_index, index))                                                                                  \
  X(matvar_t*, Mat_VarGetStructFieldByName, (matvar_t * matvar, const char* field_name, size_t index),             \
    (matvar, field_name, index))                                                                                   \
  X(matvar_t*, Mat_VarRead, (mat_t * mat, const char* name), (mat, name))                                          \
  X(int, Mat_VarReadDataLinear, (mat_t * mat, matvar_t* matvar, void* data, int start, int stride, int edge),      \
    (mat, matvar, data, start, stride, edge))                                                                      \
  X(matvar_t*, Mat_VarReadInfo, (mat_t * mat, const char* name), (mat, name))                                      \
  X(matvar_t*, Mat_VarReadNextInfo, (mat_t * mat), (mat))                                                          \
  X(matvar_t*, Mat_VarSetCell, (matvar_t * matvar, int index, matvar_t* cell), (matvar, index, cell))              \
  X(matvar_t*, Mat_VarSetStructFieldByName,                                                                        \
    (matvar_t * matvar, const char* field_name, size_t index, matvar_t* field), (matvar, field_name, index, field)) \
  X(int, Mat_VarWrite, (mat_t * mat, matvar_t* matvar, enum matio_compression compress), (mat, matvar, compress))

namespace {

piezobench::core::SharedLibrary& library() {
  static piezobench::core::SharedLibrary loaded(PIEZOBENCH_MATIO_SONAME, "reading and writing MAT files (matio)");
  return loaded;
}

struct Functions {
  PIEZOBENCH_MATIO_FUNCTIONS(PIEZOBENCH_STUB_MEMBER)
};

const Functions& functions() {
  static const Functions resolved = [] {
    Functions table;
    PIEZOBENCH_MATIO_FUNCTIONS(PIEZOBENCH_STUB_RESOLVE)
    return table;
  }();
  return resolved;
}

}  // namespace

PIEZOBENCH_MATIO_FUNCTIONS(PIEZOBENCH_STUB_DEFINE)
