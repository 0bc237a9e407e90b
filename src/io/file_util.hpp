#pragma once
// Private helpers shared by the io readers and writers: atomic output files, text parsing and
// thin RAII wrappers around matio.
#include <matio.h>

#include <Eigen/Dense>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace piezobench::io::detail {

// A file written under a temporary name in the target's directory and renamed over the target
// by commit(). Until then the target is untouched; the destructor removes an uncommitted
// temporary, so an exception anywhere in a writer leaves no partial file behind.
class AtomicFile {
 public:
  // Creates the (empty) temporary file; InputError (source = target) if that is impossible.
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  [[nodiscard]] const std::filesystem::path& temp_path() const { return temp_; }
  [[nodiscard]] const std::filesystem::path& target() const { return target_; }
  // Flushes the temporary to disk and renames it over the target; InputError on failure.
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temp_;
  bool committed_ = false;
};

// Writes a text (or binary) file atomically: `body` writes into a stream on the temporary file;
// a stream failure (disk full, file size limit) becomes an InputError and no file is left.
void write_atomically(const std::filesystem::path& target, const std::function<void(std::ostream&)>& body);

// The whole file; InputError (field "file") when it cannot be read.
[[nodiscard]] std::string read_file(const std::filesystem::path& file);

// Lower-case extension including the dot (".mat").
[[nodiscard]] std::string lower_extension(const std::filesystem::path& file);
[[nodiscard]] std::string to_lower(std::string s);
[[nodiscard]] std::string_view trim(std::string_view s);
// Splits at every `sep` (no quoting).
[[nodiscard]] std::vector<std::string_view> split(std::string_view s, char sep);
// Strict number parsing: the whole (trimmed) token must be a number ("nan"/"inf" accepted, so the
// caller can report them as non-finite values rather than as text). Fortran 'D' exponents are
// accepted when fortran is true.
[[nodiscard]] std::optional<double> parse_double(std::string_view token, bool fortran = false);
[[nodiscard]] std::optional<long long> parse_int(std::string_view token);
// %.17g (round-trips every double).
[[nodiscard]] std::string format_g17(double v);
// Shows a piece of a file in an error message: quoted, at most 40 characters.
[[nodiscard]] std::string quote(std::string_view text);
// "a, b, c"
[[nodiscard]] std::string join(const std::vector<std::string>& items, const std::string& sep = ", ");
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
//         checked; a failed read is an InputError, never data.
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

// Builders for writing (the returned variables own copies of their data).
[[nodiscard]] MatVarPtr make_real_column(const std::string& name, const Eigen::VectorXd& v);
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
