// Tests of core/file.hpp: whole-file reading and atomic output files.
#include "piezobench/core/file.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <csignal>
#include <fstream>

#include "piezobench/core/error.hpp"
#include "test_util.hpp"

namespace piezobench {
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

TEST(WriteTextAtomically, WritesTheWholeTextOrNothing) {
  TempDir dir;
  const auto target = dir.path() / "model.json";
  write_text_atomically(target, "{\"a\": 1}\n");
  EXPECT_EQ(test::read_text(target), "{\"a\": 1}\n");
  EXPECT_THROW(write_text_atomically(dir.path() / "missing-dir" / "x.json", "x"), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "missing-dir"));
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path())) ++files;
  EXPECT_EQ(files, 1U);  // no temporary left behind
}

TEST(ReadFile, ReadsBytesAndNamesAMissingFile) {
  TempDir dir;
  const fs::path file = dir.path() / "data.bin";
  const std::string bytes("a\0b\r\nc", 6);
  std::ofstream(file, std::ios::binary) << bytes;
  EXPECT_EQ(read_file(file), bytes);
  try {
    (void)read_file(dir.path() / "missing.txt");
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.txt"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)read_file(dir.path()), InputError);
}

}  // namespace
}  // namespace piezobench
