// Tests of the private io helpers: atomic output files and strict number parsing.
#include "io/file_util.hpp"

#include "piezobench/io/atomic_file.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <csignal>
#include <fstream>

#include "piezobench/core/error.hpp"
#include "test_util.hpp"

namespace piezobench::io::detail {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

size_t entries(const fs::path& dir) {
  return static_cast<size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

TEST(AtomicFile, CommitReplacesTargetAndLeavesNoTemporary) {
  TempDir dir;
  const fs::path target = dir.path() / "out.txt";
  std::ofstream(target) << "old";
  write_atomically(target, [](std::ostream& out) { out << "new content"; });
  EXPECT_EQ(test::read_text(target), "new content");
  EXPECT_EQ(entries(dir.path()), 1u);
}

TEST(AtomicFile, ExceptionInBodyLeavesTargetUntouchedAndNoTemporary) {
  TempDir dir;
  const fs::path target = dir.path() / "out.txt";
  std::ofstream(target) << "old";
  EXPECT_THROW(write_atomically(target, [](std::ostream& out) {
                 out << "half";
                 throw InputError("x", "y", "z", "w");
               }),
               InputError);
  EXPECT_EQ(test::read_text(target), "old");
  EXPECT_EQ(entries(dir.path()), 1u);
}

TEST(AtomicFile, MissingDirectoryIsAnInputErrorNamingTheFile) {
  TempDir dir;
  const fs::path target = dir.path() / "no" / "such" / "dir" / "out.txt";
  try {
    write_atomically(target, [](std::ostream& out) { out << "x"; });
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(target.string()), std::string::npos) << e.what();
  }
  EXPECT_EQ(entries(dir.path()), 0u);
}

TEST(AtomicFile, RenameOntoADirectoryFailsAndRemovesTheTemporary) {
  TempDir dir;
  const fs::path target = dir.path() / "taken";
  fs::create_directory(target);
  EXPECT_THROW(write_atomically(target, [](std::ostream& out) { out << "x"; }), InputError);
  EXPECT_EQ(entries(dir.path()), 1u);
  EXPECT_TRUE(fs::is_directory(target));
}

TEST(AtomicFile, DiskFullDuringWriteLeavesNoFile) {
  // RLIMIT_FSIZE makes write() fail with EFBIG past 4 KiB, as a full disk would.
  TempDir dir;
  const fs::path target = dir.path() / "big.txt";
  struct rlimit old_limit {};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old_limit), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  struct rlimit small = old_limit;
  small.rlim_cur = 4096;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  bool threw = false;
  try {
    write_atomically(target, [](std::ostream& out) {
      for (int i = 0; i < 100000; ++i) out << "0123456789\n";
    });
  } catch (const InputError&) {
    threw = true;
  }
  setrlimit(RLIMIT_FSIZE, &old_limit);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_TRUE(threw);
  EXPECT_FALSE(fs::exists(target));
  EXPECT_EQ(entries(dir.path()), 0u);
}

TEST(ParseDouble, AcceptsWholeNumbersOnly) {
  EXPECT_EQ(parse_double(" 1.5 ").value(), 1.5);
  EXPECT_EQ(parse_double("+2e3").value(), 2000.0);
  EXPECT_EQ(parse_double("-0.25E-1").value(), -0.025);
  EXPECT_EQ(parse_double("1.0D+02", /*fortran=*/true).value(), 100.0);
  EXPECT_FALSE(parse_double("1.0D+02").has_value());
  EXPECT_FALSE(parse_double("1.5x").has_value());
  EXPECT_FALSE(parse_double("").has_value());
  EXPECT_FALSE(parse_double("abc").has_value());
  EXPECT_FALSE(parse_double("+-1").has_value());
  EXPECT_TRUE(std::isnan(parse_double("nan").value()));
  EXPECT_TRUE(std::isinf(parse_double("1e999").value()));
  EXPECT_EQ(parse_double("0.1").value(), 0.1);
  EXPECT_EQ(parse_double(format_g17(0.1 + 0.2)).value(), 0.1 + 0.2);
}

TEST(ParseInt, RejectsFractionsAndText) {
  EXPECT_EQ(parse_int("   58").value(), 58);
  EXPECT_EQ(parse_int("-1").value(), -1);
  EXPECT_FALSE(parse_int("5.0").has_value());
  EXPECT_FALSE(parse_int("5b").has_value());
}

TEST(MatlabIdentifier, FollowsMatlabRules) {
  EXPECT_TRUE(is_matlab_identifier("d_enc2"));
  EXPECT_FALSE(is_matlab_identifier("2d"));
  EXPECT_FALSE(is_matlab_identifier("_x"));
  EXPECT_FALSE(is_matlab_identifier("a b"));
  EXPECT_FALSE(is_matlab_identifier(std::string(64, 'a')));
  EXPECT_TRUE(is_matlab_identifier(std::string(63, 'a')));
}

}  // namespace
}  // namespace piezobench::io::detail

namespace piezobench::io {
namespace {

TEST(WriteTextAtomically, WritesTheWholeTextOrNothing) {
  test::TempDir dir;
  const auto target = dir.path() / "model.json";
  write_text_atomically(target, "{\"a\": 1}\n");
  EXPECT_EQ(test::read_text(target), "{\"a\": 1}\n");
  EXPECT_THROW(write_text_atomically(dir.path() / "missing-dir" / "x.json", "x"), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "missing-dir"));
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path())) ++files;
  EXPECT_EQ(files, 1U);  // no temporary left behind
}

}  // namespace
}  // namespace piezobench::io
