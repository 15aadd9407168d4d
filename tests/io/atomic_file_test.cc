#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <algorithm>
#include <fstream>
#include <vector>

#include "robomach/common/errors.h"
#include "robomach/io/atomic_file.h"
#include "test_support.h"

namespace robomach::io {
namespace {

namespace fs = std::filesystem;
using robomach::testing::CaptureError;
using robomach::testing::TempDir;
using ::testing::HasSubstr;

TEST(AtomicFile, WritesCompletelyOrLeavesTheOldFileAndNoTemporary) {
  const std::string dir = TempDir("atomic");
  const std::string path = dir + "/out.csv";
  WriteFileAtomically(path, "first\n");
  // A writer that fails half-way: the old content stays, no temporary remains.
  EXPECT_THAT(CaptureError([&] {
                WriteFileAtomically(path, [](std::ostream& os) {
                  os << "partial";
                  throw std::runtime_error("computation failed");
                });
              }),
              HasSubstr("computation failed"));
  std::ifstream in(path);
  std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(content, "first\n");
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 1);
}

TEST(AtomicFile, MissingDirectoryIsAnOutputError) {
  EXPECT_THROW(WriteFileAtomically("/nonexistent-dir/x.csv", "x"), OutputError);
}

std::string Read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Every entry of `dir` (temporary files included), sorted.
std::vector<std::string> Entries(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(AtomicFile, SyncFileAndDirectory) {
  // fsync of a real file and its directory succeeds; a missing path is an
  // OutputError naming it (the error path the writers rely on).
  const std::string dir = TempDir("atomic_sync");
  WriteFileAtomically(dir + "/a.txt", "a");
  EXPECT_NO_THROW(SyncFile(dir + "/a.txt"));
  EXPECT_NO_THROW(SyncDirectory(dir));
  EXPECT_THAT(CaptureError([&] { SyncFile(dir + "/missing.txt"); }), HasSubstr("missing.txt"));
  EXPECT_THROW(SyncDirectory(dir + "/missing"), OutputError);
  EXPECT_EQ(Entries(dir), std::vector<std::string>{"a.txt"});
}

TEST(OutputRun, AllOutputsAppearOnlyAtCommit) {
  const std::string dir = TempDir("run_commit");
  {
    OutputRun run;
    EXPECT_EQ(OutputRun::Active(), &run);
    WriteFileAtomically(dir + "/a.csv", "a\n");
    WriteFileAtomically(dir + "/b.json", "{}");
    // Staged: only temporary files, written and fsync'ed, none under its name.
    EXPECT_FALSE(fs::exists(dir + "/a.csv"));
    EXPECT_FALSE(fs::exists(dir + "/b.json"));
    EXPECT_EQ(Entries(dir).size(), 2u);
    EXPECT_EQ(run.staged_count(), 2);
    run.Commit();
    EXPECT_EQ(OutputRun::Active(), nullptr);
  }
  EXPECT_EQ(Entries(dir), (std::vector<std::string>{"a.csv", "b.json"}));
  EXPECT_EQ(Read(dir + "/a.csv"), "a\n");
  EXPECT_EQ(Read(dir + "/b.json"), "{}");
}

TEST(OutputRun, FailingThirdOutputLeavesNoneOfTheThree) {
  const std::string dir = TempDir("run_third_fails");
  EXPECT_THAT(CaptureError([&] {
                OutputRun run;
                WriteFileAtomically(dir + "/one.csv", "1");
                WriteFileAtomically(dir + "/two.png", "2");
                WriteFileAtomically(dir + "/missing/three.json", "3");  // no such folder
                run.Commit();
              }),
              HasSubstr("missing"));
  EXPECT_TRUE(Entries(dir).empty());
  EXPECT_EQ(OutputRun::Active(), nullptr);
}

TEST(OutputRun, ThrowingWriterOrNoCommitLeavesNothing) {
  const std::string dir = TempDir("run_no_commit");
  EXPECT_THROW(
      {
        OutputRun run;
        WriteFileAtomically(dir + "/one.csv", "1");
        WriteFileAtomically(dir + "/two.csv", [](std::ostream& os) {
          os << "half";
          throw std::runtime_error("computation failed");
        });
      },
      std::runtime_error);
  EXPECT_TRUE(Entries(dir).empty());
  {
    OutputRun run;  // an error exit: destroyed without Commit
    WriteFileAtomically(dir + "/one.csv", "1");
  }
  EXPECT_TRUE(Entries(dir).empty());
}

TEST(OutputRun, RenameFailureAtCommitRestoresPreviousFiles) {
  // A directory stands where the third file must go. The first two targets
  // exist from an earlier run: after the failed commit they hold their old
  // content, and no staged or backup file is left.
  const std::string dir = TempDir("run_commit_fails");
  WriteFileAtomically(dir + "/one.csv", "old 1");
  WriteFileAtomically(dir + "/two.csv", "old 2");
  fs::create_directory(dir + "/three.csv");
  EXPECT_THAT(CaptureError([&] {
                OutputRun run;
                WriteFileAtomically(dir + "/one.csv", "new 1");
                WriteFileAtomically(dir + "/two.csv", "new 2");
                WriteFileAtomically(dir + "/three.csv", "new 3");
                run.Commit();
              }),
              HasSubstr("three.csv"));
  EXPECT_EQ(Read(dir + "/one.csv"), "old 1");
  EXPECT_EQ(Read(dir + "/two.csv"), "old 2");
  EXPECT_EQ(Entries(dir), (std::vector<std::string>{"one.csv", "three.csv", "two.csv"}));
}

TEST(OutputRun, RenameFailingAfterOthersRollsThemBack) {
  // The third staged file vanishes before the commit (as if another process
  // removed it), so its rename fails after the first two were renamed: the
  // first (which existed) gets its old content back, the second (new) goes.
  const std::string dir = TempDir("run_rollback");
  WriteFileAtomically(dir + "/one.csv", "old 1");
  EXPECT_THAT(CaptureError([&] {
                OutputRun run;
                WriteFileAtomically(dir + "/one.csv", "new 1");
                WriteFileAtomically(dir + "/two.csv", "new 2");
                WriteFileAtomically(dir + "/three.csv", "new 3");
                for (const std::string& name : Entries(dir)) {
                  if (name.rfind(".three.csv.", 0) == 0) fs::remove(dir + "/" + name);
                }
                run.Commit();
              }),
              HasSubstr("three.csv: cannot rename the staged file into place"));
  EXPECT_EQ(Read(dir + "/one.csv"), "old 1");
  EXPECT_EQ(Entries(dir), std::vector<std::string>{"one.csv"});
}

TEST(OutputRun, CommitReplacesExistingFilesAndLeavesNoBackups) {
  const std::string dir = TempDir("run_replace");
  WriteFileAtomically(dir + "/one.csv", "old");
  {
    OutputRun run;
    WriteFileAtomically(dir + "/one.csv", "first");
    WriteFileAtomically(dir + "/one.csv", "second");  // written twice: the later wins
    run.Commit();
  }
  EXPECT_EQ(Read(dir + "/one.csv"), "second");
  EXPECT_EQ(Entries(dir), std::vector<std::string>{"one.csv"});
}

TEST(OutputRun, DirectoriesCreatedByAFailedRunAreRemoved) {
  const std::string dir = TempDir("run_dirs");
  {
    OutputRun run;
    EnsureDirectory(dir + "/report/sub");
    WriteFileAtomically(dir + "/report/sub/summary.json", "{}");
    EXPECT_TRUE(fs::is_directory(dir + "/report/sub"));
  }  // no commit
  EXPECT_TRUE(Entries(dir).empty());
  {
    OutputRun run;
    EnsureDirectory(dir + "/report");
    WriteFileAtomically(dir + "/report/summary.json", "{}");
    run.Commit();
  }
  EXPECT_EQ(Read(dir + "/report/summary.json"), "{}");
}

TEST(OutputRun, DashIsStandardOutputWrittenAtCommit) {
  const std::string dir = TempDir("run_stdout");
  ::testing::internal::CaptureStdout();
  {
    OutputRun run;
    WriteFileAtomically("-", "line 1\n");
    WriteFileAtomically(dir + "/file.csv", "x");
    WriteFileAtomically("-", [](std::ostream& os) { os << "line 2\n"; });
  }  // no commit: nothing printed, no file
  EXPECT_EQ(::testing::internal::GetCapturedStdout(), "");
  EXPECT_TRUE(Entries(dir).empty());

  ::testing::internal::CaptureStdout();
  {
    OutputRun run;
    WriteFileAtomically("-", "line 1\n");
    WriteFileAtomically(dir + "/file.csv", "x");
    WriteFileAtomically("-", [](std::ostream& os) { os << "line 2\n"; });
    EXPECT_EQ(run.staged_count(), 3);
    run.Commit();
  }
  EXPECT_EQ(::testing::internal::GetCapturedStdout(), "line 1\nline 2\n");
  EXPECT_EQ(Read(dir + "/file.csv"), "x");

  // Without a run, "-" goes to stdout at once (library callers).
  ::testing::internal::CaptureStdout();
  WriteFileAtomically("-", "now\n");
  EXPECT_EQ(::testing::internal::GetCapturedStdout(), "now\n");
  EXPECT_FALSE(fs::exists("-"));
}

}  // namespace
}  // namespace robomach::io
