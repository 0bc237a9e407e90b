#pragma once
// Counts heap allocations made through the global operator new, to prove that a real-time inner
// loop allocates nothing. A test binary that uses it lists tests/alloc_counter.cpp among its
// SOURCES (it replaces the global operator new and delete; one per binary).
//
//   piezobench::test::AllocationCounter count;
//   for (...) bench.step(u);
//   EXPECT_EQ(count.allocations(), 0);
#include <cstddef>

namespace piezobench::test {

// Allocations since construction, on any thread.
class AllocationCounter {
 public:
  AllocationCounter();
  [[nodiscard]] std::size_t allocations() const;

 private:
  std::size_t start_;
};

}  // namespace piezobench::test
