#include "mapped_file.hpp"

#if defined(__unix__)
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#endif

#include <cstdint>
#include <limits>

namespace piezobench::io::detail {

std::shared_ptr<const MappedFile> MappedFile::open([[maybe_unused]] const std::filesystem::path& file) {
#if defined(__unix__)
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return nullptr;
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size <= 0) {
    ::close(fd);
    return nullptr;
  }
  const auto size = static_cast<std::size_t>(st.st_size);
  int flags = MAP_PRIVATE;
#if defined(MAP_POPULATE)
  // One call maps every page the page cache holds (instead of one fault per 64 kB).
  flags |= MAP_POPULATE;
#endif
  void* p = ::mmap(nullptr, size, PROT_READ, flags, fd, 0);
  ::close(fd);  // the mapping keeps its own reference to the file
  if (p == MAP_FAILED) return nullptr;
  (void)::madvise(p, size, MADV_SEQUENTIAL);
  return std::shared_ptr<const MappedFile>(new MappedFile(static_cast<const unsigned char*>(p), size));
#else
  return nullptr;
#endif
}

MappedFile::~MappedFile() {
#if defined(__unix__)
  ::munmap(const_cast<unsigned char*>(data_), size_);
#endif
}

const double* MappedFile::doubles(std::size_t offset, std::size_t count) const {
  if (offset > size_ || count > (size_ - offset) / sizeof(double)) return nullptr;
  const unsigned char* p = data_ + offset;
  if (reinterpret_cast<std::uintptr_t>(p) % alignof(double) != 0) return nullptr;
  return reinterpret_cast<const double*>(p);
}

}  // namespace piezobench::io::detail
