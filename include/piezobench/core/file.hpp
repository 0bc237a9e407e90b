#pragma once
// Whole files in and out: reading a file into a string, and output files that are either complete
// or absent (written under a temporary name in the target's directory and renamed over it).
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>

namespace piezobench {

// The whole file; InputError (source = file, field "file") when it is missing, a directory or
// cannot be read.
[[nodiscard]] std::string read_file(const std::filesystem::path& file);

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
// Writes `text` to `target` atomically; InputError (source = target) when it cannot.
void write_text_atomically(const std::filesystem::path& target, const std::string& text);

}  // namespace piezobench
