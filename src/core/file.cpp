#include "piezobench/core/file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>

#include "piezobench/core/error.hpp"

namespace piezobench {
namespace fs = std::filesystem;

namespace {

std::string errno_text(int err) { return std::strerror(err); }

// A name that no other writer (thread or process) picks: pid, a per-process counter and a random
// tag; O_EXCL below makes a collision an error rather than a shared file.
fs::path temp_name_for(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  static thread_local std::mt19937_64 rng{std::random_device{}()};
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  char tag[64];
  std::snprintf(tag, sizeof tag, ".tmp-%d-%u-%08llx", static_cast<int>(::getpid()), counter.fetch_add(1),
                static_cast<unsigned long long>(rng() & 0xffffffffULL));
  // Hidden, and the target's extension stays last so tools that sniff extensions behave.
  return dir / ("." + target.filename().string() + tag + target.extension().string());
}

void fsync_path(const fs::path& path, int flags) {
  const int fd = ::open(path.c_str(), flags);
  if (fd < 0) return;
  (void)::fsync(fd);
  ::close(fd);
}

}  // namespace

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)) {
  if (target_.empty() || !target_.has_filename()) {
    throw InputError(target_.string(), "output file", "a file name", "an empty name or a directory");
  }
  for (int attempt = 0; attempt < 16; ++attempt) {
    temp_ = temp_name_for(target_);
    const int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      ::close(fd);
      return;
    }
    if (errno != EEXIST) {
      const int err = errno;
      temp_.clear();
      throw InputError(target_.string(), "output file", "a writable location",
                       "cannot create a file in that directory (" + errno_text(err) + ")");
    }
  }
  temp_.clear();
  throw InputError(target_.string(), "output file", "a free temporary name", "16 collisions");
}

AtomicFile::~AtomicFile() {
  if (!committed_ && !temp_.empty()) {
    std::error_code ec;
    fs::remove(temp_, ec);
  }
}

void AtomicFile::commit() {
  // Data first, then the name: after a crash the target is either the old file or the new one.
  fsync_path(temp_, O_RDONLY | O_CLOEXEC);
  if (std::rename(temp_.c_str(), target_.c_str()) != 0) {
    const int err = errno;
    throw InputError(target_.string(), "output file", "a replaceable file",
                     "cannot rename the temporary file onto it (" + errno_text(err) + ")");
  }
  committed_ = true;
  fsync_path(target_.has_parent_path() ? target_.parent_path() : fs::path("."), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
}

void write_atomically(const fs::path& target, const std::function<void(std::ostream&)>& body) {
  AtomicFile out(target);
  {
    std::ofstream stream(out.temp_path(), std::ios::binary | std::ios::trunc);
    if (!stream) {
      throw InputError(target.string(), "output file", "a writable file", "cannot open the temporary file");
    }
    body(stream);
    stream.flush();
    if (!stream) {
      throw InputError(target.string(), "output file", "a complete write",
                       "a write error (disk full or file size limit?)");
    }
    stream.close();
    if (stream.fail()) {
      throw InputError(target.string(), "output file", "a complete write", "an error when closing the file");
    }
  }
  out.commit();
}

std::string read_file(const fs::path& file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) throw InputError(file.string(), "file", "an existing file", "no such file");
  if (fs::is_directory(file, ec)) throw InputError(file.string(), "file", "a regular file", "a directory");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "file", "a readable file", "cannot open it");
  std::string content;
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) throw InputError(file.string(), "file", "a readable file", "cannot determine its size");
  content.resize(static_cast<size_t>(size));
  in.seekg(0, std::ios::beg);
  in.read(content.data(), size);
  if (in.gcount() != size) throw InputError(file.string(), "file", "a readable file", "a read error");
  return content;
}

void write_text_atomically(const fs::path& target, const std::string& text) {
  write_atomically(target, [&](std::ostream& out) { out << text; });
}

}  // namespace piezobench
