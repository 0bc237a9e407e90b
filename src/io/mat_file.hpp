#pragma once
// Private MAT-file layer of io: the bounded reader (mat_reader.cpp: plain v5 files by its own v5
// parser, compressed or big-endian v5 through matio, v7.3 through HDF5) and the atomic writer
// (mat_file.cpp: uncompressed v5 by its own encoder, compressed v5 and v7.3 through matio).
// Variables travel as MatValue, piezobench's own: reading and writing a plain v5 file never calls
// matio (matio and HDF5 are large libraries to load). Every call into HDF5 (reading and writing
// v7.3) runs in a forked child (io/isolated.hpp) so that a fault inside the library on a hostile
// file cannot take the program down: this process never calls HDF5.
#include <matio.h>

#include <Eigen/Dense>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace piezobench::io::detail {

// Letter first, then letters, digits and '_', at most 63 characters.
[[nodiscard]] bool is_matlab_identifier(const std::string& name);

// ---- matio ----------------------------------------------------------------------------------
struct MatCloser {
  void operator()(mat_t* mat) const;
};
struct MatVarFreer {
  void operator()(matvar_t* var) const;
};
using MatioPtr = std::unique_ptr<mat_t, MatCloser>;  // a MAT file being written through matio
using MatVarPtr = std::unique_ptr<matvar_t, MatVarFreer>;

// Routes matio's messages away from stderr into a per-thread buffer (called by the functions
// below; idempotent).
void install_matio_logger();
// The last message matio logged on this thread ("" if none); clears it.
[[nodiscard]] std::string take_matio_message();
// "text (matio: <last message>)", or text when matio said nothing.
[[nodiscard]] std::string with_matio_reason(const std::string& text);
// Number of elements of matio's variable (product of dims).
[[nodiscard]] size_t element_count(const matvar_t& var);

// ---- the v5 format (MathWorks, "MAT-File Format", Level 5) -----------------------------------
// Data types (table 1-1): matio's matio_types use the same numbers.
inline constexpr std::uint32_t kMiInt8 = 1, kMiUint8 = 2, kMiUint16 = 4, kMiInt32 = 5, kMiUint32 = 6, kMiDouble = 9,
                               kMiMatrix = 14, kMiCompressed = 15,
                               kMiUtf8 = 16;
// n values of v5 data type `type` (native byte order, any alignment) as double; false for a type
// that holds no numbers. Character types count as their code units (mat_reader.cpp).
bool numbers_to_doubles(std::uint32_t type, const void* data, size_t n, double* out);

// MATLAB's char data are UTF-16 code units, piezobench's strings UTF-8 (mat_file.cpp). A byte that
// is not valid UTF-8 becomes U+FFFD.
[[nodiscard]] std::u16string utf16_from_utf8(std::string_view text);
// Code units as UTF-8: UTF-16 (surrogate pairs joined; an unpaired one becomes U+FFFD), values
// above 0xFFFF taken as code points (UTF-32 data).
[[nodiscard]] std::string utf8_from_units(const double* units, size_t n);

// ---- a MAT variable in piezobench's memory --------------------------------------------------

// What read_mat_variable returns for every format and what MatWriter writes. Numeric data are held
// as double whatever the class in the file (class_type says which it was); char data as text.
struct MatValue {
  MatValue() = default;
  MatValue(std::string value_name, matio_classes c, std::vector<size_t> shape, bool complex = false, bool logical = false)
      : name(std::move(value_name)), class_type(c), is_complex(complex), is_logical(logical), dims(std::move(shape)) {}

  std::string name;
  matio_classes class_type = MAT_C_DOUBLE;  // matio's enumeration is the v5 class numbering
  bool is_complex = false;
  bool is_logical = false;                  // class uint8 with the logical flag
  std::vector<size_t> dims;                 // MATLAB order, at least 2 once built
  std::vector<double> re, im;               // numeric (and logical) data, column-major
  const double* view = nullptr;             // writers only: real data borrowed instead of `re`
  std::string text;                         // char data, UTF-8 (dims count UTF-16 code units)
  std::vector<std::string> field_names;     // struct
  // struct: element e's field f at items[e * field_names.size() + f]; cell: the cells
  std::vector<MatValue> items;
  bool has_data = true;  // false: the header only (sparse, object, function: never read; a v7.3 cell of
                         // structs or cells, or of more than 2^20 values in all)
  // v7.3 (HDF5) only: a dataset's string attribute `units` (or `unit`, any case: h5py users write
  // one), and a group's other string attributes (name, text), e.g. `units` = "u=V, de=um" or
  // `de_units` = "um". Empty for v5.
  std::string unit;
  std::vector<std::pair<std::string, std::string>> attributes;

  [[nodiscard]] size_t count() const;  // product of dims
  [[nodiscard]] const double* real() const { return view != nullptr ? view : re.data(); }
  // The field `name` of element `element` of a struct, or nullptr.
  [[nodiscard]] const MatValue* field(const std::string& field_name, size_t element = 0) const;
};

// ---- reading MAT files (mat_reader.cpp) -----------------------------------------------------
//
// Resource bounds (docs/formats.md, "Hostile files"): before anything is allocated for a
// variable, the size its header declares is checked against the bytes the file holds for it.
//  v5/v7  every data element must hold the bytes its dimensions need (at least 1 byte per element:
//         MATLAB may store doubles as smaller integers), so a variable takes at most 8 times its
//         bytes in the file (16 for complex); a compressed variable may declare at most
//         kMaxInflation times its compressed size (zlib's own limit is 1032) and its inflated
//         stream is checked the same way. A file in the machine's byte order whose top-level
//         elements are all uncompressed matrices is then read by the same walk (no matio);
//         anything else (compressed, big-endian) by matio after these checks.
//  v7.3   read through HDF5 directly (matio 1.5 misreads class strings written by h5py and
//         hdf5storage, and reads flagged-empty datasets as dimensions): an uncompressed dataset
//         must have the bytes its dimensions need allocated in the file; a filtered (deflated)
//         one may declare at most kMaxInflation times its stored bytes. Every HDF5 return value is
//         checked; a failed read is an InputError, never data. Every operation runs in an
//         isolated child (open and list, each variable, each vector): a child that crashes or
//         exits is an InputError naming the file ("the HDF5 library failed on it (signal 11)").
inline constexpr double kMaxInflation = 1100.0;

// An open MAT file (plain v5 by the own parser, other v5/v7 through matio, v7.3 through HDF5).
class MatInput {
 public:
  virtual ~MatInput() = default;
  [[nodiscard]] virtual bool v73() const = 0;
  [[nodiscard]] const std::filesystem::path& file() const { return file_; }

 protected:
  explicit MatInput(std::filesystem::path file) : file_(std::move(file)) {}

 private:
  std::filesystem::path file_;
};
using MatFilePtr = std::unique_ptr<MatInput>;

// Opens an existing MAT file for reading; InputError (field "file") if missing, not a MAT file,
// or when a variable declares more data than the file holds for it (see above).
[[nodiscard]] MatFilePtr open_mat_for_reading(const std::filesystem::path& file);
// Whether `mat` is read without matio (a plain v5 file, see above).
[[nodiscard]] bool read_without_matio(const MatInput* mat);
// Names and classes of the variables, in file order (info only, no data read).
struct MatVarInfo {
  std::string name;
  matio_classes class_type = MAT_C_EMPTY;
  bool is_complex = false;
  std::vector<size_t> dims;
  std::string unit;  // v7.3: the dataset's string attribute `units` (h5py users write one), else ""
};
[[nodiscard]] std::vector<MatVarInfo> list_mat_variables(MatInput* mat, const std::filesystem::path& file);
// v7.3: the file's own (root group's) string attributes other than MATLAB's, e.g. h5py's
// f.attrs["units"] = "u=V, de=um" (at most 4096); empty for v5.
[[nodiscard]] std::vector<std::pair<std::string, std::string>> mat_file_attributes(MatInput* mat);
// Reads a variable with its data; InputError (field = name) when absent or unreadable. Classes
// piezobench never reads the data of (sparse, object, function) come back as their header only.
[[nodiscard]] MatValue read_mat_variable(MatInput* mat, const std::filesystem::path& file, const std::string& name);

// Fast path for large records: reads a real double vector of exactly out.size()
// elements straight into `out` (no intermediate copy), in pieces of at most `chunk` elements;
// after each piece, `on_chunk(first, count)` (if given) may look at out[first, first + count)
// while it is still in the cache. Returns false, with `out` unspecified, when the variable is
// anything else; the caller then uses read_mat_variable. A read error is an InputError.
[[nodiscard]] bool read_double_vector_into(
    MatInput* mat, const std::string& name, Eigen::Ref<Eigen::VectorXd> out, Eigen::Index chunk = 1 << 17,
    const std::function<void(Eigen::Index first, Eigen::Index count)>& on_chunk = {});
// One element of such a variable (of exactly `count` elements); nullopt as above.
[[nodiscard]] std::optional<double> read_double_element(MatInput* mat, const std::string& name, Eigen::Index count,
                                                        Eigen::Index index);

// matio's variable as a MatValue (its data copied); InputError (source, field = its name) when
// matio's data do not hold what its dimensions declare or a char variable has a type not text.
[[nodiscard]] MatValue from_matvar(const matvar_t& var, const std::string& source);

// Describes a variable for error messages: "double 3x1", "complex double 1x4", "char 1x5".
[[nodiscard]] std::string describe(const MatValue& var);
[[nodiscard]] bool is_numeric_class(matio_classes c);
// A real numeric vector (row, column or scalar; any numeric class) as doubles; InputError
// naming `field` otherwise (char, struct, cell, complex, sparse, matrix with two non-singleton
// dimensions).
[[nodiscard]] Eigen::VectorXd to_real_vector(const MatValue& var, const std::string& source, const std::string& field);
// The same into preallocated storage; InputError also when the length differs from out.size().
void copy_real_vector(const MatValue& var, const std::string& source, const std::string& field,
                      Eigen::Ref<Eigen::VectorXd> out);
// A complex (or real) numeric vector; InputError naming `field` otherwise.
[[nodiscard]] Eigen::VectorXcd to_complex_vector(const MatValue& var, const std::string& source,
                                                 const std::string& field);
// A char row as a string; InputError naming `field` otherwise.
[[nodiscard]] std::string to_text(const MatValue& var, const std::string& source, const std::string& field);

// ---- building variables for writing ---------------------------------------------------------
// A view of v's data, not a copy (a 100 s record's channel is 8 MB): write it before v changes.
[[nodiscard]] MatValue make_real_column(const std::string& name, const Eigen::Ref<const Eigen::VectorXd>& v);
// A rows x cols double matrix of column-major `data` (a copy; empty data for []).
[[nodiscard]] MatValue make_matrix(const std::string& name, size_t rows, size_t cols, std::vector<double> data);
[[nodiscard]] MatValue make_complex_column(const std::string& name, const Eigen::VectorXcd& v);
[[nodiscard]] MatValue make_scalar(const std::string& name, double v);
[[nodiscard]] MatValue make_text(const std::string& name, const std::string& text);
// A 1 x n logical row.
[[nodiscard]] MatValue make_logical(const std::string& name, const std::vector<unsigned char>& values);
// A 1x1 struct whose fields are `fields`.
[[nodiscard]] MatValue make_struct(const std::string& name, std::vector<std::pair<std::string, MatValue>> fields);

// ---- writing MAT files (mat_file.cpp) -------------------------------------------------------

// Collects the variables of a MAT file being written (see write_mat_atomically).
class MatWriter {
 public:
  // Writes one variable; InputError (source = file, field = its name) when it cannot.
  void write(const MatValue& var);
  [[nodiscard]] const std::vector<std::string>& written() const { return written_; }
  // Name, length and last value of each real double variable written (the own encoder's check).
  [[nodiscard]] const std::vector<std::pair<std::string, std::pair<size_t, double>>>& last_values() const { return last_; }

  // The writer of an uncompressed v5 file (own encoder) on the open descriptor `fd`, or of matio's
  // `mat` (compressed v5, v7.3).
  MatWriter(int fd, std::filesystem::path file) : fd_(fd), file_(std::move(file)) {}
  MatWriter(mat_t* mat, std::filesystem::path file, bool compress)
      : mat_(mat), file_(std::move(file)), compress_(compress) {}

 private:
  int fd_ = -1;
  mat_t* mat_ = nullptr;
  std::filesystem::path file_;
  bool compress_ = false;
  std::vector<std::string> written_;
  std::vector<std::pair<std::string, std::pair<size_t, double>>> last_;
};

// Creates `file` as a MAT file (v5, or v7.3 through HDF5) under a temporary name, lets `fill`
// write the variables, then re-opens the result and checks that every written variable reads
// back before renaming it over the target (atomic, see AtomicFile). An uncompressed v5 file is
// written and checked without matio.
void write_mat_atomically(const std::filesystem::path& file, bool v73, bool compress,
                          const std::function<void(MatWriter&)>& fill);

}  // namespace piezobench::io::detail
