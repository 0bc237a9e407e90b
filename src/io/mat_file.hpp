#pragma once
// Private MAT-file layer of io: thin RAII wrappers around matio, the bounded reader (v5/v7 through
// matio, v7.3 through HDF5: mat_reader.cpp) and the atomic writer (mat_file.cpp). Every call into
// HDF5 (reading and writing v7.3) runs in a forked child (io/isolated.hpp) so that a fault inside
// the library on a hostile file cannot take the program down: this process never calls HDF5.
#include <matio.h>

#include <Eigen/Dense>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
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

// ---- reading MAT files (mat_reader.cpp) -----------------------------------------------------
//
// Resource bounds (docs/formats.md, "Hostile files"): before anything is allocated for a
// variable, the size its header declares is checked against the bytes the file holds for it.
//  v5/v7  every data element must hold the bytes its dimensions need (at least 1 byte per element:
//         MATLAB may store doubles as smaller integers), so a variable takes at most 8 times its
//         bytes in the file (16 for complex); a compressed variable may declare at most
//         kMaxInflation times its compressed size (zlib's own limit is 1032) and its inflated
//         stream is checked the same way. Read by matio after these checks.
//  v7.3   read through HDF5 directly (matio 1.5 misreads class strings written by h5py and
//         hdf5storage, and reads flagged-empty datasets as dimensions): an uncompressed dataset
//         must have the bytes its dimensions need allocated in the file; a filtered (deflated)
//         one may declare at most kMaxInflation times its stored bytes. Every HDF5 return value is
//         checked; a failed read is an InputError, never data. Every operation runs in an
//         isolated child (open and list, each variable, each vector): a child that crashes or
//         exits is an InputError naming the file ("the HDF5 library failed on it (signal 11)").
inline constexpr double kMaxInflation = 1100.0;

// An open MAT file (v5/v7 through matio, v7.3 through HDF5).
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
// Names and classes of the variables, in file order (info only, no data read).
struct MatVarInfo {
  std::string name;
  matio_classes class_type = MAT_C_EMPTY;
  bool is_complex = false;
  std::vector<size_t> dims;
  std::string unit;  // v7.3: the dataset's string attribute `units` (h5py users write one), else ""
};
[[nodiscard]] std::vector<MatVarInfo> list_mat_variables(MatInput* mat, const std::filesystem::path& file);
// Reads a variable with its data; InputError (field = name) when absent or unreadable. Classes
// piezobench never reads the data of (sparse, object, function) come back as their header only.
[[nodiscard]] MatVarPtr read_mat_variable(MatInput* mat, const std::filesystem::path& file, const std::string& name);

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

// Describes a variable for error messages: "double 3x1", "complex double 1x4", "char 1x5".
[[nodiscard]] std::string describe(const matvar_t& var);
[[nodiscard]] bool is_numeric_class(matio_classes c);
// Number of elements (product of dims).
[[nodiscard]] size_t element_count(const matvar_t& var);
// A real numeric vector (row, column or scalar; any numeric class) as doubles; InputError
// naming `field` otherwise (char, struct, cell, complex, sparse, matrix with two non-singleton
// dimensions).
[[nodiscard]] Eigen::VectorXd to_real_vector(const matvar_t& var, const std::string& source, const std::string& field);
// The same into preallocated storage; InputError also when the length differs from out.size().
void copy_real_vector(const matvar_t& var, const std::string& source, const std::string& field,
                      Eigen::Ref<Eigen::VectorXd> out);
// A complex (or real) numeric vector; InputError naming `field` otherwise.
[[nodiscard]] Eigen::VectorXcd to_complex_vector(const matvar_t& var, const std::string& source,
                                                 const std::string& field);
// A char row as a string; InputError naming `field` otherwise.
[[nodiscard]] std::string to_text(const matvar_t& var, const std::string& source, const std::string& field);

// Builders for writing (the returned variables own copies of their data, except make_real_column's).
// A view of v's data, not a copy (a 100 s record's channel is 8 MB): write it before v changes.
[[nodiscard]] MatVarPtr make_real_column(const std::string& name, const Eigen::Ref<const Eigen::VectorXd>& v);
[[nodiscard]] MatVarPtr make_complex_column(const std::string& name, const Eigen::VectorXcd& v);
[[nodiscard]] MatVarPtr make_scalar(const std::string& name, double v);
[[nodiscard]] MatVarPtr make_text(const std::string& name, const std::string& text);
// A 1x1 struct whose fields are `fields` (ownership moves into the struct).
[[nodiscard]] MatVarPtr make_struct(const std::string& name, std::vector<std::pair<std::string, MatVarPtr>> fields);

// Collects the variables of a MAT file being written (see write_mat_atomically).
class MatWriter {
 public:
  MatWriter(mat_t* mat, std::filesystem::path file, bool compress)
      : mat_(mat), file_(std::move(file)), compress_(compress) {}
  // Writes one variable; InputError (source = file, field = its name) when matio fails.
  void write(const MatVarPtr& var);
  [[nodiscard]] const std::vector<std::string>& written() const { return written_; }

 private:
  mat_t* mat_;
  std::filesystem::path file_;
  bool compress_;
  std::vector<std::string> written_;
};

// Creates `file` as a MAT file (v5, or v7.3 through HDF5) under a temporary name, lets `fill`
// write the variables, then re-opens the result and checks that every written variable reads
// back before renaming it over the target (atomic, see AtomicFile).
void write_mat_atomically(const std::filesystem::path& file, bool v73, bool compress,
                          const std::function<void(MatWriter&)>& fill);

}  // namespace piezobench::io::detail
