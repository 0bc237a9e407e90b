// Tests of the isolated child (isolated.cpp): answers of any size arrive intact, and a child that
// crashes, exits or answers badly becomes an InputError naming the file; the parent never hangs.
#include "isolated.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <csignal>
#include <stdexcept>
#include <vector>

#include "piezobench/core/error.hpp"
#include "test_util.hpp"

namespace piezobench::io::detail {
namespace {

using test::expect_input_error;

IsolatedOptions options() {
  IsolatedOptions o;
  o.source = "record.mat";
  return o;
}

TEST(Isolated, TwoMillionDoublesArriveIntactWhileTheChildWrites) {
  // 16 MB: 250 times the pipe's buffer, so the child blocks until the parent reads.
  constexpr std::size_t n = 2'000'000;
  std::vector<double> got(n, 0.0);
  std::string label;
  run_isolated(
      options(),
      [&](IsolatedOut& out) {
        std::vector<double> v(n);
        for (std::size_t i = 0; i < n; ++i) v[i] = 0.5 * static_cast<double>(i) - 1e6;
        out.put_string("de");
        out.put_u64(n);
        out.put(v.data(), n * sizeof(double));
      },
      [&](IsolatedIn& in) {
        label = in.get_string();
        ASSERT_EQ(in.get_u64(), n);
        in.get(got.data(), n * sizeof(double));
      });
  EXPECT_EQ(label, "de");
  for (std::size_t i = 0; i < n; ++i) {
    if (got[i] != 0.5 * static_cast<double>(i) - 1e6) FAIL() << "sample " << i << " is " << got[i];
  }
}

TEST(Isolated, SmallPiecesAreGatheredAndReadBackInOrder) {
  std::vector<std::string> got;
  run_isolated(
      options(),
      [](IsolatedOut& out) {
        out.put_u64(20000);
        for (int i = 0; i < 20000; ++i) out.put_string("channel_" + std::to_string(i));
      },
      [&](IsolatedIn& in) {
        const std::uint64_t n = in.get_u64();
        for (std::uint64_t i = 0; i < n; ++i) got.push_back(in.get_string());
      });
  ASSERT_EQ(got.size(), 20000u);
  EXPECT_EQ(got.front(), "channel_0");
  EXPECT_EQ(got.back(), "channel_19999");
}

TEST(Isolated, AChildKilledBySigsegvIsAnInputErrorNamingTheFile) {
  expect_input_error(
      [] {
        run_isolated(
            options(),
            [](IsolatedOut& out) {
              out.put_u64(1);
              out.flush();
              std::raise(SIGSEGV);
            },
            [](IsolatedIn& in) {
              (void)in.get_u64();
              (void)in.get_u64();  // never sent
            });
      },
      {"record.mat", "file", "the HDF5 library failed on it (signal 11)"});
}

TEST(Isolated, AChildThatExitsWithoutAnAnswerIsAnInputError) {
  expect_input_error([] { run_isolated(options(), [](IsolatedOut&) { ::_exit(7); }, [](IsolatedIn& in) { (void)in.get_u64(); }); },
                     {"record.mat", "failed on it (exit status 7)"});
  // Even when the parent expected nothing.
  expect_input_error([] { run_isolated(options(), [](IsolatedOut&) { ::_exit(0); }, [](IsolatedIn&) {}); },
                     {"record.mat", "failed on it (its answer ended early)"});
}

TEST(Isolated, TheChildsInputErrorReachesTheParentAsItIs) {
  try {
    run_isolated(
        options(), [](IsolatedOut& out) {
          out.put_u64(5);
          throw InputError("record.mat", "de", "a real numeric vector", "char 1x5");
        },
        [](IsolatedIn& in) {
          (void)in.get_u64();
          (void)in.get_u64();
        });
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), std::string(InputError("record.mat", "de", "a real numeric vector", "char 1x5").what()));
  }
}

TEST(Isolated, AnAnswerOfAnotherLengthIsMalformed) {
  expect_input_error([] { run_isolated(options(), [](IsolatedOut& out) { out.put_u64(1); out.put_u64(2); },
                                       [](IsolatedIn& in) { (void)in.get_u64(); }); },
                     {"record.mat", "malformed answer", "more data than the reader took"});
  expect_input_error([] { run_isolated(options(), [](IsolatedOut& out) { out.put_u64(1); },
                                       [](IsolatedIn& in) { (void)in.get_u64(); (void)in.get_u64(); }); },
                     {"record.mat", "malformed answer", "shorter than announced"});
  expect_input_error([] { run_isolated(options(), [](IsolatedOut& out) { out.put_u64(1u << 30); },
                                       [](IsolatedIn& in) { (void)in.get_string(100); }); },
                     {"record.mat", "malformed answer", "a string of 1073741824 bytes"});
}

TEST(Isolated, TheParentsOwnErrorStopsAChildBlockedOnABigAnswer) {
  // The child writes 64 MB; the parent gives up after 8 bytes: no deadlock, the parent's error.
  EXPECT_THROW(run_isolated(
                   options(),
                   [](IsolatedOut& out) {
                     std::vector<double> v(8'000'000, 1.0);
                     out.put_u64(v.size());
                     out.put(v.data(), v.size() * sizeof(double));
                   },
                   [](IsolatedIn& in) {
                     (void)in.get_u64();
                     throw std::runtime_error("the parent refuses");
                   }),
               std::runtime_error);
}

TEST(Isolated, TheWriterKeepsItsOwnWording) {
  IsolatedOptions o = options();
  o.field = "output file";
  o.expected = "a complete write";
  o.failure = "the v7.3 writer process failed";
  expect_input_error([&] { run_isolated(o, [](IsolatedOut&) { std::raise(SIGBUS); }, [](IsolatedIn&) {}); },
                     {"record.mat", "output file", "a complete write", "the v7.3 writer process failed (signal 7)"});
}

}  // namespace
}  // namespace piezobench::io::detail
