#include "piezobench/core/parallel.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace piezobench::core {
namespace {

TEST(ParallelFor, RunsEveryJobOnceOnTheThreadsAsked) {
  for (const int threads : {0, 1, 3, 50}) {
    std::vector<std::atomic<int>> runs(20);
    std::mutex m;
    std::set<std::thread::id> ids;
    parallel_for(runs.size(), threads, [&](std::size_t i) {
      ++runs[i];
      const std::lock_guard<std::mutex> lock(m);
      ids.insert(std::this_thread::get_id());
    });
    for (const auto& r : runs) EXPECT_EQ(r.load(), 1);
    EXPECT_LE(ids.size(), static_cast<std::size_t>(std::max(threads, 1)));
  }
  parallel_for(0, 4, [](std::size_t) { FAIL() << "no job to run"; });
}

TEST(ParallelFor, StopsAfterAFailureAndRethrowsTheLowestFailedJob) {
  // One thread: jobs run in order, nothing after the failed job 3.
  std::vector<int> ran;
  try {
    parallel_for(10, 1, [&](std::size_t i) {
      ran.push_back(static_cast<int>(i));
      if (i == 3) throw std::runtime_error("job 3");
    });
    FAIL() << "expected the exception of job 3";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "job 3");
  }
  EXPECT_EQ(ran, (std::vector<int>{0, 1, 2, 3}));
  // Several threads, every job fails: which jobs start depends on the scheduling, the one rethrown
  // is the lowest of those that ran.
  std::mutex m;
  std::set<std::size_t> started;
  try {
    parallel_for(8, 4, [&](std::size_t i) {
      {
        const std::lock_guard<std::mutex> lock(m);
        started.insert(i);
      }
      throw std::runtime_error("job " + std::to_string(i));
    });
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    ASSERT_FALSE(started.empty());
    EXPECT_EQ(e.what(), "job " + std::to_string(*started.begin()));
  }
}

}  // namespace
}  // namespace piezobench::core
