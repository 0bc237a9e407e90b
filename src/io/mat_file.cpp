#include "mat_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include "isolated.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <complex>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <deque>
#include <limits>
#include <mutex>

#include "piezobench/core/error.hpp"
#include "piezobench/core/file.hpp"
#include "piezobench/core/text.hpp"

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

size_t element_count(const matvar_t& var) {
  if (var.rank < 1 || var.dims == nullptr) return 0;
  size_t n = 1;
  for (int i = 0; i < var.rank; ++i) n *= var.dims[i];
  return n;
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

// The matio data type a numeric class's data have once matio read them (matio converts to the class).
matio_types type_of_class(matio_classes c) {
  switch (c) {
    case MAT_C_DOUBLE: return MAT_T_DOUBLE;
    case MAT_C_SINGLE: return MAT_T_SINGLE;
    case MAT_C_INT8: return MAT_T_INT8;
    case MAT_C_UINT8: return MAT_T_UINT8;
    case MAT_C_INT16: return MAT_T_INT16;
    case MAT_C_UINT16: return MAT_T_UINT16;
    case MAT_C_INT32: return MAT_T_INT32;
    case MAT_C_UINT32: return MAT_T_UINT32;
    case MAT_C_INT64: return MAT_T_INT64;
    case MAT_C_UINT64: return MAT_T_UINT64;
    default: return MAT_T_UNKNOWN;
  }
}

bool is_vector_shape(const MatValue& var) {
  return !var.dims.empty() && std::count_if(var.dims.begin(), var.dims.end(), [](size_t d) { return d != 1; }) <= 1;
}

std::string name_of(const MatValue& var, const std::string& field) { return field.empty() ? var.name : field; }
}  // namespace

std::u16string utf16_from_utf8(std::string_view utf8) {
  std::u16string out;
  for (size_t i = 0; i < utf8.size();) {
    const std::optional<char32_t> c = text::take_utf8(utf8, i);
    if (!c) {
      out += u'\uFFFD';
      ++i;
    } else if (*c >= 0x10000) {
      out += static_cast<char16_t>(0xD800 + ((*c - 0x10000) >> 10));
      out += static_cast<char16_t>(0xDC00 + ((*c - 0x10000) & 0x3FF));
    } else {
      out += static_cast<char16_t>(*c);
    }
  }
  return out;
}

std::string utf8_from_units(const double* units, size_t n) {
  std::string out;
  for (size_t i = 0; i < n; ++i) {
    const double u = units[i];
    const auto c = u >= 0.0 && u <= 0x10FFFF ? static_cast<char32_t>(u) : char32_t{0xFFFD};
    if (c >= 0xD800 && c <= 0xDBFF && i + 1 < n && units[i + 1] >= 0xDC00 && units[i + 1] <= 0xDFFF) {
      text::append_utf8(out, 0x10000 + ((c - 0xD800) << 10) + (static_cast<char32_t>(units[i + 1]) - 0xDC00));
      ++i;
    } else {
      text::append_utf8(out, c >= 0xD800 && c <= 0xDFFF ? char32_t{0xFFFD} : c);
    }
  }
  return out;
}

size_t MatValue::count() const {
  if (dims.empty()) return 0;
  size_t n = 1;
  for (size_t d : dims) n *= d;
  return n;
}

const MatValue* MatValue::field(const std::string& field_name, size_t element) const {
  if (class_type != MAT_C_STRUCT) return nullptr;
  const auto it = std::find(field_names.begin(), field_names.end(), field_name);
  if (it == field_names.end()) return nullptr;
  const size_t index = element * field_names.size() + static_cast<size_t>(it - field_names.begin());
  return index < items.size() ? &items[index] : nullptr;
}

bool is_numeric_class(matio_classes c) {
  switch (c) {
    case MAT_C_DOUBLE: case MAT_C_SINGLE: case MAT_C_INT8: case MAT_C_UINT8: case MAT_C_INT16:
    case MAT_C_UINT16: case MAT_C_INT32: case MAT_C_UINT32: case MAT_C_INT64: case MAT_C_UINT64:
      return true;
    default:
      return false;
  }
}

std::string describe(const MatValue& var) {
  std::string out = var.is_complex ? "complex " : "";
  out += var.is_logical ? "logical" : class_name(var.class_type);
  out += " ";
  for (size_t i = 0; i < var.dims.size(); ++i) {
    if (i > 0) out += "x";
    out += std::to_string(var.dims[i]);
  }
  return out;
}

void copy_real_vector(const MatValue& var, const std::string& source, const std::string& field, Eigen::Ref<Eigen::VectorXd> out) {
  const std::string f = name_of(var, field);
  if (!is_numeric_class(var.class_type) || var.is_complex || !is_vector_shape(var)) {
    throw InputError(source, f, "a real numeric vector", describe(var));
  }
  const size_t n = var.count();
  if (static_cast<Eigen::Index>(n) != out.size()) {
    throw InputError(source, f, std::to_string(out.size()) + " samples", std::to_string(n));
  }
  if (n == 0) return;
  if (!var.has_data || (var.view == nullptr && var.re.size() < n)) {
    throw InputError(source, f, "a complete variable", "no data (truncated file?)");
  }
  std::memcpy(out.data(), var.real(), n * sizeof(double));
}

Eigen::VectorXd to_real_vector(const MatValue& var, const std::string& source, const std::string& field) {
  Eigen::VectorXd out(static_cast<Eigen::Index>(var.count()));
  copy_real_vector(var, source, field, out);
  return out;
}

Eigen::VectorXcd to_complex_vector(const MatValue& var, const std::string& source, const std::string& field) {
  const std::string f = name_of(var, field);
  if (!is_numeric_class(var.class_type) || !is_vector_shape(var)) {
    throw InputError(source, f, "a numeric (complex) vector", describe(var));
  }
  if (!var.is_complex) return to_real_vector(var, source, field).cast<std::complex<double>>();
  const size_t n = var.count();
  if (n > 0 && (!var.has_data || var.re.size() < n || var.im.size() < n)) {
    throw InputError(source, f, "a complete variable", "no data (truncated file?)");
  }
  Eigen::VectorXcd out(static_cast<Eigen::Index>(n));
  for (size_t i = 0; i < n; ++i) out(static_cast<Eigen::Index>(i)) = {var.re[i], var.im[i]};
  return out;
}

std::string to_text(const MatValue& var, const std::string& source, const std::string& field) {
  const std::string f = name_of(var, field);
  if (var.class_type == MAT_C_EMPTY || var.count() == 0) return "";
  if (var.class_type != MAT_C_CHAR || !is_vector_shape(var) || !var.has_data) {
    throw InputError(source, f, "a char row", describe(var));
  }
  return var.text;
}

MatValue from_matvar(const matvar_t& var, const std::string& source) {
  MatValue out;
  out.name = var.name != nullptr ? var.name : "";
  out.class_type = var.class_type;
  out.is_complex = var.isComplex != 0;
  out.is_logical = var.isLogical != 0;
  if (var.dims != nullptr && var.rank > 0) out.dims.assign(var.dims, var.dims + var.rank);
  const size_t n = out.count();
  const auto incomplete = [&](const std::string& expected, size_t bytes) {
    return InputError(source, out.name, expected + " (declared " + describe(out) + ")", std::to_string(bytes) + " bytes of data");
  };
  if ((var.class_type == MAT_C_STRUCT || var.class_type == MAT_C_CELL) && var.data == nullptr && n > 0) {
    out.has_data = false;  // a header only
  } else if (var.class_type == MAT_C_STRUCT) {
    const unsigned nfields = Mat_VarGetNumberOfFields(const_cast<matvar_t*>(&var));
    char* const* names = Mat_VarGetStructFieldnames(&var);
    for (unsigned i = 0; i < nfields; ++i) out.field_names.emplace_back(names != nullptr && names[i] != nullptr ? names[i] : "");
    for (size_t e = 0; e < n && nfields > 0; ++e) {
      for (unsigned i = 0; i < nfields; ++i) {
        const matvar_t* f = Mat_VarGetStructFieldByIndex(const_cast<matvar_t*>(&var), i, e);
        out.items.push_back(f != nullptr ? from_matvar(*f, source) : MatValue("", MAT_C_EMPTY, {0, 0}));
        out.items.back().name = out.field_names[i];
      }
    }
  } else if (var.class_type == MAT_C_CELL) {
    for (size_t i = 0; i < n; ++i) {
      const matvar_t* c = Mat_VarGetCell(const_cast<matvar_t*>(&var), static_cast<int>(i));
      out.items.push_back(c != nullptr ? from_matvar(*c, source) : MatValue("", MAT_C_EMPTY, {0, 0}));
    }
  } else if (var.class_type == MAT_C_CHAR) {
    if (n > 0) {
      // The data must hold what the dimensions declare (a corrupt header claims more than is there).
      const size_t unit = var.data_size > 0 ? static_cast<size_t>(var.data_size) : 1;
      if (var.data == nullptr || var.nbytes / unit < n) throw incomplete(std::to_string(n) + " characters", var.data == nullptr ? 0 : var.nbytes);
      switch (var.data_type) {
        case MAT_T_UINT16:
        case MAT_T_UTF16:
        case MAT_T_INT16: {
          // MATLAB stores char as UTF-16 code units.
          const auto* p = static_cast<const mat_uint16_t*>(var.data);
          const std::vector<double> units(p, p + n);
          out.text = utf8_from_units(units.data(), n);
          break;
        }
        case MAT_T_UINT8:
        case MAT_T_INT8:
        case MAT_T_UTF8: out.text.assign(static_cast<const char*>(var.data), std::max(n, var.nbytes)); break;
        default:
          throw InputError(source, out.name, "a char row", std::string("char data of matio type ") + std::to_string(var.data_type));
      }
    }
  } else if (is_numeric_class(var.class_type)) {
    if (n > 0) {
      const void* re = var.data;
      const void* im = nullptr;
      if (out.is_complex && var.data != nullptr) {
        const auto* split_data = static_cast<const mat_complex_split_t*>(var.data);
        re = split_data->Re;
        im = split_data->Im;
      }
      if (re == nullptr || (out.is_complex && im == nullptr)) throw InputError(source, out.name, "a complete variable", "no data (truncated file?)");
      if (var.data_size <= 0 || var.nbytes / static_cast<size_t>(var.data_size) < n) {
        throw incomplete(std::to_string(n) + " samples of data", var.nbytes);
      }
      const matio_types t = type_of_class(var.class_type);
      out.re.resize(n);
      if (!numbers_to_doubles(static_cast<std::uint32_t>(t), re, n, out.re.data())) throw InputError(source, out.name, "numeric data", describe(out));
      if (im != nullptr) {
        out.im.resize(n);
        (void)numbers_to_doubles(static_cast<std::uint32_t>(t), im, n, out.im.data());
      }
    }
  } else {
    out.has_data = false;  // sparse, object, function, opaque: never read
  }
  return out;
}

// ---- building variables ---------------------------------------------------------------------

MatValue make_real_column(const std::string& name, const Eigen::Ref<const Eigen::VectorXd>& v) {
  MatValue out(name, MAT_C_DOUBLE, {static_cast<size_t>(v.size()), 1});
  out.view = v.data();
  return out;
}

MatValue make_matrix(const std::string& name, size_t rows, size_t cols, std::vector<double> data) {
  MatValue out(name, MAT_C_DOUBLE, {rows, cols});
  out.re = std::move(data);
  return out;
}

MatValue make_complex_column(const std::string& name, const Eigen::VectorXcd& v) {
  MatValue out(name, MAT_C_DOUBLE, {static_cast<size_t>(v.size()), 1}, true, false);
  out.re.resize(static_cast<size_t>(v.size()));
  out.im.resize(static_cast<size_t>(v.size()));
  Eigen::Map<Eigen::VectorXd>(out.re.data(), v.size()) = v.real();
  Eigen::Map<Eigen::VectorXd>(out.im.data(), v.size()) = v.imag();
  return out;
}

MatValue make_scalar(const std::string& name, double v) { return make_matrix(name, 1, 1, {v}); }

MatValue make_text(const std::string& name, const std::string& text) {
  MatValue out(name, MAT_C_CHAR, {1, utf16_from_utf8(text).size()});
  out.text = text;
  return out;
}

MatValue make_logical(const std::string& name, const std::vector<unsigned char>& values) {
  MatValue out(name, MAT_C_UINT8, {1, values.size()}, false, true);
  for (unsigned char v : values) out.re.push_back(v != 0 ? 1.0 : 0.0);
  return out;
}

MatValue make_struct(const std::string& name, std::vector<std::pair<std::string, MatValue>> fields) {
  MatValue out(name, MAT_C_STRUCT, {1, 1});
  for (auto& [field, value] : fields) {
    out.field_names.push_back(field);
    value.name = field;
    out.items.push_back(std::move(value));
  }
  return out;
}

namespace {

// ---- writing through matio (compressed v5, v7.3) --------------------------------------------

MatVarPtr created(matvar_t* var, const std::string& name) {
  if (var == nullptr) throw InputError(name, "", "a variable matio can create", with_matio_reason("Mat_VarCreate failed"));
  return MatVarPtr(var);
}

// matio's variable for `v` (real double data borrowed from `v`, which must outlive it).
MatVarPtr to_matvar(const MatValue& v) {
  std::vector<size_t> dims = v.dims;
  const int rank = static_cast<int>(dims.size());
  const size_t n = v.count();
  switch (v.class_type) {
    case MAT_C_STRUCT: {
      std::vector<const char*> names;
      for (const auto& f : v.field_names) names.push_back(f.c_str());
      names.push_back(nullptr);  // the field list is NULL-terminated
      MatVarPtr var(Mat_VarCreateStruct2(v.name.c_str(), rank, dims.data(), names.data()));
      if (!var) throw InputError(v.name, "", "a struct matio can create", with_matio_reason("Mat_VarCreateStruct2 failed"));
      const size_t nf = v.field_names.size();
      for (size_t e = 0; e < n && nf > 0; ++e) {
        for (size_t f = 0; f < nf; ++f) {
          MatVarPtr field = to_matvar(v.items.at(e * nf + f));
          // The struct takes ownership of the field variable.
          if (Mat_VarSetStructFieldByName(var.get(), v.field_names[f].c_str(), e, field.get()) != nullptr) {
            throw InputError("", v.field_names[f], "a struct field matio can set", "a previous value");
          }
          (void)field.release();
        }
      }
      return var;
    }
    case MAT_C_CELL: {
      MatVarPtr var = created(Mat_VarCreate(v.name.c_str(), MAT_C_CELL, MAT_T_CELL, rank, dims.data(), nullptr, 0), v.name);
      for (size_t i = 0; i < n; ++i) (void)Mat_VarSetCell(var.get(), static_cast<int>(i), to_matvar(v.items.at(i)).release());
      return var;
    }
    case MAT_C_CHAR: {
      std::u16string units = utf16_from_utf8(v.text);
      if (units.size() != n) throw InputError(v.name, "", std::to_string(n) + " characters", std::to_string(units.size()));
      return created(
          Mat_VarCreate(v.name.c_str(), MAT_C_CHAR, MAT_T_UINT16, rank, dims.data(), units.empty() ? nullptr : units.data(), 0), v.name);
    }
    default: break;
  }
  if (v.is_logical) {
    std::vector<unsigned char> bytes;
    for (size_t i = 0; i < n; ++i) bytes.push_back(v.re.at(i) != 0.0 ? 1 : 0);
    return created(Mat_VarCreate(v.name.c_str(), MAT_C_UINT8, MAT_T_UINT8, rank, dims.data(), bytes.data(), MAT_F_LOGICAL), v.name);
  }
  if (v.class_type != MAT_C_DOUBLE) throw InputError(v.name, "", "a double, logical, char, struct or cell variable to write", describe(v));
  if (v.is_complex) {
    std::vector<double> re = v.re, im = v.im;
    mat_complex_split_t split_data{re.data(), im.data()};
    return created(Mat_VarCreate(v.name.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, rank, dims.data(), &split_data, MAT_F_COMPLEX), v.name);
  }
  // MAT_F_DONT_COPY_DATA: the variable points at v's data and Mat_VarFree leaves it alone.
  return created(Mat_VarCreate(v.name.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, rank, dims.data(),
                                      n > 0 ? const_cast<double*>(v.real()) : nullptr, MAT_F_DONT_COPY_DATA),
                        v.name);
}

// ---- the own v5 encoder (uncompressed) --------------------------------------------------------
// MAT-file format (MathWorks, "MAT-File Format", Level 5): a 128-byte header, then one miMATRIX
// element per variable: array flags, dimensions, name, then the data (numeric, char), the field
// names and one miMATRIX per element and field (struct), or one per cell (cell).

// n bytes to fd (a short write is continued); false with errno set when it fails.
bool write_all(int fd, const char* data, size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(fd, data, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      if (w == 0) errno = EIO;
      return false;
    }
    data += w;
    n -= static_cast<size_t>(w);
  }
  return true;
}

// The bytes of the variables as pieces: small ones owned, large arrays borrowed from the values.
class V5Encoder {
 public:
  explicit V5Encoder(std::string source) : source_(std::move(source)) {}

  // Appends a whole miMATRIX element for `v` named `name`.
  void matrix(const MatValue& v, const std::string& name) {
    const auto [tag, start] = open_tag(kMiMatrix);
    std::uint32_t flags = static_cast<std::uint32_t>(v.class_type) & 0xffu;
    if (v.is_complex) flags |= 0x800u;
    if (v.is_logical) flags |= 0x200u;
    element(kMiUint32, std::array<std::uint32_t, 2>{flags, 0}.data(), 8);
    std::vector<std::int32_t> dims;
    for (size_t d : v.dims) {
      if (d > static_cast<size_t>(std::numeric_limits<std::int32_t>::max())) fail(name, "dimensions below 2^31", describe(v));
      dims.push_back(static_cast<std::int32_t>(d));
    }
    if (dims.size() < 2) fail(name, "at least 2 dimensions", describe(v));
    element(kMiInt32, dims.data(), 4 * dims.size());
    element(kMiInt8, name.data(), name.size());
    const size_t n = v.count();
    if (v.class_type == MAT_C_STRUCT) {
      const size_t nf = v.field_names.size();
      size_t longest = 1;
      for (const auto& f : v.field_names) longest = std::max(longest, f.size() + 1);
      const auto len = static_cast<std::int32_t>(longest);
      element(kMiInt32, &len, 4);
      std::string names(nf * longest, '\0');
      for (size_t f = 0; f < nf; ++f) names.replace(f * longest, v.field_names[f].size(), v.field_names[f]);
      element(kMiInt8, names.data(), names.size());
      if (v.items.size() != n * nf) fail(name, std::to_string(n * nf) + " fields", std::to_string(v.items.size()));
      for (const MatValue& item : v.items) matrix(item, "");
    } else if (v.class_type == MAT_C_CELL) {
      if (v.items.size() != n) fail(name, std::to_string(n) + " cells", std::to_string(v.items.size()));
      for (const MatValue& item : v.items) matrix(item, "");
    } else if (v.class_type == MAT_C_CHAR) {
      // UTF-8 (miUTF8) with the dimensions counting characters (UTF-16 code units), as scipy writes
      // char; MATLAB and Octave read it so.
      const size_t units = utf16_from_utf8(v.text).size();
      if (units != n) fail(name, std::to_string(n) + " characters", std::to_string(units));
      element(kMiUtf8, v.text.data(), v.text.size());
    } else if (v.is_logical) {
      if (v.re.size() != n) fail(name, std::to_string(n) + " values", std::to_string(v.re.size()));
      std::string bytes(n, '\0');
      for (size_t i = 0; i < n; ++i) bytes[i] = v.re[i] != 0.0 ? 1 : 0;
      element(kMiUint8, bytes.data(), n);
    } else if (v.class_type == MAT_C_DOUBLE) {
      if (v.view == nullptr && v.re.size() != n) fail(name, std::to_string(n) + " values", std::to_string(v.re.size()));
      borrowed_element(kMiDouble, v.real(), 8 * n);
      if (v.is_complex) {
        if (v.im.size() != n) fail(name, std::to_string(n) + " imaginary parts", std::to_string(v.im.size()));
        borrowed_element(kMiDouble, v.im.data(), 8 * n);
      }
    } else {
      fail(name, "a double, logical, char, struct or cell variable to write", describe(v));
    }
    close_tag(tag, start, name);
  }

  // Writes the pieces to `fd`; false with errno set when a write fails.
  bool write_to(int fd) const {
    return std::all_of(pieces_.begin(), pieces_.end(), [&](const Piece& p) {
      return write_all(fd, p.owned != nullptr ? p.owned->data() + p.offset : p.borrowed, p.size);
    });
  }

 private:
  struct Piece {
    const std::string* owned = nullptr;  // bytes [offset, offset + size) of an owned string, or
    size_t offset = 0;
    const char* borrowed = nullptr;      // borrowed bytes
    size_t size = 0;
  };

  // Appends owned bytes (to the last owned piece when it is the last one).
  void append(const void* data, size_t n) {
    if (n == 0) return;
    if (pieces_.empty() || pieces_.back().owned == nullptr) {
      owned_.emplace_back();
      pieces_.push_back({&owned_.back(), 0, nullptr, 0});
    }
    owned_.back().append(static_cast<const char*>(data), n);
    pieces_.back().size += n;
    size_ += n;
  }
  void pad() {
    static const char zeros[8] = {};
    append(zeros, (8 - size_ % 8) % 8);
  }
  // A data element: small (type and size in one word, at most 4 bytes) or tag, data, padding.
  void element(std::uint32_t type, const void* data, size_t n) {
    if (n > 0 && n <= 4) {
      const std::uint32_t word = (static_cast<std::uint32_t>(n) << 16) | type;
      char small[8] = {};
      std::memcpy(small, &word, 4);
      std::memcpy(small + 4, data, n);
      append(small, 8);
      return;
    }
    const std::array<std::uint32_t, 2> tag{type, static_cast<std::uint32_t>(n)};
    append(tag.data(), 8);
    append(data, n);
    pad();
  }
  void borrowed_element(std::uint32_t type, const double* data, size_t n) {
    if (n > std::numeric_limits<std::uint32_t>::max()) fail("", "data under 4 GiB per variable (the v5 limit; write v7.3)", std::to_string(n) + " bytes");
    const std::array<std::uint32_t, 2> tag{type, static_cast<std::uint32_t>(n)};
    append(tag.data(), 8);
    if (n > 0) pieces_.push_back({nullptr, 0, reinterpret_cast<const char*>(data), n});
    size_ += n;  // doubles: a multiple of 8, no padding
  }
  // A tag whose size is filled in by close_tag: where it is, and the position after it.
  std::pair<std::pair<std::string*, size_t>, unsigned long long> open_tag(std::uint32_t type) {
    const std::array<std::uint32_t, 2> tag{type, 0};
    append(tag.data(), 8);
    return {{&owned_.back(), owned_.back().size() - 4}, size_};
  }
  void close_tag(std::pair<std::string*, size_t> where, unsigned long long start, const std::string& name) {
    const unsigned long long bytes = size_ - start;
    if (bytes > std::numeric_limits<std::uint32_t>::max()) {
      fail(name, "a variable under 4 GiB (the v5 limit; write v7.3)", std::to_string(bytes) + " bytes");
    }
    const auto b = static_cast<std::uint32_t>(bytes);
    std::memcpy(where.first->data() + where.second, &b, 4);
  }
  [[noreturn]] void fail(const std::string& name, const std::string& expected, const std::string& found) const {
    throw InputError(source_, name.empty() ? "variable" : name, expected, found);
  }

  std::string source_;
  std::deque<std::string> owned_;  // a deque: the strings never move, so pieces may point at them
  std::vector<Piece> pieces_;
  unsigned long long size_ = 0;
};

// The 128-byte header of a v5 file in this machine's byte order (the reader swaps for the other).
std::string v5_header() {
  char text[117] = {};
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  (void)::localtime_r(&now, &tm);
  char date[64] = {};
  (void)std::strftime(date, sizeof date, "%a %b %e %H:%M:%S %Y", &tm);
  std::snprintf(text, sizeof text, "MATLAB 5.0 MAT-file, Platform: %s, Created by: piezobench on: %s",
                std::endian::native == std::endian::little ? "GLNXA64" : "unknown", date);
  std::string header(text);
  header.resize(116, ' ');
  header.append(8, '\0');  // no subsystem data
  const std::uint16_t version = 0x0100, endian = ('M' << 8) | 'I';
  header.append(reinterpret_cast<const char*>(&version), 2);
  header.append(reinterpret_cast<const char*>(&endian), 2);
  return header;
}

}  // namespace

void MatWriter::write(const MatValue& var) {
  if (fd_ >= 0) {
    V5Encoder encoder(file_.string());
    encoder.matrix(var, var.name);
    if (!encoder.write_to(fd_)) {
      const int err = errno;
      throw InputError(file_.string(), var.name, "a variable written completely", std::string(std::strerror(err)));
    }
  } else {
    const MatVarPtr v = to_matvar(var);
    (void)take_matio_message();
    if (Mat_VarWrite(mat_, v.get(), compress_ ? MAT_COMPRESSION_ZLIB : MAT_COMPRESSION_NONE) != 0) {
      throw InputError(file_.string(), var.name, "a variable written completely", with_matio_reason("matio write failed"));
    }
  }
  written_.push_back(var.name);
  const bool vector = std::count_if(var.dims.begin(), var.dims.end(), [](size_t d) { return d != 1; }) <= 1;
  if (var.class_type == MAT_C_DOUBLE && !var.is_complex && !var.is_logical && vector && var.count() > 0) {
    last_.push_back({var.name, {var.count(), var.real()[var.count() - 1]}});
  }
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

// Re-opens a file matio wrote (compressed v5, v7.3) and checks that every written variable reads
// back (matio does not report every failed fwrite: disk full, file size limit).
void check_written(const fs::path& temp, const fs::path& file, const std::vector<std::string>& written) {
  MatioPtr check(Mat_Open(temp.c_str(), MAT_ACC_RDONLY));
  if (!check) throw InputError(file.string(), "output file", "a complete write", with_matio_reason("the written file does not open"));
  for (const std::string& name : written) {
    MatVarPtr var(Mat_VarRead(check.get(), name.c_str()));
    if (!var || (var->class_type != MAT_C_STRUCT && var->class_type != MAT_C_CELL && element_count(*var) > 0 && var->data == nullptr)) {
      throw InputError(file.string(), name, "a variable written completely", with_matio_reason("it does not read back"));
    }
  }
}

// Writes an uncompressed v5 file with the own encoder (no matio), closes it and returns the
// written names; `last` receives the last value of each real double variable (the check reads it
// back).
std::vector<std::string> create_and_fill_v5(const fs::path& temp, const fs::path& file, const std::function<void(MatWriter&)>& fill,
                                            std::vector<std::pair<std::string, std::pair<size_t, double>>>& last) {
  const int fd = ::open(temp.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
  if (fd < 0) {
    const int err = errno;
    throw InputError(file.string(), "output file", "a writable file", "cannot open the temporary file (" + std::string(std::strerror(err)) + ")");
  }
  struct Descriptor {
    int fd;
    ~Descriptor() {
      if (fd >= 0) ::close(fd);
    }
  } descriptor{fd};
  const std::string header = v5_header();
  if (!write_all(fd, header.data(), header.size())) {
    const int err = errno;
    throw InputError(file.string(), "output file", "a complete write", std::string(std::strerror(err)));
  }
  MatWriter writer(fd, file);
  fill(writer);
  descriptor.fd = -1;
  if (::close(fd) != 0) {
    const int err = errno;
    throw InputError(file.string(), "output file", "a complete write", "closing the file failed (" + std::string(std::strerror(err)) + ")");
  }
  last = writer.last_values();
  return writer.written();
}

// The own encoder's file, checked before it gets its name: the v5 walk of open_mat_for_reading
// checks every element against the file's size, the variables must be the ones written, in order,
// and the last value of each real double variable must read back as written.
void check_v5(const fs::path& temp, const fs::path& file, const std::vector<std::string>& written,
              const std::vector<std::pair<std::string, std::pair<size_t, double>>>& last) {
  try {
    const MatFilePtr in = open_mat_for_reading(temp);
    std::vector<std::string> found;
    for (const MatVarInfo& v : list_mat_variables(in.get(), temp)) found.push_back(v.name);
    if (!read_without_matio(in.get()) || found != written) {
      throw InputError(file.string(), "output file", "the variables written (" + text::join(written, ",") + ")",
                       text::join(found, ","));
    }
    for (const auto& [name, value] : last) {
      const auto [count, expected] = value;
      const std::optional<double> back =
          read_double_element(in.get(), name, static_cast<Eigen::Index>(count), static_cast<Eigen::Index>(count) - 1);
      if (!back || std::memcmp(&*back, &expected, sizeof expected) != 0) {
        throw InputError(file.string(), name, "a variable written completely", "its last value does not read back");
      }
    }
  } catch (const InputError& e) {
    if (e.source() == file.string()) throw;
    throw InputError(file.string(), "output file", "a complete write", std::string("the written file does not read back: ") + e.what());
  }
}

}  // namespace

void write_mat_atomically(const fs::path& file, bool v73, bool compress, const std::function<void(MatWriter&)>& fill) {
  AtomicFile out(file);
  if (!v73 && !compress) {
    std::vector<std::pair<std::string, std::pair<size_t, double>>> last;
    const std::vector<std::string> written = create_and_fill_v5(out.temp_path(), file, fill, last);
    check_v5(out.temp_path(), file, written, last);
    out.commit();
    return;
  }
  install_matio_logger();
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
        [&](IsolatedOut&) { check_written(out.temp_path(), file, create_and_fill(out.temp_path(), file, true, compress, fill)); },
        [](IsolatedIn&) {});
  } else {
    check_written(out.temp_path(), file, create_and_fill(out.temp_path(), file, false, compress, fill));
  }
  out.commit();
}

}  // namespace piezobench::io::detail
