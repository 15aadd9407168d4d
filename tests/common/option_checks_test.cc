#include "robomach/common/option_checks.h"

#include <gtest/gtest.h>

#include <string>

#include "robomach/common/errors.h"

namespace robomach {
namespace {

// An options struct names a field as its caller says (a tool: its option);
// a field the caller did not rename goes by its own name.
struct DemoOptions : FieldNames {
  double fmax_hz{5000.0};
};

TEST(FieldNames, NamesAFieldAsTheCallerSaysElseByItsOwnName) {
  DemoOptions o;
  EXPECT_EQ(o.Name("fmax_hz"), "fmax_hz");
  o.names["fmax_hz"] = "--fmax-hz";
  EXPECT_EQ(o.Name("fmax_hz"), "--fmax-hz");
  EXPECT_EQ(o.Name("averages"), "averages");
}

TEST(CheckOptionRange, NamesTheFieldTheValueAndTheBound) {
  EXPECT_NO_THROW(CheckOptionRange("min_snr", 3.0, 0.001, 1e6));
  try {
    CheckOptionRange("min_snr", 0.0, 0.001, 1e6);
    FAIL() << "expected OptionError";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.field(), "min_snr");
    EXPECT_STREQ(e.what(), "min_snr: expected a value in [0.001, 1e+06], got 0");
  }
}

}  // namespace
}  // namespace robomach
