#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

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

}  // namespace
}  // namespace robomach::io
