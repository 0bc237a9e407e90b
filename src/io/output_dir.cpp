#include "piezobench/io/output_dir.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "piezobench/core/error.hpp"

namespace piezobench::io {
namespace fs = std::filesystem;

OutputLock::OutputLock(const fs::path& dir, const std::string& field) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    throw InputError(dir.string(), field, "a folder that can be created", ec ? ec.message() : "not a folder");
  }
  const fs::path lock = dir / ".piezobench.lock";
  fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
  if (fd_ < 0) {
    throw InputError(dir.string(), field, "a writable folder",
                     "cannot create its lock file .piezobench.lock (" + std::string(std::strerror(errno)) + ")");
  }
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    ::close(fd_);
    fd_ = -1;
    throw InputError(dir.string(), field, "a folder no other piezobench run is writing",
                     err == EWOULDBLOCK ? "it is locked by another run (.piezobench.lock)"
                                        : "cannot lock it (" + std::string(std::strerror(err)) + ")");
  }
}

OutputLock::~OutputLock() {
  if (fd_ >= 0) ::close(fd_);  // closing releases the flock
}

StagedOutputs::StagedOutputs(fs::path dir) : dir_(std::move(dir)) {
  for (int attempt = 0; attempt < 16; ++attempt) {
    char tag[64];
    std::snprintf(tag, sizeof tag, ".staging-%d-%d", static_cast<int>(::getpid()), attempt);
    const fs::path candidate = dir_ / tag;
    if (::mkdir(candidate.c_str(), 0777) == 0) {
      staging_ = candidate;
      return;
    }
    if (errno != EEXIST) {
      throw InputError(dir_.string(), "output folder", "a writable folder",
                       "cannot create a staging folder in it (" + std::string(std::strerror(errno)) + ")");
    }
    std::error_code ec;
    fs::remove_all(candidate, ec);  // a leftover of a crashed run with a recycled pid
  }
  throw InputError(dir_.string(), "output folder", "a free staging name", "16 collisions");
}

StagedOutputs::~StagedOutputs() {
  std::error_code ec;
  if (!staging_.empty()) fs::remove_all(staging_, ec);
}

fs::path StagedOutputs::stage(const std::string& name) {
  names_.push_back(name);
  return staging_ / name;
}

std::vector<fs::path> StagedOutputs::commit() {
  std::vector<fs::path> out;
  for (const auto& name : names_) {
    const fs::path target = dir_ / name;
    if (std::rename((staging_ / name).c_str(), target.c_str()) != 0) {
      const int err = errno;
      throw InputError(target.string(), "output file", "a replaceable file",
                       "cannot move the finished file into place (" + std::string(std::strerror(err)) + ")");
    }
    out.push_back(target);
  }
  std::error_code ec;
  fs::remove(staging_, ec);  // empty now
  staging_.clear();
  return out;
}

}  // namespace piezobench::io
