// Tests of the all-or-nothing output folder: the lock refuses a second holder, staged files reach
// the folder only on commit.
#include "piezobench/io/output_dir.hpp"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace piezobench::io
