#include "piezobench/io/output_dir.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "piezobench/core/error.hpp"

namespace piezobench::io {
namespace fs = std::filesystem;

namespace {

// The pid in a leftover's name: ".staging-PID-N" or ".NAME.tmp-PID-COUNTER-TAG.EXT"; -1 if none.
long leftover_pid(const std::string& name) {
  std::size_t at = std::string::npos;
  if (name.rfind(".staging-", 0) == 0) {
    at = 9;
  } else if (name.size() > 1 && name[0] == '.') {
    const std::size_t tmp = name.rfind(".tmp-");
    if (tmp != std::string::npos && tmp > 1) at = tmp + 5;
  }
  if (at == std::string::npos) return -1;
  std::size_t end = at;
  while (end < name.size() && end - at < 10 && name[end] >= '0' && name[end] <= '9') ++end;
  if (end == at || end >= name.size() || name[end] != '-') return -1;
  return std::stol(name.substr(at, end - at));
}

bool process_exists(long pid) { return pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM); }

}  // namespace

std::size_t remove_leftovers(const fs::path& dir) {
  std::size_t removed = 0;
  std::error_code ec;
  std::vector<fs::path> doomed;
  for (auto it = fs::recursive_directory_iterator(dir, fs::directory_options::skip_permission_denied, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    // run and demo write into DIR and its folders (data/, superelement/): two levels.
    if (it.depth() >= 1 && it->is_directory(ec)) it.disable_recursion_pending();
    const long pid = leftover_pid(it->path().filename().string());
    if (pid < 0 || pid == ::getpid() || process_exists(pid)) continue;
    doomed.push_back(it->path());
    if (it->is_directory(ec)) it.disable_recursion_pending();
  }
  for (const fs::path& p : doomed) removed += fs::remove_all(p, ec) > 0 ? 1 : 0;
  return removed;
}

OutputLock::OutputLock(const fs::path& dir, const std::string& field) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    throw InputError(dir.string(), field, "a folder that can be created", ec ? ec.message() : "not a folder");
  }
  const fs::path lock = dir / ".piezobench.lock";
  // A run that ends unlinks its lock file while it holds the lock: one that opened the old file
  // just before then holds a lock on a file no longer there. So after flock the path must still
  // name the file locked; if not, try again (a few times: each retry means another run finished).
  for (int attempt = 0; attempt < 8 && fd_ < 0; ++attempt) {
    fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0644);
    if (fd_ < 0) {
      const int err = errno;
      throw InputError(dir.string(), field, "a writable folder whose .piezobench.lock is a plain file",
                       err == ELOOP ? ".piezobench.lock is a symbolic link (refused: never followed)"
                                    : "cannot create its lock file .piezobench.lock (" + std::string(std::strerror(err)) + ")");
    }
    struct stat held {};
    if (::fstat(fd_, &held) != 0 || !S_ISREG(held.st_mode)) {
      ::close(fd_);
      fd_ = -1;
      throw InputError(dir.string(), field, "a writable folder whose .piezobench.lock is a plain file", "something else there");
    }
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      ::close(fd_);
      fd_ = -1;
      throw InputError(dir.string(), field, "a folder no other piezobench run is writing",
                       err == EWOULDBLOCK ? "it is locked by another run (.piezobench.lock)"
                                          : "cannot lock it (" + std::string(std::strerror(err)) + ")");
    }
    struct stat named {};
    if (::lstat(lock.c_str(), &named) != 0 || named.st_ino != held.st_ino || named.st_dev != held.st_dev) {
      ::close(fd_);
      fd_ = -1;
    }
  }
  if (fd_ < 0) throw InputError(dir.string(), field, "a lock file that stays in place", "it was replaced 8 times");
  file_ = lock;
  remove_leftovers(dir);
}

OutputLock::~OutputLock() {
  if (fd_ < 0) return;
  ::unlink(file_.c_str());  // while still holding the lock (see the constructor)
  ::close(fd_);             // closing releases the flock
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
