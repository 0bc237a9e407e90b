// Tests of the all-or-nothing output folder: the lock refuses a second holder, staged files reach
// the folder only on commit.
#include "piezobench/io/output_dir.hpp"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <fstream>

#include "piezobench/core/error.hpp"
#include "test_util.hpp"

namespace piezobench::io {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

std::vector<std::string> names(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

TEST(OutputLock, SecondHolderIsRefusedUntilTheFirstIsGone) {
  TempDir dir;
  const fs::path out = dir.path() / "out";
  {
    const OutputLock first(out);
    EXPECT_TRUE(fs::is_directory(out));
    try {
      const OutputLock second(out);
      ADD_FAILURE() << "second lock taken";
    } catch (const InputError& e) {
      EXPECT_TRUE(test::contains(e.what(), out.string())) << e.what();
      EXPECT_TRUE(test::contains(e.what(), "locked by another run")) << e.what();
    }
  }
  EXPECT_NO_THROW(const OutputLock again(out));
}

TEST(OutputLock, AFileInsteadOfAFolderIsAnInputError) {
  TempDir dir;
  std::ofstream(dir.path() / "f") << "x";
  test::input_error([&] { const OutputLock lock(dir.path() / "f"); });
}

TEST(StagedOutputs, NothingReachesTheFolderWithoutCommit) {
  TempDir dir;
  std::ofstream(dir.path() / "a.txt") << "old";
  {
    StagedOutputs staged(dir.path());
    std::ofstream(staged.stage("a.txt")) << "new";
    std::ofstream(staged.stage("b.txt")) << "new";
  }
  EXPECT_EQ(names(dir.path()), (std::vector<std::string>{"a.txt"}));
  EXPECT_EQ(test::read_text(dir.path() / "a.txt"), "old");
}

TEST(StagedOutputs, CommitRenamesInOrderAndLeavesNoStagingFolder) {
  TempDir dir;
  std::ofstream(dir.path() / "a.txt") << "old";
  StagedOutputs staged(dir.path());
  std::ofstream(staged.stage("a.txt")) << "new a";
  std::ofstream(staged.stage("b.txt")) << "new b";
  const auto written = staged.commit();
  ASSERT_EQ(written.size(), 2u);
  EXPECT_EQ(written.back(), dir.path() / "b.txt");
  EXPECT_EQ(test::read_text(dir.path() / "a.txt"), "new a");
  EXPECT_EQ(names(dir.path()), (std::vector<std::string>{"a.txt", "b.txt"}));
}

TEST(OutputLock, ASymbolicLinkIsNeverFollowedAndTheLockFileGoesAtTheEnd) {
  TempDir dir;
  const fs::path out = dir.path() / "out";
  fs::create_directories(out);
  fs::create_symlink(dir.path() / "victim", out / ".piezobench.lock");
  const std::string e = test::input_error([&] { const OutputLock lock(out); });
  EXPECT_TRUE(test::contains(e, "symbolic link")) << e;
  EXPECT_FALSE(fs::exists(dir.path() / "victim"));  // issue 35: a file was created at the link's target
  fs::remove(out / ".piezobench.lock");
  {
    const OutputLock lock(out);
    EXPECT_TRUE(fs::is_regular_file(out / ".piezobench.lock"));
  }
  EXPECT_FALSE(fs::exists(out / ".piezobench.lock"));
}

// The pid of a process that has ended (a child that exited; until the kernel recycles it).
long dead_pid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);
  return child;
}

TEST(OutputLock, RemovesWhatDeadRunsLeftAndNothingElse) {
  TempDir dir;
  const fs::path out = dir.path() / "out";
  const long dead = dead_pid();
  fs::create_directories(out / ("data"));
  fs::create_directories(out / (".staging-" + std::to_string(dead) + "-0"));
  std::ofstream(out / (".staging-" + std::to_string(dead) + "-0") / "results.mat") << "partial";
  std::ofstream(out / "data" / (".unit1_frf.mat.tmp-" + std::to_string(dead) + "-3-0badcafe.mat")) << "partial";
  std::ofstream(out / (".results.json.tmp-" + std::to_string(dead) + "-0-12345678.json")) << "partial";
  // Kept: a live process's (pid 1), files that only look alike, the results.
  fs::create_directories(out / ".staging-1-0");
  std::ofstream(out / "data" / ".notes.tmp-abc") << "x";
  std::ofstream(out / "results.json") << "{}";
  { const OutputLock lock(out); }
  EXPECT_EQ(names(out), (std::vector<std::string>{".staging-1-0", "data", "results.json"}));
  EXPECT_EQ(names(out / "data"), (std::vector<std::string>{".notes.tmp-abc"}));
}

}  // namespace
}  // namespace piezobench::io
