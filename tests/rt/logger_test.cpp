#include "piezobench/rt/logger.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <thread>

#include "piezobench/io/timeseries.hpp"
#include "piezobench/rt/spsc_ring.hpp"
#include "test_util.hpp"

namespace piezobench::rt {
namespace {

TEST(SpscRing, CapacityFifoOrderAndFull) {
  SpscRing<int> ring(5);
  EXPECT_EQ(ring.capacity(), 8u);  // rounded up to a power of two
  int v = 0;
  EXPECT_FALSE(ring.pop(v));
  for (int round = 0; round < 3; ++round) {  // wraps around the storage
    for (int i = 0; i < 8; ++i) ASSERT_TRUE(ring.push(round * 100 + i));
    EXPECT_FALSE(ring.push(-1));
    EXPECT_EQ(ring.size(), 8u);
    for (int i = 0; i < 8; ++i) {
      ASSERT_TRUE(ring.pop(v));
      EXPECT_EQ(v, round * 100 + i);
    }
    EXPECT_FALSE(ring.pop(v));
  }
}

// One producer, one consumer, a small ring: every value arrives once and in order.
TEST(SpscRing, ConcurrentProducerAndConsumerLoseNothing) {
  SpscRing<std::uint64_t> ring(64);
  constexpr std::uint64_t kCount = 50000;
  std::uint64_t next_expected = 0;
  bool in_order = true;
  std::thread consumer([&] {
    std::uint64_t v = 0;
    while (next_expected < kCount) {
      if (ring.pop(v)) {
        in_order = in_order && v == next_expected;
        ++next_expected;
      } else {
        std::this_thread::yield();
      }
    }
  });
  for (std::uint64_t i = 0; i < kCount; ++i) {
    while (!ring.push(i)) std::this_thread::yield();
  }
  consumer.join();
  EXPECT_TRUE(in_order);
  EXPECT_EQ(next_expected, kCount);
}

LogRecord record(int k) {
  LogRecord r;
  r.t = k * 1e-4;
  r.u_prime = 0.01 * k;
  r.u = 0.02 * k;
  r.va = 0.4 * k;
  r.va_cmd = 0.4 * k + 1.0;
  r.de = 1e-9 * k;
  r.vs = -0.001 * k;
  r.y = 0.5;
  r.latency_us = 3.0;
  r.step_us = 1.5;
  r.flags = static_cast<std::uint32_t>(k % 16);
  return r;
}

TEST(SignalLogger, WritesEveryRecordToTheFile) {
  test::TempDir dir;
  LoggerOptions o;
  o.file = dir.path() / "log.mat";
  o.ring_capacity = 256;  // smaller than the run: the thread must drain while the producer pushes
  o.max_samples = 5000;
  o.settings["gain"] = 280000.0;
  SignalLogger logger(o);
  logger.start();
  for (int k = 0; k < 5000; ++k) logger.push_wait(record(k));
  const io::TimeSeries& log = logger.finish();
  EXPECT_EQ(logger.stored(), 5000u);
  EXPECT_EQ(logger.dropped(), 0u);
  EXPECT_EQ(log.samples(), 5000);

  const io::TimeSeries back = io::read_timeseries(*o.file);
  ASSERT_EQ(back.samples(), 5000);
  EXPECT_DOUBLE_EQ(back.sample_rate, 10e3);
  for (const char* name : {"u_prime", "u", "Va", "Va_cmd", "de", "Vs", "y", "latency_us", "step_us", "flags"}) {
    EXPECT_NO_THROW((void)back.index(name)) << name;
  }
  EXPECT_EQ(back.unit("de"), "m");
  for (int k : {0, 1, 2500, 4999}) {
    const LogRecord r = record(k);
    EXPECT_DOUBLE_EQ(back.t(k), r.t);
    EXPECT_DOUBLE_EQ(back.channel("u_prime")(k), r.u_prime);
    EXPECT_DOUBLE_EQ(back.channel("Va")(k), r.va);
    EXPECT_DOUBLE_EQ(back.channel("Va_cmd")(k), r.va_cmd);
    EXPECT_DOUBLE_EQ(back.channel("de")(k), r.de);
    EXPECT_DOUBLE_EQ(back.channel("Vs")(k), r.vs);
    EXPECT_DOUBLE_EQ(back.channel("flags")(k), static_cast<double>(r.flags));
  }
  EXPECT_EQ(std::get<double>(back.settings.at("gain")), 280000.0);
}

// A full ring drops (push returns false) and counts; so does storage beyond max_samples.
TEST(SignalLogger, CountsDrops) {
  LoggerOptions o;
  o.ring_capacity = 4;
  o.max_samples = 3;
  SignalLogger logger(o);  // thread not started: nothing drains the ring
  int accepted = 0;
  for (int k = 0; k < 10; ++k) accepted += logger.push(record(k)) ? 1 : 0;
  EXPECT_EQ(accepted, 4);
  EXPECT_EQ(logger.dropped(), 6u);
  const io::TimeSeries& log = logger.finish();  // drains the 4: 3 stored, 1 beyond max_samples
  EXPECT_EQ(log.samples(), 3);
  EXPECT_EQ(logger.stored(), 3u);
  EXPECT_EQ(logger.dropped(), 7u);
  EXPECT_DOUBLE_EQ(log.channel("u")(2), record(2).u);
}

TEST(SignalLogger, BadOptionsAndUnwritableFile) {
  LoggerOptions o;
  o.ring_capacity = 1;
  test::input_error([&] { SignalLogger l(o); }, "ring_capacity");
  o = {};
  o.sample_rate = 0.0;
  test::input_error([&] { SignalLogger l(o); }, "sample_rate");

  test::TempDir dir;
  o = {};
  o.file = dir.path() / "no-such-dir" / "log.mat";
  o.max_samples = 10;
  SignalLogger logger(o);
  logger.start();
  logger.push_wait(record(1));
  test::input_error([&] { logger.finish(); });
  EXPECT_FALSE(std::filesystem::exists(*o.file));

  // Asked for a file but nothing logged: an error, not an empty file.
  LoggerOptions e;
  e.file = dir.path() / "empty.mat";
  e.max_samples = 10;
  SignalLogger empty(e);
  empty.start();
  test::input_error([&] { empty.finish(); });
  EXPECT_FALSE(std::filesystem::exists(*e.file));
}

}  // namespace
}  // namespace piezobench::rt
