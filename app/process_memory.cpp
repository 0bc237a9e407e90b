// The piezobench program's memory policy, set before main: freed memory is kept for the next
// allocations (core::keep_freed_memory, core/memory.hpp). Every command allocates and frees
// record-sized buffers; returning them to the kernel and faulting them in again cost the demo 0.25 s
// of system time (docs/performance.md, "The demo").
#include "piezobench/core/memory.hpp"

namespace {

[[maybe_unused]] const bool kKeepFreedMemory = piezobench::core::keep_freed_memory();

}  // namespace
