#include "robomach/io/yaml_doc.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "robomach/common/errors.h"

namespace robomach::io {
namespace {

// The file's text: "drill:" on line 1, "  hole_axis: sideways" on line 2
// (the value at column 14, 1-based).
YamlDoc Doc() { return YamlDoc::LoadString("drill:\n  hole_axis: sideways\n", "r.yaml"); }

std::string ParseAxis(const std::string& text) {
  if (text != "z") throw std::invalid_argument("expected z, got '" + text + "'");
  return text;
}

TEST(YamlDocChecked, ReturnsWhatTheCallReturns) {
  const YamlDoc d = YamlDoc::LoadString("drill:\n  hole_axis: z\n", "r.yaml");
  const YamlDoc axis = d["drill"]["hole_axis"];
  EXPECT_EQ(axis.Checked([&] { return ParseAxis(axis.String()); }), "z");
  int calls = 0;
  axis.Checked([&] { ++calls; });  // a check that returns nothing
  EXPECT_EQ(calls, 1);
}

// The rethrown error is the node's Error: its file, line and column, its
// key path, then the check's message unchanged.
TEST(YamlDocChecked, RethrowsAtTheNodeWithItsKeyPathAndTheMessage) {
  const YamlDoc d = Doc();
  const YamlDoc axis = d["drill"]["hole_axis"];
  ASSERT_EQ(axis.key_path(), "drill.hole_axis");
  try {
    axis.Checked([&] { return ParseAxis(axis.String()); });
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().path, "r.yaml");
    EXPECT_EQ(e.where().line, 2);
    EXPECT_EQ(e.where().column, 14);
    EXPECT_EQ(e.message(), "drill.hole_axis: expected z, got 'sideways'");
    EXPECT_STREQ(e.what(), "r.yaml:2:14: drill.hole_axis: expected z, got 'sideways'");
    // The same error the node's Error gives: one wording for both.
    EXPECT_STREQ(e.what(), axis.Error("expected z, got 'sideways'").what());
  }
}

// Only E is rethrown at the node: another exception passes unchanged.
TEST(YamlDocChecked, PassesOtherExceptionsUnchanged) {
  const YamlDoc d = Doc();
  const YamlDoc axis = d["drill"]["hole_axis"];
  EXPECT_THROW(axis.Checked([]() -> int { throw std::runtime_error("solver"); }), std::runtime_error);
  try {
    axis.Checked<std::out_of_range>([]() -> int { throw std::invalid_argument("not this one"); });
    FAIL() << "expected std::invalid_argument";
  } catch (const InputError&) {
    FAIL() << "rethrown at the node although E is std::out_of_range";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "not this one");
  }
  EXPECT_THROW(axis.Checked<std::out_of_range>([]() -> int { throw std::out_of_range("index"); }), InputError);
}

}  // namespace
}  // namespace robomach::io
