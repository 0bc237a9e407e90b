// Tests of the MAT readers' defences (mat_reader.cpp): hostile files made by
// scripts/fixtures/make_io_hostile_fixtures.py from scipy and h5py output, each refused with an
// InputError naming the variable before anything is allocated for what it declares.
#include "io/mat_file.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include "piezobench/io/frf_file.hpp"
#include "piezobench/io/timeseries.hpp"
#include "test_util.hpp"

namespace piezobench::io {
namespace {

namespace fs = std::filesystem;
using test::expect_input_error;

fs::path hostile(const std::string& name) { return test::fixture_path("io/hostile/" + name); }

// Every hostile read runs under an address-space limit far below what the files declare, so a
// reader that allocated first would fail with bad_alloc (not an InputError) instead of passing.
class AddressSpaceLimit {
 public:
  explicit AddressSpaceLimit(rlim_t bytes) {
    getrlimit(RLIMIT_AS, &old_);
    rlimit lim = old_;
    lim.rlim_cur = std::min<rlim_t>(bytes, old_.rlim_max);
    active_ = setrlimit(RLIMIT_AS, &lim) == 0;
  }
  ~AddressSpaceLimit() {
    if (active_) setrlimit(RLIMIT_AS, &old_);
  }

 private:
  rlimit old_{};
  bool active_ = false;
};

// Sanitizer builds reserve terabytes of address space: no limit there.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kLimitAddressSpace = false;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer) || __has_feature(thread_sanitizer)
constexpr bool kLimitAddressSpace = false;
#else
constexpr bool kLimitAddressSpace = true;
#endif
#else
constexpr bool kLimitAddressSpace = true;
#endif

template <typename F>
void expect_refused(F&& f, const std::vector<std::string>& needles) {
  std::optional<AddressSpaceLimit> limit;
  if (kLimitAddressSpace) limit.emplace(rlim_t{6} << 30);  // 6 GiB: the test binary's own mappings fit
  expect_input_error(std::forward<F>(f), needles);
}

ReadOptions channels(std::vector<std::string> names) {
  ReadOptions o;
  o.channels = std::move(names);
  return o;
}

TEST(MatReaderHostile, CharDimensionsBeyondItsDataAreRefusedNotCopied) {
  // The heap overflow of issue 21: `channels` claims 16,777,216 characters and holds 4.
  expect_refused([] { (void)read_timeseries(hostile("char_dims_overflow.mat"), channels({"u", "de"})); },
                 {"char_dims_overflow.mat", "'channels'", "1x16777216", "16777216 elements of 1 byte", "4 bytes of data"});
}

TEST(MatReaderHostile, FrfTextBeyondItsDataIsRefused) {
  expect_refused([] { (void)read_frf(hostile("frf_text_overflow.mat")); },
                 {"frf_text_overflow.mat", "'input'", "1x16777216", "1 byte of data"});
}

TEST(MatReaderHostile, NumericDimensionsBeyondItsDataAreRefused) {
  // matio would allocate 800 KB and return 99,936 uninitialised samples.
  expect_refused([] { (void)read_timeseries(hostile("numeric_dims_short.mat"), channels({"u", "de"})); },
                 {"numeric_dims_short.mat", "'de'", "1x100000", "100000 elements of 8 bytes", "512 bytes of data"});
}

TEST(MatReaderHostile, CompressedDimensionsAskingFor32GiBAreRefusedBeforeInflating) {
  expect_refused([] { (void)read_timeseries(hostile("compressed_dims_32gb.mat"), channels({"u", "de"})); },
                 {"compressed_dims_32gb.mat", "65536x65536", "4294967296 elements of 8 bytes"});
}

TEST(MatReaderHostile, V73EmptyFlagWithDimensionsHoldingNoZeroIsRefused) {
  expect_refused([] { (void)read_timeseries(hostile("v73_empty_flag_dims.mat"), channels({"u", "de"})); },
                 {"v73_empty_flag_dims.mat", "de", "MATLAB_empty", "500x1 holding no zero"});
}

TEST(MatReaderHostile, V73EmptyFlagOnStoredDataIsRefusedNotReadAsMemory) {
  // The FRF of issue 21 changed with MALLOC_PERTURB_: the failed read went unnoticed.
  expect_refused([] { (void)read_timeseries(hostile("v73_empty_flag_data.mat"), channels({"u", "de"})); },
                 {"v73_empty_flag_data.mat", "de", "MATLAB_empty", "500 values"});
}

TEST(MatReaderHostile, V73CompressedDeclarationBeyondTheInflationCapIsRefused) {
  expect_refused([] { (void)read_timeseries(hostile("v73_declares_3e8.mat"), ReadOptions{}); },
                 {"v73_declares_3e8.mat", "de (declared 300000000x1)", "at most 1100 times", "2400000000 bytes once inflated"});
}

TEST(MatReaderHostile, V73UnwrittenContiguousDatasetIsRefused) {
  expect_refused([] { (void)read_timeseries(hostile("v73_declares_2e9.mat"), ReadOptions{}); },
                 {"v73_declares_2e9.mat", "de (declared 2000000000x1)", "16000000000 bytes of data in the file", "0 bytes"});
}

// An attribute read by H5Aread fills one element per point of its dataspace: MATLAB_class as an
// array of strings overran the one-string buffer (found by fuzz_mat_timeseries).
TEST(MatReaderHostile, V73ClassAttributeHoldingManyStringsIsRefused) {
  for (const char* name : {"v73_class_vlen_array.mat", "v73_class_fixed_array.mat"}) {
    expect_refused([&] { (void)read_timeseries(hostile(name), channels({"u", "de"})); },
                   {name, "de", "MATLAB_class as one string", "40 elements"});
  }
}

TEST(MatReaderHostile, EveryHostileFileIsAnInputErrorThroughEveryReader) {
  for (const auto& entry : fs::directory_iterator(test::fixture_path("io/hostile"))) {
    if (entry.path().extension() != ".mat") continue;
    SCOPED_TRACE(entry.path().filename().string());
    expect_refused([&] { (void)read_timeseries(entry.path()); }, {entry.path().filename().string()});
    expect_refused([&] { (void)read_frf(entry.path()); }, {entry.path().filename().string()});
  }
}

}  // namespace
}  // namespace piezobench::io
