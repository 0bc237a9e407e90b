#pragma once
// Memory hints for large buffers (records of 10^6..10^7 samples).
#include <cstddef>

namespace piezobench::core {

// Asks the kernel to back the whole 2 MiB pages inside [data, data + bytes) with transparent huge
// pages (Linux, THP in "madvise" mode): a buffer of 8 MB is then faulted in 4 times instead of
// 2,048, which is a third to a half of the cost of filling a fresh record. Call it after the
// allocation and before the first write. A hint: it never fails and does nothing elsewhere.
void advise_huge_pages(void* data, std::size_t bytes) noexcept;

// Makes the C library's malloc (glibc) keep freed memory for the process's next allocations instead
// of handing it back to the kernel: blocks up to 256 MiB come from the heap rather than from a fresh
// mmap each, and the heap keeps up to 512 MiB of free space at its top. A program that allocates and
// frees record-sized buffers over and over (the demo: simulated records, fits' tall matrices) then
// faults each page in once instead of at every allocation (the demo: 139,000 minor page faults ->
// 26,000, 0.46 -> 0.21 s of system time; docs/performance.md, "The demo"), for a peak about 20 MB
// higher. A policy of the whole process: the piezobench program sets it at start-up (app/
// process_memory.cpp), the library never does. Returns false where it is not supported.
bool keep_freed_memory() noexcept;

}  // namespace piezobench::core
