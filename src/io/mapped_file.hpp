#pragma once
// A read-only mapping of a whole file, for readers that use large uncompressed arrays in place
// (no copy into fresh memory, no zeroing of new pages).
#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

namespace piezobench::io::detail {

class MappedFile {
 public:
  // Maps `file` read-only and private, prefaulted from the page cache; nullptr when it cannot be
  // mapped (empty, not a regular file, no mmap on this platform, mmap refused): the caller then
  // reads the file instead. Never throws for those reasons.
  [[nodiscard]] static std::shared_ptr<const MappedFile> open(const std::filesystem::path& file);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  [[nodiscard]] const unsigned char* data() const { return data_; }
  [[nodiscard]] std::size_t size() const { return size_; }
  // The `count` doubles at byte `offset`, or nullptr when they are not all inside the mapping or
  // the offset is not aligned for double.
  [[nodiscard]] const double* doubles(std::size_t offset, std::size_t count) const;

 private:
  MappedFile(const unsigned char* data, std::size_t size) : data_(data), size_(size) {}
  const unsigned char* data_;
  std::size_t size_;
};

class MatInput;

// A vector used in place: `data` points into `file`, which must outlive every use of it.
struct MappedDoubles {
  const double* data = nullptr;
  std::shared_ptr<const MappedFile> file;
};

// The data of a top-level real double vector of exactly `count` elements of a v5 MAT file, stored
// uncompressed in native byte order, from a mapping of the file (mat_reader.cpp). nullopt for
// anything else (v7.3, compressed, another class or length, a file that cannot be mapped): the
// caller reads it with read_double_vector_into. The declared sizes were checked against the file
// when it was opened (open_mat_for_reading), and are checked again against the mapping.
[[nodiscard]] std::optional<MappedDoubles> map_double_vector(MatInput* mat, const std::string& name, std::size_t count);

}  // namespace piezobench::io::detail
