// Tests of the MAT readers' defences (mat_reader.cpp): hostile files made by
// scripts/fixtures/make_io_hostile_fixtures.py from scipy and h5py output, each refused with an
// InputError naming the variable before anything is allocated for what it declares.
#include "mat_file.hpp"

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
constexpr bool kLimitAddressSpace = !test::kSanitizerBuild;

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

// ---- v7.3 through the isolated child (isolated.cpp) ----------------------------------------

// A 16 MB vector comes back from the child intact, both in pieces into place (the timeseries
// fast path) and as one whole variable.
TEST(MatReaderV73, TwoMillionDoublesRoundTripThroughTheChild) {
  test::TempDir dir;
  const fs::path file = dir.path() / "big73.mat";
  constexpr Eigen::Index n = 2'000'000;
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(n, -1.0, 1.0).array().sin() * 3.0;
  detail::write_mat_atomically(file, /*v73=*/true, false, [&](detail::MatWriter& w) { w.write(detail::make_real_column("de", x)); });
  const detail::MatFilePtr mat = detail::open_mat_for_reading(file);
  const std::vector<detail::MatVarInfo> vars = detail::list_mat_variables(mat.get(), file);
  ASSERT_EQ(vars.size(), 1u);
  EXPECT_EQ(vars[0].name, "de");
  EXPECT_EQ(vars[0].dims, (std::vector<size_t>{static_cast<size_t>(n), 1}));

  Eigen::VectorXd into(n);
  Eigen::Index pieces = 0, covered = 0;
  ASSERT_TRUE(detail::read_double_vector_into(mat.get(), "de", into, 1 << 17, [&](Eigen::Index first, Eigen::Index count) {
    EXPECT_EQ(first, covered);
    covered += count;
    ++pieces;
  }));
  EXPECT_EQ(covered, n);
  EXPECT_EQ(pieces, (n + (1 << 17) - 1) / (1 << 17));
  EXPECT_TRUE(into == x);
  EXPECT_EQ(detail::read_double_element(mat.get(), "de", n, n - 1), x(n - 1));

  const detail::MatValue whole = detail::read_mat_variable(mat.get(), file, "de");
  EXPECT_TRUE(detail::to_real_vector(whole, file.string(), "de") == x);
}

// Every kind of variable the child sends (struct, char, complex, scalar) arrives as it was written.
TEST(MatReaderV73, StructsTextAndComplexDataComeBackFromTheChild) {
  test::TempDir dir;
  const fs::path file = dir.path() / "kinds73.mat";
  Eigen::VectorXcd h(3);
  h << std::complex<double>(1.0, -2.0), std::complex<double>(0.5, 0.25), std::complex<double>(-3.0, 4.0);
  detail::write_mat_atomically(file, /*v73=*/true, false, [&](detail::MatWriter& w) {
    std::vector<std::pair<std::string, detail::MatValue>> fields;
    fields.emplace_back("name", detail::make_text("name", "APA300ML"));
    fields.emplace_back("k", detail::make_scalar("k", 1.75e6));
    w.write(detail::make_struct("settings", std::move(fields)));
    w.write(detail::make_complex_column("H", h));
    w.write(detail::make_text("input", "u"));
    w.write(detail::make_text("unit", "\u00b5m \u00dc \u221e"));  // non-ASCII: UTF-16 units in the file
  });
  const detail::MatFilePtr mat = detail::open_mat_for_reading(file);
  EXPECT_EQ(detail::to_text(detail::read_mat_variable(mat.get(), file, "unit"), file.string(), "unit"), "\u00b5m \u00dc \u221e");
  const detail::MatValue s = detail::read_mat_variable(mat.get(), file, "settings");
  ASSERT_EQ(s.class_type, MAT_C_STRUCT);
  const detail::MatValue* name = s.field("name");
  const detail::MatValue* k = s.field("k");
  ASSERT_NE(name, nullptr);
  ASSERT_NE(k, nullptr);
  EXPECT_EQ(detail::to_text(*name, file.string(), "name"), "APA300ML");
  EXPECT_EQ(detail::to_real_vector(*k, file.string(), "k")(0), 1.75e6);
  EXPECT_TRUE(detail::to_complex_vector(detail::read_mat_variable(mat.get(), file, "H"), file.string(), "H") == h);
  EXPECT_EQ(detail::to_text(detail::read_mat_variable(mat.get(), file, "input"), file.string(), "input"), "u");
  // A variable the file lacks: the child's InputError, as it was.
  expect_input_error([&] { (void)detail::read_mat_variable(mat.get(), file, "missing"); },
                     {"kinds73.mat", "missing", "none of that name"});
}

// Files on which Debian's HDF5 1.10.8 itself over-reads a heap buffer (under H5Aexists) or leaks
// (found by fuzz_mat_frf and fuzz_mat_timeseries; replayed from fuzz/regression/): read in the
// isolated child, they end as an InputError naming the file through every reader.
TEST(MatReaderV73, FilesHdf5ItselfFailsOnAreInputErrors) {
  for (const char* name : {"mat_frf/hdf5_attr_overread.mat", "mat_timeseries/hdf5_leak.mat"}) {
    const fs::path file = fs::path(PIEZOBENCH_SOURCE_DIR) / "fuzz" / "regression" / name;
    SCOPED_TRACE(name);
    expect_refused([&] { (void)read_timeseries(file); }, {file.filename().string()});
    expect_refused([&] { (void)read_frf(file); }, {file.filename().string()});
  }
}

}  // namespace
}  // namespace piezobench::io
