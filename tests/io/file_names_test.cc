#include <gtest/gtest.h>

#include "robomach/io/file_names.h"

namespace robomach::io {
namespace {

TEST(SafeFileStems, KeepsSafeIdsAndReplacesSeparatorsDotsAndOtherCharacters) {
  const auto s = SafeFileStems({"P1", "kr210_pose-3.a", "../escaped", "sub/dir", "a\\b", "P 1", "", ".hidden",
                                "a..b", "ü"});
  EXPECT_EQ(s.at("P1"), "P1");
  EXPECT_EQ(s.at("kr210_pose-3.a"), "kr210_pose-3.a");
  EXPECT_EQ(s.at("../escaped"), "___escaped");
  EXPECT_EQ(s.at("sub/dir"), "sub_dir");
  EXPECT_EQ(s.at("a\\b"), "a_b");
  EXPECT_EQ(s.at("P 1"), "P_1");
  EXPECT_EQ(s.at(""), "_");
  EXPECT_EQ(s.at(".hidden"), "_hidden");
  EXPECT_EQ(s.at("a..b"), "a._b");
  EXPECT_EQ(s.at("ü"), "__");  // two UTF-8 bytes
  for (const auto& [id, stem] : s) {
    EXPECT_EQ(stem.find('/'), std::string::npos) << id;
    EXPECT_EQ(stem.find(".."), std::string::npos) << id;
    EXPECT_NE(stem.front(), '.') << id;
  }
}

TEST(SafeFileStems, TwoIdsNeverShareAName) {
  // "a_b" is a file name already and keeps it, whichever order the IDs come
  // in; "a/b" and "a b" get suffixes. "Q1" and "q1" would be one file on a
  // case-insensitive file system.
  for (const std::vector<std::string>& ids : {std::vector<std::string>{"a/b", "a b", "a_b", "Q1", "q1"},
                                              std::vector<std::string>{"q1", "Q1", "a_b", "a b", "a/b"}}) {
    const auto s = SafeFileStems(ids);
    EXPECT_EQ(s.at("a_b"), "a_b");
    EXPECT_EQ(s.at("a b"), "a_b_2");
    EXPECT_EQ(s.at("a/b"), "a_b_3");
    EXPECT_EQ(s.at("Q1"), "Q1");
    EXPECT_EQ(s.at("q1"), "q1_2");
  }
  // A suffixed name that is itself an ID is not taken twice.
  const auto t = SafeFileStems({"x/y", "x_y", "x_y_2"});
  EXPECT_EQ(t.at("x_y"), "x_y");
  EXPECT_EQ(t.at("x_y_2"), "x_y_2");
  EXPECT_EQ(t.at("x/y"), "x_y_3");
}

TEST(SafeFileStems, CutsLongIds) {
  const auto s = SafeFileStems({std::string(300, 'p'), std::string(301, 'p')});
  EXPECT_EQ(s.at(std::string(300, 'p')), std::string(100, 'p'));
  EXPECT_EQ(s.at(std::string(301, 'p')), std::string(100, 'p') + "_2");
}

}  // namespace
}  // namespace robomach::io
