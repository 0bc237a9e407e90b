#pragma once
// An output folder written all or nothing, by one process at a time.
//
//  - OutputLock: an advisory lock (flock on DIR/.piezobench.lock) held for the life of the object;
//    a second holder is refused with InputError (exit 3) naming the folder. The kernel releases it
//    when the process ends, so a crashed run never leaves the folder locked. The lock file is
//    opened without following a symbolic link (O_NOFOLLOW: a link there is refused, never a file
//    created at its target), must be a regular file, and is removed when the lock is released.
//    Once it holds the lock, it removes what dead runs left in DIR (kill -9, SIGTERM, a power
//    cut): staging folders `.staging-PID-N/` and temporary files `.NAME.tmp-PID-...` (core/file.hpp)
//    of processes that no longer exist, anywhere under DIR.
//  - StagedOutputs: files are written into a hidden sibling staging folder inside DIR and renamed
//    into DIR only by commit(); destroying it uncommitted removes the staging folder, so a failed
//    write (disk full, a throw) leaves DIR as it was.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace piezobench::io {

class OutputLock {
 public:
  // Creates `dir` if needed and takes its lock; InputError (source = dir, field `field`) when the
  // folder cannot be created or another process holds the lock.
  explicit OutputLock(const std::filesystem::path& dir, const std::string& field = "--out");
  ~OutputLock();
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

 private:
  int fd_ = -1;
  std::filesystem::path file_;
};

// Removes, under `dir` (symbolic links not followed), the staging folders and temporary files of
// processes that no longer exist; returns how many entries it removed. OutputLock calls it.
std::size_t remove_leftovers(const std::filesystem::path& dir);

class StagedOutputs {
 public:
  // `dir` must exist (OutputLock creates it).
  explicit StagedOutputs(std::filesystem::path dir);
  ~StagedOutputs();
  StagedOutputs(const StagedOutputs&) = delete;
  StagedOutputs& operator=(const StagedOutputs&) = delete;

  // Where to write the file that will become dir/name.
  [[nodiscard]] std::filesystem::path stage(const std::string& name);
  // Renames every staged file into dir in the order stage() was called (put the file that marks a
  // complete set last); returns the final paths.
  std::vector<std::filesystem::path> commit();

 private:
  std::filesystem::path dir_, staging_;
  std::vector<std::string> names_;
};

}  // namespace piezobench::io
