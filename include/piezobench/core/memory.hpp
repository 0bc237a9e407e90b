#pragma once
// Memory hints for large buffers (records of 10^6..10^7 samples).
#include <cstddef>

namespace piezobench::core {

// Asks the kernel to back the whole 2 MiB pages inside [data, data + bytes) with transparent huge
// pages (Linux, THP in "madvise" mode): a buffer of 8 MB is then faulted in 4 times instead of
// 2,048, which is a third to a half of the cost of filling a fresh record. Call it after the
// allocation and before the first write. A hint: it never fails and does nothing elsewhere.
void advise_huge_pages(void* data, std::size_t bytes) noexcept;

}  // namespace piezobench::core
