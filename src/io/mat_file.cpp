#include "io/mat_file.hpp"

#include "io/isolated.hpp"

#include <algorithm>
#include <cctype>
#include <complex>
#include <cstdint>
#include <cstring>
#include <limits>
#include <mutex>

#include "piezobench/core/error.hpp"
#include "piezobench/core/file.hpp"

namespace piezobench::io::detail {
namespace fs = std::filesystem;

bool is_matlab_identifier(const std::string& name) {
  if (name.empty() || name.size() > 63) return false;
  if (std::isalpha(static_cast<unsigned char>(name.front())) == 0) return false;
  return std::all_of(name.begin(), name.end(),
                     [](char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_'; });
}

// ---- matio ----------------------------------------------------------------------------------

namespace {
thread_local std::string matio_message;

void matio_log(int log_level, char* message) {
  // Errors and warnings are kept for our own messages; matio's debug chatter is dropped. Nothing
  // goes to stderr: the command's stderr is for our progress lines.
  if ((log_level & (MATIO_LOG_LEVEL_ERROR | MATIO_LOG_LEVEL_CRITICAL | MATIO_LOG_LEVEL_WARNING)) != 0 &&
      message != nullptr) {
    matio_message = message;
  }
}
}  // namespace

void install_matio_logger() {
  static std::once_flag once;
  std::call_once(once, [] { Mat_LogInitFunc("piezobench", &matio_log); });
}

std::string take_matio_message() {
  std::string m = std::move(matio_message);
  matio_message.clear();
  return m;
}

void MatCloser::operator()(mat_t* mat) const {
  if (mat != nullptr) Mat_Close(mat);
}
void MatVarFreer::operator()(matvar_t* var) const {
  if (var != nullptr) Mat_VarFree(var);
}

std::string with_matio_reason(const std::string& text) {
  const std::string reason = take_matio_message();
  return reason.empty() ? text : text + " (matio: " + reason + ")";
}

namespace {
const char* class_name(matio_classes c) {
  switch (c) {
    case MAT_C_EMPTY: return "empty";
    case MAT_C_CELL: return "cell";
    case MAT_C_STRUCT: return "struct";
    case MAT_C_OBJECT: return "object";
    case MAT_C_CHAR: return "char";
    case MAT_C_SPARSE: return "sparse";
    case MAT_C_DOUBLE: return "double";
    case MAT_C_SINGLE: return "single";
    case MAT_C_INT8: return "int8";
    case MAT_C_UINT8: return "uint8";
    case MAT_C_INT16: return "int16";
    case MAT_C_UINT16: return "uint16";
    case MAT_C_INT32: return "int32";
    case MAT_C_UINT32: return "uint32";
    case MAT_C_INT64: return "int64";
    case MAT_C_UINT64: return "uint64";
    case MAT_C_FUNCTION: return "function";
    case MAT_C_OPAQUE: return "opaque";
  }
  return "unknown";
}

template <typename T>
void copy_as_double(const void* data, size_t n, double* out) {
  const T* p = static_cast<const T*>(data);
  for (size_t i = 0; i < n; ++i) out[i] = static_cast<double>(p[i]);
}

// Converts n elements of a numeric class to double.
void to_doubles(matio_classes c, const void* data, size_t n, double* out) {
  switch (c) {
    case MAT_C_DOUBLE: std::memcpy(out, data, n * sizeof(double)); return;
    case MAT_C_SINGLE: copy_as_double<float>(data, n, out); return;
    case MAT_C_INT8: copy_as_double<mat_int8_t>(data, n, out); return;
    case MAT_C_UINT8: copy_as_double<mat_uint8_t>(data, n, out); return;
    case MAT_C_INT16: copy_as_double<mat_int16_t>(data, n, out); return;
    case MAT_C_UINT16: copy_as_double<mat_uint16_t>(data, n, out); return;
    case MAT_C_INT32: copy_as_double<mat_int32_t>(data, n, out); return;
    case MAT_C_UINT32: copy_as_double<mat_uint32_t>(data, n, out); return;
    case MAT_C_INT64: copy_as_double<mat_int64_t>(data, n, out); return;
    case MAT_C_UINT64: copy_as_double<mat_uint64_t>(data, n, out); return;
    default: break;
  }
}

bool is_vector_shape(const matvar_t& var) {
  if (var.rank < 1 || var.dims == nullptr) return false;
  int non_singleton = 0;
  for (int i = 0; i < var.rank; ++i) {
    if (var.dims[i] != 1) ++non_singleton;
  }
  return non_singleton <= 1;
}

std::string name_of(const matvar_t& var, const std::string& field) {
  return field.empty() && var.name != nullptr ? std::string(var.name) : field;
}
}  // namespace

bool is_numeric_class(matio_classes c) {
  switch (c) {
    case MAT_C_DOUBLE: case MAT_C_SINGLE: case MAT_C_INT8: case MAT_C_UINT8: case MAT_C_INT16:
    case MAT_C_UINT16: case MAT_C_INT32: case MAT_C_UINT32: case MAT_C_INT64: case MAT_C_UINT64:
      return true;
    default:
      return false;
  }
}

size_t element_count(const matvar_t& var) {
  if (var.rank < 1 || var.dims == nullptr) return 0;
  size_t n = 1;
  for (int i = 0; i < var.rank; ++i) n *= var.dims[i];
  return n;
}

std::string describe(const matvar_t& var) {
  std::string out = var.isComplex != 0 ? "complex " : "";
  out += var.isLogical != 0 ? "logical" : class_name(var.class_type);
  out += " ";
  for (int i = 0; i < var.rank && var.dims != nullptr; ++i) {
    if (i > 0) out += "x";
    out += std::to_string(var.dims[i]);
  }
  return out;
}

void copy_real_vector(const matvar_t& var, const std::string& source, const std::string& field, Eigen::Ref<Eigen::VectorXd> out) {
  const std::string f = name_of(var, field);
  if (!is_numeric_class(var.class_type) || var.isComplex != 0 || !is_vector_shape(var)) {
    throw InputError(source, f, "a real numeric vector", describe(var));
  }
  const size_t n = element_count(var);
  if (static_cast<Eigen::Index>(n) != out.size()) {
    throw InputError(source, f, std::to_string(out.size()) + " samples", std::to_string(n));
  }
  if (n > 0) {
    if (var.data == nullptr) throw InputError(source, f, "a complete variable", "no data (truncated file?)");
    if (var.data_size <= 0 || var.nbytes / static_cast<size_t>(var.data_size) < n) {
      throw InputError(source, f, std::to_string(n) + " samples of data (declared " + describe(var) + ")",
                       std::to_string(var.nbytes) + " bytes");
    }
    to_doubles(var.class_type, var.data, n, out.data());
  }
}

Eigen::VectorXd to_real_vector(const matvar_t& var, const std::string& source, const std::string& field) {
  Eigen::VectorXd out(static_cast<Eigen::Index>(element_count(var)));
  copy_real_vector(var, source, field, out);
  return out;
}

Eigen::VectorXcd to_complex_vector(const matvar_t& var, const std::string& source, const std::string& field) {
  const std::string f = name_of(var, field);
  if (!is_numeric_class(var.class_type) || !is_vector_shape(var)) {
    throw InputError(source, f, "a numeric (complex) vector", describe(var));
  }
  if (var.isComplex == 0) return to_real_vector(var, source, field).cast<std::complex<double>>();
  const size_t n = element_count(var);
  Eigen::VectorXcd out(static_cast<Eigen::Index>(n));
  if (n == 0) return out;
  const auto* split_data = static_cast<const mat_complex_split_t*>(var.data);
  if (split_data == nullptr || split_data->Re == nullptr || split_data->Im == nullptr) {
    throw InputError(source, f, "a complete variable", "no data (truncated file?)");
  }
  Eigen::VectorXd re(static_cast<Eigen::Index>(n)), im(static_cast<Eigen::Index>(n));
  to_doubles(var.class_type, split_data->Re, n, re.data());
  to_doubles(var.class_type, split_data->Im, n, im.data());
  out.real() = re;
  out.imag() = im;
  return out;
}

std::string to_text(const matvar_t& var, const std::string& source, const std::string& field) {
  const std::string f = name_of(var, field);
  if (var.class_type == MAT_C_EMPTY || element_count(var) == 0) return "";
  if (var.class_type != MAT_C_CHAR || !is_vector_shape(var) || var.data == nullptr) {
    throw InputError(source, f, "a char row", describe(var));
  }
  const size_t n = element_count(var);
  // The data must hold what the dimensions declare (a corrupt header claims more than is there).
  const size_t unit = var.data_size > 0 ? static_cast<size_t>(var.data_size) : 1;
  if (var.nbytes / unit < n) {
    throw InputError(source, f, std::to_string(n) + " characters (declared " + describe(var) + ")",
                     std::to_string(var.nbytes) + " bytes of data");
  }
  std::string out;
  out.reserve(n);
  switch (var.data_type) {
    case MAT_T_UINT16:
    case MAT_T_UTF16:
    case MAT_T_INT16: {
      // MATLAB stores char as UTF-16 code units; piezobench names are ASCII.
      const auto* p = static_cast<const mat_uint16_t*>(var.data);
      for (size_t i = 0; i < n; ++i) out += p[i] < 128 ? static_cast<char>(p[i]) : '?';
      break;
    }
    case MAT_T_UINT8:
    case MAT_T_INT8:
    case MAT_T_UTF8: {
      const auto* p = static_cast<const char*>(var.data);
      out.assign(p, n);
      break;
    }
    default:
      throw InputError(source, f, "a char row", std::string("char data of matio type ") + std::to_string(var.data_type));
  }
  return out;
}

MatVarPtr make_real_column(const std::string& name, const Eigen::Ref<const Eigen::VectorXd>& v) {
  size_t dims[2] = {static_cast<size_t>(v.size()), 1};
  // MAT_F_DONT_COPY_DATA: the variable points at v's data and Mat_VarFree leaves it alone.
  MatVarPtr var(Mat_VarCreate(name.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims,
                              const_cast<double*>(v.data()), MAT_F_DONT_COPY_DATA));
  if (!var) throw InputError(name, "", "a variable matio can create", with_matio_reason("Mat_VarCreate failed"));
  return var;
}

MatVarPtr make_complex_column(const std::string& name, const Eigen::VectorXcd& v) {
  size_t dims[2] = {static_cast<size_t>(v.size()), 1};
  Eigen::VectorXd re = v.real(), im = v.imag();
  mat_complex_split_t split_data{re.data(), im.data()};
  MatVarPtr var(Mat_VarCreate(name.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, &split_data, MAT_F_COMPLEX));
  if (!var) throw InputError(name, "", "a variable matio can create", with_matio_reason("Mat_VarCreate failed"));
  return var;
}

MatVarPtr make_scalar(const std::string& name, double v) {
  size_t dims[2] = {1, 1};
  MatVarPtr var(Mat_VarCreate(name.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, &v, 0));
  if (!var) throw InputError(name, "", "a variable matio can create", with_matio_reason("Mat_VarCreate failed"));
  return var;
}

MatVarPtr make_text(const std::string& name, const std::string& text) {
  size_t dims[2] = {1, text.size()};
  std::string copy = text;
  MatVarPtr var(Mat_VarCreate(name.c_str(), MAT_C_CHAR, MAT_T_UTF8, 2, dims, copy.empty() ? nullptr : copy.data(), 0));
  if (!var) throw InputError(name, "", "a variable matio can create", with_matio_reason("Mat_VarCreate failed"));
  return var;
}

MatVarPtr make_struct(const std::string& name, std::vector<std::pair<std::string, MatVarPtr>> fields) {
  size_t dims[2] = {1, 1};
  std::vector<const char*> names;
  names.reserve(fields.size());
  for (const auto& f : fields) names.push_back(f.first.c_str());
  names.push_back(nullptr);  // the field list is NULL-terminated
  MatVarPtr var(Mat_VarCreateStruct2(name.c_str(), 2, dims, names.data()));
  if (!var) throw InputError(name, "", "a struct matio can create", with_matio_reason("Mat_VarCreateStruct2 failed"));
  for (auto& f : fields) {
    // The struct takes ownership of the field variable.
    Mat_VarSetStructFieldByName(var.get(), f.first.c_str(), 0, f.second.release());
  }
  return var;
}

void MatWriter::write(const MatVarPtr& var) {
  const std::string name = var->name != nullptr ? var->name : "";
  (void)take_matio_message();
  if (Mat_VarWrite(mat_, var.get(), compress_ ? MAT_COMPRESSION_ZLIB : MAT_COMPRESSION_NONE) != 0) {
    throw InputError(file_.string(), name, "a variable written completely", with_matio_reason("matio write failed"));
  }
  written_.push_back(name);
}

namespace {

// Creates the file, writes the variables and closes it; returns the written names.
std::vector<std::string> create_and_fill(const fs::path& temp, const fs::path& file, bool v73, bool compress,
                                         const std::function<void(MatWriter&)>& fill) {
  (void)take_matio_message();
  MatioPtr mat(Mat_CreateVer(temp.c_str(), nullptr, v73 ? MAT_FT_MAT73 : MAT_FT_MAT5));
  if (!mat) {
    throw InputError(file.string(), "output file", "a MAT file matio can create", with_matio_reason("Mat_CreateVer failed"));
  }
  MatWriter writer(mat.get(), file, compress && !v73);
  fill(writer);
  mat_t* raw = mat.release();
  if (Mat_Close(raw) != 0) {
    throw InputError(file.string(), "output file", "a complete write", with_matio_reason("closing the MAT file failed"));
  }
  return writer.written();
}

}  // namespace

namespace {

// Re-opens the written file and checks that every written variable reads back (matio does not
// report every failed fwrite: disk full, file size limit). A long real column of an uncompressed
// v5 file is proven by reading its last element (its header and its end are in the file, and v5
// stores it contiguously) instead of all of it: a 100 s record is 40 MB.
void check_written(const fs::path& temp, const fs::path& file, bool v73, bool compress, const std::vector<std::string>& written) {
  MatioPtr check(Mat_Open(temp.c_str(), MAT_ACC_RDONLY));
  if (!check) throw InputError(file.string(), "output file", "a complete write", with_matio_reason("the written file does not open"));
  for (const std::string& name : written) {
    const auto incomplete = [&] {
      return InputError(file.string(), name, "a variable written completely", with_matio_reason("it does not read back"));
    };
    if (!v73 && !compress) {
      MatVarPtr info(Mat_VarReadInfo(check.get(), name.c_str()));
      if (!info) throw incomplete();
      const size_t n = info->class_type == MAT_C_DOUBLE && info->isComplex == 0 ? element_count(*info) : 0;
      if (n > 4096) {
        double last = 0.0;
        int start = static_cast<int>(n - 1), stride = 1, edge = 1;
        if (n - 1 > static_cast<size_t>(std::numeric_limits<int>::max()) ||
            Mat_VarReadDataLinear(check.get(), info.get(), &last, start, stride, edge) != 0) {
          throw incomplete();
        }
        continue;
      }
    }
    MatVarPtr var(Mat_VarRead(check.get(), name.c_str()));
    if (!var || (var->class_type != MAT_C_STRUCT && element_count(*var) > 0 && var->data == nullptr)) throw incomplete();
  }
}

}  // namespace

void write_mat_atomically(const fs::path& file, bool v73, bool compress, const std::function<void(MatWriter&)>& fill) {
  install_matio_logger();
  AtomicFile out(file);
  if (v73) {
    // HDF5 keeps a file it failed to flush (disk full, file size limit) in its global table and
    // crashes on it when the process exits: a v7.3 file is written and checked by an isolated
    // child (io/isolated.hpp), which also keeps this process free of HDF5 altogether.
    IsolatedOptions isolated;
    isolated.source = file.string();
    isolated.field = "output file";
    isolated.expected = "a complete write";
    isolated.failure = "the v7.3 writer process failed";
    run_isolated(
        isolated,
        [&](IsolatedOut&) { check_written(out.temp_path(), file, true, compress, create_and_fill(out.temp_path(), file, true, compress, fill)); },
        [](IsolatedIn&) {});
  } else {
    check_written(out.temp_path(), file, false, compress, create_and_fill(out.temp_path(), file, false, compress, fill));
  }
  out.commit();
}

}  // namespace piezobench::io::detail
