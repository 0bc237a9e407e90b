#include "piezobench/core/memory.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <vector>

#include "test_util.hpp"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace piezobench::core {
namespace {

// A hint only: nothing happens to the data, null and small buffers are ignored, and a buffer of
// several huge pages at any alignment stays readable and writable.
TEST(Memory, AdvisingHugePagesKeepsTheData) {
  advise_huge_pages(nullptr, 0);
  advise_huge_pages(nullptr, std::size_t{1} << 30);
  double small[4] = {1.0, 2.0, 3.0, 4.0};
  advise_huge_pages(small, sizeof small);
  EXPECT_EQ(small[3], 4.0);
  for (const std::size_t offset : {0u, 1u, 511u}) {
    std::vector<double> big((std::size_t{3} << 20) + offset);  // 24 MB: at least 10 whole 2 MiB pages
    for (std::size_t i = 0; i < big.size(); i += 4096) big[i] = static_cast<double>(i);
    advise_huge_pages(big.data() + offset, (big.size() - offset) * sizeof(double));
    double sum = 0.0;
    for (std::size_t i = 0; i < big.size(); i += 4096) sum += big[i] - static_cast<double>(i);
    EXPECT_EQ(sum, 0.0);
    big.back() = 7.0;
    EXPECT_EQ(big.back(), 7.0);
  }
}

// After keep_freed_memory, a 16 MB block comes from the heap (glibc maps blocks above 128 KiB on
// their own by default: mallinfo2's hblks counts them) and a freed one is not returned.
TEST(Memory, KeepFreedMemoryServesRecordSizedBlocksFromTheHeap) {
  if (test::kSanitizerBuild) GTEST_SKIP() << "the sanitizer replaces malloc: glibc's mallopt and mallinfo2 do not describe its heap";
#if defined(__GLIBC__)
  ASSERT_TRUE(keep_freed_memory());
  const std::size_t mapped_before = mallinfo2().hblks;
  void* block = std::malloc(std::size_t{16} << 20);
  ASSERT_NE(block, nullptr);
  EXPECT_EQ(mallinfo2().hblks, mapped_before);
  const std::size_t heap = mallinfo2().arena;
  std::free(block);
  EXPECT_EQ(mallinfo2().arena, heap);  // the heap's top kept, not trimmed
#else
  EXPECT_FALSE(keep_freed_memory());
#endif
}

}  // namespace
}  // namespace piezobench::core
