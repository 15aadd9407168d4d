// Issue #36, one vocabulary: every options struct of io has a Validate()
// that passes its defaults and refuses a bad value of each checked field
// with an OptionError naming the field, its value and the bound.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "options_validate_support.h"
#include "robomach/common/errors.h"
#include "robomach/io/cad_face.h"
#include "robomach/io/kq_yaml.h"

namespace robomach::io {
namespace {

using ::testing::HasSubstr;

using robomach::testing::ExpectRefused;

TEST(OptionsValidate, DefaultsPass) {
  EXPECT_NO_THROW(CadReadOptions{}.Validate());
  EXPECT_NO_THROW(KqYamlOptions{}.Validate());
}

TEST(OptionsValidate, CadReadOptionsNameFieldValueAndBound) {
  using O = CadReadOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.unit_scale = 0; }, "unit_scale",
                   {"unit_scale: expected a finite value > 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.unit_scale = std::numeric_limits<double>::infinity(); }, "unit_scale",
                   {"> 0", "got inf"});
}

TEST(OptionsValidate, KqYamlOptionsNameFieldValueAndBound) {
  using O = KqYamlOptions;
  O d;
  d.header_comments = {"one line"};
  EXPECT_NO_THROW(d.Validate());
  ExpectRefused<O>(d, [](O& o) { o.header_comments.push_back("two\nlines"); }, "header_comments",
                   {"header_comments: expected one line per comment", "two\nlines"});
}

}  // namespace
}  // namespace robomach::io
