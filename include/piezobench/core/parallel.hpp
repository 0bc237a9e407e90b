#pragma once
// Independent jobs on a few threads: the campaign's simulation of the demo records and its
// analysis of the units.
#include <cstddef>
#include <functional>

namespace piezobench::core {

// Calls job(i) once for each i in 0 .. count - 1 on `threads` threads (at most `count`; fewer than
// 1 means 1; the calling thread is one of them), each thread taking the next index in turn. After
// a job throws, no job starts; once every thread has finished, the exception of the failed job
// with the lowest index is rethrown.
void parallel_for(std::size_t count, int threads, const std::function<void(std::size_t)>& job);

}  // namespace piezobench::core
